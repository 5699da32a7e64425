// Tests for raster/Rasterizer: coverage, fill rule, sub-pixel precision, clipping, perspective
// interpolation, depth test, culling, submission order, viewport borders and determinism. Every
// expectation comes from an oracle that does not reuse the rasterizer's arithmetic:
// - Closed forms first: pixel-centre lattices for the fill rule, ray-plane intersections for
//   interpolation and depth, "each pixel exactly once" for meshes that cover the whole screen.
// - 2D coverage oracle (oracleCovers): point-in-triangle in double at the pixel centre, with the
//   top-left tie rule written as a symbolic perturbation: the sample moves by (e, e^2), e -> 0+,
//   in screen space (y down). A sample on a left edge (interior to its right) or on a horizontal
//   top edge (interior below) then moves inside, one on a right or bottom edge moves outside, and
//   a vertex shared by a fan lands in exactly one triangle. It is exact when every vertex lies on
//   the 1/256-pixel grid (8 sub-pixel bits: snapping is then the identity) and coordinates stay
//   below 2^20 pixels; tests that need exactness build their inputs that way.
// - 3D oracle (viewRayHit): the pixel's view ray intersected in double with the ORIGINAL
//   view-space triangle, visible between the near and far planes. Snapping to 1/256 pixel may
//   move a vertex, hence an edge, by up to sqrt(2)/512 pixel, so pixels whose centre lies within
//   kEdgeBandPixels of a boundary of the visible part are not compared. Interpolated values get
//   the matching tolerance: the change of the analytic value over that distance.
// Conventions used by the helpers: screen pixels with y down, ndc.x = 2 sx / W - 1,
// ndc.y = 1 - 2 sy / H, clip w = 1 unless a camera is involved; view space is right-handed with
// the camera at the origin looking down -z (glm::perspectiveRH_ZO).
// A failed image comparison writes _img, _ref and _error images (binary PPM) under
// <build>/test-output/raster/<suite.test>/ and prints their paths.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "raster/Rasterizer.h"
#include "tests/raster/DrawRecording.h"

namespace raster {
namespace {

namespace fs = std::filesystem;

static_assert(kSubpixelBits == 8, "the exact-grid inputs below assume 1/256-pixel snapping");

// Sub-pixel grid step in pixels; vertices on this grid are exact in the rasterizer's fixed point.
constexpr double kSubpixel = 1.0 / 256.0;
// Largest distance by which snapping may move a vertex: half a step along x and along y.
constexpr double kSnapRadiusPixels = 1.4142135623730951 / 512.0;
// Pixels whose centre lies closer than this to a boundary are not compared with a 3D oracle.
constexpr double kEdgeBandPixels = 1.0 / 256.0;
constexpr uint32_t kNoTriangle = 0xffffffffu;

// ---------------------------------------------------------------------------------------------
// Deterministic random numbers: identical on every platform (std distributions are not).

class Random {
public:
    explicit Random(uint64_t seed) : mState(seed) {}
    uint64_t next() { // splitmix64
        uint64_t z = (mState += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    int integer(int lo, int hi) { return lo + int(next() % uint64_t(hi - lo + 1)); } // inclusive
    bool coin() { return (next() >> 63) != 0; }
    // A point on the 1/256-pixel grid.
    double onGrid(double lo, double hi) { return std::round(uniform(lo, hi) * 256.0) / 256.0; }

private:
    uint64_t mState;
};

// ---------------------------------------------------------------------------------------------
// Meshes

using Tri2 = std::array<glm::dvec2, 3>;
using Tri3 = std::array<glm::dvec3, 3>;

// Clip-space triangles as the rasterizer takes them.
struct ClipMesh {
    std::vector<glm::vec4> positions;
    std::vector<uint32_t> indices;
    TriangleList list() const { return TriangleList{positions, indices}; }
    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
};

// Triangles in screen space (pixels, y down), each vertex with its NDC depth; w = 1 in clip.
struct ScreenMesh {
    std::vector<glm::dvec2> positions;
    std::vector<float> depths;
    std::vector<uint32_t> indices;

    uint32_t addVertex(glm::dvec2 p, float depthNdc = 0.5f) {
        positions.push_back(p);
        depths.push_back(depthNdc);
        return uint32_t(positions.size() - 1);
    }
    void addTriangle(uint32_t a, uint32_t b, uint32_t c) {
        indices.insert(indices.end(), {a, b, c});
    }
    void addTriangle(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, float depthNdc = 0.5f) {
        addTriangle(addVertex(a, depthNdc), addVertex(b, depthNdc), addVertex(c, depthNdc));
    }
    // Axis-aligned rectangle [x0, x1] x [y0, y1] as two triangles.
    void addRectangle(double x0, double y0, double x1, double y1, float depthNdc = 0.5f) {
        addTriangle({x0, y0}, {x1, y1}, {x1, y0}, depthNdc);
        addTriangle({x0, y0}, {x0, y1}, {x1, y1}, depthNdc);
    }
    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
    Tri2 triangle(uint32_t t) const {
        return {positions[indices[3 * t]], positions[indices[3 * t + 1]],
                positions[indices[3 * t + 2]]};
    }
};

// Screen position to NDC: ndc.x = 2 sx / W - 1, ndc.y = 1 - 2 sy / H (y up in NDC).
glm::dvec2 ndcFromScreen(glm::dvec2 s, int width, int height) {
    return {2.0 * s.x / width - 1.0, 1.0 - 2.0 * s.y / height};
}

ClipMesh toClip(const ScreenMesh& mesh, int width, int height) {
    ClipMesh clip;
    clip.indices = mesh.indices;
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::dvec2 ndc = ndcFromScreen(mesh.positions[i], width, height);
        clip.positions.emplace_back(float(ndc.x), float(ndc.y), mesh.depths[i], 1.0f);
    }
    return clip;
}

// ---------------------------------------------------------------------------------------------
// 2D coverage oracle

double cross(glm::dvec2 a, glm::dvec2 b) {
    return a.x * b.y - a.y * b.x;
}

// Does the triangle cover sample p? See the file comment: exact for 1/256-grid inputs, top-left
// ties resolved by moving the sample by (e, e^2).
bool oracleCovers(const Tri2& v, glm::dvec2 p) {
    if (cross(v[1] - v[0], v[2] - v[0]) == 0.0)
        return false; // zero area covers nothing
    for (int i = 0; i < 3; ++i) {
        const glm::dvec2 a = v[i], d = v[(i + 1) % 3] - v[i], opposite = v[(i + 2) % 3];
        const double interiorSide = cross(d, opposite - a);
        double side = cross(d, p - a);
        if (side == 0.0) {
            // cross(d, (e, e^2)) = -d.y e + d.x e^2: the e term decides unless d is horizontal.
            side = d.y != 0.0 ? -d.y : d.x;
        }
        if ((side > 0.0) != (interiorSide > 0.0))
            return false;
    }
    return true;
}

// ---------------------------------------------------------------------------------------------
// Images and evidence

template <class T> struct Image {
    int width = 0;
    int height = 0;
    std::vector<T> pixels;
    Image() = default;
    Image(int w, int h, T value = T{}) : width(w), height(h), pixels(size_t(w) * h, value) {}
    T& at(int x, int y) { return pixels[size_t(y) * width + x]; }
    const T& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

fs::path evidenceFolder() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
#ifdef TESTBED_BINARY_DIR
    const fs::path root = fs::path(TESTBED_BINARY_DIR) / "test-output" / "raster";
#else
    const fs::path root = fs::temp_directory_path() / "testbed-test-output" / "raster";
#endif
    const fs::path dir = root / name;
    fs::create_directories(dir);
    return dir;
}

using Rgb = std::array<uint8_t, 3>;

void writePpm(const fs::path& path, int width, int height,
              const std::function<Rgb(int, int)>& rgb) {
    std::ofstream file(path, std::ios::binary);
    file << "P6\n" << width << " " << height << "\n255\n";
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const Rgb c = rgb(x, y);
            file.write(reinterpret_cast<const char*>(c.data()), 3);
        }
}

// Counts as grey levels (0 black, 1 mid grey, 2+ white); triangle ids as hashed colours.
Rgb visualise(uint32_t value, bool isId) {
    if (!isId) {
        const uint8_t g = uint8_t(std::min<uint32_t>(255, value * 128));
        return {g, g, g};
    }
    if (value == kNoTriangle)
        return {0, 0, 0};
    const uint32_t h = value * 2654435761u;
    return {uint8_t(64 + (h >> 24) % 192), uint8_t(64 + (h >> 16) % 192),
            uint8_t(64 + (h >> 8) % 192)};
}

// Compares img with ref pixel by pixel, except where ignore is set; on a mismatch writes
// evidence images (error: red = img above ref, blue = below, green = ignored) and fails with the
// first mismatching pixels and the image paths.
void expectSameImage(const Image<uint32_t>& img, const Image<uint32_t>& ref,
                     const std::string& label, bool isId = false,
                     const Image<uint8_t>* ignore = nullptr) {
    ASSERT_EQ(img.width, ref.width);
    ASSERT_EQ(img.height, ref.height);
    size_t mismatches = 0;
    std::ostringstream first;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            if (ignore && ignore->at(x, y))
                continue;
            if (img.at(x, y) != ref.at(x, y)) {
                if (mismatches < 8)
                    first << " (" << x << "," << y << "): got " << img.at(x, y) << " expected "
                          << ref.at(x, y) << ";";
                ++mismatches;
            }
        }
    if (mismatches == 0)
        return;
    const fs::path dir = evidenceFolder();
    const fs::path imgPath = dir / (label + "_img.ppm"), refPath = dir / (label + "_ref.ppm"),
                   errorPath = dir / (label + "_error.ppm");
    writePpm(imgPath, img.width, img.height,
             [&](int x, int y) { return visualise(img.at(x, y), isId); });
    writePpm(refPath, ref.width, ref.height,
             [&](int x, int y) { return visualise(ref.at(x, y), isId); });
    writePpm(errorPath, img.width, img.height, [&](int x, int y) -> Rgb {
        if (ignore && ignore->at(x, y))
            return {0, 96, 0};
        if (img.at(x, y) == ref.at(x, y))
            return {0, 0, 0};
        return img.at(x, y) > ref.at(x, y) ? Rgb{255, 0, 0} : Rgb{0, 0, 255};
    });
    ADD_FAILURE() << label << ": " << mismatches << " pixels differ;" << first.str()
                  << "\n  evidence: " << imgPath.string() << "\n            " << refPath.string()
                  << "\n            " << errorPath.string();
}

// ---------------------------------------------------------------------------------------------
// Running the rasterizer

// Runs fn inside an arena of the given thread count (0: TBB's default).
template <class Fn> void withThreads(int threadCount, Fn&& fn) {
    if (threadCount <= 0) {
        fn();
        return;
    }
    tbb::task_arena arena(threadCount);
    arena.execute([&] { fn(); });
}

struct CoverageResult {
    Image<uint32_t> count;        // fragments per pixel
    Image<uint32_t> lastTriangle; // triangle of the last fragment, kNoTriangle if none
    uint64_t fragmentsOutsideViewport = 0;
    uint64_t nonFiniteFragments = 0; // NaN or infinite depth or barycentrics
    RasterStats stats;
};

bool finiteFragment(const Fragment& f) {
    return std::isfinite(f.depth) && std::isfinite(f.barycentric.x) &&
           std::isfinite(f.barycentric.y) && std::isfinite(f.barycentric.z);
}

// Draws with the given state (no depth buffer unless one is passed) and records coverage.
CoverageResult rasterizeCoverage(int width, int height, const ClipMesh& mesh,
                                 RasterState state = {CullMode::None, DepthTest::Always, false},
                                 float* depth = nullptr, int threadCount = 0) {
    CoverageResult result;
    result.count = Image<uint32_t>(width, height, 0);
    result.lastTriangle = Image<uint32_t>(width, height, kNoTriangle);
    std::atomic<uint64_t> outside{0}, nonFinite{0};
    Rasterizer rasterizer(width, height);
    withThreads(threadCount, [&] {
        rasterizer.draw(mesh.list(), state, depth, [&](const Fragment& f) {
            if (f.x < 0 || f.y < 0 || f.x >= width || f.y >= height) {
                ++outside;
                return;
            }
            if (!finiteFragment(f))
                ++nonFinite;
            ++result.count.at(f.x, f.y);
            result.lastTriangle.at(f.x, f.y) = f.triangle;
        });
    });
    result.fragmentsOutsideViewport = outside;
    result.nonFiniteFragments = nonFinite;
    result.stats = rasterizer.lastStats();
    return result;
}

struct OracleCoverage {
    Image<uint32_t> count;
    Image<uint32_t> lastTriangle;
};

// Brute force over each triangle's (generous) bounding box, triangles in submission order.
OracleCoverage oracleCoverage(const ScreenMesh& mesh, int width, int height) {
    OracleCoverage oracle{Image<uint32_t>(width, height, 0),
                          Image<uint32_t>(width, height, kNoTriangle)};
    for (uint32_t t = 0; t < mesh.triangleCount(); ++t) {
        const Tri2 v = mesh.triangle(t);
        const double minX = std::min({v[0].x, v[1].x, v[2].x}),
                     maxX = std::max({v[0].x, v[1].x, v[2].x});
        const double minY = std::min({v[0].y, v[1].y, v[2].y}),
                     maxY = std::max({v[0].y, v[1].y, v[2].y});
        const int x0 = int(std::max(0.0, std::floor(minX) - 1)),
                  x1 = int(std::min(width - 1.0, std::ceil(maxX) + 1));
        const int y0 = int(std::max(0.0, std::floor(minY) - 1)),
                  y1 = int(std::min(height - 1.0, std::ceil(maxY) + 1));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                if (oracleCovers(v, {x + 0.5, y + 0.5})) {
                    ++oracle.count.at(x, y);
                    oracle.lastTriangle.at(x, y) = t;
                }
    }
    return oracle;
}

// Rasterizes a grid-exact screen mesh and compares counts and last triangles with the oracle.
void expectCoverageMatchesOracle(const ScreenMesh& mesh, int width, int height,
                                 const std::string& label, CullMode cull = CullMode::None) {
    const CoverageResult got = rasterizeCoverage(width, height, toClip(mesh, width, height),
                                                 {cull, DepthTest::Always, false});
    const OracleCoverage ref = oracleCoverage(mesh, width, height);
    EXPECT_EQ(got.fragmentsOutsideViewport, 0u) << label;
    EXPECT_EQ(got.nonFiniteFragments, 0u) << label;
    expectSameImage(got.count, ref.count, label + "_count");
    expectSameImage(got.lastTriangle, ref.lastTriangle, label + "_last", true);
}

Image<uint32_t> constantImage(int width, int height, uint32_t value) {
    return Image<uint32_t>(width, height, value);
}

// ---------------------------------------------------------------------------------------------
// Perspective camera and the 3D oracle

struct Camera {
    int width = 160;
    int height = 120;
    double fovyRadians = glm::radians(60.0);
    double nearDistance = 0.5;
    double farDistance = 50.0;
    bool reversedZ = false; // depth 1 at the near plane, 0 at the far plane

    double aspect() const { return double(width) / double(height); }
    double tanHalfFovy() const { return std::tan(0.5 * fovyRadians); }
    glm::mat4 clipFromView() const {
        const glm::mat4 standard = glm::perspectiveRH_ZO(float(fovyRadians), float(aspect()),
                                                         float(nearDistance), float(farDistance));
        if (!reversedZ)
            return standard;
        glm::mat4 reverse(1.0f); // z' = w - z
        reverse[2][2] = -1.0f;
        reverse[3][2] = 1.0f;
        return reverse * standard;
    }
    // The point on the view-space plane z = -1 seen through screen position (sx, sy); the view
    // ray through it reaches view distance t (along -z) at t * imagePoint.
    glm::dvec3 imagePoint(double sx, double sy) const {
        const glm::dvec2 ndc = ndcFromScreen({sx, sy}, width, height);
        return {ndc.x * tanHalfFovy() * aspect(), ndc.y * tanHalfFovy(), -1.0};
    }
    double pixelsPerImageUnit() const { return height / (2.0 * tanHalfFovy()); }
    // Zero-to-one depth of a point at view distance d: 0 on the near plane, 1 on the far plane.
    double depthNdc(double d) const {
        const double standard =
            farDistance / (farDistance - nearDistance) * (1.0 - nearDistance / d);
        return reversedZ ? 1.0 - standard : standard;
    }
};

// View-space vertices rounded to float, so that oracle and rasterizer see the same triangle.
Tri3 floatExact(const Tri3& v) {
    Tri3 r;
    for (int i = 0; i < 3; ++i)
        r[i] = glm::dvec3(glm::vec3(v[i]));
    return r;
}

void addViewTriangle(ClipMesh& mesh, const Camera& camera, const Tri3& v) {
    const glm::mat4 clipFromView = camera.clipFromView();
    for (int i = 0; i < 3; ++i) {
        mesh.indices.push_back(uint32_t(mesh.positions.size()));
        mesh.positions.push_back(clipFromView * glm::vec4(glm::vec3(v[i]), 1.0f));
    }
}

double det3(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    return glm::dot(a, glm::cross(b, c));
}

struct RayHit {
    bool visible = false;
    double distance = 0.0; // along -z, i.e. the view depth of the hit
    glm::dvec3 barycentric{0.0};
};

// Intersects the ray from the eye through image point q with the triangle (Cramer's rule on
// t q = v0 + b1 (v1 - v0) + b2 (v2 - v0)); visible when inside and between near and far.
RayHit viewRayHit(const Tri3& v, glm::dvec3 q, const Camera& camera) {
    const glm::dvec3 e1 = v[1] - v[0], e2 = v[2] - v[0], rhs = -v[0];
    const double d = det3(e1, e2, -q);
    RayHit hit;
    if (d == 0.0)
        return hit;
    const double b1 = det3(rhs, e2, -q) / d, b2 = det3(e1, rhs, -q) / d, t = det3(e1, e2, rhs) / d;
    hit.distance = t;
    hit.barycentric = {1.0 - b1 - b2, b1, b2};
    hit.visible =
        b1 >= 0 && b2 >= 0 && b1 + b2 <= 1 && t >= camera.nearDistance && t <= camera.farDistance;
    return hit;
}

// Distance in pixels from image point q to the nearest line that can bound the visible part of
// the triangle on screen: the projections of its three edge lines and of its intersections with
// the near and far planes.
double boundaryDistancePixels(const Tri3& v, glm::dvec3 q, const Camera& camera) {
    double nearest = std::numeric_limits<double>::infinity();
    auto lineDistance = [&](glm::dvec3 m, double offset) { // line m.x u + m.y v - m.z = offset
        const double len = std::hypot(m.x, m.y);
        if (len > 0)
            nearest = std::min(nearest, std::abs(glm::dot(m, q) - offset) / len);
    };
    for (int i = 0; i < 3; ++i)
        lineDistance(glm::cross(v[i], v[(i + 1) % 3]), 0.0);
    const glm::dvec3 normal = glm::cross(v[1] - v[0], v[2] - v[0]);
    // The ray through q meets the triangle's plane at the distance t with
    // t dot(normal, q) = dot(normal, v0).
    lineDistance(normal, glm::dot(normal, v[0]) / camera.nearDistance);
    lineDistance(normal, glm::dot(normal, v[0]) / camera.farDistance);
    return nearest * camera.pixelsPerImageUnit();
}

// Front-facing seen from the eye: the CCW side (normal (v1-v0)x(v2-v0)) points at the camera.
bool facesCamera(const Tri3& v) {
    return glm::dot(glm::cross(v[1] - v[0], v[2] - v[0]), -v[0]) > 0.0;
}

// Fragment record used by the 3D tests.
struct FragmentImage {
    Image<uint32_t> count;
    std::vector<Fragment> last; // per pixel
    uint64_t outside = 0;
    RasterStats stats;
};

FragmentImage rasterizeFragments(int width, int height, const ClipMesh& mesh,
                                 CullMode cull = CullMode::None) {
    FragmentImage result{
        Image<uint32_t>(width, height, 0), std::vector<Fragment>(size_t(width) * height), 0, {}};
    std::atomic<uint64_t> outside{0};
    Rasterizer rasterizer(width, height);
    rasterizer.draw(mesh.list(), {cull, DepthTest::Always, false}, nullptr, [&](const Fragment& f) {
        if (f.x < 0 || f.y < 0 || f.x >= width || f.y >= height) {
            ++outside;
            return;
        }
        ++result.count.at(f.x, f.y);
        result.last[size_t(f.y) * width + f.x] = f;
    });
    result.outside = outside;
    result.stats = rasterizer.lastStats();
    return result;
}

// Renders one view-space triangle and compares it with the 3D oracle: coverage outside the
// edge band, facing, perspective-correct barycentrics and depth. Returns the number of pixels
// the oracle sees covered (outside the band), so callers can check a test is not vacuous.
size_t expectViewTriangleMatchesOracle(const Camera& camera, const Tri3& triangle,
                                       const std::string& label) {
    const Tri3 v = floatExact(triangle);
    ClipMesh mesh;
    addViewTriangle(mesh, camera, v);
    const FragmentImage got = rasterizeFragments(camera.width, camera.height, mesh);
    EXPECT_EQ(got.outside, 0u) << label;

    Image<uint32_t> ref(camera.width, camera.height, 0);
    Image<uint8_t> band(camera.width, camera.height, 0);
    size_t visible = 0, badFacing = 0, badBarycentric = 0, badDepth = 0;
    double worstBarycentric = 0, worstDepth = 0;
    const bool front = facesCamera(v);
    const double h = 1.0 / 256.0; // finite-difference step for the snapping tolerance, pixels
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
            const glm::dvec3 q = camera.imagePoint(x + 0.5, y + 0.5);
            const RayHit hit = viewRayHit(v, q, camera);
            ref.at(x, y) = hit.visible ? 1 : 0;
            band.at(x, y) = boundaryDistancePixels(v, q, camera) < kEdgeBandPixels;
            if (band.at(x, y) || !hit.visible)
                continue;
            ++visible;
            if (got.count.at(x, y) != 1)
                continue; // reported by the image comparison
            const Fragment& f = got.last[size_t(y) * camera.width + x];
            if (f.frontFacing != front)
                ++badFacing;
            // Snapping turns the sample into one within kSnapRadiusPixels of it (see file
            // comment), so allow the oracle's change over that distance, from central differences.
            const RayHit hx0 = viewRayHit(v, camera.imagePoint(x + 0.5 - h, y + 0.5), camera);
            const RayHit hx1 = viewRayHit(v, camera.imagePoint(x + 0.5 + h, y + 0.5), camera);
            const RayHit hy0 = viewRayHit(v, camera.imagePoint(x + 0.5, y + 0.5 - h), camera);
            const RayHit hy1 = viewRayHit(v, camera.imagePoint(x + 0.5, y + 0.5 + h), camera);
            for (int i = 0; i < 3; ++i) {
                const double gradient = std::hypot(hx1.barycentric[i] - hx0.barycentric[i],
                                                   hy1.barycentric[i] - hy0.barycentric[i]) /
                                        (2 * h);
                const double tolerance = 1e-4 + 1.5 * gradient * kSnapRadiusPixels;
                const double error = std::abs(double(f.barycentric[i]) - hit.barycentric[i]);
                worstBarycentric = std::max(worstBarycentric, error / tolerance);
                if (error > tolerance)
                    ++badBarycentric;
            }
            const double depthGradient =
                std::hypot(camera.depthNdc(hx1.distance) - camera.depthNdc(hx0.distance),
                           camera.depthNdc(hy1.distance) - camera.depthNdc(hy0.distance)) /
                (2 * h);
            const double depthTolerance = 2e-6 + 1.5 * depthGradient * kSnapRadiusPixels;
            const double depthError = std::abs(double(f.depth) - camera.depthNdc(hit.distance));
            worstDepth = std::max(worstDepth, depthError / depthTolerance);
            if (depthError > depthTolerance)
                ++badDepth;
        }
    expectSameImage(got.count, ref, label, false, &band);
    EXPECT_EQ(badFacing, 0u) << label;
    EXPECT_EQ(badBarycentric, 0u) << label << ": worst error / tolerance " << worstBarycentric;
    EXPECT_EQ(badDepth, 0u) << label << ": worst error / tolerance " << worstDepth;
    return visible;
}

// =============================================================================================
// 0. Construction

TEST(RasterizerConstruction, RejectsViewportsOutsideTheSupportedRange) {
    EXPECT_THROW(Rasterizer(0, 10), std::invalid_argument);
    EXPECT_THROW(Rasterizer(10, -1), std::invalid_argument);
    EXPECT_THROW(Rasterizer(kMaxViewportSize + 1, 1), std::invalid_argument);
    const Rasterizer largest(kMaxViewportSize, 1);
    EXPECT_EQ(largest.tileCountX(), kMaxViewportSize / kTileSize);
    const Rasterizer odd(2 * kTileSize + 5, kTileSize + 13);
    EXPECT_EQ(odd.tileCountX(), 3);
    EXPECT_EQ(odd.tileCountY(), 2);
}

// =============================================================================================
// 1. Watertightness: meshes that cover the screen cover each pixel exactly once.

TEST(RasterWatertight, JitteredGridCoversEveryPixelOnce) {
    const int width = 200, height = 150, cellsX = 23, cellsY = 17;
    Random random(11);
    const double cellW = double(width) / cellsX, cellH = double(height) / cellsY;
    std::vector<glm::dvec2> grid;
    for (int j = 0; j <= cellsY; ++j)
        for (int i = 0; i <= cellsX; ++i) {
            glm::dvec2 p(i * cellW, j * cellH);
            // Interior vertices move by up to 0.2 cell: no triangle can fold over (it would need
            // 0.35 cell), and the positions are arbitrary floats, not on the sub-pixel grid.
            if (i > 0 && i < cellsX)
                p.x += random.uniform(-0.2, 0.2) * cellW;
            if (j > 0 && j < cellsY)
                p.y += random.uniform(-0.2, 0.2) * cellH;
            grid.push_back(p);
        }
    ClipMesh mesh;
    for (const glm::dvec2& p : grid) {
        // Homogeneous scale by a random w > 0: same point on screen, different clip coordinates.
        const glm::dvec2 ndc = ndcFromScreen(p, width, height);
        const float w = float(random.uniform(0.25, 4.0));
        mesh.positions.emplace_back(float(ndc.x) * w, float(ndc.y) * w, 0.5f * w, w);
    }
    auto vertex = [&](int i, int j) { return uint32_t(j * (cellsX + 1) + i); };
    for (int j = 0; j < cellsY; ++j)
        for (int i = 0; i < cellsX; ++i) {
            uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1),
                     d = vertex(i, j + 1);
            std::array<std::array<uint32_t, 3>, 2> tris =
                ((i + j) % 2) ? std::array<std::array<uint32_t, 3>, 2>{{{a, b, c}, {a, c, d}}}
                              : std::array<std::array<uint32_t, 3>, 2>{{{a, b, d}, {b, c, d}}};
            for (auto t : tris) {
                ASSERT_GT(cross(grid[t[1]] - grid[t[0]], grid[t[2]] - grid[t[0]]), 0.0)
                    << "mesh folded";
                if (random.coin())
                    std::swap(t[1], t[2]); // mixed windings, culling off
                mesh.indices.insert(mesh.indices.end(), t.begin(), t.end());
            }
        }
    const CoverageResult got = rasterizeCoverage(width, height, mesh);
    EXPECT_EQ(got.fragmentsOutsideViewport, 0u);
    expectSameImage(got.count, constantImage(width, height, 1), "grid");
}

// A fan of many thin triangles around a centre vertex, rim on a rectangle enclosing the screen.
ClipMesh screenCoveringFan(int width, int height, glm::dvec2 centre, int rimCount, Random& random) {
    const double margin = 3.0, x0 = -margin, y0 = -margin, x1 = width + margin,
                 y1 = height + margin;
    const double sides[4] = {x1 - x0, y1 - y0, x1 - x0, y1 - y0};
    const double perimeter = 2 * (sides[0] + sides[1]);
    auto rimPoint = [&](double s) -> glm::dvec2 { // walk the rectangle clockwise on screen
        if (s < sides[0])
            return {x0 + s, y0};
        s -= sides[0];
        if (s < sides[1])
            return {x1, y0 + s};
        s -= sides[1];
        if (s < sides[2])
            return {x1 - s, y1};
        s -= sides[2];
        return {x0, y1 - s};
    };
    std::vector<double> params = {0.0, sides[0], sides[0] + sides[1],
                                  2 * sides[0] + sides[1]}; // corners
    for (int i = 0; i < rimCount; ++i)
        params.push_back(random.uniform(0.0, perimeter));
    std::sort(params.begin(), params.end());
    ScreenMesh fan;
    const uint32_t c = fan.addVertex(centre);
    std::vector<uint32_t> rim;
    for (double s : params)
        rim.push_back(fan.addVertex(rimPoint(s)));
    for (size_t i = 0; i < rim.size(); ++i) {
        const uint32_t a = rim[i], b = rim[(i + 1) % rim.size()];
        if (random.coin())
            fan.addTriangle(c, a, b);
        else
            fan.addTriangle(c, b, a);
    }
    return toClip(fan, width, height);
}

// The phase times a draw reports (RasterPhaseTimes, issue 31's breakdown) are each measured,
// non-negative and together no longer than the draw (its parts, not another clock's figure).
TEST(RasterPhaseTimes, ThePhasesOfADrawAreMeasuredAndFitInsideIt) {
    const int width = 640, height = 480;
    Random random(3);
    const ClipMesh mesh = screenCoveringFan(width, height, {301.7, 222.2}, 20000, random);
    Rasterizer rasterizer(width, height);
    std::atomic<uint64_t> fragments{0}; // tiles run in parallel
    const auto start = std::chrono::steady_clock::now();
    rasterizer.draw(mesh.list(), {CullMode::None, DepthTest::Always, false}, nullptr,
                    [&](const Fragment&) { ++fragments; });
    const double drawMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const RasterPhaseTimes& phases = rasterizer.lastPhaseTimes();
    for (double ms : {phases.projectMs, phases.setupMs, phases.binSortMs, phases.traversalMs})
        EXPECT_GE(ms, 0.0);
    EXPECT_GT(phases.setupMs, 0.0);
    EXPECT_GT(phases.traversalMs, 0.0);
    EXPECT_LE(phases.totalMs(), drawMs);
    EXPECT_EQ(fragments.load(), uint64_t(width) * height);
}

TEST(RasterWatertight, ThinFanCoversEveryPixelOnce) {
    const int width = 190, height = 130;
    Random random(5);
    // Centre anywhere, then exactly on a pixel centre, then on a pixel corner.
    const glm::dvec2 centres[] = {{71.3171, 52.9413}, {95.5, 64.5}, {40.0, 100.0}};
    for (const glm::dvec2 centre : centres) {
        const ClipMesh fan = screenCoveringFan(width, height, centre, 1500, random);
        const CoverageResult got = rasterizeCoverage(width, height, fan);
        expectSameImage(got.count, constantImage(width, height, 1),
                        "fan_" + std::to_string(int(centre.x)) + "_" +
                            std::to_string(int(centre.y)));
    }
}

TEST(RasterWatertight, FanInsideTheScreenMatchesOracleExactly) {
    // Rim on a circle, vertices on the 1/256 grid: the union's outer boundary is checked by the
    // exact oracle, which must itself count at most one triangle per pixel.
    const int width = 150, height = 120;
    Random random(7);
    ScreenMesh fan;
    const uint32_t c = fan.addVertex({70.5, 60.5});
    std::vector<uint32_t> rim;
    const int rimCount = 300;
    for (int i = 0; i < rimCount; ++i) {
        const double angle = 2 * M_PI * (i + random.uniform(0.0, 0.8)) / rimCount;
        const double radius = random.uniform(40.0, 55.0);
        rim.push_back(fan.addVertex({std::round((70.5 + radius * std::cos(angle)) * 256) / 256,
                                     std::round((60.5 + radius * std::sin(angle)) * 256) / 256}));
    }
    for (int i = 0; i < rimCount; ++i)
        fan.addTriangle(c, rim[i], rim[(i + 1) % rimCount]);
    const OracleCoverage ref = oracleCoverage(fan, width, height);
    ASSERT_LE(*std::max_element(ref.count.pixels.begin(), ref.count.pixels.end()), 1u);
    expectCoverageMatchesOracle(fan, width, height, "fan_region");
}

// A jittered sphere around the eye: every view ray leaves it exactly once, whatever the
// near-plane, w < 0 and guard-band clipping do to the triangles beside and behind the camera.
// Returns the rasterizer's statistics.
RasterStats expectClosedSurfaceCoversOnce(int rings, int segments, uint64_t seed,
                                          const std::string& label) {
    Camera camera;
    camera.width = 170;
    camera.height = 110;
    camera.fovyRadians = glm::radians(100.0);
    camera.nearDistance = 0.05;
    camera.farDistance = 10.0;
    Random random(seed);
    // A fixed, arbitrary rotation so that no seam lines up with the view axes.
    const glm::dmat3 rotation =
        glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(0.3, 1.0, -0.4))));
    std::vector<glm::dvec3> points;
    auto onSphere = [&](double theta, double phi) {
        const double radius =
            random.uniform(0.7, 1.3); // radial jitter keeps the surface star-shaped
        return rotation * (radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                               std::sin(theta) * std::sin(phi)));
    };
    points.push_back(onSphere(0.0, 0.0)); // north pole
    for (int r = 1; r < rings; ++r)
        for (int s = 0; s < segments; ++s)
            points.push_back(onSphere(M_PI * r / rings, 2 * M_PI * (s + 0.5 * (r % 2)) / segments));
    points.push_back(onSphere(M_PI, 0.0)); // south pole
    auto ringVertex = [&](int r, int s) {
        return uint32_t(1 + (r - 1) * segments + (s % segments));
    };
    const uint32_t south = uint32_t(points.size() - 1);
    ClipMesh mesh;
    for (const glm::dvec3& p : points)
        mesh.positions.push_back(camera.clipFromView() * glm::vec4(glm::vec3(p), 1.0f));
    for (int s = 0; s < segments; ++s) {
        mesh.indices.insert(mesh.indices.end(), {0u, ringVertex(1, s), ringVertex(1, s + 1)});
        mesh.indices.insert(mesh.indices.end(),
                            {south, ringVertex(rings - 1, s + 1), ringVertex(rings - 1, s)});
    }
    for (int r = 1; r + 1 < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = ringVertex(r, s), b = ringVertex(r, s + 1),
                           c = ringVertex(r + 1, s + 1), d = ringVertex(r + 1, s);
            mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
        }
    const CoverageResult got = rasterizeCoverage(camera.width, camera.height, mesh);
    EXPECT_EQ(got.nonFiniteFragments, 0u) << label;
    expectSameImage(got.count, constantImage(camera.width, camera.height, 1), label);
    return got.stats;
}

TEST(RasterWatertight, ClosedSurfaceAroundTheCameraCoversEveryPixelOnce) {
    // Coarse: large triangles reach from behind the eye into view, so set-up must clip them.
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const RasterStats stats =
            expectClosedSurfaceCoversOnce(4, 5, seed, "coarse_" + std::to_string(seed));
        EXPECT_GT(stats.trianglesClipped, 0u);
    }
    expectClosedSurfaceCoversOnce(24, 40, 9, "fine");
}

// =============================================================================================
// 2. Top-left rule on edges and vertices through pixel centres.

// Rectangle with corners on pixel centres (x0 + 0.5, y0 + 0.5) .. (x1 + 0.5, y1 + 0.5): the top
// and left edges are included and the bottom and right ones excluded, so exactly the pixels
// x0 <= px < x1, y0 <= py < y1 are covered, each once (the diagonal is shared).
TEST(RasterTopLeft, RectangleOnPixelCentresCoversHalfOpenRange) {
    const int width = 133, height = 77;
    struct Rect {
        int x0, y0, x1, y1;
    };
    const Rect rects[] = {
        {3, 4, 20, 15}, {60, 10, 70, 70}, {0, 0, 133, 77}, {100, 60, 132, 76}, {5, 5, 6, 6}};
    for (const Rect r : rects)
        for (int variant = 0; variant < 4; ++variant) { // both diagonals, both windings
            ScreenMesh mesh;
            const glm::dvec2 a(r.x0 + 0.5, r.y0 + 0.5), b(r.x1 + 0.5, r.y0 + 0.5),
                c(r.x1 + 0.5, r.y1 + 0.5), d(r.x0 + 0.5, r.y1 + 0.5);
            const bool flip = variant & 2;
            auto add = [&](glm::dvec2 p, glm::dvec2 q, glm::dvec2 s) {
                if (flip)
                    mesh.addTriangle(p, s, q);
                else
                    mesh.addTriangle(p, q, s);
            };
            if (variant & 1) {
                add(a, b, c);
                add(a, c, d);
            } else {
                add(a, b, d);
                add(b, c, d);
            }
            Image<uint32_t> expected(width, height, 0);
            for (int y = r.y0; y < std::min(r.y1, height); ++y)
                for (int x = r.x0; x < std::min(r.x1, width); ++x)
                    expected.at(x, y) = 1;
            const CoverageResult got =
                rasterizeCoverage(width, height, toClip(mesh, width, height));
            expectSameImage(got.count, expected,
                            "rect_" + std::to_string(r.x0) + "_" + std::to_string(r.y0) + "_v" +
                                std::to_string(variant));
        }
}

// Right triangles with corners on pixel centres, legs a = x1 - x0 and b = y1 - y0, and closed
// forms for the pixels they cover: the upper-left one has a top and a left leg (included) and a
// hypotenuse that is a right edge (excluded); the lower-right one has a bottom and a right leg
// (excluded) and the same hypotenuse as a left edge (included).
TEST(RasterTopLeft, LegsAndHypotenusesFollowTheRule) {
    const int width = 96, height = 80;
    const int x0 = 10, y0 = 7, x1 = 70, y1 = 52, a = x1 - x0,
              b = y1 - y0; // hypotenuse hits centres every (4, -3)
    const glm::dvec2 pa(x0 + 0.5, y0 + 0.5), pb(x1 + 0.5, y0 + 0.5), pc(x1 + 0.5, y1 + 0.5),
        pd(x0 + 0.5, y1 + 0.5);
    for (bool flip : {false, true}) {
        ScreenMesh upperLeft, lowerRight;
        if (flip) {
            upperLeft.addTriangle(pa, pd, pb);
            lowerRight.addTriangle(pb, pd, pc);
        } else {
            upperLeft.addTriangle(pa, pb, pd);
            lowerRight.addTriangle(pb, pc, pd);
        }
        Image<uint32_t> expectedUL(width, height, 0), expectedLR(width, height, 0);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const long s = long(x - x0) * b + long(y - y0) * a; // a b on the hypotenuse
                expectedUL.at(x, y) = x >= x0 && y >= y0 && s < long(a) * b;
                expectedLR.at(x, y) = x < x1 && y < y1 && s >= long(a) * b;
            }
        const std::string suffix = flip ? "_cw" : "_ccw";
        expectSameImage(rasterizeCoverage(width, height, toClip(upperLeft, width, height)).count,
                        expectedUL, "upper_left" + suffix);
        expectSameImage(rasterizeCoverage(width, height, toClip(lowerRight, width, height)).count,
                        expectedLR, "lower_right" + suffix);
    }
}

// Horizontal edges alone: the top edge of a downward triangle includes its row of centres
// (except the right end, which is also on a right edge); the bottom edge of an upward triangle
// excludes its whole row. A vertical left edge includes its column, a vertical right edge not.
TEST(RasterTopLeft, HorizontalAndVerticalEdgesThroughCentres) {
    const int width = 64, height = 64;
    ScreenMesh down, up, leftEdge, rightEdge;
    down.addTriangle({10.5, 20.5}, {30.5, 20.5}, {20.5, 40.5});      // top edge at y = 20.5
    up.addTriangle({10.5, 40.5}, {20.5, 20.5}, {30.5, 40.5});        // bottom edge at y = 40.5
    leftEdge.addTriangle({10.5, 10.5}, {10.5, 50.5}, {40.5, 30.5});  // left edge at x = 10.5
    rightEdge.addTriangle({40.5, 10.5}, {10.5, 30.5}, {40.5, 50.5}); // right edge at x = 40.5
    const CoverageResult d = rasterizeCoverage(width, height, toClip(down, width, height));
    const CoverageResult u = rasterizeCoverage(width, height, toClip(up, width, height));
    const CoverageResult l = rasterizeCoverage(width, height, toClip(leftEdge, width, height));
    const CoverageResult r = rasterizeCoverage(width, height, toClip(rightEdge, width, height));
    for (int x = 10; x <= 30; ++x) {
        EXPECT_EQ(d.count.at(x, 20), x < 30 ? 1u : 0u) << "top edge, x " << x;
        EXPECT_EQ(u.count.at(x, 40), 0u) << "bottom edge, x " << x;
        EXPECT_EQ(u.count.at(x, 39), x > 10 && x < 30 ? 1u : 0u)
            << "row above the bottom edge, x " << x;
    }
    for (int y = 10; y <= 50; ++y) {
        // Both ends of the left edge are also on the slanted right edges, hence excluded.
        EXPECT_EQ(l.count.at(10, y), y > 10 && y < 50 ? 1u : 0u) << "left edge, y " << y;
        EXPECT_EQ(r.count.at(40, y), 0u) << "right edge, y " << y;
    }
    // And everything else matches the exact oracle.
    expectCoverageMatchesOracle(down, width, height, "down");
    expectCoverageMatchesOracle(up, width, height, "up");
    expectCoverageMatchesOracle(leftEdge, width, height, "left");
    expectCoverageMatchesOracle(rightEdge, width, height, "right");
}

// A fan whose centre and rim vertices all sit on pixel centres, so that spokes pass through
// many centres: the union is the square ring's interior with the half-open closed form, the
// shared centre pixel is covered exactly once.
TEST(RasterTopLeft, FanVertexOnPixelCentreCoveredOnce) {
    const int width = kTileSize + 32, height = kTileSize + 8;
    Random random(17);
    const int radius = 12;
    // The last two on tile borders.
    const glm::ivec2 centres[] = {{40, 30}, {kTileSize - 1, kTileSize - 1}, {kTileSize, 20}};
    for (const glm::ivec2 centre : centres) {
        ScreenMesh fan;
        const uint32_t c = fan.addVertex({centre.x + 0.5, centre.y + 0.5});
        std::vector<uint32_t> rim; // every pixel centre on the square's border, clockwise
        for (int i = -radius; i < radius; ++i)
            rim.push_back(fan.addVertex({centre.x + i + 0.5, centre.y - radius + 0.5}));
        for (int i = -radius; i < radius; ++i)
            rim.push_back(fan.addVertex({centre.x + radius + 0.5, centre.y + i + 0.5}));
        for (int i = radius; i > -radius; --i)
            rim.push_back(fan.addVertex({centre.x + i + 0.5, centre.y + radius + 0.5}));
        for (int i = radius; i > -radius; --i)
            rim.push_back(fan.addVertex({centre.x - radius + 0.5, centre.y + i + 0.5}));
        for (size_t i = 0; i < rim.size(); ++i) {
            const uint32_t a = rim[i], b = rim[(i + 1) % rim.size()];
            if (random.coin())
                fan.addTriangle(c, a, b);
            else
                fan.addTriangle(c, b, a);
        }
        Image<uint32_t> expected(width, height, 0);
        for (int y = centre.y - radius; y < centre.y + radius; ++y)
            for (int x = centre.x - radius; x < centre.x + radius; ++x)
                if (x >= 0 && y >= 0 && x < width && y < height)
                    expected.at(x, y) = 1;
        const CoverageResult got = rasterizeCoverage(width, height, toClip(fan, width, height));
        EXPECT_EQ(got.count.at(centre.x, centre.y), 1u);
        const std::string label =
            "fan_" + std::to_string(centre.x) + "_" + std::to_string(centre.y);
        expectSameImage(got.count, expected, label);
        // Which triangle owns each pixel follows the oracle too.
        expectSameImage(got.lastTriangle, oracleCoverage(fan, width, height).lastTriangle,
                        label + "_owner", true);
    }
}

// =============================================================================================
// 3. Sub-pixel precision: coverage flips at exactly the expected 1/256-pixel step.

TEST(RasterSubpixel, AxisAlignedEdgeSweepsAcrossACentre) {
    const int width = 64, height = 64;
    const int px = 20, py = 30; // the pixel whose centre (20.5, 30.5) the edges cross
    for (int k = -6; k <= 6; ++k) {
        const double e = k * kSubpixel;
        ScreenMesh left, right, top, bottom;
        left.addRectangle(px + 0.5 + e, 25.0, 40.0, 35.0);   // left edge at centre + e
        right.addRectangle(5.0, 25.0, px + 0.5 + e, 35.0);   // right edge at centre + e
        top.addRectangle(10.0, py + 0.5 + e, 30.0, 50.0);    // top edge
        bottom.addRectangle(10.0, 10.0, 30.0, py + 0.5 + e); // bottom edge
        auto at = [&](const ScreenMesh& m) {
            return rasterizeCoverage(width, height, toClip(m, width, height)).count.at(px, py);
        };
        // Included when the sample is inside or on a top/left edge, i.e. edge <= centre for
        // left/top edges and edge > centre for right/bottom edges.
        EXPECT_EQ(at(left), k <= 0 ? 1u : 0u) << "left edge at +" << k << "/256";
        EXPECT_EQ(at(right), k >= 1 ? 1u : 0u) << "right edge at +" << k << "/256";
        EXPECT_EQ(at(top), k <= 0 ? 1u : 0u) << "top edge at +" << k << "/256";
        EXPECT_EQ(at(bottom), k >= 1 ? 1u : 0u) << "bottom edge at +" << k << "/256";
    }
}

TEST(RasterSubpixel, SlantedEdgeFlipsAtTheAnalyticStep) {
    // Left edge from (x0 + k/256, y0) to (x0 + k/256 + 2, y0 + 6), slope dx/dy = 1/3. At the
    // centre's row cy = y0 + 1 the edge is at x0 + k/256 + 1/3, so the centre cx is covered iff
    // k/256 + 1/3 <= cx - x0, i.e. k <= 256 (cx - x0) - 256/3: the last covered k is
    // floor(256 (cx - x0) - 85.33..), never a tie.
    const int width = 64, height = 64;
    const double cx = 20.5, cy = 30.5, x0 = 19.0, y0 = cy - 1.0;
    const int lastCovered = int(std::floor(256.0 * (cx - x0) - 256.0 / 3.0));
    ASSERT_EQ(lastCovered, 298);
    for (int k = lastCovered - 3; k <= lastCovered + 3; ++k) {
        const double s = k * kSubpixel;
        ScreenMesh m;
        // Interior to the right of the slanted edge, closed by vertices far to the right.
        m.addTriangle({x0 + s, y0}, {x0 + s + 2, y0 + 6}, {x0 + s + 30, y0 + 3});
        const CoverageResult got = rasterizeCoverage(width, height, toClip(m, width, height));
        EXPECT_EQ(got.count.at(20, 30), k <= lastCovered ? 1u : 0u) << "k " << k;
    }
}

TEST(RasterSubpixel, SweptTrianglesMatchOracleAtEveryStep) {
    // A slanted, thin triangle translated in 1/256-pixel steps across a patch of centres: every
    // step compared with the exact oracle.
    const int width = 40, height = 40;
    ScreenMesh base;
    base.addTriangle({5.25, 3.0 + 7 * kSubpixel}, {31.0 + 3 * kSubpixel, 17.5},
                     {12.0 - 5 * kSubpixel, 36.75});
    for (int k = 0; k < 512; k += 3) {
        ScreenMesh moved = base;
        for (glm::dvec2& p : moved.positions)
            p += glm::dvec2(k * kSubpixel, (k / 2) * kSubpixel);
        expectCoverageMatchesOracle(moved, width, height, "sweep_" + std::to_string(k));
        if (::testing::Test::HasFailure())
            break;
    }
}

TEST(RasterSubpixel, TinyTrianglesCoverAtMostTheirCentre) {
    const int width = 64, height = 64;
    // Contains the centre (20.5, 20.5): exactly one fragment there, in both windings.
    for (bool flip : {false, true}) {
        ScreenMesh inside;
        const glm::dvec2 a(20.4, 20.4), b(20.6, 20.45), c(20.5, 20.6);
        if (flip)
            inside.addTriangle(a, c, b);
        else
            inside.addTriangle(a, b, c);
        const CoverageResult got = rasterizeCoverage(width, height, toClip(inside, width, height));
        EXPECT_EQ(got.stats.samplesCovered, 1u);
        EXPECT_EQ(got.count.at(20, 20), 1u);
    }
    // Inside a pixel but not around its centre, or straddling pixel borders between centres.
    ScreenMesh none;
    none.addTriangle({20.1, 20.1}, {20.4, 20.1}, {20.1, 20.4});
    none.addTriangle({20.9, 20.9}, {21.1, 20.95}, {21.0, 21.1});
    none.addTriangle({20.5 + kSubpixel, 20.4}, {20.7, 20.5},
                     {20.5 + kSubpixel, 20.6}); // just right of the centre
    EXPECT_EQ(rasterizeCoverage(width, height, toClip(none, width, height)).stats.samplesCovered,
              0u);
    // A tiny triangle with a vertex exactly on the centre: covered only if the rule says so.
    ScreenMesh touching;
    touching.addTriangle({20.5, 20.5}, {20.75, 20.5},
                         {20.5, 20.75}); // top-left corner at the centre: in
    touching.addTriangle({30.5, 30.5}, {30.25, 30.5},
                         {30.5, 30.25}); // bottom-right corner at the centre: out
    const CoverageResult t = rasterizeCoverage(width, height, toClip(touching, width, height));
    EXPECT_EQ(t.count.at(20, 20), 1u);
    EXPECT_EQ(t.count.at(30, 30), 0u);
    EXPECT_EQ(t.stats.samplesCovered, 1u);
}

TEST(RasterSubpixel, RandomTinyTrianglesMatchOracle) {
    // One sub-pixel triangle (grid vertices, at most 0.45 pixel from a point near the centre of
    // the cell's middle pixel) per 3x3 cell: 0 or 1 fragment each, exactly where the oracle says.
    const int width = 150, height = 96;
    Random random(23);
    ScreenMesh mesh;
    for (int cy = 0; cy + 3 <= height; cy += 3)
        for (int cx = 0; cx + 3 <= width; cx += 3) {
            // Vertices spread around a point near the centre, so that about half contain it.
            const glm::dvec2 origin(cx + 1.5 + random.uniform(-0.25, 0.25),
                                    cy + 1.5 + random.uniform(-0.25, 0.25));
            std::array<glm::dvec2, 3> v;
            const double phase = random.uniform(0.0, 2 * M_PI);
            for (int k = 0; k < 3; ++k) {
                const double angle = phase + k * 2 * M_PI / 3 + random.uniform(-0.6, 0.6);
                const double radius = random.uniform(0.05, 0.45);
                v[k] = {std::round((origin.x + radius * std::cos(angle)) * 256) / 256,
                        std::round((origin.y + radius * std::sin(angle)) * 256) / 256};
            }
            mesh.addTriangle(v[0], v[1], v[2]);
        }
    const OracleCoverage ref = oracleCoverage(mesh, width, height);
    size_t covered = 0;
    for (uint32_t c : ref.count.pixels)
        covered += c;
    EXPECT_GT(covered, 200u) << "test would be vacuous";
    EXPECT_LT(covered, mesh.triangleCount()) << "test would be vacuous";
    expectCoverageMatchesOracle(mesh, width, height, "tiny");
}

// =============================================================================================
// 4. Near (and far) plane clipping against the 3D oracle.

struct ViewCase {
    const char* name;
    Tri3 vertices;
    bool expectVisible;
};

class RasterClipping : public ::testing::TestWithParam<std::tuple<ViewCase, bool>> {};

TEST_P(RasterClipping, MatchesRayCastOracle) {
    const ViewCase& c = std::get<0>(GetParam());
    Camera camera; // 160 x 120, 60 degrees, near 0.5, far 50
    camera.reversedZ = std::get<1>(GetParam());
    for (bool flip : {false, true}) {
        Tri3 v = c.vertices;
        if (flip)
            std::swap(v[1], v[2]);
        const size_t visible = expectViewTriangleMatchesOracle(
            camera, v, std::string(c.name) + (flip ? "_cw" : "_ccw"));
        if (c.expectVisible)
            EXPECT_GT(visible, 50u) << "test would be vacuous";
        else
            EXPECT_EQ(visible, 0u);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RasterClipping,
    ::testing::Combine(
        ::testing::Values(
            // One vertex between the eye and the near plane (z < 0 < w in clip space), close to the
            // view axis so that the near-plane cut is on screen.
            ViewCase{"one_before_near", {{{-2, -1, -4}, {2, -1.5, -5}, {0.05, 0.03, -0.2}}}, true},
            // Two vertices between the eye and the near plane.
            ViewCase{
                "two_before_near", {{{-0.1, -0.05, -0.3}, {0.12, -0.08, -0.25}, {0, 1, -6}}}, true},
            // One vertex on the near plane exactly (in view space; float clip z may not be 0).
            ViewCase{"vertex_on_near", {{{-2, -1, -4}, {2, -1.5, -5}, {0.05, 0.03, -0.5}}}, true},
            // One vertex behind the camera (w < 0): must not turn into an inverted triangle.
            ViewCase{"one_behind_eye", {{{-3, -1, -6}, {3, -1, -6}, {0.5, 2, 3}}}, true},
            // Two vertices behind the camera.
            ViewCase{"two_behind_eye", {{{-2, -1, 2}, {2, -1, 2.5}, {0, 1, -4}}}, true},
            // Vertices on both sides of the eye and far outside the side planes.
            ViewCase{
                "through_eye_plane_sideways", {{{-40, -3, 5}, {2, 1, -3}, {30, -2, -1}}}, true},
            // Crossing near, far and all four side planes.
            ViewCase{"huge_crossing_everything",
                     {{{-100, -30, 10}, {100, -20, -80}, {5, 60, -70}}},
                     true},
            // Crossing the far plane only.
            ViewCase{"crossing_far", {{{-5, -3, -20}, {5, -2, -80}, {0, 4, -60}}}, true},
            // Entirely behind the camera, entirely before the near plane, entirely beyond far.
            ViewCase{"behind_eye", {{{-3, -1, 2}, {3, -1, 3}, {0, 2, 1}}}, false},
            ViewCase{
                "before_near", {{{-0.1, -0.1, -0.4}, {0.1, -0.1, -0.45}, {0, 0.1, -0.3}}}, false},
            ViewCase{"beyond_far", {{{-30, -10, -60}, {30, -10, -70}, {0, 20, -55}}}, false}),
        ::testing::Bool()), // standard or reversed Z
    [](const ::testing::TestParamInfo<std::tuple<ViewCase, bool>>& info) {
        return std::string(std::get<0>(info.param).name) +
               (std::get<1>(info.param) ? "_reversedZ" : "");
    });

TEST(RasterClippingRandom, RandomTrianglesAroundTheEyeMatchOracle) {
    Camera camera;
    camera.width = 96;
    camera.height = 72;
    camera.nearDistance = 0.3;
    camera.farDistance = 40.0;
    Random random(31);
    size_t visibleTotal = 0;
    for (int i = 0; i < 120 && !::testing::Test::HasFailure(); ++i) {
        camera.reversedZ = i % 2;
        Tri3 v;
        for (glm::dvec3& p : v)
            p = {random.uniform(-8, 8), random.uniform(-6, 6), random.uniform(-45, 6)};
        // Every other triangle has a vertex just before the near plane near the view axis, where
        // the near-plane cut is on screen.
        if (i % 4 >= 2)
            v[0] = {random.uniform(-0.1, 0.1), random.uniform(-0.08, 0.08),
                    random.uniform(-0.29, -0.05)};
        visibleTotal += expectViewTriangleMatchesOracle(camera, v, "random_" + std::to_string(i));
    }
    EXPECT_GT(visibleTotal, 5000u);
}

TEST(RasterClippingRandom, FullyHiddenTrianglesAreRejectedWithoutFragments) {
    Camera camera;
    Random random(37);
    ClipMesh mesh;
    for (int i = 0; i < 500; ++i) {
        Tri3 v;
        const int kind = i % 3; // behind the eye, before the near plane, beyond the far plane
        for (glm::dvec3& p : v) {
            const double z = kind == 0   ? random.uniform(0.01, 20)
                             : kind == 1 ? -random.uniform(0.0, 0.49)
                                         : -random.uniform(51, 200);
            p = {random.uniform(-30, 30), random.uniform(-30, 30), z};
        }
        addViewTriangle(mesh, camera, v);
    }
    const CoverageResult got = rasterizeCoverage(camera.width, camera.height, mesh);
    EXPECT_EQ(got.stats.samplesCovered, 0u);
    EXPECT_EQ(got.stats.trianglesSetUp, 0u);
    EXPECT_EQ(got.stats.trianglesIn, 500u);
}

TEST(RasterEdgeCases, VertexAtTheEyeOfAZeroNearProjectionProducesNothing) {
    // With near = 0 (glm::perspectiveRH_ZO(fovy, aspect, 0, far)) a vertex at the eye maps to the
    // clip-space origin (0, 0, 0, 0), which lies on every clip plane. The triangle contains the
    // eye, so it is seen edge-on: all its points project onto the line through the other two
    // vertices and it covers no pixel centre. The header promises w > 0 for every vertex that
    // reaches set-up; a vertex with w = 0 there would project to NaN.
    Camera camera;
    camera.nearDistance = 0.0;
    ClipMesh mesh;
    addViewTriangle(mesh, camera, {{{0, 0, 0}, {-2, -1, -5}, {3, 2, -6}}});
    ASSERT_EQ(mesh.positions[0], glm::vec4(0.0f));
    // The same in clip space directly, in both windings.
    mesh.positions.insert(mesh.positions.end(),
                          {{0, 0, 0, 0}, {-0.5f, -0.5f, 0.5f, 1}, {0.5f, 0.3f, 0.5f, 1}});
    mesh.indices.insert(mesh.indices.end(), {3, 4, 5, 3, 5, 4});
    const CoverageResult got = rasterizeCoverage(camera.width, camera.height, mesh);
    EXPECT_EQ(got.nonFiniteFragments, 0u);
    EXPECT_EQ(got.stats.samplesCovered, 0u);
}

TEST(RasterEdgeCases, EmptyDrawProducesNothing) {
    Rasterizer rasterizer(70, 70);
    const ClipMesh empty;
    size_t calls = 0;
    rasterizer.draw(empty.list(), {}, nullptr, [&](const Fragment&) { ++calls; });
    EXPECT_EQ(calls, 0u);
    EXPECT_EQ(rasterizer.lastStats().trianglesIn, 0u);
    EXPECT_EQ(rasterizer.lastStats().samplesCovered, 0u);
}

TEST(RasterEdgeCases, LargestViewportWithHugeTriangles) {
    // At kMaxViewportSize the guard band is tightest and snapped coordinates largest (the int64
    // overflow bound in the header): screen-filling and sliver triangles from +-1e6 NDC.
    const int width = kMaxViewportSize, height = 3;
    ClipMesh mesh;
    mesh.positions = {{-1e6f, -1e6f, 0.5f, 1},
                      {1e6f, -1e6f, 0.5f, 1},
                      {1e6f, 1e6f, 0.5f, 1},
                      {-1e6f, 1e6f, 0.5f, 1}};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    const CoverageResult got = rasterizeCoverage(width, height, mesh);
    expectSameImage(got.count, constantImage(width, height, 1), "max_viewport");
    EXPECT_EQ(got.nonFiniteFragments, 0u);
}

// =============================================================================================
// 5. Perspective-correct interpolation and depth on a ground plane, against ray-plane hits.

struct GroundCase {
    const char* name;
    double zNear; // the quad spans x in [-40, 40], z in [zFar, zNear] at y = 0
    double zFar;
};

class RasterPerspective : public ::testing::TestWithParam<GroundCase> {};

TEST_P(RasterPerspective, VaryingsAndDepthMatchRayPlaneIntersection) {
    const GroundCase& g = GetParam();
    Camera camera;
    camera.width = 192;
    camera.height = 108;
    camera.fovyRadians = glm::radians(70.0);
    camera.nearDistance = 0.1;
    camera.farDistance = 200.0;
    const glm::dvec3 eye(0.5, 2.0, 3.0), target(0.0, 0.0, -10.0), up(0, 1, 0);
    // The camera's own basis (independent of glm::lookAt, which only builds the input).
    const glm::dvec3 forward = glm::normalize(target - eye),
                     right = glm::normalize(glm::cross(forward, up)),
                     cameraUp = glm::cross(right, forward);
    const glm::mat4 clipFromWorld =
        camera.clipFromView() * glm::mat4(glm::lookAtRH(eye, target, up));

    const std::array<glm::dvec3, 4> corners = {
        glm::dvec3(-40, 0, g.zNear), glm::dvec3(40, 0, g.zNear), glm::dvec3(40, 0, g.zFar),
        glm::dvec3(-40, 0, g.zFar)};
    ClipMesh mesh;
    std::array<float, 4> worldX, viewDistance;
    for (int i = 0; i < 4; ++i) {
        mesh.positions.push_back(clipFromWorld * glm::vec4(glm::vec3(corners[i]), 1.0f));
        worldX[i] = float(corners[i].x);
        viewDistance[i] = float(glm::dot(corners[i] - eye, forward));
    }
    mesh.indices = {0, 1, 2, 0, 2, 3}; // counter-clockwise seen from above

    // Analytic values at a screen position: the view ray (through the image plane at unit
    // distance) meets y = 0 at parameter t, which is also the hit's view distance. The plane's
    // values exist wherever the ray goes down; inside says whether the hit is on the visible quad.
    struct Analytic {
        bool plane, inside;
        double x, distance;
    };
    auto analytic = [&](double sx, double sy) -> Analytic {
        const glm::dvec3 q = camera.imagePoint(sx, sy);
        const glm::dvec3 d = right * q.x + cameraUp * q.y + forward;
        if (d.y >= 0)
            return {false, false, 0, 0};
        const double t = -eye.y / d.y;
        const glm::dvec3 p = eye + t * d;
        const bool inside = p.x >= -40 && p.x <= 40 && p.z <= g.zNear && p.z >= g.zFar &&
                            t >= camera.nearDistance && t <= camera.farDistance;
        return {true, inside, p.x, t};
    };

    FragmentImage got = rasterizeFragments(camera.width, camera.height, mesh);
    EXPECT_EQ(got.outside, 0u);
    Image<uint32_t> ref(camera.width, camera.height, 0);
    Image<uint8_t> band(camera.width, camera.height, 0);
    size_t checked = 0, bad = 0;
    double worst = 0;
    std::ostringstream firstBad;
    const double h = 1.0 / 256.0;
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
            const double sx = x + 0.5, sy = y + 0.5;
            const Analytic a = analytic(sx, sy);
            ref.at(x, y) = a.inside;
            // Near the quad's outline (its edges, the near and far lines): not compared.
            for (int k = 0; k < 8; ++k) {
                const double angle = k * M_PI / 4;
                const Analytic n = analytic(sx + kEdgeBandPixels * std::cos(angle),
                                            sy + kEdgeBandPixels * std::sin(angle));
                if (n.inside != a.inside)
                    band.at(x, y) = 1;
            }
            if (got.count.at(x, y) != 1 || !a.plane)
                continue; // coverage is compared below
            const Fragment& f = got.last[size_t(y) * camera.width + x];
            const float gotX = interpolate(worldX[mesh.indices[3 * f.triangle]],
                                           worldX[mesh.indices[3 * f.triangle + 1]],
                                           worldX[mesh.indices[3 * f.triangle + 2]], f.barycentric);
            const float gotDistance =
                interpolate(viewDistance[mesh.indices[3 * f.triangle]],
                            viewDistance[mesh.indices[3 * f.triangle + 1]],
                            viewDistance[mesh.indices[3 * f.triangle + 2]], f.barycentric);
            // Tolerance: 1e-4 relative, plus the analytic value's change over the snapping
            // radius (central differences of the analytic solution).
            const Analytic ax0 = analytic(sx - h, sy), ax1 = analytic(sx + h, sy),
                           ay0 = analytic(sx, sy - h), ay1 = analytic(sx, sy + h);
            auto check = [&](const char* what, double value, double expected, double v_x0,
                             double v_x1, double v_y0, double v_y1, double floor, double absolute) {
                const double gradient = std::hypot(v_x1 - v_x0, v_y1 - v_y0) / (2 * h);
                const double tolerance = 1e-4 * std::max(std::abs(expected), floor) + absolute +
                                         1.5 * gradient * kSnapRadiusPixels;
                const double error = std::abs(value - expected);
                worst = std::max(worst, error / tolerance);
                if (error > tolerance) {
                    if (bad < 5)
                        firstBad << " " << what << " at (" << x << "," << y << "): got " << value
                                 << " expected " << expected << " tolerance " << tolerance << ";";
                    ++bad;
                }
            };
            check("worldX", gotX, a.x, ax0.x, ax1.x, ay0.x, ay1.x, 1.0, 0.0);
            check("viewDistance", gotDistance, a.distance, ax0.distance, ax1.distance, ay0.distance,
                  ay1.distance, 1.0, 0.0);
            check("depth", f.depth, camera.depthNdc(a.distance), camera.depthNdc(ax0.distance),
                  camera.depthNdc(ax1.distance), camera.depthNdc(ay0.distance),
                  camera.depthNdc(ay1.distance), 0.0, 2e-6);
            EXPECT_NEAR(f.barycentric.x + f.barycentric.y + f.barycentric.z, 1.0f, 1e-5f);
            ++checked;
        }
    EXPECT_EQ(bad, 0u) << "worst error / tolerance " << worst << ";" << firstBad.str();
    expectSameImage(got.count, ref, std::string(g.name) + "_coverage", false, &band);
    EXPECT_GT(checked, size_t(camera.width * camera.height / 4)) << "test would be vacuous";
}

INSTANTIATE_TEST_SUITE_P(Ground, RasterPerspective,
                         ::testing::Values(GroundCase{"in_front", 2.0, -150.0},
                                           GroundCase{"behind_eye_clipped", 20.0, -150.0},
                                           GroundCase{"beyond_far_clipped", 0.0, -400.0}),
                         [](const ::testing::TestParamInfo<GroundCase>& info) {
                             return std::string(info.param.name);
                         });

// =============================================================================================
// 6. Degenerate, sliver and huge triangles.

TEST(RasterDegenerate, ZeroAreaTrianglesProduceNothing) {
    const int width = 100, height = 80;
    ScreenMesh mesh;
    mesh.addTriangle({10.5, 10.5}, {50.5, 30.5}, {90.5, 50.5}); // collinear through centres
    mesh.addTriangle({10, 70}, {10, 10}, {10, 40});             // collinear vertical
    mesh.addTriangle({5.5, 20.5}, {95.5, 20.5},
                     {40.5, 20.5}); // collinear horizontal through centres
    mesh.addTriangle({20.25, 30.5}, {20.25, 30.5}, {60.5, 70.75}); // repeated vertex
    mesh.addTriangle({33.5, 33.5}, {33.5, 33.5}, {33.5, 33.5});    // a single point on a centre
    // Distinct in float but collinear after snapping (offsets far below 1/512 pixel).
    mesh.addTriangle({10.5, 60.5}, {50.5, 60.5 + 1e-4}, {90.5, 60.5 - 1e-4});
    const uint32_t degenerateCount = mesh.triangleCount();
    ClipMesh clip = toClip(mesh, width, height);
    // Repeated index rather than repeated position.
    clip.indices.insert(clip.indices.end(), {0, 0, 1});
    // Zero area in 3D crossing the near plane (three points on a line through w < 0).
    Camera camera;
    camera.width = width;
    camera.height = height;
    addViewTriangle(clip, camera, {{{-1, 0, -5}, {1, 0, 1}, {0, 0, -2}}});
    const CoverageResult got = rasterizeCoverage(width, height, clip);
    EXPECT_EQ(got.stats.samplesCovered, 0u);
    EXPECT_EQ(got.stats.trianglesIn, degenerateCount + 2u);
    EXPECT_EQ(got.stats.trianglesSetUp, 0u);
    EXPECT_EQ(got.nonFiniteFragments, 0u);
    // The same triangles beside a real one add nothing to it.
    ScreenMesh real;
    real.addTriangle({20.5, 5.5}, {80.5, 5.5}, {50.5, 75.5});
    mesh.addTriangle(real.positions[0], real.positions[1], real.positions[2]);
    const CoverageResult both = rasterizeCoverage(width, height, toClip(mesh, width, height));
    expectSameImage(both.count, oracleCoverage(real, width, height).count, "with_real");
}

TEST(RasterDegenerate, LongSliversMatchOracleExactly) {
    const int width = 200, height = 140;
    Random random(41);
    ScreenMesh mesh;
    for (int i = 0; i < 400; ++i) {
        // Long edge across (and beyond) the screen, third vertex 1/256 .. 2 pixels off it.
        const glm::dvec2 a(random.onGrid(-50, 250), random.onGrid(-50, 190));
        const glm::dvec2 b(random.onGrid(-50, 250), random.onGrid(-50, 190));
        const double t = random.uniform(0.1, 0.9);
        const glm::dvec2 along = a + t * (b - a);
        const glm::dvec2 offset =
            glm::dvec2(random.integer(-512, 512), random.integer(-512, 512)) / 256.0;
        const glm::dvec2 c(std::round(along.x * 256) / 256 + offset.x,
                           std::round(along.y * 256) / 256 + offset.y);
        if (random.coin())
            mesh.addTriangle(a, b, c);
        else
            mesh.addTriangle(a, c, b);
    }
    // Slivers one sub-pixel step wide whose long edge runs through a row, column or diagonal of
    // centres: the first four have it as a top or left edge (the centres are covered), the
    // mirrored four as a bottom or right edge (nothing is covered).
    const uint32_t firstAligned = mesh.triangleCount();
    mesh.addTriangle({0.5, 50.5}, {199.5, 50.5}, {100.5, 50.5 + kSubpixel});
    mesh.addTriangle({70.5, 0.5}, {70.5 + kSubpixel, 100.0}, {70.5, 139.5});
    mesh.addTriangle({10.5, 10.5}, {130.5, 130.5}, {70.5 + kSubpixel, 70.5});
    mesh.addTriangle({10.5, 130.5}, {130.5, 10.5}, {70.5, 70.5 + kSubpixel});
    mesh.addTriangle({0.5, 60.5}, {199.5, 60.5}, {100.5, 60.5 - kSubpixel});
    mesh.addTriangle({80.5, 0.5}, {80.5 - kSubpixel, 100.0}, {80.5, 139.5});
    mesh.addTriangle({10.5, 10.5}, {130.5, 130.5}, {70.5 - kSubpixel, 70.5});
    mesh.addTriangle({10.5, 130.5}, {130.5, 10.5}, {70.5, 70.5 - kSubpixel});
    expectCoverageMatchesOracle(mesh, width, height, "slivers");
    // Each alone too: overlapping slivers could hide a miss behind a neighbour's extra fragment.
    for (uint32_t t = firstAligned; t < mesh.triangleCount(); ++t) {
        ScreenMesh one;
        const Tri2 v = mesh.triangle(t);
        one.addTriangle(v[0], v[1], v[2]);
        const OracleCoverage ref = oracleCoverage(one, width, height);
        size_t covered = 0;
        for (uint32_t c : ref.count.pixels)
            covered += c;
        if (t < firstAligned + 4) {
            EXPECT_GT(covered, 100u) << "sliver " << t;
        } else {
            EXPECT_EQ(covered, 0u) << "sliver " << t;
        }
        expectCoverageMatchesOracle(one, width, height, "sliver_" + std::to_string(t));
    }
}

// Triangles given in NDC with coordinates up to 1e6, far beyond the guard band: coverage must
// match the original triangle's, except within kEdgeBandPixels of its edges.
void expectHugeNdcCoverage(const std::vector<std::array<glm::dvec2, 3>>& trianglesNdc, int width,
                           int height, const std::string& label, bool expectFullScreenOnce,
                           bool expectClipping = true) {
    ClipMesh mesh;
    std::vector<Tri2> screen;
    for (const auto& t : trianglesNdc) {
        Tri2 s;
        for (int i = 0; i < 3; ++i) {
            const glm::vec2 ndc(t[i]); // what the rasterizer gets
            s[i] = {(double(ndc.x) + 1.0) * 0.5 * width, (1.0 - double(ndc.y)) * 0.5 * height};
            mesh.indices.push_back(uint32_t(mesh.positions.size()));
            mesh.positions.emplace_back(ndc.x, ndc.y, 0.25f, 1.0f);
        }
        screen.push_back(s);
    }
    const CoverageResult got = rasterizeCoverage(width, height, mesh);
    EXPECT_EQ(got.nonFiniteFragments, 0u) << label;
    EXPECT_EQ(got.fragmentsOutsideViewport, 0u) << label;
    if (expectClipping) {
        EXPECT_GT(got.stats.trianglesClipped, 0u) << label;
    }
    if (expectFullScreenOnce) {
        expectSameImage(got.count, constantImage(width, height, 1), label);
        return;
    }
    Image<uint32_t> ref(width, height, 0);
    Image<uint8_t> band(width, height, 0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const glm::dvec2 p(x + 0.5, y + 0.5);
            for (const Tri2& s : screen) {
                ref.at(x, y) += oracleCovers(s, p);
                for (int i = 0; i < 3; ++i) {
                    const glm::dvec2 d = s[(i + 1) % 3] - s[i];
                    if (std::abs(cross(d, p - s[i])) / glm::length(d) < kEdgeBandPixels)
                        band.at(x, y) = 1;
                }
            }
        }
    expectSameImage(got.count, ref, label, false, &band);
}

TEST(RasterDegenerate, HugeTrianglesBeyondTheGuardBand) {
    const int width = 133, height = 77;
    // Two triangles sharing a diagonal through the screen, all vertices at +-1e6: every pixel
    // exactly once (watertight through guard-band clipping).
    expectHugeNdcCoverage(
        {{{{-1e6, -1e6}, {1e6, -1e6}, {1e6, 1e6}}}, {{{-1e6, -1e6}, {1e6, 1e6}, {-1e6, 1e6}}}},
        width, height, "square", true);
    expectHugeNdcCoverage(
        {{{{-1e6, -3.3e5}, {1e6, 7e5}, {-1e6, 1e6}}}, {{{-1e6, -3.3e5}, {1e6, -1e6}, {1e6, 7e5}}}},
        width, height, "slanted_shared_edge", true);
    // Single huge triangles whose edges cross the screen at various slopes.
    expectHugeNdcCoverage({{{{-1e6, -0.3e6}, {1e6, 0.2e6 + 0.37}, {0.1, 1e6}}}}, width, height,
                          "one_edge", false);
    expectHugeNdcCoverage({{{{-7e5, -1e6}, {2e5 + 0.1, 1e6}, {3e5, -1e6}}}}, width, height,
                          "two_edges", false);
    expectHugeNdcCoverage({{{{-1e6, 0.5}, {1e6, -0.25}, {0.05, -1e6}}}}, width, height, "grazing",
                          false);
    // Huge but with one vertex on screen.
    expectHugeNdcCoverage({{{{0.2, 0.3}, {1e6, 3e5}, {-2e5, 1e6}}}}, width, height,
                          "vertex_on_screen", false);
}

TEST(RasterDegenerate, HugeRandomTrianglesMatchOracle) {
    const int width = 100, height = 60;
    Random random(43);
    for (int i = 0; i < 60 && !::testing::Test::HasFailure(); ++i) {
        std::array<glm::dvec2, 3> t;
        for (glm::dvec2& p : t) {
            const double scale = std::pow(10.0, random.uniform(0.0, 6.0));
            p = {random.uniform(-1, 1) * scale, random.uniform(-1, 1) * scale};
        }
        // Only triangles that cross the screen make a useful case.
        expectHugeNdcCoverage({t}, width, height, "random_" + std::to_string(i), false, false);
    }
}

// =============================================================================================
// 7. Depth test, depth write, early depth test, culling and facing.

// Reference depth semantics, written from the enum's meaning.
bool referencePasses(DepthTest test, float fragment, float stored) {
    switch (test) {
    case DepthTest::Always:
        return true;
    case DepthTest::Less:
        return fragment < stored;
    case DepthTest::LessEqual:
        return fragment <= stored;
    case DepthTest::Greater:
        return fragment > stored;
    case DepthTest::GreaterEqual:
        return fragment >= stored;
    }
    return false;
}

struct DepthCase {
    DepthTest test;
    bool depthWrite;
    float clear;
};

std::string depthCaseName(const ::testing::TestParamInfo<DepthCase>& info) {
    static const char* names[] = {"Always", "Less", "LessEqual", "Greater", "GreaterEqual"};
    std::string clear = std::to_string(int(info.param.clear * 100));
    return std::string(names[int(info.param.test)]) +
           (info.param.depthWrite ? "_write" : "_nowrite") + "_clear" + clear;
}

class RasterDepth : public ::testing::TestWithParam<DepthCase> {};

TEST_P(RasterDepth, OverlappingConstantDepthRectanglesFollowTheTest) {
    const DepthCase& c = GetParam();
    const int width = 96, height = 80;
    // Rectangles on pixel centres (closed forms), drawn in this order, overlapping pairwise,
    // with depths exactly representable; two share a depth to exercise the equal cases.
    struct Rect {
        int x0, y0, x1, y1;
        float depth;
    };
    const Rect rects[] = {
        {5, 5, 60, 50, 0.6f}, {30, 20, 90, 70, 0.4f}, {20, 30, 70, 78, 0.6f}, {0, 0, 96, 10, 0.5f}};
    ScreenMesh mesh;
    for (const Rect& r : rects)
        mesh.addRectangle(r.x0 + 0.5, r.y0 + 0.5, r.x1 + 0.5, r.y1 + 0.5, r.depth);

    // Expected result: per pixel, replay the rectangles covering it in order.
    Image<uint32_t> expectedCalls(width, height, 0), expectedLast(width, height, kNoTriangle);
    std::vector<float> expectedDepth(size_t(width) * height, c.clear);
    uint64_t expectedCovered = 0, expectedPassed = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int r = 0; r < 4; ++r) {
                if (x < rects[r].x0 || x >= rects[r].x1 || y < rects[r].y0 || y >= rects[r].y1)
                    continue;
                ++expectedCovered;
                float& stored = expectedDepth[size_t(y) * width + x];
                if (!referencePasses(c.test, rects[r].depth, stored))
                    continue;
                ++expectedPassed;
                ++expectedCalls.at(x, y);
                expectedLast.at(x, y) = kNoTriangle - 1 - uint32_t(r); // marker: rectangle r
                if (c.depthWrite)
                    stored = rects[r].depth;
            }

    std::vector<float> depth(size_t(width) * height, c.clear);
    Image<uint32_t> calls(width, height, 0), last(width, height, kNoTriangle);
    std::atomic<uint64_t> wrongDepth{0};
    Rasterizer rasterizer(width, height);
    rasterizer.draw(toClip(mesh, width, height).list(), {CullMode::None, c.test, c.depthWrite},
                    depth.data(), [&](const Fragment& f) {
                        const uint32_t r = f.triangle / 2;
                        if (f.depth != rects[r].depth)
                            ++wrongDepth;
                        ++calls.at(f.x, f.y);
                        last.at(f.x, f.y) = kNoTriangle - 1 - r;
                    });
    EXPECT_EQ(wrongDepth.load(), 0u);
    // The fragment function runs only for fragments that pass (early depth test).
    expectSameImage(calls, expectedCalls, "calls");
    expectSameImage(last, expectedLast, "last", true);
    size_t depthMismatches = 0;
    for (size_t i = 0; i < depth.size(); ++i)
        depthMismatches += depth[i] != expectedDepth[i];
    EXPECT_EQ(depthMismatches, 0u) << "depth buffer";
    EXPECT_EQ(rasterizer.lastStats().samplesCovered, expectedCovered);
    EXPECT_EQ(rasterizer.lastStats().samplesPassed, expectedPassed);
}

std::vector<DepthCase> allDepthCases() {
    std::vector<DepthCase> cases;
    for (DepthTest t : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                        DepthTest::Greater, DepthTest::GreaterEqual})
        for (bool write : {true, false})
            for (float clear : {0.0f, 0.5f, 1.0f})
                cases.push_back({t, write, clear});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Modes, RasterDepth, ::testing::ValuesIn(allDepthCases()), depthCaseName);

TEST(RasterDepthPlanes, IntersectingPlanesShowTheNearerOrFartherSurface) {
    // Two screen-covering triangles with depth linear in screen space:
    // A(x, y) = 0.2 + 0.3 x / W, B(x, y) = 0.7 - 0.3 y / H; they cross on x/W + y/H = 5/3.
    const int width = 128, height = 96;
    auto depthA = [&](double x, double y) { return 0.2 + 0.3 * x / width; };
    auto depthB = [&](double x, double y) { return 0.7 - 0.3 * y / height; };
    ScreenMesh mesh;
    const glm::dvec2 a0(0, 0), a1(2.0 * width, 0), a2(0, 2.0 * height);
    mesh.addTriangle(mesh.addVertex(a0, float(depthA(a0.x, a0.y))),
                     mesh.addVertex(a1, float(depthA(a1.x, a1.y))),
                     mesh.addVertex(a2, float(depthA(a2.x, a2.y))));
    mesh.addTriangle(mesh.addVertex(a0, float(depthB(a0.x, a0.y))),
                     mesh.addVertex(a1, float(depthB(a1.x, a1.y))),
                     mesh.addVertex(a2, float(depthB(a2.x, a2.y))));
    for (DepthTest test : {DepthTest::Less, DepthTest::Greater}) {
        const float clear = test == DepthTest::Less ? 1.0f : 0.0f;
        std::vector<float> depth(size_t(width) * height, clear);
        const CoverageResult got = rasterizeCoverage(width, height, toClip(mesh, width, height),
                                                     {CullMode::None, test, true}, depth.data());
        size_t wrongWinner = 0, wrongDepth = 0, compared = 0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const double da = depthA(x + 0.5, y + 0.5), db = depthB(x + 0.5, y + 0.5);
                const double expected =
                    test == DepthTest::Less ? std::min(da, db) : std::max(da, db);
                if (std::abs(double(depth[size_t(y) * width + x]) - expected) > 1e-6)
                    ++wrongDepth;
                if (std::abs(da - db) < 1e-5)
                    continue; // too close to the intersection to call
                ++compared;
                const uint32_t winner = (test == DepthTest::Less) == (da < db) ? 0u : 1u;
                if (got.lastTriangle.at(x, y) != winner)
                    ++wrongWinner;
            }
        EXPECT_EQ(wrongWinner, 0u);
        EXPECT_EQ(wrongDepth, 0u);
        EXPECT_GT(compared, size_t(width * height * 9 / 10));
    }
}

TEST(RasterCulling, WindingDecidesFacingAndCulling) {
    const int width = 80, height = 60;
    // NDC, y up: counter-clockwise on the left, clockwise on the right.
    ClipMesh mesh;
    mesh.positions = {{-0.9f, -0.8f, 0.5f, 1}, {-0.1f, -0.8f, 0.5f, 1}, {-0.5f, 0.8f, 0.5f, 1},
                      {0.1f, -0.8f, 0.5f, 1},  {0.5f, 0.8f, 0.5f, 1},   {0.9f, -0.8f, 0.5f, 1}};
    mesh.indices = {0, 1, 2, 3, 4, 5};
    for (CullMode cull : {CullMode::None, CullMode::Back, CullMode::Front}) {
        Image<uint32_t> facing(width, height, kNoTriangle); // 1 front, 0 back
        std::atomic<uint64_t> wrong{0};
        Rasterizer rasterizer(width, height);
        rasterizer.draw(mesh.list(), {cull, DepthTest::Always, false}, nullptr,
                        [&](const Fragment& f) {
                            if (f.frontFacing != (f.triangle == 0))
                                ++wrong;
                            facing.at(f.x, f.y) = f.frontFacing;
                        });
        EXPECT_EQ(wrong.load(), 0u);
        size_t front = 0, back = 0;
        for (uint32_t v : facing.pixels) {
            front += v == 1;
            back += v == 0;
        }
        EXPECT_EQ(front > 0, cull != CullMode::Front) << "cull mode " << int(cull);
        EXPECT_EQ(back > 0, cull != CullMode::Back) << "cull mode " << int(cull);
        EXPECT_EQ(rasterizer.lastStats().trianglesCulled, cull == CullMode::None ? 0u : 1u);
    }
}

TEST(RasterCulling, NonFiniteVerticesCullTheirTrianglesOnly) {
    // A NaN or infinite coordinate in any component makes its triangles cover nothing (they are
    // counted as culled); a valid triangle sharing nothing with them still draws. Set-up reads
    // a per-vertex flag for this, so every component and every vertex slot is tried.
    const int width = 64, height = 48;
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::infinity(),
                         -std::numeric_limits<float>::infinity()};
    for (float value : bad)
        for (int component = 0; component < 4; ++component)
            for (int slot = 0; slot < 3; ++slot) {
                ClipMesh mesh;
                mesh.positions = {{-0.9f, -0.9f, 0.5f, 1}, {0.9f, -0.9f, 0.5f, 1},
                                  {0.0f, 0.9f, 0.5f, 1},   {-0.5f, -0.5f, 0.5f, 1},
                                  {0.5f, -0.5f, 0.5f, 1},  {0.0f, 0.5f, 0.5f, 1}};
                mesh.positions[size_t(3 + slot)][component] = value;
                mesh.indices = {3, 4, 5, 0, 1, 2};
                std::atomic<uint64_t> fromBad{0}, fromGood{0};
                Rasterizer rasterizer(width, height);
                rasterizer.draw(
                    mesh.list(), {CullMode::None, DepthTest::Always, false}, nullptr,
                    [&](const Fragment& f) { ++(f.triangle == 0 ? fromBad : fromGood); });
                EXPECT_EQ(fromBad.load(), 0u) << value << " in component " << component;
                EXPECT_GT(fromGood.load(), 0u);
                EXPECT_EQ(rasterizer.lastStats().trianglesCulled, 1u);
            }
}

TEST(RasterCulling, RandomTrianglesFacingMatchesSignedNdcArea) {
    // Random triangles with random positive w: facing is the sign of the NDC area (y up), which
    // the test computes from the projected float inputs in double.
    const int width = 120, height = 90;
    Random random(47);
    ClipMesh mesh;
    std::vector<bool> front;
    for (int i = 0; i < 300; ++i) {
        std::array<glm::dvec2, 3> ndc;
        for (int k = 0; k < 3; ++k) {
            ndc[k] = {random.uniform(-1.2, 1.2), random.uniform(-1.2, 1.2)};
            const float w = float(random.uniform(0.2, 5.0));
            mesh.indices.push_back(uint32_t(mesh.positions.size()));
            mesh.positions.emplace_back(float(ndc[k].x) * w, float(ndc[k].y) * w, 0.3f * w, w);
        }
        front.push_back(cross(ndc[1] - ndc[0], ndc[2] - ndc[0]) > 0);
    }
    for (CullMode cull : {CullMode::None, CullMode::Back, CullMode::Front}) {
        std::atomic<uint64_t> wrongFacing{0}, culledButDrawn{0};
        std::vector<std::atomic<uint32_t>> drawn(mesh.triangleCount());
        Rasterizer rasterizer(width, height);
        rasterizer.draw(
            mesh.list(), {cull, DepthTest::Always, false}, nullptr, [&](const Fragment& f) {
                const bool isFront = front[f.triangle];
                if (f.frontFacing != isFront)
                    ++wrongFacing;
                if ((cull == CullMode::Back && !isFront) || (cull == CullMode::Front && isFront))
                    ++culledButDrawn;
                drawn[f.triangle] = 1;
            });
        EXPECT_EQ(wrongFacing.load(), 0u);
        EXPECT_EQ(culledButDrawn.load(), 0u);
        size_t drawnFront = 0, drawnBack = 0;
        for (uint32_t t = 0; t < mesh.triangleCount(); ++t)
            if (drawn[t])
                (front[t] ? drawnFront : drawnBack)++;
        EXPECT_EQ(drawnFront > 20, cull != CullMode::Front);
        EXPECT_EQ(drawnBack > 20, cull != CullMode::Back);
    }
}

// =============================================================================================
// 8. Determinism across thread counts.

struct SoupOutput {
    std::vector<uint32_t> triangle;
    std::vector<float> depth;       // fragment depth of the last fragment written
    std::vector<float> barycentric; // 3 per pixel
    std::vector<float> depthBuffer;
    RasterStats stats;
};

ClipMesh randomSoup(int width, int height, uint32_t triangleCount, uint64_t seed) {
    Random random(seed);
    ClipMesh mesh;
    Camera camera;
    camera.width = width;
    camera.height = height;
    for (uint32_t t = 0; t < triangleCount; ++t) {
        if (t % 10 == 9) { // some in 3D around the eye: near-plane and w < 0 clipping
            Tri3 v;
            for (glm::dvec3& p : v)
                p = {random.uniform(-6, 6), random.uniform(-4, 4), random.uniform(-30, 3)};
            addViewTriangle(mesh, camera, v);
            continue;
        }
        const glm::dvec2 centre(random.uniform(-20, width + 20), random.uniform(-20, height + 20));
        const double size = std::pow(2.0, random.uniform(-1.0, 7.0));
        for (int k = 0; k < 3; ++k) {
            const glm::dvec2 ndc = ndcFromScreen(
                centre + size * glm::dvec2(random.uniform(-1, 1), random.uniform(-1, 1)), width,
                height);
            const float w = float(random.uniform(0.5, 3.0));
            mesh.indices.push_back(uint32_t(mesh.positions.size()));
            mesh.positions.emplace_back(float(ndc.x) * w, float(ndc.y) * w,
                                        float(random.uniform(0.0, 1.0)) * w, w);
        }
    }
    return mesh;
}

SoupOutput drawSoup(Rasterizer& rasterizer, const ClipMesh& mesh, const RasterState& state,
                    bool useDepth, int threads) {
    const int width = rasterizer.width(), height = rasterizer.height();
    SoupOutput out{std::vector<uint32_t>(size_t(width) * height, kNoTriangle),
                   std::vector<float>(size_t(width) * height, -1.0f),
                   std::vector<float>(size_t(width) * height * 3, -1.0f),
                   std::vector<float>(size_t(width) * height, 0.5f),
                   {}};
    withThreads(threads, [&] {
        rasterizer.draw(mesh.list(), state, useDepth ? out.depthBuffer.data() : nullptr,
                        [&](const Fragment& f) {
                            const size_t i = size_t(f.y) * width + f.x;
                            out.triangle[i] = f.triangle;
                            out.depth[i] = f.depth;
                            std::memcpy(&out.barycentric[3 * i], &f.barycentric, sizeof(float) * 3);
                        });
    });
    out.stats = rasterizer.lastStats();
    return out;
}

void expectIdentical(const SoupOutput& a, const SoupOutput& b, const std::string& label) {
    auto same = [](const auto& x, const auto& y) {
        return x.size() == y.size() &&
               std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
    };
    EXPECT_TRUE(same(a.triangle, b.triangle)) << label << ": triangle ids";
    EXPECT_TRUE(same(a.depth, b.depth)) << label << ": fragment depths";
    EXPECT_TRUE(same(a.barycentric, b.barycentric)) << label << ": barycentrics";
    EXPECT_TRUE(same(a.depthBuffer, b.depthBuffer)) << label << ": depth buffer";
    raster_test::expectSameStats(a.stats, b.stats, label);
}

TEST(RasterDeterminism, SameOutputForAnyThreadCount) {
    // Let TBB really run 7 threads even on a smaller machine.
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 8);
    // 4 x 3 tiles, partial at the right and bottom.
    const int width = 3 * kTileSize + 19, height = 2 * kTileSize + 15;
    const ClipMesh mesh = randomSoup(width, height, 5000, 53); // three set-up batches
    const RasterState states[] = {{CullMode::None, DepthTest::LessEqual, true},
                                  {CullMode::Back, DepthTest::Greater, true},
                                  {CullMode::None, DepthTest::Always, false}};
    for (const RasterState& state : states)
        for (bool useDepth : {true, false}) {
            Rasterizer reference(width, height);
            const SoupOutput one = drawSoup(reference, mesh, state, useDepth, 1);
            ASSERT_GT(one.stats.samplesPassed, 10000u);
            ASSERT_GT(one.stats.trianglesClipped, 0u);
            for (int threads : {2, 7}) {
                Rasterizer rasterizer(width, height);
                expectIdentical(one, drawSoup(rasterizer, mesh, state, useDepth, threads),
                                std::to_string(threads) + " threads");
            }
            // A reused object (scratch memory from a larger and a smaller draw) changes nothing.
            Rasterizer reused(width, height);
            drawSoup(reused, randomSoup(width, height, 7000, 59), state, useDepth, 2);
            drawSoup(reused, randomSoup(width, height, 10, 61), state, useDepth, 2);
            expectIdentical(one, drawSoup(reused, mesh, state, useDepth, 7), "reused object");
        }
}

TEST(RasterDeterminism, BarycentricsOffChangesNothingButTheBarycentrics) {
    // Passes that resolve attributes themselves skip the barycentric set-up; coverage, depth and
    // statistics must not notice, on a soup with clipped pieces and several set-up batches.
    const int width = 3 * kTileSize + 19, height = 2 * kTileSize + 15;
    const ClipMesh mesh = randomSoup(width, height, 5000, 67);
    RasterState with{CullMode::None, DepthTest::LessEqual, true};
    RasterState without = with;
    without.barycentrics = false;
    Rasterizer rasterizer(width, height);
    const SoupOutput full = drawSoup(rasterizer, mesh, with, true, 2);
    ASSERT_GT(full.stats.trianglesClipped, 0u);
    SoupOutput bare = drawSoup(rasterizer, mesh, without, true, 2);
    size_t written = 0;
    for (size_t i = 0; i < bare.triangle.size(); ++i) {
        if (bare.triangle[i] == kNoTriangle)
            continue;
        ++written;
        for (int k = 0; k < 3; ++k)
            ASSERT_EQ(bare.barycentric[3 * i + k], 0.0f) << "pixel " << i;
    }
    ASSERT_GT(written, 10000u);
    bare.barycentric = full.barycentric; // the one output allowed to differ
    expectIdentical(full, bare, "barycentrics off");
    // And back on, the same object (scratch from a draw without barycentrics) is unchanged.
    expectIdentical(full, drawSoup(rasterizer, mesh, with, true, 2), "barycentrics on again");
}

// =============================================================================================
// 9. Submission order across set-up batches.

TEST(RasterOrder, LastSubmittedWinsAcrossBatches) {
    const int width = 133, height = 77;
    Random random(67);
    ScreenMesh mesh;
    const uint32_t total = 2 * kTrianglesPerBatch + 777;
    const glm::dvec2 s0(-5, -5), s1(width + 5, -5), s2(width + 5, height + 5), s3(-5, height + 5);
    while (mesh.triangleCount() < total) {
        const uint32_t t = mesh.triangleCount();
        // Screen-covering quads whose two halves straddle each batch boundary.
        if (t + 1 == kTrianglesPerBatch || t + 1 == 2 * kTrianglesPerBatch) {
            mesh.addTriangle(s0, s1, s2, 0.9f);
            mesh.addTriangle(s0, s2, s3, 0.1f);
            continue;
        }
        const glm::dvec2 centre(random.onGrid(-10, width + 10), random.onGrid(-10, height + 10));
        const double size = random.uniform(2.0, 30.0);
        std::array<glm::dvec2, 3> v;
        for (glm::dvec2& p : v)
            p = {std::round((centre.x + random.uniform(-size, size)) * 256) / 256,
                 std::round((centre.y + random.uniform(-size, size)) * 256) / 256};
        mesh.addTriangle(v[0], v[1], v[2], float(random.uniform(0.0, 1.0)));
    }
    ASSERT_EQ(mesh.triangleCount(), total);
    const OracleCoverage ref = oracleCoverage(mesh, width, height);
    // Always with a depth buffer and writes (depths vary randomly), and without a depth buffer.
    for (bool useDepth : {true, false}) {
        std::vector<float> depth(size_t(width) * height, 0.5f);
        const CoverageResult got = rasterizeCoverage(width, height, toClip(mesh, width, height),
                                                     {CullMode::None, DepthTest::Always, true},
                                                     useDepth ? depth.data() : nullptr);
        const std::string label = useDepth ? "depth" : "nodepth";
        expectSameImage(got.lastTriangle, ref.lastTriangle, label + "_last", true);
        expectSameImage(got.count, ref.count, label + "_count");
    }
}

// =============================================================================================
// 10. Viewport borders and sizes that are not multiples of the tile size.

class RasterViewport : public ::testing::TestWithParam<glm::ivec2> {};

TEST_P(RasterViewport, PartlyOffscreenTrianglesMatchOracle) {
    const int width = GetParam().x, height = GetParam().y;
    const Rasterizer rasterizer(width, height);
    EXPECT_EQ(rasterizer.tileCountX(), (width + kTileSize - 1) / kTileSize);
    EXPECT_EQ(rasterizer.tileCountY(), (height + kTileSize - 1) / kTileSize);
    // The whole viewport, exactly once.
    ScreenMesh full;
    full.addRectangle(0, 0, width, height);
    const CoverageResult f = rasterizeCoverage(width, height, toClip(full, width, height));
    expectSameImage(f.count, constantImage(width, height, 1), "full");
    // Triangles reaching beyond every border, and ones ending on the last pixel centres.
    Random random(uint64_t(width) * 1000 + height);
    ScreenMesh mesh;
    for (int i = 0; i < 80; ++i) {
        std::array<glm::dvec2, 3> v;
        for (glm::dvec2& p : v)
            p = {random.onGrid(-0.6 * width - 3, 1.6 * width + 3),
                 random.onGrid(-0.6 * height - 3, 1.6 * height + 3)};
        mesh.addTriangle(v[0], v[1], v[2]);
    }
    const double r = width - 0.5, b = height - 0.5; // centres of the last column and row
    mesh.addTriangle({r, b}, {r - 10, b}, {r, b - 10});
    mesh.addTriangle({r + 0.25, b + 0.25}, {r - 5, b + 3}, {r + 3, b - 5});
    mesh.addTriangle({width + 0.0, 0}, {width - 1.0, height + 0.0},
                     {width + 30.0, height / 2.0}); // right border strip
    mesh.addTriangle({0, height + 0.0}, {width + 0.0, height - 1.0},
                     {width / 2.0, height + 30.0}); // bottom border strip
    expectCoverageMatchesOracle(mesh, width, height, "offscreen");
}

INSTANTIATE_TEST_SUITE_P(Sizes, RasterViewport,
                         ::testing::Values(glm::ivec2(133, 77), glm::ivec2(1, 1),
                                           glm::ivec2(64, 64), glm::ivec2(65, 65),
                                           glm::ivec2(127, 1), glm::ivec2(1, 130),
                                           glm::ivec2(200, 129), glm::ivec2(kTileSize, kTileSize),
                                           glm::ivec2(kTileSize + 1, 2 * kTileSize + 1),
                                           glm::ivec2(3 * kTileSize - 1, 1)),
                         [](const ::testing::TestParamInfo<glm::ivec2>& info) {
                             return std::to_string(info.param.x) + "x" +
                                    std::to_string(info.param.y);
                         });

} // namespace
} // namespace raster
