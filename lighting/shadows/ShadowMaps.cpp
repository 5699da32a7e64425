// ShadowMaps: face set-up (matrices, cascade fitting), the per-light caster cull, the depth-only
// renders and the lookup. Conventions in ShadowMaps.h.
#include "lighting/shadows/ShadowMaps.h"

#include "lighting/shadows/CasterMaterials.h"
#include "lighting/shadows/ShadowCasterSets.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightList.h"
#include "raster/Rasterizer.h"

namespace lighting {

// The render's per-thread scratch (ShadowMaps::mScratch): a rasterizer of the map's size and the
// clip positions of the face being drawn.
struct ShadowMaps::RenderScratch {
    struct Thread {
        // One per map size met: its rasterizer, and the float buffer Unorm16 faces of that size
        // are drawn into before packUnorm16, with its own record of the tiles that are not
        // clear (the next face this thread draws at that size then clears only those).
        struct SizedTarget {
            std::unique_ptr<raster::Rasterizer> rasterizer;
            std::vector<float> unormDepth;
            std::vector<uint8_t> unormTilesNotClear;
        };
        std::vector<SizedTarget> sizes;
        std::vector<glm::vec4> clip;
        // Perspective and orthographic faces: the clip positions' frustum outcodes and the
        // indices of the triangles the face keeps.
        std::vector<uint8_t> outcodes;
        std::vector<uint32_t> faceIndices;
        // Paraboloid faces: the casters in the face's light frame, clipped and split (three
        // corners per triangle), and 0, 1, 2, ... to index them.
        std::vector<glm::vec3> lightSpace;
        std::vector<uint32_t> sequential;
        // The alpha-tested casters of the face: clip positions and uvs per corner (a paraboloid
        // piece's corners lie inside its scene triangle), the material per triangle.
        std::vector<glm::vec4> testedClip;
        std::vector<glm::vec2> testedUv;
        std::vector<uint32_t> testedMaterial;
        std::vector<glm::vec3> testedLightSpace, testedWeights; // one triangle's pieces
    };
    tbb::enumerable_thread_specific<Thread> threads;
    // Per light, the corner lists of its casters (Casters::ownPositions, by shadow index) and
    // 0, 1, 2, ... to index them: a frame's lists are megabytes, which a fresh allocation pays
    // in page faults every frame.
    std::vector<std::vector<glm::vec3>> casterPositions;
    std::vector<uint32_t> sequentialIndices;
};

namespace {

// clip = m * (p, 1), inlined: GCC leaves GLM's mat4 * vec4 out of line here, and the call showed
// as 16% of the shadow maps' samples (perf, shadowMapRender). The same float operations in GLM's
// order, (m0 x + m1 y) + (m2 z + m3 1), so the positions are bitwise GLM's (m3 * 1 is m3).
[[gnu::always_inline]] inline glm::vec4 transformPoint(const glm::mat4& m, const glm::vec3& p) {
    return (m[0] * p.x + m[1] * p.y) + (m[2] * p.z + m[3]);
}

using Clock = std::chrono::steady_clock;

// Triangles per chunk of the caster cull: a chunk's box is tested against a light's sphere
// before its triangles are (consecutive triangles of one mesh are close together).
constexpr uint32_t kTrianglesPerChunk = 64;

// A face's depth buffer and its record of which tiles are not clear (ShadowFace), handed from a
// frame's maps to the next frame's.
struct DepthBuffer {
    std::vector<float> depth;
    std::vector<uint8_t> tilesNotClear;
    std::vector<uint32_t> packed; // Unorm16 faces' texels
};

// A Unorm16 face's texels from the float depth its draw wrote (ShadowSettings.h): the linear
// depth (far - distance) / (far - near), rounded down (towards the far plane) to a multiple of
// 1 / 65535, two texels per word (ShadowMapsView.h unorm16Texel: texel k in the half of word
// k / 2 that a little-endian machine stores at byte 2 k, so the texels are written as an array of
// 16-bit values). Perspective faces' reversed-Z depth z is a distance n f / (n + z (f - n)) (the
// lookup's b / (z - a)); orthographic and paraboloid faces store the linear depth already.
// Computed in float (a rounding of the linear depth, ~6e-8, against a step of 1.5e-5: at most a
// step lower at a step's boundary, the same on every machine); 0 (nothing) stays 0. A tile the
// draw's record says is clear (drawnTiles, raster::kTileSize) is zeroed without reading, and only
// when `packedTiles` (the record of `packed`, which may be a previous frame's) says it is not
// zero already: the clear two thirds of a cube map then cost no memory traffic. `packed` and
// `packedTiles` must be sized for the face.
void packUnorm16(const ShadowFace& face, std::span<const float> depth,
                 std::span<const uint8_t> drawnTiles, std::span<uint32_t> packed,
                 std::span<uint8_t> packedTiles) {
    static_assert(std::endian::native == std::endian::little,
                  "unorm16Texel's packing is written as 16-bit values in memory order");
    const float n = float(face.nearMetres), f = float(face.farMetres);
    const bool linear = face.orthographic || face.paraboloid;
    const float scale = float(kUnorm16Max);
    const float nf = n * f, range = f - n;
    const size_t size = size_t(face.mapSize);
    const size_t tilesX = (size + raster::kTileSize - 1) / raster::kTileSize;
    unsigned char* bytes = reinterpret_cast<unsigned char*>(packed.data());
    uint16_t row[raster::kTileSize];
    for (size_t y = 0; y < size; ++y)
        for (size_t x0 = 0; x0 < size; x0 += raster::kTileSize) {
            const size_t count = std::min(size_t(raster::kTileSize), size - x0);
            const size_t k0 = y * size + x0;
            const size_t tile = (y / raster::kTileSize) * tilesX + x0 / raster::kTileSize;
            if (!drawnTiles[tile]) {
                if (packedTiles[tile])
                    std::memset(bytes + 2 * k0, 0, 2 * count);
                continue;
            }
            // Two loops without a branch inside, which the compiler may put on SIMD lanes (not
            // checked: the packing is bound by the memory it reads and writes, README.md).
            const float* z = depth.data() + k0;
            if (linear) {
                for (size_t i = 0; i < count; ++i)
                    row[i] = uint16_t(int32_t(std::clamp(z[i] * scale, 0.0f, scale)));
            } else {
                for (size_t i = 0; i < count; ++i) {
                    const float steps = (f - nf / (n + z[i] * range)) / range * scale;
                    row[i] = uint16_t(int32_t(std::clamp(steps, 0.0f, scale)));
                }
            }
            std::memcpy(bytes + 2 * k0, row, 2 * count);
        }
    std::copy(drawnTiles.begin(), drawnTiles.end(), packedTiles.begin());
}

double milliseconds(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A unit vector not parallel to `direction`: the world axis least aligned with it.
glm::dvec3 upFor(const glm::dvec3& direction) {
    const glm::dvec3 a = glm::abs(direction);
    if (a.x <= a.y && a.x <= a.z)
        return {1.0, 0.0, 0.0};
    if (a.y <= a.z)
        return {0.0, 1.0, 0.0};
    return {0.0, 0.0, 1.0};
}

// Reversed-Z perspective: z_ndc = a + b / d for light-space depth d = -z, 1 at near, 0 at far.
glm::dmat4 perspectiveReversed(double tanHalfFov, double nearMetres, double farMetres) {
    const double a = -nearMetres / (farMetres - nearMetres);
    const double b = nearMetres * farMetres / (farMetres - nearMetres);
    glm::dmat4 m(0.0);
    m[0][0] = 1.0 / tanHalfFov;
    m[1][1] = 1.0 / tanHalfFov;
    m[2][2] = -a;
    m[3][2] = b;
    m[2][3] = -1.0;
    return m;
}

// Relative widening of both solids in perspectiveFaceOutsideView: covers the float positions a
// forward stage interpolates and a G-buffer reconstructs, and a point on a cube face's edge,
// which the major axis may give to either face. (Multisampled receivers lie inside the image's
// rectangle like pixel centres; the maps are rendered for the unjittered view only: the
// supersampled reference, whose sub-frames jitter the camera, shadows with rays.)
constexpr double kFaceCullSlack = 0.01;

// A pyramid or frustum with its apex at the origin of its own frame, looking down -Z: the points
// with |x| <= slopeX d, |y| <= slopeY d and near <= d <= far, d = -z (far may be infinite).
struct ViewVolume {
    double slopeX, slopeY, near, far;

    // Whether every one of `points` (in the volume's frame) lies outside one of its six planes.
    bool allOutsideOnePlane(std::span<const glm::dvec3> points) const {
        auto all = [&](auto outside) { return std::all_of(points.begin(), points.end(), outside); };
        return all([&](const glm::dvec3& p) { return -p.z < near; }) ||
               all([&](const glm::dvec3& p) { return -p.z > far; }) ||
               all([&](const glm::dvec3& p) { return p.x > slopeX * -p.z; }) ||
               all([&](const glm::dvec3& p) { return p.x < -slopeX * -p.z; }) ||
               all([&](const glm::dvec3& p) { return p.y > slopeY * -p.z; }) ||
               all([&](const glm::dvec3& p) { return p.y < -slopeY * -p.z; });
    }
    // Its 8 corners (near then far; a pyramid's near ones are its apex) through `otherFromVolume`.
    // Needs a finite far.
    std::array<glm::dvec3, 8> corners(const glm::dmat4& otherFromVolume) const {
        std::array<glm::dvec3, 8> points;
        for (int k = 0; k < 8; ++k) {
            const double d = k & 4 ? far : near;
            points[size_t(k)] =
                glm::dvec3(otherFromVolume * glm::dvec4((k & 1 ? slopeX : -slopeX) * d,
                                                        (k & 2 ? slopeY : -slopeY) * d, -d, 1.0));
        }
        return points;
    }
};

// Whether a perspective face can never be looked up: its pyramid (apex at the light, axis down
// the light frame's -Z, half-width tanHalfFov, out to light-space depth farMetres, beyond which
// every lookup is lit) and the camera's frustum (every receiver a stage looks up lies on a ray
// of the image's samples, at a view depth between the near and far planes: G-buffer positions
// are reconstructed from a depth in [near, far], forward fragments are clipped to it) are
// disjoint. Proved by a separating plane among the two solids' faces, each solid widened by
// kFaceCullSlack; a pair that only an edge-edge plane separates is kept (conservative). With an
// infinite far plane only the pyramid's corners are tested against the camera's planes.
bool perspectiveFaceOutsideView(const glm::dmat4& lightFromWorld, double tanHalfFov,
                                double farMetres, const gbuffer::CameraView& view) {
    const double grow = 1.0 + kFaceCullSlack;
    const ViewVolume pyramid{tanHalfFov * grow, tanHalfFov * grow, 0.0, farMetres * grow};
    // Symmetric pinhole (CameraView.h): the side slopes from the projection's diagonal.
    const bool finiteFar = !view.infiniteFar && std::isfinite(double(view.farMetres) * grow);
    const ViewVolume camera{grow / double(view.clipFromView[0][0]),
                            grow / double(view.clipFromView[1][1]), double(view.nearMetres) / grow,
                            finiteFar ? double(view.farMetres) * grow
                                      : std::numeric_limits<double>::infinity()};
    const glm::dmat4 viewFromLight = view.viewFromWorldExact * glm::inverse(lightFromWorld);
    if (camera.allOutsideOnePlane(pyramid.corners(viewFromLight)))
        return true;
    return finiteFar && pyramid.allOutsideOnePlane(camera.corners(glm::inverse(viewFromLight)));
}

// Reversed-Z orthographic box: x in [x0, x1], y in [y0, y1], depth d = -z in [near, far] maps
// to z_ndc = (far - d) / (far - near).
glm::dmat4 orthographicReversed(double x0, double x1, double y0, double y1, double nearMetres,
                                double farMetres) {
    glm::dmat4 m(1.0);
    m[0][0] = 2.0 / (x1 - x0);
    m[3][0] = -(x0 + x1) / (x1 - x0);
    m[1][1] = 2.0 / (y1 - y0);
    m[3][1] = -(y0 + y1) / (y1 - y0);
    m[2][2] = 1.0 / (farMetres - nearMetres);
    m[3][2] = farMetres / (farMetres - nearMetres);
    return m;
}

// Triangles a light's faces draw: either the scene's own buffers (directional lights) or the
// corners of the triangles within a point or spot light's range, three per triangle; and apart,
// the alpha-tested ones (CasterMaterials.h), three corners and the scene's triangle index each.
struct Casters {
    std::vector<glm::vec3> ownPositions;
    bool whole = false;
    std::vector<glm::vec3> testedPositions;
    std::vector<uint32_t> testedTriangles;
    std::span<const glm::vec3> positions(const gbuffer::SceneGeometry& geometry) const {
        return whole ? std::span<const glm::vec3>(geometry.positionWorld)
                     : std::span<const glm::vec3>(ownPositions);
    }
};

// What a face task needs beyond the ShadowFace it fills.
struct FaceJob {
    size_t shadow = 0;
    glm::mat4 clipFromWorld{1.0f}; // paraboloid faces: the light frame from world
};

// Casters are split no finer than this fraction of the light's range (the angle rule alone
// would never stop at an edge whose line passes through the light).
constexpr double kMinParaboloidEdgeFraction = 1e-4;

// One triangle of a paraboloid face, in the face's light frame (looking down -Z), appended to
// `out` (three corners per triangle) after clipping to the face's hemisphere z <= 0 and splitting
// every edge that spans more than the angle whose cosine is cosMaxEdge (and is longer than
// minEdge). Every decision and new point depends only on the edge's two ends, in an order that
// does not depend on which triangle asks (clip points from the lexicographically smaller end,
// midpoints as 0.5 * (a + b)): triangles that share an edge split it alike, so no T-junction
// opens a crack between them.
//
// weightsOut, when given, receives each output corner's weights of the input corners (the
// corners' own weights are `weights`, lerped along with the positions), so that an alpha-tested
// caster's pieces find their uv; the positions do not depend on it.
void appendParaboloidCasters(const std::array<glm::vec3, 3>& corners,
                             const std::array<glm::vec3, 3>& weights, float cosMaxEdge,
                             float minEdge, std::vector<glm::vec3>& out,
                             std::vector<glm::vec3>* weightsOut) {
    struct Corner {
        glm::vec3 p; // light frame
        glm::vec3 w; // weights of the input triangle's corners
    };
    auto lexLess = [](const glm::vec3& p, const glm::vec3& q) {
        return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z < q.z;
    };
    auto midpoint = [](const Corner& p, const Corner& q) {
        return Corner{0.5f * (p.p + q.p), 0.5f * (p.w + q.w)};
    };
    // Clip to z <= 0 (Sutherland-Hodgman against one plane: 0, 3 or 4 corners).
    std::array<Corner, 4> polygon;
    int count = 0;
    const std::array<Corner, 3> input = {Corner{corners[0], weights[0]},
                                         Corner{corners[1], weights[1]},
                                         Corner{corners[2], weights[2]}};
    for (int i = 0; i < 3; ++i) {
        const Corner& p = input[size_t(i)];
        const Corner& q = input[size_t((i + 1) % 3)];
        const bool pIn = p.p.z <= 0.0f, qIn = q.p.z <= 0.0f;
        if (pIn)
            polygon[size_t(count++)] = p;
        if (pIn != qIn) {
            const Corner& from = lexLess(p.p, q.p) ? p : q;
            const Corner& to = lexLess(p.p, q.p) ? q : p;
            const float t = from.p.z / (from.p.z - to.p.z);
            Corner x{from.p + t * (to.p - from.p), from.w + t * (to.w - from.w)};
            x.p.z = 0.0f;
            polygon[size_t(count++)] = x;
        }
    }
    if (count < 3)
        return;
    auto splits = [&](const glm::vec3& p, const glm::vec3& q) {
        const float lengths = glm::length(p) * glm::length(q);
        return lengths > 0.0f && glm::dot(p, q) < cosMaxEdge * lengths &&
               glm::length(q - p) > minEdge;
    };
    // Red-green refinement on an explicit stack: a triangle with k split edges becomes k + 1
    // triangles, each split again until none of its edges splits.
    std::vector<std::array<Corner, 3>> stack;
    stack.push_back({polygon[0], polygon[1], polygon[2]});
    if (count == 4)
        stack.push_back({polygon[0], polygon[2], polygon[3]});
    while (!stack.empty()) {
        const std::array<Corner, 3> t = stack.back();
        stack.pop_back();
        int first = -1, splitCount = 0;
        std::array<bool, 3> split{};
        for (int e = 0; e < 3; ++e) {
            split[size_t(e)] =
                cosMaxEdge < 1.0f && splits(t[size_t(e)].p, t[size_t((e + 1) % 3)].p);
            if (split[size_t(e)]) {
                splitCount += 1;
                if (first < 0)
                    first = e;
            }
        }
        if (splitCount == 0) {
            for (const Corner& corner : t) {
                out.push_back(corner.p);
                if (weightsOut)
                    weightsOut->push_back(corner.w);
            }
            continue;
        }
        // Rotate so that edge 0 (t0 t1) splits; m_e is the midpoint of edge e (t_e t_{e+1}).
        std::array<Corner, 3> r;
        std::array<bool, 3> s;
        for (int k = 0; k < 3; ++k) {
            r[size_t(k)] = t[size_t((first + k) % 3)];
            s[size_t(k)] = split[size_t((first + k) % 3)];
        }
        const Corner m0 = midpoint(r[0], r[1]), m1 = midpoint(r[1], r[2]),
                     m2 = midpoint(r[2], r[0]);
        if (splitCount == 3) {
            stack.push_back({r[0], m0, m2});
            stack.push_back({m0, r[1], m1});
            stack.push_back({m2, m1, r[2]});
            stack.push_back({m0, m1, m2});
        } else if (splitCount == 1) {
            stack.push_back({r[0], m0, r[2]});
            stack.push_back({m0, r[1], r[2]});
        } else if (s[1]) { // edges 0 and 1
            stack.push_back({m0, r[1], m1});
            stack.push_back({r[0], m0, m1});
            stack.push_back({r[0], m1, r[2]});
        } else { // edges 0 and 2
            stack.push_back({r[0], m0, m2});
            stack.push_back({m0, r[1], r[2]});
            stack.push_back({m0, r[2], m2});
        }
    }
}

// Marks 1 in `tilesNotClear` (row-major, tilesX x tilesY tiles of raster::kTileSize) every tile
// the screen box of a triangle of `clip` (three corners each, a size x size viewport) touches,
// with a pixel's margin for the rasterizer's snapping; every tile when a corner is not in front
// of the projection (w <= 0: no finite box).
void markTilesTouched(std::span<const glm::vec4> clip, int size, int tilesX, int tilesY,
                      std::span<uint8_t> tilesNotClear) {
    auto tileOf = [](float pixel, int tiles) {
        return int(
            std::clamp(std::floor(pixel / float(raster::kTileSize)), 0.0f, float(tiles - 1)));
    };
    for (size_t i = 0; i + 2 < clip.size(); i += 3) {
        glm::vec2 low(std::numeric_limits<float>::max()), high(-low);
        bool finite = true;
        for (size_t k = 0; k < 3; ++k) {
            const glm::vec4& c = clip[i + k];
            finite = finite && c.w > 0.0f;
            const glm::vec2 pixel((c.x / c.w * 0.5f + 0.5f) * float(size),
                                  (0.5f - c.y / c.w * 0.5f) * float(size));
            low = glm::min(low, pixel);
            high = glm::max(high, pixel);
        }
        finite = finite && std::isfinite(low.x) && std::isfinite(low.y) && std::isfinite(high.x) &&
                 std::isfinite(high.y);
        const int x0 = finite ? tileOf(low.x - 1.0f, tilesX) : 0;
        const int x1 = finite ? tileOf(high.x + 1.0f, tilesX) : tilesX - 1;
        const int y0 = finite ? tileOf(low.y - 1.0f, tilesY) : 0;
        const int y1 = finite ? tileOf(high.y + 1.0f, tilesY) : tilesY - 1;
        for (int ty = y0; ty <= y1; ++ty)
            for (int tx = x0; tx <= x1; ++tx)
                tilesNotClear[size_t(ty) * size_t(tilesX) + size_t(tx)] = 1;
    }
}

} // namespace

std::vector<uint32_t> ShadowMaps::chooseLights(const std::vector<scenes::Light>& lights,
                                               const gbuffer::CameraView& view,
                                               int maxShadowLights) {
    // A scene that marks no caster (the built-in scenes' generated lights): every light casts.
    const bool anyMarked = std::any_of(lights.begin(), lights.end(), [](const scenes::Light& l) {
        return l.castsShadows && l.type != scenes::LightType::Ambient;
    });
    std::vector<uint32_t> casting;
    for (size_t i = 0; i < lights.size(); ++i)
        if ((lights[i].castsShadows || !anyMarked) && lights[i].type != scenes::LightType::Ambient)
            casting.push_back(uint32_t(i));
    if (maxShadowLights < 0 || casting.size() <= size_t(maxShadowLights))
        return casting;

    const LightList list = LightList::build(lights, view);
    const std::vector<LightSphere> spheres = boundingSpheresView(list);
    const ViewFrustum frustum(view);
    struct Rank {
        bool misses;
        double score;
        uint32_t index;
    };
    std::vector<Rank> ranks;
    const double nearMetres = std::max(double(view.nearMetres), 1e-6);
    for (uint32_t i : casting) {
        const LightSphere& sphere = spheres[i];
        const double distance =
            sphere.unbounded
                ? 0.0
                : std::max(0.0, glm::length(glm::dvec3(sphere.centreView)) - sphere.radius);
        const double clamped = std::max(distance, nearMetres);
        const glm::vec3& colour = lights[i].color;
        const double power =
            double(lights[i].intensity) * std::max({colour.r, colour.g, colour.b, 0.0f});
        ranks.push_back({!frustum.mayTouch(sphere), power / (clamped * clamped), i});
    }
    std::sort(ranks.begin(), ranks.end(), [](const Rank& a, const Rank& b) {
        if (a.misses != b.misses)
            return !a.misses;
        if (a.score != b.score)
            return a.score > b.score;
        return a.index < b.index;
    });
    std::vector<uint32_t> chosen;
    for (int k = 0; k < maxShadowLights; ++k)
        chosen.push_back(ranks[size_t(k)].index);
    std::sort(chosen.begin(), chosen.end());
    return chosen;
}

ShadowMaps ShadowMaps::render(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry,
                              const gbuffer::CameraView& view, const ShadowSettings& settings,
                              ShadowMaps* recycled) {
    const auto start = Clock::now();
    auto checkMapSize = [](int mapSize) {
        if (!(mapSize >= 1 && mapSize <= raster::kMaxViewportSize))
            throw std::invalid_argument("shadow map size must be in [1, " +
                                        std::to_string(raster::kMaxViewportSize) + "], got " +
                                        std::to_string(mapSize));
    };
    checkMapSize(settings.mapSize);
    if (!(settings.cascades >= 1 && settings.cascades <= 8))
        throw std::invalid_argument("shadow cascades must be in [1, 8], got " +
                                    std::to_string(settings.cascades));

    ShadowMaps maps;
    // The depth buffers of a previous frame's maps, reused: a fresh face costs its page faults
    // (the kernel zeroes every new page) on top of its clear. Indexed by the previous face, so
    // that a face takes over its own last buffer, whose drawn tiles are then mostly its own.
    std::vector<DepthBuffer> depthPool;
    if (recycled) {
        for (ShadowFace& face : recycled->mFaces)
            depthPool.push_back({std::move(face.depth), std::move(face.tilesNotClear),
                                 std::move(face.packedDepth)});
        recycled->mFaces.clear();
        recycled->mFaceViews.clear();
        recycled->mShadowViews.clear();
        recycled->mView = shadows::ShadowMapsView{};
    }
    maps.mSettings = settings;
    maps.mShadowOfLight.assign(scene.lights.size(), kNoShadow);
    const glm::dmat4 worldFromView = glm::inverse(view.viewFromWorldExact);
    const glm::dmat4& viewFromWorld = view.viewFromWorldExact;
    maps.mWorldFromViewRotation = glm::dmat3(worldFromView);

    // Chunk boxes and the geometry's bounds (the receivers and casters of the scene).
    const uint32_t triangleCount = geometry.triangleCount();
    const uint32_t chunkCount = (triangleCount + kTrianglesPerChunk - 1) / kTrianglesPerChunk;
    std::vector<scenes::Aabb> chunkBounds(chunkCount);
    tbb::parallel_for(
        tbb::blocked_range<uint32_t>(0, chunkCount),
        [&](const tbb::blocked_range<uint32_t>& range) {
            for (uint32_t c = range.begin(); c != range.end(); ++c) {
                const uint32_t end = std::min(triangleCount, (c + 1) * kTrianglesPerChunk);
                for (uint32_t t = c * kTrianglesPerChunk; t < end; ++t)
                    for (int k = 0; k < 3; ++k)
                        chunkBounds[c].extend(geometry.positionWorld[geometry.indices[3 * t + k]]);
            }
        });
    scenes::Aabb sceneBounds;
    for (const scenes::Aabb& box : chunkBounds)
        sceneBounds.extend(box);

    const std::vector<uint32_t> chosen = chooseLights(scene.lights, view, settings.maxShadowLights);
    maps.mStats.castingLightCount = chooseLights(scene.lights, view, -1).size();

    // Faces: matrices and planes, per light in index order.
    std::vector<FaceJob> jobs;
    auto addFace = [&](size_t shadow, const glm::dmat4& clipFromLight,
                       const glm::dmat4& lightFromWorld, bool orthographic, double nearMetres,
                       double farMetres, double tanHalfFov, double extentMetres) {
        ShadowFace face;
        const glm::dmat4 clipFromWorld = clipFromLight * lightFromWorld;
        face.lightClipFromViewExact = clipFromWorld * worldFromView;
        face.lightClipFromView = glm::mat4(face.lightClipFromViewExact);
        face.orthographic = orthographic;
        face.nearMetres = nearMetres;
        face.farMetres = farMetres;
        face.tanHalfFov = tanHalfFov;
        face.extentMetres = extentMetres;
        // A cube or spot face no receiver in view can select is never looked up: left empty,
        // it is neither drawn nor stored (typically the faces of a light that look away from
        // the camera).
        if (!orthographic && settings.cullFacesOutsideView &&
            perspectiveFaceOutsideView(lightFromWorld, tanHalfFov, farMetres, view)) {
            face.empty = true;
            face.outsideView = true;
        }
        maps.mFaces.push_back(std::move(face));
        jobs.push_back({shadow, glm::mat4(clipFromWorld)});
    };
    // A paraboloid face (ShadowMaps.h): lightFromWorld its light frame.
    auto addParaboloidFace = [&](size_t shadow, const glm::dmat4& lightFromWorld, double nearMetres,
                                 double farMetres) {
        ShadowFace face;
        face.lightClipFromViewExact = lightFromWorld * worldFromView;
        face.lightClipFromView = glm::mat4(face.lightClipFromViewExact);
        face.paraboloid = true;
        face.nearMetres = nearMetres;
        face.farMetres = farMetres;
        face.tanHalfFov = 2.0;
        maps.mFaces.push_back(std::move(face));
        jobs.push_back({shadow, glm::mat4(lightFromWorld)});
    };
    auto addEmptyFace = [&](size_t shadow) {
        ShadowFace face;
        face.empty = true;
        maps.mFaces.push_back(std::move(face));
        jobs.push_back({shadow, glm::mat4(1.0f)});
    };

    // View depth range of the receivers (the camera's, clipped to the scene's bounds) and the
    // frustum's side slopes (symmetric pinhole, CameraView.h).
    double depthMin = std::numeric_limits<double>::max(), depthMax = -depthMin;
    std::array<glm::dvec3, 8> sceneCornersWorld;
    for (int k = 0; k < 8; ++k) {
        sceneCornersWorld[size_t(k)] = glm::dvec3(k & 1 ? sceneBounds.max.x : sceneBounds.min.x,
                                                  k & 2 ? sceneBounds.max.y : sceneBounds.min.y,
                                                  k & 4 ? sceneBounds.max.z : sceneBounds.min.z);
        const double depth = -(viewFromWorld * glm::dvec4(sceneCornersWorld[size_t(k)], 1.0)).z;
        depthMin = std::min(depthMin, depth);
        depthMax = std::max(depthMax, depth);
    }
    const double receiverNear = std::max(double(view.nearMetres), depthMin);
    const double receiverFar = std::min(double(view.farMetres), depthMax);
    const double tanHalfX = 1.0 / double(view.clipFromView[0][0]);
    const double tanHalfY = 1.0 / double(view.clipFromView[1][1]);

    for (uint32_t lightIndex : chosen) {
        const scenes::Light& light = scene.lights[lightIndex];
        Shadow shadow;
        shadow.lightIndex = lightIndex;
        shadow.type = light.type;
        shadow.firstFace = maps.mFaces.size();
        // The light's own settings (a JSON light's "shadow") over the global ones.
        shadow.settings = settingsForLight(settings, light.shadow);
        checkMapSize(shadow.settings.mapSize);
        const int size = shadow.settings.mapSize;
        // Spot and cascade faces are widened so that their outer kFaceMarginTexels texels lie
        // beyond the region they must cover (when the map is large enough to afford it).
        const double marginScale = size > 4 * kFaceMarginTexels
                                       ? double(size) / double(size - 2 * kFaceMarginTexels)
                                       : 1.0;
        const size_t shadowIndex = maps.mShadows.size();
        const glm::dvec3 position(light.positionWorld);
        const double nearMetres = kNearFraction * light.rangeMetres;
        const double farMetres = light.rangeMetres;
        if (light.type == scenes::LightType::Point &&
            settings.pointProjection == ShadowPointProjection::DualParaboloid) {
            // Front (looking down world -Y, faceFor's first) and back.
            for (const double sign : {-1.0, 1.0}) {
                const glm::dvec3 forward(0.0, sign, 0.0);
                addParaboloidFace(shadowIndex,
                                  scenes::viewFromBasis(position, forward, upFor(forward)),
                                  nearMetres, farMetres);
            }
            shadow.paraboloid = true;
            shadow.positionView = glm::dvec3(viewFromWorld * glm::dvec4(position, 1.0));
        } else if (light.type == scenes::LightType::Point) {
            // World axes: +X, -X, +Y, -Y, +Z, -Z (faceFor's order), each with an up vector
            // perpendicular to it.
            static constexpr std::array<std::array<double, 6>, 6> kCube = {{
                {1, 0, 0, 0, -1, 0},
                {-1, 0, 0, 0, -1, 0},
                {0, 1, 0, 0, 0, 1},
                {0, -1, 0, 0, 0, -1},
                {0, 0, 1, 0, -1, 0},
                {0, 0, -1, 0, -1, 0},
            }};
            const glm::dmat4 clipFromLight = perspectiveReversed(1.0, nearMetres, farMetres);
            for (const auto& axes : kCube) {
                const glm::dvec3 forward(axes[0], axes[1], axes[2]), up(axes[3], axes[4], axes[5]);
                addFace(shadowIndex, clipFromLight, scenes::viewFromBasis(position, forward, up),
                        false, nearMetres, farMetres, 1.0, 0.0);
            }
            shadow.positionView = glm::dvec3(viewFromWorld * glm::dvec4(position, 1.0));
        } else if (light.type == scenes::LightType::Spot) {
            const double halfAngle =
                std::min(std::acos(std::clamp(double(light.spotOuterCos), -1.0, 1.0)),
                         glm::radians(kMaxSpotHalfAngleDegrees));
            const double tanHalf = std::tan(halfAngle) * marginScale;
            const glm::dvec3 forward = glm::normalize(glm::dvec3(light.directionWorld));
            addFace(shadowIndex, perspectiveReversed(tanHalf, nearMetres, farMetres),
                    scenes::viewFromBasis(position, forward, upFor(forward)), false, nearMetres,
                    farMetres, tanHalf, 0.0);
        } else { // directional
            const glm::dvec3 forward = glm::normalize(glm::dvec3(light.directionWorld));
            const glm::dvec3 centre(sceneBounds.centre());
            const glm::dmat4 lightFromWorld =
                scenes::viewFromBasis(centre, forward, upFor(forward));
            const glm::dmat4 lightFromView = lightFromWorld * worldFromView;
            glm::dvec3 sceneLo(std::numeric_limits<double>::max()), sceneHi(-sceneLo);
            for (const glm::dvec3& corner : sceneCornersWorld) {
                const glm::dvec3 p(lightFromWorld * glm::dvec4(corner, 1.0));
                sceneLo = glm::min(sceneLo, p);
                sceneHi = glm::max(sceneHi, p);
            }
            const int cascades = settings.cascades;
            for (int c = 0; c < cascades; ++c) {
                auto split = [&](int i) {
                    if (i == 0)
                        return receiverNear;
                    if (i == cascades)
                        return receiverFar;
                    const double f = double(i) / cascades;
                    return kCascadeLambda * receiverNear * std::pow(receiverFar / receiverNear, f) +
                           (1.0 - kCascadeLambda) *
                               (receiverNear + (receiverFar - receiverNear) * f);
                };
                const double d0 = split(c), d1 = split(c + 1);
                shadow.cascadeFarDepthView.push_back(d1);
                if (!(receiverFar > receiverNear) || sceneBounds.empty()) {
                    addEmptyFace(shadowIndex);
                    continue;
                }
                glm::dvec3 sliceLo(std::numeric_limits<double>::max()), sliceHi(-sliceLo);
                for (int k = 0; k < 8; ++k) {
                    const double d = k & 4 ? d1 : d0;
                    const glm::dvec3 cornerView((k & 1 ? 1.0 : -1.0) * tanHalfX * d,
                                                (k & 2 ? 1.0 : -1.0) * tanHalfY * d, -d);
                    const glm::dvec3 p(lightFromView * glm::dvec4(cornerView, 1.0));
                    sliceLo = glm::min(sliceLo, p);
                    sliceHi = glm::max(sliceHi, p);
                }
                double x0 = std::max(sliceLo.x, sceneLo.x), x1 = std::min(sliceHi.x, sceneHi.x);
                double y0 = std::max(sliceLo.y, sceneLo.y), y1 = std::min(sliceHi.y, sceneHi.y);
                // Light-space depth d = -z: the near plane at the scene's bound nearest the light
                // (every caster in), the far plane at the farther receiver bound.
                double dNear = -sceneHi.z, dFar = std::min(-sliceLo.z, -sceneLo.z);
                if (!(x1 >= x0 && y1 >= y0 && dFar >= dNear)) {
                    addEmptyFace(shadowIndex);
                    continue;
                }
                // Margins: kFaceMarginTexels on each side; depth by 1% and 1 mm so that casters
                // on the bounds are not clipped; a minimum size for flat receivers.
                const double halfX = 0.5 * std::max(x1 - x0, 1e-3) * marginScale;
                const double halfY = 0.5 * std::max(y1 - y0, 1e-3) * marginScale;
                const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
                x0 = cx - halfX, x1 = cx + halfX, y0 = cy - halfY, y1 = cy + halfY;
                const double depthMargin = 0.01 * (dFar - dNear) + 1e-3;
                dNear -= depthMargin;
                dFar += depthMargin;
                addFace(shadowIndex, orthographicReversed(x0, x1, y0, y1, dNear, dFar),
                        lightFromWorld, true, dNear, dFar, 0.0, 2.0 * std::max(halfX, halfY));
            }
        }
        shadow.faceCount = maps.mFaces.size() - shadow.firstFace;
        for (size_t f = shadow.firstFace; f < maps.mFaces.size(); ++f) {
            maps.mFaces[f].mapSize = size;
            maps.mFaces[f].depthFormat = settings.depthFormat;
        }
        maps.mShadowOfLight[lightIndex] = uint32_t(shadowIndex);
        maps.mShadows.push_back(std::move(shadow));
    }

    // Shadow-casting sets (ShadowCasterSets.h): per light, the instances that may cast onto a
    // visible receiver, kept within the reach of the filter's taps (the widest face texel of the
    // light times the largest tap distance, the normal offset and a texel centre's half
    // diagonal), and for point and spot lights touching the range sphere (the range cull below,
    // exactly: ShadowCasterSets.h). Without receivers in view, or with settings.casterSets off,
    // every instance.
    const bool useSets = settings.casterSets && receiverFar > receiverNear && !sceneBounds.empty();
    const std::vector<scenes::Aabb> objectBounds =
        instanceBoundsFromChunks(geometry, scene.instances.size(), chunkBounds, kTrianglesPerChunk);
    const std::vector<glm::dvec3> frustumCorners =
        useSets ? frustumCornersWorld(view, receiverNear, receiverFar) : std::vector<glm::dvec3>{};
    const double sweepMetres = 1.01 * double(glm::length(sceneBounds.size())) + 1.0;
    std::vector<std::vector<uint8_t>> mayCast(maps.mShadows.size()); // per instance; empty: all
    std::vector<ShadowLightStats> setStats(maps.mShadows.size());
    // Per light with the sets on: its volume and margin, which also cull its point or spot
    // casters chunk by chunk below.
    std::vector<CasterVolume> volumes(maps.mShadows.size());
    std::vector<double> margins(maps.mShadows.size(), 0.0);
    for (const scenes::Aabb& box : objectBounds)
        maps.mStats.objectCount += box.empty() ? 0 : 1;
    if (useSets)
        tbb::parallel_for(size_t(0), maps.mShadows.size(), [&](size_t s) {
            const Shadow& shadow = maps.mShadows[s];
            double texelWorld = 0.0;
            for (size_t f = shadow.firstFace; f < shadow.firstFace + shadow.faceCount; ++f) {
                const ShadowFace& face = maps.mFaces[f];
                if (face.empty)
                    continue;
                const double size = face.mapSize;
                texelWorld = std::max(texelWorld, face.orthographic ? face.extentMetres / size
                                                                    : 2.0 * face.tanHalfFov *
                                                                          face.farMetres / size);
            }
            const double margin =
                (kMaxTapDistanceTexels + 1.0 + double(shadow.settings.normalOffset)) * texelWorld;
            volumes[s] = casterVolume(frustumCorners, scene.lights[shadow.lightIndex], sweepMetres);
            margins[s] = margin;
            const CasterVolume& volume = volumes[s];
            std::vector<uint8_t>& set = mayCast[s];
            set.resize(objectBounds.size());
            for (size_t i = 0; i < objectBounds.size(); ++i) {
                set[i] = volume.mayCast(objectBounds[i], margin) ? 1 : 0;
                setStats[s].casterObjects += set[i];
            }
            setStats[s].lightInFrustum = volume.lightInFrustum;
        });

    // Casters per light: point and spot lights draw the triangles of their casting set whose box
    // touches their range sphere (chunk boxes first), in triangle order; directional lights the
    // triangles of their casting set (everything when the set holds every instance).
    // Triangles of materials that cast no shadow (CasterMaterials.h: blended, masked with a
    // constant alpha below the cutoff) are left out, as the rays leave them out; alpha-tested ones
    // are kept apart, for the faces' second, alpha-testing draw.
    const std::vector<uint8_t> castingMaterial = shadows::castingMaterials(scene);
    const shadows::CasterAlphaTest alphaTest(scene, geometry);
    const bool everyMaterial = std::all_of(castingMaterial.begin(), castingMaterial.end(),
                                           [](uint8_t casts) { return casts != 0; });
    // Per-thread rasterizers and clip buffers, and the casters' lists, taken over from the
    // recycled maps (their bins and buffers then cost no allocation and no page fault).
    maps.mScratch = recycled && recycled->mScratch ? std::move(recycled->mScratch)
                                                   : std::make_shared<RenderScratch>();
    std::vector<Casters> casters(maps.mShadows.size());
    std::vector<std::vector<glm::vec3>>& casterPositions = maps.mScratch->casterPositions;
    casterPositions.resize(std::max(casterPositions.size(), casters.size()));
    for (size_t s = 0; s < casters.size(); ++s) {
        casters[s].ownPositions = std::move(casterPositions[s]);
        casters[s].ownPositions.clear();
    }
    tbb::parallel_for(size_t(0), maps.mShadows.size(), [&](size_t s) {
        const scenes::Light& light = scene.lights[maps.mShadows[s].lightIndex];
        Casters& set = casters[s];
        const std::vector<uint8_t>& inSet = mayCast[s];
        const bool everyObject = inSet.empty() || std::all_of(inSet.begin(), inSet.end(),
                                                              [&](uint8_t in) { return in != 0; });
        auto excluded = [&](uint32_t t) {
            return (!everyObject && !inSet[geometry.triangleInstance[t]]) ||
                   (!everyMaterial && !castingMaterial[geometry.triangleMaterial[t]]);
        };
        auto add = [&](uint32_t t) {
            const bool tested = alphaTest.tested(t);
            for (int k = 0; k < 3; ++k)
                (tested ? set.testedPositions : set.ownPositions)
                    .push_back(geometry.positionWorld[geometry.indices[3 * t + k]]);
            if (tested)
                set.testedTriangles.push_back(t);
        };
        if (light.type == scenes::LightType::Directional) {
            if (everyObject && everyMaterial && !alphaTest.any()) {
                set.whole = true;
                return;
            }
            for (uint32_t t = 0; t < triangleCount; ++t)
                if (!excluded(t))
                    add(t);
            return;
        }
        const glm::dvec3 centre(light.positionWorld);
        const double radius = light.rangeMetres;
        // The casting set's volume applied to chunk boxes as to object boxes: a box farther
        // than the margin from the hull of the view and the light holds nothing that can shadow
        // a texel a visible receiver reads (ShadowCasterSets.h), so a large object partly in
        // view (a room's walls) draws only its chunks near the view. Per triangle the test
        // costs more than the triangles it drops (lighting/shadows/README.md).
        const bool hull = useSets && !volumes[s].unbounded;
        auto outsideHull = [&](const scenes::Aabb& box) {
            return hull && !volumes[s].mayContain(box, margins[s]);
        };
        for (uint32_t c = 0; c < chunkCount; ++c) {
            if (!boxTouchesSphere(centre, radius, chunkBounds[c]) || outsideHull(chunkBounds[c]))
                continue;
            const uint32_t end = std::min(triangleCount, (c + 1) * kTrianglesPerChunk);
            for (uint32_t t = c * kTrianglesPerChunk; t < end; ++t) {
                if (excluded(t))
                    continue;
                scenes::Aabb box;
                for (int k = 0; k < 3; ++k)
                    box.extend(geometry.positionWorld[geometry.indices[3 * t + k]]);
                if (!boxTouchesSphere(centre, radius, box))
                    continue;
                add(t);
            }
        }
    });
    size_t maxCorners = 0;
    for (const Casters& set : casters)
        if (!set.whole)
            maxCorners = std::max(maxCorners, set.ownPositions.size());
    std::vector<uint32_t>& sequentialIndices = maps.mScratch->sequentialIndices;
    if (sequentialIndices.size() < maxCorners) {
        sequentialIndices.resize(maxCorners);
        std::iota(sequentialIndices.begin(), sequentialIndices.end(), 0u);
    }

    // The depth-only renders. Per face: clip positions, then a draw with a no-op fragment
    // function (reversed Z: Greater, cleared to 0).
    raster::RasterState state;
    state.cullMode = raster::CullMode::None;
    state.depthTest = raster::DepthTest::Greater;
    state.barycentrics = false;
    state.clearDepth = 0.0f;
    tbb::enumerable_thread_specific<RenderScratch::Thread>& scratches = maps.mScratch->threads;
    std::vector<double> faceMs(maps.mFaces.size(), 0.0);
    std::vector<uint64_t> faceTriangles(maps.mFaces.size(), 0);
    // Face f takes the buffer of the previous frame's face f; faces beyond the previous count
    // (or whose previous face had none) take what is left.
    std::vector<DepthBuffer> pooled(maps.mFaces.size());
    for (size_t f = 0; f < maps.mFaces.size() && f < depthPool.size(); ++f)
        if (!maps.mFaces[f].empty)
            pooled[f] = std::move(depthPool[f]);
    auto unused = [](const DepthBuffer& b) {
        return b.depth.capacity() == 0 && b.packed.capacity() == 0;
    };
    std::erase_if(depthPool, unused);
    for (size_t f = 0; f < maps.mFaces.size() && !depthPool.empty(); ++f)
        if (!maps.mFaces[f].empty && unused(pooled[f])) {
            pooled[f] = std::move(depthPool.back());
            depthPool.pop_back();
        }
    auto renderFace = [&](size_t f) {
        ShadowFace& face = maps.mFaces[f];
        if (face.empty)
            return;
        const auto faceStart = Clock::now();
        RenderScratch::Thread& scratch = scratches.local();
        const int size = face.mapSize;
        auto sized = std::find_if(scratch.sizes.begin(), scratch.sizes.end(),
                                  [&](const auto& s) { return s.rasterizer->width() == size; });
        if (sized == scratch.sizes.end()) {
            // Lights with their own map size: one rasterizer per size met, each kept.
            scratch.sizes.push_back({std::make_unique<raster::Rasterizer>(size, size), {}, {}});
            sized = scratch.sizes.end() - 1;
        }
        raster::Rasterizer* rasterizer = sized->rasterizer.get();
        const Casters& set = casters[jobs[f].shadow];
        const std::span<const glm::vec3> positions = set.positions(geometry);
        const std::span<const uint32_t> indices =
            set.whole ? std::span<const uint32_t>(geometry.indices)
                      : std::span<const uint32_t>(sequentialIndices.data(), positions.size());
        const glm::mat4& clipFromWorld = jobs[f].clipFromWorld;
        // Paraboloid faces: clipped and split in the light frame, then projected: x, y as they
        // are and w = |l| - l.z, so that x / w is the paraboloid's coordinate; z / w the linear
        // reversed depth (far - |l|) / (far - near).
        const float cosMaxEdge =
            settings.paraboloidMaxEdgeDegrees > 0.0
                ? float(std::cos(glm::radians(std::min(settings.paraboloidMaxEdgeDegrees, 180.0))))
                : 1.0f;
        const float minEdge = float(kMinParaboloidEdgeFraction * face.farMetres);
        const float nearM = float(face.nearMetres), farM = float(face.farMetres);
        auto paraboloidClip = [&](const glm::vec3& l) {
            const float distance = glm::length(l);
            const float w = distance - l.z;
            return glm::vec4(l.x, l.y, w * (farM - distance) / (farM - nearM), w);
        };
        constexpr std::array<glm::vec3, 3> kCornerWeights = {
            glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f)};
        auto lightFrame = [&](const glm::vec3& world) {
            return glm::vec3(transformPoint(clipFromWorld, world));
        };
        if (face.paraboloid) {
            scratch.lightSpace.clear();
            const size_t cornerCount = indices.size();
            for (size_t i = 0; i + 2 < cornerCount; i += 3)
                appendParaboloidCasters(
                    {lightFrame(positions[indices[i]]), lightFrame(positions[indices[i + 1]]),
                     lightFrame(positions[indices[i + 2]])},
                    kCornerWeights, cosMaxEdge, minEdge, scratch.lightSpace, nullptr);
            scratch.clip.resize(scratch.lightSpace.size());
            for (size_t i = 0; i < scratch.lightSpace.size(); ++i)
                scratch.clip[i] = paraboloidClip(scratch.lightSpace[i]);
            if (scratch.sequential.size() < scratch.clip.size()) {
                scratch.sequential.resize(scratch.clip.size());
                std::iota(scratch.sequential.begin(), scratch.sequential.end(), 0u);
            }
            faceTriangles[f] = scratch.clip.size() / 3;
        } else if (!settings.cullCastersPerFace) {
            scratch.clip.resize(positions.size());
            for (size_t i = 0; i < positions.size(); ++i)
                scratch.clip[i] = transformPoint(clipFromWorld, positions[i]);
            scratch.faceIndices.assign(indices.begin(), indices.end());
        } else if (set.whole) {
            // Shared vertices: each projected once, the triangles outside the face dropped from
            // the index list.
            scratch.clip.resize(positions.size());
            scratch.outcodes.resize(positions.size());
            for (size_t i = 0; i < positions.size(); ++i) {
                scratch.clip[i] = transformPoint(clipFromWorld, positions[i]);
                scratch.outcodes[i] = raster::frustumOutcode(scratch.clip[i]);
            }
            scratch.faceIndices.clear();
            for (size_t i = 0; i + 2 < indices.size(); i += 3)
                if (!(scratch.outcodes[indices[i]] & scratch.outcodes[indices[i + 1]] &
                      scratch.outcodes[indices[i + 2]]))
                    scratch.faceIndices.insert(scratch.faceIndices.end(), &indices[i],
                                               &indices[i + 3]);
        } else {
            // Three corners per triangle: only the triangles inside the face are kept, so that
            // the draw projects and sets up about a sixth of a cube map's casters per face.
            scratch.clip.clear();
            for (size_t i = 0; i + 2 < positions.size(); i += 3) {
                const glm::vec4 corners[3] = {transformPoint(clipFromWorld, positions[i]),
                                              transformPoint(clipFromWorld, positions[i + 1]),
                                              transformPoint(clipFromWorld, positions[i + 2])};
                if (!(raster::frustumOutcode(corners[0]) & raster::frustumOutcode(corners[1]) &
                      raster::frustumOutcode(corners[2])))
                    scratch.clip.insert(scratch.clip.end(), corners, corners + 3);
            }
            scratch.faceIndices.assign(sequentialIndices.begin(),
                                       sequentialIndices.begin() + scratch.clip.size());
        }
        // The face's triangles: paraboloid faces their split pieces; perspective and orthographic
        // faces those the face's frustum may hold (settings.cullCastersPerFace), by the draw's
        // own trivial reject on the same clip positions (raster::frustumOutcode), so the map is
        // bitwise the one the whole caster list draws, in a sixth of the set-up for a cube face.
        const std::span<const uint32_t> drawIndices =
            face.paraboloid
                ? std::span<const uint32_t>(scratch.sequential.data(), scratch.clip.size())
                : std::span<const uint32_t>(scratch.faceIndices);
        if (!face.paraboloid)
            faceTriangles[f] = scratch.faceIndices.size() / 3;
        // Cleared to 0 (nothing: the far plane) tile by tile inside the draw (clearDepth), only
        // where the buffer is not clear already or casters are drawn (tilesNotClear). A buffer
        // of another size is refilled: its tiles' record no longer describes it. Float32 faces
        // draw into their own buffer, Unorm16 faces into the thread's float buffer of their
        // size, packed after the draws.
        const size_t texels = size_t(size) * size_t(size);
        const size_t tiles = size_t(rasterizer->tileCountX()) * size_t(rasterizer->tileCountY());
        const bool unorm16 = face.depthFormat == ShadowDepthFormat::Unorm16;
        std::vector<float>& target = unorm16 ? sized->unormDepth : face.depth;
        std::vector<uint8_t>& targetTiles =
            unorm16 ? sized->unormTilesNotClear : face.tilesNotClear;
        face.tilesNotClear = std::move(pooled[f].tilesNotClear);
        if (unorm16) {
            // The packed texels keep their own record of the tiles that are not zero.
            face.packedDepth = std::move(pooled[f].packed);
            const size_t words = (texels + 1) / 2;
            if (face.packedDepth.size() != words || face.tilesNotClear.size() != tiles) {
                face.packedDepth.assign(words, 0u);
                face.tilesNotClear.assign(tiles, 0);
            }
        } else {
            face.depth = std::move(pooled[f].depth);
        }
        if (target.size() != texels || targetTiles.size() != tiles) {
            target.assign(texels, 0.0f);
            targetTiles.assign(tiles, 0);
        }
        raster::RasterState faceState = state;
        faceState.tilesNotClear = targetTiles;
        rasterizer->draw(raster::TriangleList{scratch.clip, drawIndices}, faceState, target.data(),
                         raster::DepthOnly{});
        if (!set.testedTriangles.empty()) {
            // The alpha-tested casters, drawn after the others into the same buffer (the depth
            // test keeps the nearest whatever the order): each corner carries its uv (a
            // paraboloid piece's from its weights of its scene triangle's corners), the fragment
            // interpolates it with its perspective-correct barycentrics, and the texel keeps the
            // fragment only where the material's alpha passes there (CasterAlphaTest, the rays'
            // test). A paraboloid piece's barycentrics are perspective-correct for its clip w,
            // not for the paraboloid's nonlinear projection: within the split's angle, about a
            // texel.
            scratch.testedClip.clear();
            scratch.testedUv.clear();
            scratch.testedMaterial.clear();
            for (size_t t = 0; t < set.testedTriangles.size(); ++t) {
                const uint32_t triangle = set.testedTriangles[t];
                const uint32_t material = geometry.triangleMaterial[triangle];
                const glm::vec3* corner = &set.testedPositions[3 * t];
                if (face.paraboloid) {
                    scratch.testedLightSpace.clear();
                    scratch.testedWeights.clear();
                    appendParaboloidCasters(
                        {lightFrame(corner[0]), lightFrame(corner[1]), lightFrame(corner[2])},
                        kCornerWeights, cosMaxEdge, minEdge, scratch.testedLightSpace,
                        &scratch.testedWeights);
                    for (size_t k = 0; k < scratch.testedLightSpace.size(); ++k) {
                        scratch.testedClip.push_back(paraboloidClip(scratch.testedLightSpace[k]));
                        scratch.testedUv.push_back(
                            alphaTest.uvAt(triangle, scratch.testedWeights[k]));
                    }
                    scratch.testedMaterial.insert(scratch.testedMaterial.end(),
                                                  scratch.testedLightSpace.size() / 3, material);
                    continue;
                }
                const glm::vec4 clip[3] = {transformPoint(clipFromWorld, corner[0]),
                                           transformPoint(clipFromWorld, corner[1]),
                                           transformPoint(clipFromWorld, corner[2])};
                if (raster::frustumOutcode(clip[0]) & raster::frustumOutcode(clip[1]) &
                    raster::frustumOutcode(clip[2]))
                    continue;
                scratch.testedClip.insert(scratch.testedClip.end(), clip, clip + 3);
                for (const glm::vec3& weights : kCornerWeights)
                    scratch.testedUv.push_back(alphaTest.uvAt(triangle, weights));
                scratch.testedMaterial.push_back(material);
            }
            if (scratch.sequential.size() < scratch.testedClip.size()) {
                scratch.sequential.resize(scratch.testedClip.size());
                std::iota(scratch.sequential.begin(), scratch.sequential.end(), 0u);
            }
            raster::RasterState testedState = state;
            testedState.barycentrics = true;
            testedState.clearDepth.reset(); // the first draw cleared
            const std::vector<glm::vec2>& uv = scratch.testedUv;
            const std::vector<uint32_t>& materialOf = scratch.testedMaterial;
            rasterizer->draw(
                raster::TriangleList{scratch.testedClip,
                                     std::span<const uint32_t>(scratch.sequential.data(),
                                                               scratch.testedClip.size())},
                testedState, target.data(), [&](const raster::Fragment& fragment) {
                    const size_t i = 3 * size_t(fragment.triangle);
                    return alphaTest.castsAtUv(
                        materialOf[fragment.triangle],
                        raster::interpolate(uv[i], uv[i + 1], uv[i + 2], fragment.barycentric));
                });
            faceTriangles[f] += scratch.testedMaterial.size();
            // The tiles record only the first draw's bins: the tested triangles' tiles may now
            // hold depth too.
            markTilesTouched(scratch.testedClip, size, rasterizer->tileCountX(),
                             rasterizer->tileCountY(), targetTiles);
        }
        if (unorm16)
            packUnorm16(face, target, targetTiles, face.packedDepth, face.tilesNotClear);
        faceMs[f] = milliseconds(faceStart);
    };
    if (settings.schedule == ShadowSchedule::FacesInParallel) {
        // Isolation: while a face's draw waits for its own tile tasks, its thread must not start
        // another face, which would reuse the thread's rasterizer in the middle of a draw.
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, maps.mFaces.size(), 1),
            [&](const tbb::blocked_range<size_t>& range) {
                for (size_t f = range.begin(); f != range.end(); ++f)
                    tbb::this_task_arena::isolate([&] { renderFace(f); });
            },
            tbb::simple_partitioner());
    } else {
        for (size_t f = 0; f < maps.mFaces.size(); ++f)
            renderFace(f);
    }

    for (size_t s = 0; s < casters.size(); ++s)
        casterPositions[s] = std::move(casters[s].ownPositions);

    for (size_t s = 0; s < maps.mShadows.size(); ++s) {
        const Shadow& shadow = maps.mShadows[s];
        ShadowLightStats lightStats;
        lightStats.lightIndex = shadow.lightIndex;
        lightStats.type = shadow.type;
        lightStats.faceCount = shadow.faceCount;
        lightStats.settings = shadow.settings;
        lightStats.casterObjects = useSets ? setStats[s].casterObjects : maps.mStats.objectCount;
        lightStats.lightInFrustum = setStats[s].lightInFrustum;
        for (size_t f = shadow.firstFace; f < shadow.firstFace + shadow.faceCount; ++f) {
            lightStats.facesOutsideView += maps.mFaces[f].outsideView ? 1 : 0;
            lightStats.bytes += maps.mFaces[f].depth.size() * sizeof(float) +
                                maps.mFaces[f].packedDepth.size() * sizeof(uint32_t);
            lightStats.renderMs += faceMs[f];
            lightStats.trianglesDrawn += faceTriangles[f];
        }
        maps.mStats.totalBytes += lightStats.bytes;
        maps.mStats.facesOutsideView += lightStats.facesOutsideView;
        maps.mStats.lights.push_back(lightStats);
    }
    maps.mStats.faceCount = maps.mFaces.size();
    maps.mStats.renderMs = milliseconds(start);

    // The plain-data view for the kernel's vector lookup: the same numbers visibility() reads.
    for (const ShadowFace& face : maps.mFaces) {
        shadows::ShadowFaceView faceView{};
        for (int column = 0; column < 4; ++column)
            for (int row = 0; row < 4; ++row)
                faceView.lightClipFromView[column][row] = face.lightClipFromViewExact[column][row];
        faceView.nearMetres = face.nearMetres;
        faceView.farMetres = face.farMetres;
        faceView.tanHalfFov = face.tanHalfFov;
        faceView.extentMetres = face.extentMetres;
        faceView.depth = face.empty || face.depth.empty() ? nullptr : face.depth.data();
        faceView.packedDepth =
            face.empty || face.packedDepth.empty() ? nullptr : face.packedDepth.data();
        faceView.orthographic = face.orthographic;
        faceView.empty = face.empty;
        maps.mFaceViews.push_back(faceView);
    }
    for (const Shadow& shadow : maps.mShadows) {
        shadows::ShadowView shadowView{};
        shadowView.type = uint32_t(shadow.type);
        shadowView.firstFace = uint32_t(shadow.firstFace);
        shadowView.faceCount = uint32_t(shadow.faceCount);
        for (int k = 0; k < 3; ++k)
            shadowView.positionView[k] = shadow.positionView[k];
        shadowView.cascadeFarDepthView = shadow.cascadeFarDepthView.data();
        const ShadowSettings& own = shadow.settings;
        shadowView.scalarOnly =
            shadow.paraboloid || own.mapSize != settings.mapSize || own.filter != settings.filter ||
            own.biasConstant != settings.biasConstant || own.biasSlope != settings.biasSlope ||
            own.normalOffset != settings.normalOffset;
        maps.mShadowViews.push_back(shadowView);
    }
    shadows::ShadowMapsView& mapsView = maps.mView;
    mapsView.shadows = maps.mShadowViews.data();
    mapsView.shadowCount = uint32_t(maps.mShadowViews.size());
    mapsView.faces = maps.mFaceViews.data();
    for (int column = 0; column < 3; ++column)
        for (int row = 0; row < 3; ++row)
            mapsView.worldFromViewRotation[column][row] = maps.mWorldFromViewRotation[column][row];
    mapsView.mapSize = settings.mapSize;
    mapsView.filter = settings.filter;
    mapsView.biasConstant = settings.biasConstant;
    mapsView.biasSlope = settings.biasSlope;
    mapsView.normalOffset = settings.normalOffset;
    return maps;
}

size_t ShadowMaps::faceFor(const Shadow& shadow, const glm::dvec3& positionView) const {
    if (shadow.type == scenes::LightType::Point && shadow.paraboloid) {
        // The front face looks down world -Y (render's order).
        const glm::dvec3 d = mWorldFromViewRotation * (positionView - shadow.positionView);
        return shadow.firstFace + (d.y <= 0.0 ? 0 : 1);
    }
    if (shadow.type == scenes::LightType::Point) {
        const glm::dvec3 d = mWorldFromViewRotation * (positionView - shadow.positionView);
        const glm::dvec3 a = glm::abs(d);
        int axis = 0;
        if (a.y > a.x && a.y >= a.z)
            axis = 1;
        else if (a.z > a.x && a.z > a.y)
            axis = 2;
        return shadow.firstFace + size_t(2 * axis + (d[axis] < 0.0 ? 1 : 0));
    }
    if (shadow.type == scenes::LightType::Directional) {
        const double depth = -positionView.z;
        for (size_t c = 0; c < shadow.faceCount; ++c)
            if (depth <= shadow.cascadeFarDepthView[c] || c + 1 == shadow.faceCount)
                return shadow.firstFace + c;
        return SIZE_MAX;
    }
    return shadow.firstFace;
}

float ShadowMaps::visibility(uint32_t shadow, const glm::vec3& positionView,
                             const glm::vec3& normalView) const {
    if (shadow >= mShadows.size())
        return 1.0f;
    const glm::dvec3 p(positionView), n(normalView);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(n.x) ||
        !std::isfinite(n.y) || !std::isfinite(n.z))
        return 1.0f;
    const size_t f = faceFor(mShadows[shadow], p);
    if (f == SIZE_MAX)
        return 1.0f;
    const float v = faceVisibility(mFaces[f], mShadows[shadow].settings, p, n);
    return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 1.0f;
}

float ShadowMaps::faceVisibility(const ShadowFace& face, const ShadowSettings& settings,
                                 glm::dvec3 p, const glm::dvec3& normalView) const {
    if (face.empty)
        return 1.0f;
    const int size = face.mapSize;
    const double sizeD = size;
    const glm::dmat4& m = face.lightClipFromViewExact;
    // Texel coordinates (u right, v down, texel i covers [i, i+1)) and light-space depth
    // (paraboloid: the distance to the light; cosAxis the cosine of the angle from the face's
    // axis).
    struct Projected {
        double u, v, depth;
        bool valid;
        double cosAxis;
    };
    auto project = [&](const glm::dvec3& q) {
        const glm::dvec4 c = m * glm::dvec4(q, 1.0);
        Projected r{0.0, 0.0, 0.0, false, 1.0};
        if (face.paraboloid) {
            const double distance = glm::length(glm::dvec3(c));
            const double w = distance - c.z;
            if (distance > 0.0 && w > 0.0) {
                r.depth = distance;
                r.u = (c.x / w * 0.5 + 0.5) * sizeD;
                r.v = (0.5 - 0.5 * c.y / w) * sizeD;
                r.cosAxis = -c.z / distance;
                r.valid = true;
            }
        } else if (face.orthographic) {
            r.depth = face.farMetres - c.z * (face.farMetres - face.nearMetres);
            r.u = (c.x * 0.5 + 0.5) * sizeD;
            r.v = (0.5 - 0.5 * c.y) * sizeD;
            r.valid = true;
        } else if (c.w > 0.0) {
            r.depth = c.w;
            r.u = (c.x / c.w * 0.5 + 0.5) * sizeD;
            r.v = (0.5 - 0.5 * c.y / c.w) * sizeD;
            r.valid = true;
        }
        return r;
    };
    // Side of one texel at a projected point, metres. Paraboloid: the coordinate is
    // tan(theta / 2) of the angle theta from the axis, d/dtheta = 1 / (1 + cos theta), so a texel
    // (2 / mapSize of the coordinate) spans (2 / mapSize) (1 + cos theta) radians.
    auto texelWorld = [&](const Projected& q) {
        if (face.paraboloid)
            return q.depth * 2.0 * (1.0 + q.cosAxis) / sizeD;
        return face.orthographic ? face.extentMetres / sizeD
                                 : 2.0 * q.depth * face.tanHalfFov / sizeD;
    };

    const double normalLength = glm::length(normalView);
    const bool hasNormal = normalLength > 0.0 && std::isfinite(normalLength);
    const glm::dvec3 n = hasNormal ? normalView / normalLength : glm::dvec3(0.0);
    Projected r = project(p);
    if (!r.valid)
        return 1.0f;
    if (hasNormal && settings.normalOffset != 0.0f) {
        p += n * (double(settings.normalOffset) * texelWorld(r));
        r = project(p);
        if (!r.valid)
            return 1.0f;
    }
    // Outside the face's coverage: lit (a tolerance of 1e-9 of the face for points on a cube
    // face's edge, which the major axis assigns to this face).
    const double tolerance = kFaceEdgeTolerance * sizeD;
    if (!(r.u >= -tolerance && r.u <= sizeD + tolerance && r.v >= -tolerance &&
          r.v <= sizeD + tolerance && r.depth >= face.nearMetres && r.depth <= face.farMetres))
        return 1.0f;

    // Receiver plane: depth change per texel along u and v, from two tangent directions.
    const double texel = texelWorld(r);
    glm::dvec2 gradient(0.0);
    double tanTheta = 0.0;
    if (hasNormal && texel > 0.0) {
        const glm::dvec3 t1 = glm::normalize(glm::cross(n, upFor(n)));
        const glm::dvec3 t2 = glm::cross(n, t1);
        const Projected a = project(p + texel * t1), b = project(p + texel * t2);
        const double du1 = a.u - r.u, dv1 = a.v - r.v, dd1 = a.depth - r.depth;
        const double du2 = b.u - r.u, dv2 = b.v - r.v, dd2 = b.depth - r.depth;
        const double det = du1 * dv2 - dv1 * du2;
        if (a.valid && b.valid && std::abs(det) > kMinReceiverPlaneDeterminant) {
            gradient = glm::dvec2(dd1 * dv2 - dv1 * dd2, du1 * dd2 - dd1 * du2) / det;
            tanTheta = glm::length(gradient) / texel;
        } else {
            tanTheta = kMaxBiasTan; // the plane contains the light's direction
        }
        if (tanTheta > kMaxBiasTan) {
            gradient *= kMaxBiasTan / tanTheta;
            tanTheta = kMaxBiasTan;
        }
    }
    const double bias =
        double(settings.biasConstant) + double(settings.biasSlope) * texel * tanTheta;

    // Stored depth -> light-space depth (reversed Z; 0 = nothing = the far plane; orthographic
    // and paraboloid faces store it linearly).
    const double n0 = face.nearMetres, f0 = face.farMetres;
    const double a = -n0 / (f0 - n0), b = n0 * f0 / (f0 - n0);
    const bool unorm16 = face.depthFormat == ShadowDepthFormat::Unorm16;
    auto lit = [&](int ti, int tj) {
        ti = std::clamp(ti, 0, size - 1);
        tj = std::clamp(tj, 0, size - 1);
        const size_t k = size_t(tj) * size_t(size) + size_t(ti);
        double occluder;
        if (unorm16) {
            const double stored = double(shadows::unorm16Texel(face.packedDepth.data(), k));
            occluder = f0 - stored / kUnorm16Max * (f0 - n0);
        } else {
            const double stored = face.depth[k];
            occluder =
                face.orthographic || face.paraboloid ? f0 - stored * (f0 - n0) : b / (stored - a);
        }
        const double receiver =
            r.depth + gradient.x * (ti + 0.5 - r.u) + gradient.y * (tj + 0.5 - r.v);
        return receiver - bias <= occluder ? 1 : 0;
    };
    const int i = int(std::floor(r.u)), j = int(std::floor(r.v));
    int litCount = 0, tapCount = 0;
    switch (settings.filter) {
    case ShadowFilter::None:
        return float(lit(i, j));
    case ShadowFilter::Pcf3:
    case ShadowFilter::Pcf5: {
        const int radius = settings.filter == ShadowFilter::Pcf3 ? 1 : 2;
        for (int dj = -radius; dj <= radius; ++dj)
            for (int di = -radius; di <= radius; ++di, ++tapCount)
                litCount += lit(i + di, j + dj);
        break;
    }
    case ShadowFilter::Poisson:
        for (const auto& offset : kPoissonDisk) {
            litCount += lit(int(std::floor(r.u + kPoissonRadiusTexels * offset[0])),
                            int(std::floor(r.v + kPoissonRadiusTexels * offset[1])));
            ++tapCount;
        }
        break;
    }
    return float(litCount) / float(tapCount);
}

} // namespace lighting
