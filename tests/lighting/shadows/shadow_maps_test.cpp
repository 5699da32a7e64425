// ShadowMaps against a brute-force oracle: every receiver sample's visibility with filter None is
// compared with a double-precision ray cast (Moller-Trumbore over every triangle of the exact
// geometry) from the sample to the light; the fraction of samples classified differently must
// stay below a bound stated per case (shadow maps are sampled at texel resolution, so samples
// within a texel or two of a shadow edge may differ). Hard cases of issue 29: a point light's
// cube seams, a 1 km ground plane with cascades, grazing-angle acne, peter-panning, a 1 cm pole,
// casters outside the camera's frustum. Also: 1 and 2 threads give bitwise the same maps (both
// schedules), no NaN, and the shadow-light budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/task_arena.h>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/CasterMaterials.h"
#include "lighting/shadows/ExactRayCast.h"
#include "lighting/shadows/RayVisibility.h"
#include "lighting/shadows/ShadowMaps.h"
#include "scenes/Scene.h"
#include "scenes/mesh/MeshBuilder.h"

namespace {

using lighting::ShadowDepthFormat;
using lighting::ShadowFilter;
using lighting::ShadowMaps;
using lighting::ShadowSettings;
using scenes::Light;
using scenes::LightType;

// ---- scene building -------------------------------------------------------------------------

struct TestScene {
    scenes::Scene scene;

    TestScene() {
        scene.name = "shadow-test";
        scene.materials.emplace_back();
    }
    scenes::Mesh& newMesh() {
        scene.meshes.emplace_back();
        scene.instances.push_back({uint32_t(scene.meshes.size() - 1), glm::mat4(1.0f)});
        return scene.meshes.back();
    }
    // A horizontal square at height y, centred at (cx, cz), facing +Y.
    void ground(float halfSize, float y = 0.0f, float cx = 0.0f, float cz = 0.0f, int cells = 4) {
        scenes::appendQuad(newMesh(), {cx - halfSize, y, cz + halfSize}, {2 * halfSize, 0, 0},
                           {0, 0, -2 * halfSize}, cells, cells);
    }
    void box(const glm::vec3& lo, const glm::vec3& hi) {
        scenes::Aabb b;
        b.min = lo;
        b.max = hi;
        scenes::appendBox(newMesh(), b, 1e6f);
    }
    void camera(const glm::vec3& position, const glm::vec3& target, float farMetres = 100.0f) {
        scenes::Camera c;
        c.positionWorld = position;
        c.forwardWorld = glm::normalize(target - position);
        c.upWorld = std::abs(c.forwardWorld.y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
        c.verticalFovRadians = glm::radians(60.0f);
        c.nearMetres = 0.1f;
        c.farMetres = farMetres;
        scene.cameras = {c};
    }
    void light(const Light& l) {
        Light copy = l;
        copy.castsShadows = true;
        scene.lights.push_back(copy);
    }
};

Light pointLight(const glm::vec3& position, float range) {
    Light l;
    l.type = LightType::Point;
    l.positionWorld = position;
    l.rangeMetres = range;
    return l;
}

Light spotLight(const glm::vec3& position, const glm::vec3& direction, float range,
                float outerDegrees) {
    Light l;
    l.type = LightType::Spot;
    l.positionWorld = position;
    l.directionWorld = glm::normalize(direction);
    l.rangeMetres = range;
    l.spotOuterCos = std::cos(glm::radians(outerDegrees));
    l.spotInnerCos = std::cos(glm::radians(outerDegrees * 0.8f));
    return l;
}

Light directionalLight(const glm::vec3& direction) {
    Light l;
    l.type = LightType::Directional;
    l.directionWorld = glm::normalize(direction);
    return l;
}

// A prepared frame: geometry, camera view, maps.
struct Frame {
    scenes::Scene scene;
    gbuffer::SceneGeometry geometry;
    gbuffer::CameraView view;
    ShadowMaps maps;

    Frame(scenes::Scene s, const ShadowSettings& settings)
        : scene(std::move(s)), geometry(gbuffer::SceneGeometry::build(scene)),
          view(gbuffer::CameraView::fromCamera(scene.cameras[0], 640, 480)),
          maps(ShadowMaps::render(scene, geometry, view, settings)) {}

    glm::vec3 toView(const glm::dvec3& world) const {
        return glm::vec3(view.viewFromWorldExact * glm::dvec4(world, 1.0));
    }
    glm::vec3 normalToView(const glm::vec3& normalWorld) const {
        return view.viewFromWorldNormal * normalWorld;
    }
    bool inView(const glm::dvec3& world) const {
        const glm::vec4 c = view.clipFromWorld() * glm::vec4(glm::vec3(world), 1.0f);
        return c.w > 0.0f && std::abs(c.x) <= c.w && std::abs(c.y) <= c.w;
    }
    float visibility(size_t light, const glm::dvec3& world, const glm::vec3& normalWorld) const {
        const uint32_t shadow = maps.shadowOf(light);
        EXPECT_NE(shadow, ShadowMaps::kNoShadow);
        return maps.visibility(shadow, toView(world), normalToView(normalWorld));
    }
};

// Every face's texels of `scene`'s maps (`texels`: ShadowFace::depth, or packedDepth for
// Unorm16 maps), rendered in an arena of `threads`.
template <typename Texel>
std::vector<std::vector<Texel>> mapsTexels(const scenes::Scene& scene,
                                           const ShadowSettings& settings, int threads,
                                           std::vector<Texel> lighting::ShadowFace::*texels) {
    tbb::task_arena arena(threads);
    return arena.execute([&] {
        const Frame frame(scene, settings);
        std::vector<std::vector<Texel>> faces;
        for (size_t f = 0; f < frame.maps.faceCount(); ++f)
            faces.push_back(frame.maps.face(f).*texels);
        return faces;
    });
}

std::vector<std::vector<float>> mapsDepth(const scenes::Scene& scene,
                                          const ShadowSettings& settings, int threads) {
    return mapsTexels(scene, settings, threads, &lighting::ShadowFace::depth);
}

std::vector<std::vector<uint32_t>> mapsPackedDepth(const scenes::Scene& scene,
                                                   const ShadowSettings& settings, int threads) {
    return mapsTexels(scene, settings, threads, &lighting::ShadowFace::packedDepth);
}

const ShadowDepthFormat kDepthFormats[] = {ShadowDepthFormat::Float32, ShadowDepthFormat::Unorm16};

// ---- the brute-force oracle -----------------------------------------------------------------

// Moller-Trumbore: the ray origin + t dir hits the triangle for some t in (tMin, tMax).
bool rayHitsTriangle(const glm::dvec3& origin, const glm::dvec3& dir, const glm::dvec3& v0,
                     const glm::dvec3& v1, const glm::dvec3& v2, double tMin, double tMax) {
    const glm::dvec3 e1 = v1 - v0, e2 = v2 - v0;
    const glm::dvec3 p = glm::cross(dir, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-18)
        return false;
    const double inv = 1.0 / det;
    const glm::dvec3 s = origin - v0;
    const double u = glm::dot(s, p) * inv;
    if (u < 0.0 || u > 1.0)
        return false;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(dir, q) * inv;
    if (v < 0.0 || u + v > 1.0)
        return false;
    const double t = glm::dot(e2, q) * inv;
    return t > tMin && t < tMax;
}

// 1 when nothing lies between the world point and the light (the surface the point lies on is
// excluded by the minimum distance), else 0.
int bruteVisibility(const gbuffer::SceneGeometry& geometry, const Light& light,
                    const glm::dvec3& point) {
    glm::dvec3 dir;
    double tMax;
    if (light.type == LightType::Directional) {
        dir = -glm::normalize(glm::dvec3(light.directionWorld));
        tMax = std::numeric_limits<double>::infinity();
    } else {
        dir = glm::dvec3(light.positionWorld) - point;
        tMax = glm::length(dir);
        dir /= tMax;
        tMax *= 1.0 - 1e-9;
    }
    const auto& p = geometry.positionWorldExact;
    for (uint32_t t = 0; t < geometry.triangleCount(); ++t)
        if (rayHitsTriangle(point, dir, p[geometry.indices[3 * t]], p[geometry.indices[3 * t + 1]],
                            p[geometry.indices[3 * t + 2]], 1e-6, tMax))
            return 0;
    return 1;
}

struct Sample {
    glm::dvec3 world;
    glm::vec3 normalWorld;
};

// Samples on a horizontal plane at height y: an n x n grid over [x0, x1] x [z0, z1], normal +Y.
std::vector<Sample> groundGrid(double x0, double x1, double z0, double z1, int n, double y = 0.0) {
    std::vector<Sample> samples;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            samples.push_back({{x0 + (x1 - x0) * (i + 0.5) / n, y, z0 + (z1 - z0) * (j + 0.5) / n},
                               {0.0f, 1.0f, 0.0f}});
    return samples;
}

struct Comparison {
    int samples = 0;
    int mismatched = 0;
    int shadowedTruth = 0;
    int shadowedBoth = 0;
    double fraction() const { return samples ? double(mismatched) / samples : 0.0; }
};

// Visibility (filter None: 0 or 1) of every sample against the oracle.
Comparison compare(const Frame& frame, size_t light, const std::vector<Sample>& samples) {
    Comparison result;
    for (const Sample& s : samples) {
        const float v = frame.visibility(light, s.world, s.normalWorld);
        EXPECT_TRUE(v == 0.0f || v == 1.0f) << "filter None gives " << v;
        const int truth = bruteVisibility(frame.geometry, frame.scene.lights[light], s.world);
        ++result.samples;
        result.mismatched += (v > 0.5f ? 1 : 0) != truth;
        result.shadowedTruth += truth == 0;
        result.shadowedBoth += truth == 0 && v < 0.5f;
    }
    // The measured figures, for the record (lighting/shadows/README.md quotes them).
    std::printf("  misclassified %d of %d samples (%.2f%%); truly shadowed %d, found %d\n",
                result.mismatched, result.samples, 100.0 * result.fraction(), result.shadowedTruth,
                result.shadowedBoth);
    return result;
}

ShadowSettings noFilter(int mapSize = 1024) {
    ShadowSettings settings;
    settings.mapSize = mapSize;
    settings.filter = ShadowFilter::None;
    return settings;
}

std::vector<Sample> withinCone(const Light& spot, const std::vector<Sample>& samples) {
    std::vector<Sample> kept;
    for (const Sample& s : samples) {
        const glm::dvec3 d = s.world - glm::dvec3(spot.positionWorld);
        if (glm::dot(glm::normalize(d), glm::dvec3(spot.directionWorld)) > spot.spotOuterCos &&
            glm::length(d) < spot.rangeMetres)
            kept.push_back(s);
    }
    return kept;
}

// The closed room of PointLightInClosedRoomHasNoSeamGaps (4 x 3 x 4 m, each wall two
// triangles) with a pillar, the point light inside: floor and far-wall samples outside the
// pillar against the rays.
Comparison compareClosedRoomWithPillar(const ShadowSettings& settings) {
    TestScene t;
    t.box({-2, 0, -2}, {2, 3, 2});
    t.box({-1.0f, 0.0f, 0.5f}, {-0.6f, 2.0f, 0.9f});
    t.camera({1.5f, 2.5f, 1.5f}, {-1, 0.5f, -1});
    t.light(pointLight({0.3f, 1.4f, -0.2f}, 10.0f));
    const Frame frame(t.scene, settings);
    EXPECT_EQ(frame.maps.faceCount(),
              settings.pointProjection == lighting::ShadowPointProjection::Cube ? 6u : 2u);
    std::vector<Sample> samples = groundGrid(-1.95, 1.95, -1.95, 1.95, 40);
    for (int j = 0; j < 30; ++j)
        for (int i = 0; i < 40; ++i)
            samples.push_back({{-1.95 + 3.9 * (i + 0.5) / 40, 0.05 + 2.9 * (j + 0.5) / 30, 2.0},
                               {0.0f, 0.0f, -1.0f}});
    std::vector<Sample> outsidePillar;
    for (const Sample& s : samples)
        if (!(s.world.x > -1.0 && s.world.x < -0.6 && s.world.z > 0.5 && s.world.z < 0.9))
            outsidePillar.push_back(s);
    return compare(frame, 0, outsidePillar);
}

// ---- cases ----------------------------------------------------------------------------------

// Bound: 2% of the samples in the cone (the shadow's outline is ~1 texel wide at 1024^2; a 60x60
// grid has ~4% of its samples within a texel of the outline).
TEST(ShadowMaps, SpotOverBoxOnPlaneMatchesRayCast) {
    TestScene t;
    t.ground(5.0f);
    t.box({-0.5f, 0.5f, -0.5f}, {0.5f, 1.5f, 0.5f});
    t.camera({0, 6, 8}, {0, 0, 0});
    t.light(spotLight({0.7f, 5.0f, 0.3f}, {0, -1, 0}, 10.0f, 40.0f));
    const Frame frame(t.scene, noFilter());
    const auto samples = withinCone(t.scene.lights[0], groundGrid(-4, 4, -4, 4, 60));
    const Comparison c = compare(frame, 0, samples);
    EXPECT_GT(c.shadowedTruth, 50);
    EXPECT_LT(c.fraction(), 0.02) << c.mismatched << " of " << c.samples;
    EXPECT_EQ(frame.maps.faceCount(), 1u);
}

// Directions near a cube-map seam (|two components| equal): wall points of a closed, empty room
// around a point light must all be lit with every filter; a pillar's shadow matches the rays.
TEST(ShadowMaps, PointLightInClosedRoomHasNoSeamGaps) {
    const glm::vec3 lo(-2, 0, -2), hi(2, 3, 2);
    const glm::dvec3 lightPosition(0.3, 1.4, -0.2);
    std::vector<Sample> seamSamples;
    // Rays from the light along the 12 cube edges' planes, |a| = |b| for two axes.
    for (int axis = 0; axis < 3; ++axis)
        for (int sa = -1; sa <= 1; sa += 2)
            for (int sb = -1; sb <= 1; sb += 2)
                for (int k = 0; k <= 40; ++k) {
                    glm::dvec3 d(0.0);
                    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
                    d[a] = sa;
                    d[b] = sb;
                    d[axis] = -0.99 + 1.98 * k / 40.0;
                    // Exit point of the ray from the light through the room's walls.
                    double tExit = std::numeric_limits<double>::max();
                    int wall = 0;
                    for (int c = 0; c < 3; ++c) {
                        if (d[c] == 0.0)
                            continue;
                        const double bound = d[c] > 0 ? hi[c] : lo[c];
                        const double tc = (bound - lightPosition[c]) / d[c];
                        if (tc < tExit)
                            tExit = tc, wall = c;
                    }
                    glm::vec3 normal(0.0f);
                    normal[wall] = d[wall] > 0 ? -1.0f : 1.0f;
                    // Not within 2 cm of a second wall: at the room's concave edges the wider
                    // filters' taps (2 texels, ~1.5 cm here) reach the other wall, which is
                    // nearer the light than the receiver's plane extended (a known limit of
                    // receiver-plane PCF, not a seam gap; filter None and Pcf3 are lit there).
                    const glm::dvec3 p = lightPosition + tExit * d;
                    bool nearEdge = false;
                    for (int c = 0; c < 3; ++c)
                        nearEdge |= c != wall && (p[c] - lo[c] < 0.02 || hi[c] - p[c] < 0.02);
                    if (!nearEdge)
                        seamSamples.push_back({p, normal});
                }
    for (ShadowFilter filter :
         {ShadowFilter::None, ShadowFilter::Pcf3, ShadowFilter::Pcf5, ShadowFilter::Poisson}) {
        TestScene t;
        t.box(lo, hi);
        t.camera({1.5f, 2.5f, 1.5f}, {-1, 0.5f, -1});
        t.light(pointLight(glm::vec3(lightPosition), 10.0f));
        ShadowSettings settings;
        settings.mapSize = 512;
        settings.filter = filter;
        const Frame frame(t.scene, settings);
        EXPECT_EQ(frame.maps.faceCount(), 6u);
        int unlit = 0;
        for (const Sample& s : seamSamples)
            unlit += frame.visibility(0, s.world, s.normalWorld) != 1.0f;
        EXPECT_EQ(unlit, 0) << lighting::formatShadowFilter(filter) << ": " << unlit << " of "
                            << seamSamples.size() << " seam samples not fully lit";
    }
    // A pillar: floor and wall samples against the rays. Bound 2%.
    const Comparison c = compareClosedRoomWithPillar(noFilter(512));
    EXPECT_GT(c.shadowedTruth, 30);
    EXPECT_LT(c.fraction(), 0.02) << c.mismatched << " of " << c.samples;
}

ShadowSettings dualParaboloid(int mapSize, double maxEdgeDegrees,
                              ShadowFilter filter = ShadowFilter::None) {
    ShadowSettings settings = noFilter(mapSize);
    settings.filter = filter;
    settings.pointProjection = lighting::ShadowPointProjection::DualParaboloid;
    settings.paraboloidMaxEdgeDegrees = maxEdgeDegrees;
    return settings;
}

// Dual-paraboloid maps in the closed room with the pillar, against the rays. Unsplit, the room's
// walls (two triangles each, spanning up to ~150 degrees seen from the light) are drawn with
// straight edges and linear depth where the paraboloid has arcs and a non-linear distance: the
// walls land in the wrong texels at the wrong depth. Here that costs nothing (measured: 2 of 2784
// samples either way, cube 1): the walls are only receivers, and the chords' linear depth lies
// beyond the true distance (no acne); the pillar is small. The table below shows the error.
// Bound 2%, as the cube's.
TEST(ShadowMaps, DualParaboloidInClosedRoomMatchesRayCast) {
    std::printf(" cube 512:\n");
    const Comparison cube = compareClosedRoomWithPillar(noFilter(512));
    std::printf(" dual-paraboloid 512, unsplit:\n");
    const Comparison unsplit = compareClosedRoomWithPillar(dualParaboloid(512, 0.0));
    std::printf(" dual-paraboloid 512, split to the default:\n");
    const Comparison split =
        compareClosedRoomWithPillar(dualParaboloid(512, ShadowSettings{}.paraboloidMaxEdgeDegrees));
    // The cube's bytes: 6 * 512^2 = 2 * 887^2.
    std::printf(" dual-paraboloid 887 (the cube's bytes), split to the default:\n");
    const Comparison sameBytes =
        compareClosedRoomWithPillar(dualParaboloid(887, ShadowSettings{}.paraboloidMaxEdgeDegrees));
    EXPECT_GT(split.shadowedTruth, 30);
    EXPECT_LT(split.fraction(), 0.02) << split.mismatched << " of " << split.samples;
    EXPECT_LT(sameBytes.fraction(), 0.02) << sameBytes.mismatched << " of " << sameBytes.samples;
    EXPECT_LT(unsplit.fraction(), 0.02);
    EXPECT_LT(cube.fraction(), 0.02);
}

// A 2 x 2 m table top 0.55 m below a point light: its edges span up to ~120 degrees seen from
// the light, so the straight-edge error of unsplit paraboloid faces moves the outline of its
// shadow on the floor; floor samples outside the table's footprint against the rays, for the
// split angles in turn (the figures README.md quotes), with the triangles the faces drew.
Comparison compareTable(const ShadowSettings& settings) {
    TestScene t;
    t.ground(4.0f, 0.0f, 0.0f, 0.0f, 8);
    t.box({-1.0f, 0.8f, -1.0f}, {1.0f, 0.85f, 1.0f});
    t.camera({3.0f, 3.0f, 3.0f}, {0, 0, 0});
    t.light(pointLight({0.2f, 1.4f, 0.1f}, 10.0f));
    const Frame frame(t.scene, settings);
    std::printf("  %llu triangles drawn, %zu bytes\n",
                (unsigned long long)frame.maps.stats().lights[0].trianglesDrawn,
                frame.maps.stats().totalBytes);
    std::vector<Sample> samples;
    for (const Sample& s : groundGrid(-3.9, 3.9, -3.9, 3.9, 80))
        if (!(std::abs(s.world.x) < 1.0 && std::abs(s.world.z) < 1.0))
            samples.push_back(s);
    return compare(frame, 0, samples);
}

TEST(ShadowMaps, DualParaboloidTableShadowMatchesRayCast) {
    std::printf(" cube 512:\n");
    const Comparison cube = compareTable(noFilter(512));
    std::vector<Comparison> byAngle;
    for (double degrees : {0.0, 16.0, 8.0, 4.0, 2.0}) {
        std::printf(" dual-paraboloid 512, edges split to %g degrees (0: unsplit):\n", degrees);
        byAngle.push_back(compareTable(dualParaboloid(512, degrees)));
    }
    std::printf(" dual-paraboloid 887, split to the default:\n");
    const Comparison sameBytes =
        compareTable(dualParaboloid(887, ShadowSettings{}.paraboloidMaxEdgeDegrees));
    const Comparison split =
        compareTable(dualParaboloid(512, ShadowSettings{}.paraboloidMaxEdgeDegrees));
    EXPECT_GT(split.shadowedTruth, 500);
    EXPECT_LT(cube.fraction(), 0.02);
    // Measured 17.8% unsplit, 0.70% split to 8 degrees (the default), cube 0.05%.
    EXPECT_GT(byAngle[0].fraction(), 0.10) << "the unsplit straight-edge error";
    EXPECT_LT(split.fraction(), 0.015) << split.mismatched << " of " << split.samples;
    EXPECT_LT(sameBytes.fraction(), 0.02);
}

// Receivers on the hemispheres' seam (the horizontal plane through the light) and beside it, on
// the closed room's walls with nothing in the room: lit with every filter (taps beyond a face's
// disk read the clear value: lit).
TEST(ShadowMaps, DualParaboloidHasNoSeamGaps) {
    const glm::dvec3 lightPosition(0.3, 1.4, -0.2);
    std::vector<Sample> seamSamples;
    for (int k = 0; k < 200; ++k) {
        const double angle = 2.0 * std::numbers::pi * (k + 0.5) / 200.0;
        for (double dy : {-0.01, -0.001, 0.0, 0.001, 0.01}) {
            const glm::dvec3 d(std::cos(angle), 0.0, std::sin(angle));
            // Exit through the side walls (x, z = +-2).
            const double tx = (d.x > 0 ? 2.0 - lightPosition.x : -2.0 - lightPosition.x) / d.x;
            const double tz = (d.z > 0 ? 2.0 - lightPosition.z : -2.0 - lightPosition.z) / d.z;
            const double tExit = std::min(tx, tz);
            glm::dvec3 p = lightPosition + tExit * d;
            p.y += dy;
            glm::vec3 normal(0.0f);
            if (tx < tz)
                normal.x = d.x > 0 ? -1.0f : 1.0f;
            else
                normal.z = d.z > 0 ? -1.0f : 1.0f;
            // Not within 4 cm of a corner: there the wider filters' taps reach the other wall
            // (the cube test's reason; a rim texel here spans 2 * 3.2 m / 512 = 1.25 cm, so
            // Poisson's 2.5 texels reach 3.1 cm).
            if (std::abs(p.x) > 1.96 && std::abs(p.z) > 1.96)
                continue;
            seamSamples.push_back({p, normal});
        }
    }
    for (ShadowFilter filter :
         {ShadowFilter::None, ShadowFilter::Pcf3, ShadowFilter::Pcf5, ShadowFilter::Poisson}) {
        TestScene t;
        t.box({-2, 0, -2}, {2, 3, 2});
        t.camera({1.5f, 2.5f, 1.5f}, {-1, 0.5f, -1});
        t.light(pointLight(glm::vec3(lightPosition), 10.0f));
        const Frame frame(t.scene,
                          dualParaboloid(512, ShadowSettings{}.paraboloidMaxEdgeDegrees, filter));
        int unlit = 0;
        for (const Sample& s : seamSamples) {
            const float v = frame.visibility(0, s.world, s.normalWorld);
            unlit += v != 1.0f;
        }
        EXPECT_EQ(unlit, 0) << lighting::formatShadowFilter(filter) << ": " << unlit << " of "
                            << seamSamples.size() << " seam samples not fully lit";
    }
}

// A 1 km ground plane, a sun and a 2 x 3 x 2 m caster 12 m in front of the camera: the shadow
// near the camera is found with 1 cascade (one map over the whole visible kilometre: texels of
// ~1 m, so only its bulk: >= 50% of the truly shadowed samples) and with 4 cascades (>= 90%,
// mismatch below 5% of the samples around the caster).
TEST(ShadowMaps, DirectionalOverKilometrePlaneFindsShadowNearCamera) {
    for (const ShadowDepthFormat format : kDepthFormats)
        for (int cascades : {1, 4}) {
            SCOPED_TRACE(lighting::formatShadowDepthFormat(format));
            TestScene t;
            t.ground(500.0f, 0.0f, 0.0f, 0.0f, 8);
            t.box({-1.0f, 0.0f, -13.0f}, {1.0f, 3.0f, -11.0f});
            t.camera({0, 1.7f, 0}, {0, 0.5f, -20}, 2000.0f);
            t.light(directionalLight({0.4f, -1.0f, 0.3f}));
            ShadowSettings settings = noFilter();
            settings.cascades = cascades;
            settings.depthFormat = format;
            const Frame frame(t.scene, settings);
            EXPECT_EQ(frame.maps.faceCount(), size_t(cascades));
            std::vector<Sample> samples;
            for (const Sample& s : groundGrid(-4, 6, -16, -6, 50))
                if (frame.inView(s.world) && !(s.world.x > -1.0 && s.world.x < 1.0 &&
                                               s.world.z > -13.0 && s.world.z < -11.0))
                    samples.push_back(s);
            const Comparison c = compare(frame, 0, samples);
            ASSERT_GT(c.shadowedTruth, 100);
            const double found = double(c.shadowedBoth) / c.shadowedTruth;
            EXPECT_GE(found, cascades == 1 ? 0.5 : 0.9) << cascades << " cascades";
            if (cascades > 1) {
                EXPECT_LT(c.fraction(), 0.05) << c.mismatched << " of " << c.samples;
            }
        }
}

// Acne: a plane lit 80 degrees from its normal (a sun and a spot) shadows no sample of itself
// with the default bias and every filter.
TEST(ShadowMaps, GrazingLightCausesNoAcneWithDefaultBias) {
    const double angle = glm::radians(80.0);
    for (const ShadowDepthFormat format : kDepthFormats)
        for (ShadowFilter filter :
             {ShadowFilter::None, ShadowFilter::Pcf3, ShadowFilter::Pcf5, ShadowFilter::Poisson}) {
            SCOPED_TRACE(lighting::formatShadowDepthFormat(format));
            TestScene t;
            t.ground(10.0f);
            t.camera({0, 4, 6}, {0, 0, -2});
            t.light(directionalLight({float(std::sin(angle)), float(-std::cos(angle)), 0.0f}));
            // A spot 1 m above the plane, its axis 80 degrees from the normal, at 5.7 m.
            t.light(spotLight({-5.67f, 1.0f, -2.0f},
                              {float(std::sin(angle)), float(-std::cos(angle)), 0}, 20.0f, 10.0f));
            ShadowSettings settings;
            settings.filter = filter;
            settings.depthFormat = format;
            const Frame frame(t.scene, settings);
            int shadowedSun = 0, shadowedSpot = 0, spotSamples = 0;
            for (const Sample& s : groundGrid(-6, 6, -8, 4, 60)) {
                if (!frame.inView(s.world))
                    continue;
                shadowedSun += frame.visibility(0, s.world, s.normalWorld) < 1.0f;
                if (!withinCone(t.scene.lights[1], {s}).empty()) {
                    ++spotSamples;
                    shadowedSpot += frame.visibility(1, s.world, s.normalWorld) < 1.0f;
                }
            }
            EXPECT_EQ(shadowedSun, 0) << lighting::formatShadowFilter(filter);
            EXPECT_GT(spotSamples, 20);
            EXPECT_EQ(shadowedSpot, 0) << lighting::formatShadowFilter(filter);
        }
}

// Peter-panning: a 1 m box standing on the ground, a sun 45 degrees from the vertical. Along the
// shadow's centre line the ground is shadowed from kContactGap beyond the box's face to the end
// of the shadow (1 m) with the default bias; the gap the bias allows is 5 mm * sin(45 deg) plus
// a texel or two (texels of ~5 mm here).
constexpr double kContactGap = 0.02; // metres
TEST(ShadowMaps, ContactShadowStartsWithinSmallGap) {
    for (const ShadowDepthFormat format : kDepthFormats)
        for (ShadowFilter filter : {ShadowFilter::None, ShadowFilter::Pcf3}) {
            SCOPED_TRACE(lighting::formatShadowDepthFormat(format));
            TestScene t;
            t.ground(3.0f);
            t.box({-0.5f, 0.0f, -0.5f}, {0.5f, 1.0f, 0.5f});
            t.camera({0, 3, 4}, {0.5f, 0, 0});
            t.light(directionalLight({1.0f, -1.0f, 0.0f}));
            ShadowSettings settings;
            settings.filter = filter;
            settings.depthFormat = format;
            const Frame frame(t.scene, settings);
            // Measured gap: the first sample (1 mm steps) from the face that is fully shadowed.
            double gap = -1.0;
            for (int k = 0; k < 200 && gap < 0.0; ++k) {
                const double x = 0.5 + 0.001 * (k + 0.5);
                if (frame.visibility(0, {x, 0.0, 0.0}, {0, 1, 0}) == 0.0f)
                    gap = x - 0.5;
            }
            std::printf("  %s, %s: contact shadow from %.1f mm beyond the box\n",
                        lighting::formatShadowDepthFormat(format),
                        lighting::formatShadowFilter(filter), gap * 1e3);
            EXPECT_GE(gap, 0.0) << "no contact shadow";
            EXPECT_LE(gap, kContactGap) << lighting::formatShadowFilter(filter);
            // ... and it stays shadowed to the end of the shadow (minus the filter's reach).
            int lit = 0;
            for (double x = 0.5 + kContactGap; x < 1.45; x += 0.01)
                lit += frame.visibility(0, {x, 0.0, 0.0}, {0, 1, 0}) > 0.0f;
            EXPECT_EQ(lit, 0) << lighting::formatShadowFilter(filter);
        }
}

// A 1 cm pole, 2 m tall, at mapSize 2048 (texels of ~3 mm): the centre line of its shadow on
// the ground is shadowed in >= 90% of its samples between 0.1 m and 1.5 m from the pole.
TEST(ShadowMaps, ThinPoleCastsAShadow) {
    TestScene t;
    t.ground(3.0f);
    scenes::appendCylinder(t.newMesh(), {0, 0, 0}, 0.005f, 2.0f, 12, 1);
    t.camera({0, 2.5f, 3.5f}, {0.8f, 0, 0});
    t.light(directionalLight({1.0f, -1.0f, 0.0f}));
    const Frame frame(t.scene, noFilter(2048));
    int shadowed = 0, samples = 0;
    for (double x = 0.1; x <= 1.5; x += 0.01, ++samples)
        shadowed += frame.visibility(0, {x, 0.0, 0.0}, {0, 1, 0}) == 0.0f;
    std::printf("  pole shadow line: %d of %d samples shadowed\n", shadowed, samples);
    EXPECT_GE(shadowed, int(0.9 * samples)) << shadowed << " of " << samples;
    const std::vector<Sample> line = groundGrid(0.1, 1.5, -0.05, 0.05, 30);
    const Comparison c = compare(frame, 0, line);
    EXPECT_LT(c.fraction(), 0.1) << c.mismatched << " of " << c.samples;
}

// Casters outside the camera's frustum throw shadows into it: a wall behind the camera under a
// low sun, and a box beside a spot light above and behind the camera. Bound 2% each.
TEST(ShadowMaps, CasterOutsideFrustumShadowsTheView) {
    {
        TestScene t;
        t.ground(20.0f);
        t.box({-3.0f, 0.0f, 1.0f}, {3.0f, 4.0f, 1.5f}); // behind the camera (which looks -Z)
        t.camera({0, 1.5f, 0}, {0, 0, -6});
        t.light(directionalLight({0.0f, -1.0f, -1.2f}));
        const Frame frame(t.scene, noFilter());
        EXPECT_FALSE(frame.inView({0, 2, 1.2}));
        std::vector<Sample> samples;
        for (const Sample& s : groundGrid(-5, 5, -8, 0, 50))
            if (frame.inView(s.world))
                samples.push_back(s);
        const Comparison c = compare(frame, 0, samples);
        EXPECT_GT(c.shadowedTruth, 100);
        EXPECT_LT(c.fraction(), 0.02) << c.mismatched << " of " << c.samples;
    }
    {
        TestScene t;
        t.ground(20.0f);
        t.box({-0.5f, 2.5f, 1.5f}, {0.5f, 3.0f, 2.0f}); // above and behind the camera
        t.camera({0, 1.5f, 0}, {0, 0, -6});
        t.light(spotLight({0, 4.0f, 3.0f}, {0, -1.0f, -1.0f}, 15.0f, 35.0f));
        const Frame frame(t.scene, noFilter());
        EXPECT_FALSE(frame.inView({0, 2.75, 1.75}));
        std::vector<Sample> samples;
        for (const Sample& s : withinCone(t.scene.lights[0], groundGrid(-5, 5, -8, 0, 50)))
            if (frame.inView(s.world))
                samples.push_back(s);
        const Comparison c = compare(frame, 0, samples);
        EXPECT_GT(c.shadowedTruth, 50);
        EXPECT_LT(c.fraction(), 0.02) << c.mismatched << " of " << c.samples;
    }
}

// Ground, two boxes, a spot, a point light and a sun: every kind of light over casters.
TestScene everyLightKindScene() {
    TestScene t;
    t.ground(5.0f);
    t.box({-0.5f, 0.0f, -0.5f}, {0.5f, 1.0f, 0.5f});
    t.box({1.0f, 0.0f, 1.0f}, {1.5f, 2.0f, 1.5f});
    t.camera({0, 3, 6}, {0, 0, 0});
    t.light(spotLight({0, 4, 0}, {0.2f, -1, 0}, 8.0f, 40.0f));
    t.light(pointLight({-1.5f, 1.0f, 0.5f}, 5.0f));
    t.light(directionalLight({0.3f, -1.0f, 0.2f}));
    return t;
}

// A scene with every kind of light, rendered with 1 and 2 threads, both schedules: the maps are
// bitwise the same; visibility is finite and in [0, 1] for samples, zero normals and points at
// the light.
TEST(ShadowMaps, RenderIsBitwiseIndependentOfThreadsAndNeverNaN) {
    const TestScene t = everyLightKindScene();
    for (const lighting::ShadowPointProjection projection :
         {lighting::ShadowPointProjection::Cube, lighting::ShadowPointProjection::DualParaboloid}) {
        SCOPED_TRACE(lighting::formatShadowPointProjection(projection));
        const size_t pointFaces = projection == lighting::ShadowPointProjection::Cube ? 6 : 2;
        ShadowSettings settings;
        settings.mapSize = 256;
        settings.cascades = 3;
        settings.pointProjection = projection;
        auto renderWith = [&](int threads, lighting::ShadowSchedule schedule) {
            ShadowSettings s = settings;
            s.schedule = schedule;
            return mapsDepth(t.scene, s, threads);
        };
        const auto reference = renderWith(1, lighting::ShadowSchedule::FacesInParallel);
        EXPECT_EQ(reference.size(), 1u + pointFaces + 3u);
        EXPECT_EQ(renderWith(2, lighting::ShadowSchedule::FacesInParallel), reference);
        EXPECT_EQ(renderWith(2, lighting::ShadowSchedule::FacesInSequence), reference);

        const Frame frame(t.scene, settings);
        EXPECT_EQ(frame.maps.stats().faceCount, 1u + pointFaces + 3u);
        EXPECT_EQ(frame.maps.stats().lights.size(), 3u);
        size_t bytes = 0;
        for (const auto& light : frame.maps.stats().lights)
            bytes += light.bytes;
        EXPECT_EQ(bytes, frame.maps.stats().totalBytes);
        int nonFinite = 0;
        for (size_t light = 0; light < 3; ++light)
            for (const Sample& s : groundGrid(-5, 5, -5, 5, 30)) {
                for (const glm::vec3& n : {s.normalWorld, glm::vec3(0.0f), glm::vec3(1, 0, 0)}) {
                    const float v = frame.visibility(light, s.world, n);
                    nonFinite += !(v >= 0.0f && v <= 1.0f);
                }
            }
        nonFinite += !(frame.visibility(1, {-1.5, 1.0, 0.5}, {0, 1, 0}) >= 0.0f);
        nonFinite += !(frame.visibility(0, {0, 4, 0}, {0, 1, 0}) >= 0.0f);
        EXPECT_EQ(nonFinite, 0);
    }
}

// ShadowDepthFormat::Unorm16: every texel is the float map's depth made linear ((far - distance)
// / (far - near)) and rounded down to a multiple of 1 / 65535, so that no occluder is stored
// nearer than it is (a float rounding may land a step lower at a step's boundary, never higher);
// nothing stays 0. Spot, cube and dual-paraboloid point and 3-cascade directional faces of an
// odd size (the last word holds one texel), half the bytes, bitwise the same for 1 and 2
// threads and both schedules.
TEST(ShadowMaps, Unorm16TexelsAreTheFloatDepthRoundedTowardsTheFarPlane) {
    const TestScene t = everyLightKindScene();
    constexpr int kSize = 255;
    for (const lighting::ShadowPointProjection projection :
         {lighting::ShadowPointProjection::Cube, lighting::ShadowPointProjection::DualParaboloid}) {
        SCOPED_TRACE(lighting::formatShadowPointProjection(projection));
        ShadowSettings settings;
        settings.mapSize = kSize;
        settings.cascades = 3;
        settings.pointProjection = projection;
        const Frame floats(t.scene, settings);
        settings.depthFormat = ShadowDepthFormat::Unorm16;
        const Frame unorm(t.scene, settings);
        ASSERT_EQ(unorm.maps.faceCount(), floats.maps.faceCount());
        size_t covered = 0, exact = 0, wordsTotal = 0;
        for (size_t f = 0; f < unorm.maps.faceCount(); ++f) {
            const lighting::ShadowFace& face = unorm.maps.face(f);
            const lighting::ShadowFace& reference = floats.maps.face(f);
            ASSERT_EQ(face.empty, reference.empty);
            if (face.empty)
                continue;
            EXPECT_TRUE(face.depth.empty());
            ASSERT_EQ(face.packedDepth.size(), (size_t(kSize) * kSize + 1) / 2);
            wordsTotal += face.packedDepth.size();
            const double n = reference.nearMetres, far = reference.farMetres;
            for (size_t k = 0; k < size_t(kSize) * kSize; ++k) {
                const double z = reference.depth[k];
                const uint32_t u = lighting::shadows::unorm16Texel(face.packedDepth.data(), k);
                if (z == 0.0) {
                    EXPECT_EQ(u, 0u) << "face " << f << " texel " << k;
                    continue;
                }
                ++covered;
                const double linear = reference.orthographic || reference.paraboloid
                                          ? z
                                          : (far - n * far / (n + z * (far - n))) / (far - n);
                const double steps = linear * lighting::kUnorm16Max;
                EXPECT_LE(double(u), steps + 1e-2) << "face " << f << " texel " << k;
                EXPECT_GE(double(u), std::floor(steps) - 1.0) << "face " << f << " texel " << k;
                exact += double(u) == std::floor(steps);
            }
        }
        EXPECT_GT(covered, size_t(kSize) * kSize) << "the maps hold almost nothing";
        EXPECT_GE(double(exact), 0.99 * double(covered)) << exact << " of " << covered;
        EXPECT_EQ(unorm.maps.stats().totalBytes, wordsTotal * sizeof(uint32_t));
        EXPECT_LT(unorm.maps.stats().totalBytes, floats.maps.stats().totalBytes / 2 + 64);

        const auto reference = mapsPackedDepth(t.scene, settings, 1);
        EXPECT_EQ(mapsPackedDepth(t.scene, settings, 2), reference);
        settings.schedule = lighting::ShadowSchedule::FacesInSequence;
        EXPECT_EQ(mapsPackedDepth(t.scene, settings, 2), reference);
    }
}

// The closed room's pillar (compareClosedRoomWithPillar) with 16-bit maps: the shadow against
// the rays is as good as the float maps' (a step of 0.15 mm for the light's 10 m range, far
// below the 5 mm bias).
TEST(ShadowMaps, Unorm16MapsMatchTheRaysAsWellAsFloatMaps) {
    ShadowSettings settings = noFilter();
    const Comparison floats = compareClosedRoomWithPillar(settings);
    settings.depthFormat = ShadowDepthFormat::Unorm16;
    const Comparison unorm = compareClosedRoomWithPillar(settings);
    EXPECT_GT(unorm.shadowedTruth, 100);
    EXPECT_LE(unorm.mismatched, floats.mismatched + unorm.samples / 500)
        << unorm.mismatched << " vs " << floats.mismatched << " of " << unorm.samples;
}

// Each face drops the casters outside its frustum before the draw (cullCastersPerFace): the maps
// are bitwise the ones drawn from the whole caster lists, for the indexed lists (a directional
// light with every object, sets off) and the per-light corner lists (sets on, point and spot),
// and a cube face is given clearly fewer triangles than its light's whole list.
TEST(ShadowMaps, PerFaceCasterCullGivesTheSameMaps) {
    TestScene t;
    t.ground(5.0f);
    t.box({-0.5f, 0.0f, -0.5f}, {0.5f, 1.0f, 0.5f});
    t.box({1.0f, 0.0f, 1.0f}, {1.5f, 2.0f, 1.5f});
    t.box({-3.0f, 0.0f, 2.0f}, {-2.5f, 3.0f, 2.5f});
    t.camera({0, 3, 6}, {0, 0, 0});
    t.light(spotLight({0, 4, 0}, {0.2f, -1, 0}, 8.0f, 40.0f));
    t.light(pointLight({-1.5f, 1.0f, 0.5f}, 5.0f));
    t.light(directionalLight({0.3f, -1.0f, 0.2f}));
    for (const bool sets : {false, true})
        for (const int cascades : {1, 3}) {
            SCOPED_TRACE(std::string("sets ") + (sets ? "on" : "off") + ", cascades " +
                         std::to_string(cascades));
            ShadowSettings settings;
            settings.mapSize = 256;
            settings.cascades = cascades;
            settings.casterSets = sets;
            ShadowSettings whole = settings;
            whole.cullCastersPerFace = false;
            const Frame culled(t.scene, settings), drawnWhole(t.scene, whole);
            ASSERT_EQ(culled.maps.faceCount(), drawnWhole.maps.faceCount());
            for (size_t f = 0; f < culled.maps.faceCount(); ++f)
                EXPECT_EQ(culled.maps.face(f).depth, drawnWhole.maps.face(f).depth) << "face " << f;
            const auto& point = culled.maps.stats().lights[1];
            const auto& pointWhole = drawnWhole.maps.stats().lights[1];
            EXPECT_EQ(point.faceCount, 6u);
            EXPECT_LT(2 * point.trianglesDrawn, pointWhole.trianglesDrawn);
        }
}

// The budget keeps the lights that matter most in view: brighter and nearer first, lights whose
// support misses the view last, ambient and non-casting lights never.
TEST(ShadowMaps, BudgetChoosesTheLightsThatMatterMostInView) {
    TestScene t;
    t.ground(5.0f);
    t.camera({0, 2, 5}, {0, 0, 0});
    t.light(pointLight({0, 1, 0}, 2.0f));  // 0: in view, near
    t.light(pointLight({0, 1, -4}, 1.0f)); // 1: in view, farther
    Light behind = pointLight({0, 1, 30}, 1.0f);
    behind.intensity = 1e6f;
    t.light(behind); // 2: bright but behind the camera
    Light ambient;
    ambient.type = LightType::Ambient;
    t.light(ambient); // 3: never casts
    Light plain = pointLight({0, 1, 1}, 2.0f);
    t.scene.lights.push_back(plain); // 4: castsShadows false
    const auto view = gbuffer::CameraView::fromCamera(t.scene.cameras[0], 640, 480);
    using V = std::vector<uint32_t>;
    EXPECT_EQ(ShadowMaps::chooseLights(t.scene.lights, view, -1), (V{0, 1, 2}));
    EXPECT_EQ(ShadowMaps::chooseLights(t.scene.lights, view, 1), (V{0}));
    EXPECT_EQ(ShadowMaps::chooseLights(t.scene.lights, view, 2), (V{0, 1}));
    EXPECT_EQ(ShadowMaps::chooseLights(t.scene.lights, view, 0), V{});

    ShadowSettings settings;
    settings.mapSize = 64;
    settings.maxShadowLights = 1;
    const Frame frame(t.scene, settings);
    EXPECT_EQ(frame.maps.shadowOf(0), 0u);
    for (size_t light : {1, 2, 3, 4})
        EXPECT_EQ(frame.maps.shadowOf(light), ShadowMaps::kNoShadow);
    EXPECT_EQ(frame.maps.stats().castingLightCount, 3u);

    // A scene that marks no caster (the built-in scenes' generated lights): every non-ambient
    // light casts, under the same budget.
    for (Light& light : t.scene.lights)
        light.castsShadows = false;
    EXPECT_EQ(ShadowMaps::chooseLights(t.scene.lights, view, -1), (V{0, 1, 2, 4}));
    EXPECT_EQ(ShadowMaps::chooseLights(t.scene.lights, view, 2), (V{0, 4}));
}

// Per-light settings (a JSON light's "shadow"): two lights with their own map size, bias,
// filter and normal offset, a third with none. Each light's maps have its own size, and its
// maps and lookups are bitwise those of a render of that light alone whose GLOBAL settings are
// the light's own (what --shadow-map-size, --shadow-bias and --shadow-filter would give).
TEST(ShadowMaps, PerLightSettingsOverrideTheGlobalOnes) {
    TestScene t;
    t.ground(5.0f);
    t.box({-0.5f, 0.0f, -0.5f}, {0.5f, 1.0f, 0.5f});
    t.box({1.0f, 0.0f, 1.0f}, {1.5f, 2.0f, 1.5f});
    t.camera({0, 3, 6}, {0, 0, 0});
    Light spot = spotLight({0.3f, 4, 0.2f}, {0.1f, -1, 0}, 8.0f, 40.0f);
    spot.shadow.mapSize = 256;
    spot.shadow.filter = ShadowFilter::Pcf5;
    spot.shadow.biasConstant = 0.02f;
    spot.shadow.biasSlope = 3.0f;
    t.light(spot);
    Light point = pointLight({-1.5f, 1.5f, 0.5f}, 6.0f);
    point.shadow.mapSize = 128;
    point.shadow.filter = ShadowFilter::Poisson;
    point.shadow.normalOffset = 0.5f;
    t.light(point);
    t.light(spotLight({1.5f, 4, -1}, {-0.2f, -1, 0.1f}, 8.0f, 35.0f)); // the global settings
    ShadowSettings global;
    global.mapSize = 512;
    global.filter = ShadowFilter::Pcf3;
    const Frame frame(t.scene, global);

    const std::vector<int> expectedSize = {256, 128, 512};
    for (size_t light = 0; light < 3; ++light) {
        SCOPED_TRACE("light " + std::to_string(light));
        const uint32_t shadow = frame.maps.shadowOf(light);
        ASSERT_NE(shadow, ShadowMaps::kNoShadow);
        const ShadowSettings own = lighting::settingsForLight(global, t.scene.lights[light].shadow);
        EXPECT_EQ(frame.maps.stats().lights[shadow].settings.mapSize, expectedSize[light]);
        EXPECT_EQ(frame.maps.stats().lights[shadow].settings.filter, own.filter);
        EXPECT_EQ(frame.maps.stats().lights[shadow].settings.biasConstant, own.biasConstant);
        EXPECT_EQ(frame.maps.stats().lights[shadow].settings.normalOffset, own.normalOffset);

        // The light alone, its own settings as the global ones.
        TestScene alone = t;
        alone.scene.lights = {t.scene.lights[light]};
        alone.scene.lights[0].shadow = {};
        const Frame single(alone.scene, own);
        ASSERT_EQ(single.maps.faceCountOf(0), frame.maps.faceCountOf(shadow));
        for (size_t f = 0; f < single.maps.faceCountOf(0); ++f) {
            const lighting::ShadowFace& mine = frame.maps.face(frame.maps.firstFace(shadow) + f);
            EXPECT_EQ(mine.mapSize, expectedSize[light]);
            EXPECT_EQ(mine.depth.size(), size_t(expectedSize[light] * expectedSize[light]));
            EXPECT_EQ(mine.depth, single.maps.face(single.maps.firstFace(0) + f).depth);
        }
        int differing = 0, partial = 0;
        for (const Sample& s : groundGrid(-4, 4, -4, 4, 60)) {
            const float v = frame.visibility(light, s.world, s.normalWorld);
            differing += v != single.visibility(0, s.world, s.normalWorld);
            partial += v > 0.0f && v < 1.0f;
        }
        EXPECT_EQ(differing, 0);
        EXPECT_GT(partial, 0) << "the filter's penumbra is missing";
    }
    // The lookups do differ from the global settings' (the light's own settings are used).
    TestScene globalOnly = t;
    for (Light& light : globalOnly.scene.lights)
        light.shadow = {};
    const Frame plain(globalOnly.scene, global);
    for (size_t light = 0; light < 2; ++light) {
        int differing = 0;
        for (const Sample& s : groundGrid(-4, 4, -4, 4, 60))
            differing += frame.visibility(light, s.world, s.normalWorld) !=
                         plain.visibility(light, s.world, s.normalWorld);
        EXPECT_GT(differing, 0) << "light " << light;
    }
}

// The casting policy by material (CasterMaterials.h), the same in maps and rays: under a sun
// straight above, 1 m squares over the ground, opaque / blended (alpha 0.3) / masked with a
// constant alpha 0.3 below its cutoff 0.5 / masked with 0.8 above it. The ground under each
// square's centre (a 0.6 m grid inside it) is shadowed by the opaque and the masked-above
// squares only, in the maps (filter none) and in the rays (RayVisibility with the policy).
TEST(ShadowMaps, BlendedAndMaskedBelowCutoffCastNoShadowInMapsAndRays) {
    TestScene t;
    t.ground(4.0f);
    struct Square {
        scenes::AlphaMode mode;
        float alpha;
        bool casts;
    };
    const std::vector<Square> squares = {{scenes::AlphaMode::Opaque, 1.0f, true},
                                         {scenes::AlphaMode::Blend, 0.3f, false},
                                         {scenes::AlphaMode::Mask, 0.3f, false},
                                         {scenes::AlphaMode::Mask, 0.8f, true}};
    for (size_t i = 0; i < squares.size(); ++i) {
        scenes::Material material;
        material.alphaMode = squares[i].mode;
        material.baseColorFactor.a = squares[i].alpha;
        material.alphaCutoff = 0.5f;
        t.scene.materials.push_back(material);
        scenes::Mesh& mesh = t.newMesh();
        const float x = -3.0f + 1.5f * float(i);
        scenes::appendQuad(mesh, {x, 1.0f, 0.5f}, {1, 0, 0}, {0, 0, -1}, 1, 1);
        mesh.material = uint32_t(t.scene.materials.size() - 1);
    }
    t.camera({0, 5, 6}, {0, 0, 0});
    t.light(directionalLight({0.0f, -1.0f, 0.0f}));
    const Frame frame(t.scene, noFilter());
    const std::vector<uint8_t> casting = lighting::shadows::castingMaterials(t.scene);
    EXPECT_EQ(casting, (std::vector<uint8_t>{1, 1, 0, 0, 1}));
    const lighting::shadows::RayVisibility rays(frame.geometry, casting);
    for (size_t i = 0; i < squares.size(); ++i) {
        const double x = -3.0 + 1.5 * double(i) + 0.5;
        int mapShadowed = 0, rayShadowed = 0, samples = 0;
        for (const Sample& s : groundGrid(x - 0.3, x + 0.3, -0.3, 0.3, 10)) {
            ++samples;
            mapShadowed += frame.visibility(0, s.world, s.normalWorld) == 0.0f;
            rayShadowed += rays.occludedDirectional(s.world, glm::dvec3(s.normalWorld),
                                                    glm::dvec3(0.0, -1.0, 0.0));
        }
        EXPECT_EQ(mapShadowed, squares[i].casts ? samples : 0) << "square " << i;
        EXPECT_EQ(rayShadowed, squares[i].casts ? samples : 0) << "square " << i;
    }
    EXPECT_EQ(rays.droppedTriangleCount(), 4u); // the two squares that cast nothing
}

// A cut-out (a textured Mask material: a 4x4 checker of alpha 0 and 1) over a ground plane casts
// only where its alpha passes, in every kind of map and in the rays (Embree's filter and the exact
// oracle alike). The receivers are the points whose rays to the light pass through the centres of
// the texture's texels, where the bilinear alpha is the texel's own (0 or 1): half must be
// shadowed, half lit. Before the per-texel test, every one was shadowed.
// A quad corner + s * edgeU + t * edgeV cut out by a 4x4 checker of alpha 0 and 1 (a textured
// Mask material, cutoff 0.5, added to the scene with its texture); returns the texture.
scenes::Texture addCheckerCutOut(TestScene& t, const glm::vec3& corner, const glm::vec3& edgeU,
                                 const glm::vec3& edgeV) {
    scenes::Texture checker;
    checker.name = "checker";
    checker.width = checker.height = 4;
    for (int r = 0; r < 4; ++r)
        for (int i = 0; i < 4; ++i)
            checker.rgba8.insert(checker.rgba8.end(),
                                 {200, 200, 200, uint8_t((i + r) % 2 == 0 ? 255 : 0)});
    t.scene.textures.push_back(checker);
    scenes::Material cutOut;
    cutOut.alphaMode = scenes::AlphaMode::Mask;
    cutOut.alphaCutoff = 0.5f;
    cutOut.baseColorTexture = int(t.scene.textures.size() - 1);
    t.scene.materials.push_back(cutOut);
    scenes::Mesh& quad = t.newMesh();
    scenes::appendQuad(quad, corner, edgeU, edgeV, 1, 1);
    quad.material = uint32_t(t.scene.materials.size() - 1);
    return checker;
}

TEST(ShadowMaps, AlphaTestedCastersCastOnlyWhereTheirAlphaPasses) {
    TestScene t;
    t.ground(6.0f);
    // uv.x = (x + 1) / 2, uv.y = (z + 1) / 2 (MeshBuilder: uv.x along edgeU, uv.y falling along
    // edgeV), facing +Y, two triangles.
    const scenes::Texture checker = addCheckerCutOut(t, {-1.0f, 1.0f, 1.0f}, {2, 0, 0}, {0, 0, -2});
    t.camera({0, 5, 6}, {0, 0, 0});
    t.light(directionalLight({0.0f, -1.0f, 0.0f}));
    t.light(spotLight({0.2f, 4.0f, 0.1f}, {0, -1, 0}, 12.0f, 50.0f));
    t.light(pointLight({-0.3f, 4.0f, 0.2f}, 12.0f));

    // The receivers: under texel (i, r)'s centre, seen from light `light`.
    struct Receiver {
        glm::dvec3 ground;
        bool shadowed;
    };
    auto receivers = [&](const Light& light) {
        std::vector<Receiver> out;
        for (int r = 0; r < 4; ++r)
            for (int i = 0; i < 4; ++i) {
                const glm::vec2 uv((i + 0.5f) / 4.0f, (r + 0.5f) / 4.0f);
                const glm::dvec3 centre(2.0 * uv.x - 1.0, 1.0, 2.0 * uv.y - 1.0);
                const glm::dvec3 from = light.type == LightType::Directional
                                            ? centre - 10.0 * glm::dvec3(light.directionWorld)
                                            : glm::dvec3(light.positionWorld);
                const glm::dvec3 ground = from + (centre - from) * (from.y / (from.y - 1.0));
                out.push_back({ground, checker.sample(uv).a >= 0.5f});
            }
        return out;
    };
    ShadowSettings settings = noFilter(512);
    for (const lighting::ShadowPointProjection projection :
         {lighting::ShadowPointProjection::Cube, lighting::ShadowPointProjection::DualParaboloid}) {
        SCOPED_TRACE(lighting::formatShadowPointProjection(projection));
        settings.pointProjection = projection;
        const Frame frame(t.scene, settings);
        const lighting::shadows::RayVisibility rays(frame.scene, frame.geometry);
        EXPECT_EQ(rays.alphaTestedTriangleCount(), 2u);
        const lighting::shadows::CasterAlphaTest alphaTest(frame.scene, frame.geometry);
        for (size_t l = 0; l < t.scene.lights.size(); ++l) {
            const Light& light = t.scene.lights[l];
            int shadowedTruth = 0;
            for (const Receiver& receiver : receivers(light)) {
                SCOPED_TRACE(testing::Message() << "light " << l << " at (" << receiver.ground.x
                                                << ", " << receiver.ground.z << ")");
                const glm::dvec3 up(0.0, 1.0, 0.0);
                const lighting::shadows::ShadowRay ray =
                    light.type == LightType::Directional
                        ? lighting::shadows::ShadowRay::directional(
                              receiver.ground, up, glm::dvec3(light.directionWorld))
                        : lighting::shadows::ShadowRay::toPoint(receiver.ground, up,
                                                                glm::dvec3(light.positionWorld));
                shadowedTruth += receiver.shadowed;
                EXPECT_EQ(lighting::shadows::segmentBlockedExact(frame.geometry, ray, &alphaTest),
                          receiver.shadowed);
                EXPECT_EQ(lighting::shadows::segmentBlockedExact(frame.geometry, ray),
                          true); // without the test, the holes block
                EXPECT_EQ(rays.occluded(ray), receiver.shadowed);
                std::vector<lighting::shadows::ShadowRay> packet(16, ray);
                std::vector<uint8_t> answers(packet.size());
                rays.occluded(packet, answers);
                EXPECT_EQ(std::count(answers.begin(), answers.end(), uint8_t(1)),
                          receiver.shadowed ? 16 : 0);
                EXPECT_EQ(frame.visibility(l, receiver.ground, glm::vec3(up)) == 0.0f,
                          receiver.shadowed);
            }
            EXPECT_EQ(shadowedTruth, 8);
        }
        // The second, alpha-testing draw keeps the maps bitwise independent of the threads.
        EXPECT_EQ(mapsDepth(t.scene, settings, 1), mapsDepth(t.scene, settings, 2));
    }
}

TEST(ShadowSettings, FilterNamesRoundTrip) {
    for (ShadowFilter filter :
         {ShadowFilter::None, ShadowFilter::Pcf3, ShadowFilter::Pcf5, ShadowFilter::Poisson})
        EXPECT_EQ(lighting::parseShadowFilter(lighting::formatShadowFilter(filter)), filter);
    EXPECT_FALSE(lighting::parseShadowFilter("pcf7").has_value());
    EXPECT_FALSE(lighting::parseShadowFilter("").has_value());
}

} // namespace

namespace {

// A frame that takes over the last frame's buffers (what the runner does every repetition)
// renders bitwise the same maps into the same memory.
TEST(ShadowMaps, RecycledBuffersGiveTheSameMapsInTheSameMemory) {
    TestScene t;
    t.ground(10.0f);
    t.box({-1, 0, -4}, {1, 2, -3});
    t.camera({0, 2, 3}, {0, 0, -4});
    t.light(pointLight({0, 3, -2}, 10.0f));
    t.light(spotLight({2, 4, 0}, {-0.3f, -1.0f, -0.5f}, 12.0f, 40.0f));
    t.light(directionalLight({0.2f, -1.0f, -0.3f}));
    const Frame fresh(t.scene, noFilter());
    ShadowMaps previous = ShadowMaps::render(fresh.scene, fresh.geometry, fresh.view, noFilter());
    std::vector<const float*> buffers;
    for (size_t f = 0; f < previous.faceCount(); ++f)
        if (!previous.face(f).empty)
            buffers.push_back(previous.face(f).depth.data());
    ASSERT_GE(buffers.size(), 8u);
    const ShadowMaps next =
        ShadowMaps::render(fresh.scene, fresh.geometry, fresh.view, noFilter(), &previous);
    EXPECT_EQ(previous.faceCount(), 0u) << "the recycled maps give their faces away";
    ASSERT_EQ(next.faceCount(), fresh.maps.faceCount());
    for (size_t f = 0; f < next.faceCount(); ++f) {
        EXPECT_EQ(next.face(f).depth, fresh.maps.face(f).depth) << "face " << f;
        if (!next.face(f).empty)
            EXPECT_NE(std::find(buffers.begin(), buffers.end(), next.face(f).depth.data()),
                      buffers.end())
                << "face " << f << " allocated a new buffer";
    }
}

// Frames whose casters move between the faces' tiles (the lights move, a box appears, the map
// size changes, a light is dropped, the ground goes) and that take over the last frame's buffers
// and their record of drawn tiles (ShadowFace::tilesNotClear) give bitwise the maps a fresh
// render gives, and the record is the fresh render's; with both depth formats (Unorm16: the
// packed texels' record, and the per-thread float buffers shared by the faces of a size).
TEST(ShadowMaps, RecycledBuffersStayExactWhenTheCastersMove) {
    auto frameScene = [](int step) {
        TestScene t;
        if (step != 5)
            t.ground(10.0f);
        t.box({-1, 0, -4}, {1, 2, -3});
        if (step % 2 == 1)
            t.box({2, 0, -2}, {2.5f, 3, -1.5f});
        t.camera({0, 2, 3}, {0, 0, -4});
        t.light(pointLight({0.7f * float(step), 3, -2}, 10.0f));
        if (step != 2)
            t.light(spotLight({2, 4, float(step) - 1.0f}, {-0.3f, -1.0f, -0.5f}, 12.0f, 40.0f));
        t.light(directionalLight({0.2f, -1.0f, -0.3f + 0.1f * float(step)}));
        return t.scene;
    };
    size_t clearTilesSeen = 0;
    for (const ShadowDepthFormat format : kDepthFormats) {
        SCOPED_TRACE(lighting::formatShadowDepthFormat(format));
        ShadowMaps previous;
        // Tiles that held depth in the last frame's buffer and must be cleared in this one's.
        size_t tilesEmptied = 0;
        std::vector<std::vector<uint8_t>> lastRecords; // per face of the last frame
        for (int step = 0; step < 6; ++step) {
            ShadowSettings settings = noFilter();
            settings.mapSize = step == 3 ? 384 : 256;
            settings.depthFormat = format;
            const Frame fresh(frameScene(step), settings);
            ShadowMaps next =
                ShadowMaps::render(fresh.scene, fresh.geometry, fresh.view, settings, &previous);
            ASSERT_EQ(next.faceCount(), fresh.maps.faceCount()) << "step " << step;
            for (size_t f = 0; f < next.faceCount(); ++f) {
                EXPECT_EQ(next.face(f).depth, fresh.maps.face(f).depth)
                    << "step " << step << ", face " << f;
                EXPECT_EQ(next.face(f).packedDepth, fresh.maps.face(f).packedDepth)
                    << "step " << step << ", face " << f;
                EXPECT_EQ(next.face(f).tilesNotClear, fresh.maps.face(f).tilesNotClear)
                    << "step " << step << ", face " << f;
                clearTilesSeen += size_t(std::count(next.face(f).tilesNotClear.begin(),
                                                    next.face(f).tilesNotClear.end(), uint8_t(0)));
                if (f < lastRecords.size() &&
                    lastRecords[f].size() == next.face(f).tilesNotClear.size())
                    for (size_t k = 0; k < lastRecords[f].size(); ++k)
                        tilesEmptied += lastRecords[f][k] && !next.face(f).tilesNotClear[k];
            }
            lastRecords.clear();
            for (size_t f = 0; f < next.faceCount(); ++f)
                lastRecords.push_back(next.face(f).tilesNotClear);
            previous = std::move(next);
        }
        EXPECT_GT(tilesEmptied, 0u) << "no tile is emptied: the test exercises nothing";
    }
    EXPECT_GT(clearTilesSeen, 0u) << "no face has an empty tile: the test exercises nothing";
}

// The same with an alpha-tested cut-out that moves from frame to frame (its second draw's tiles
// must be recorded, or a recycled buffer keeps its old depth there), for cube and paraboloid
// point maps, a spot light and a sun.
TEST(ShadowMaps, RecycledBuffersStayExactWhenAlphaTestedCastersMove) {
    for (const lighting::ShadowPointProjection projection :
         {lighting::ShadowPointProjection::Cube, lighting::ShadowPointProjection::DualParaboloid}) {
        SCOPED_TRACE(lighting::formatShadowPointProjection(projection));
        ShadowMaps previous;
        for (int step = 0; step < 4; ++step) {
            // No ground: the cut-out's tiles hold nothing else, so only its own record clears them.
            TestScene t;
            t.box({-1, 0, -4}, {1, 2, -3});
            const float x = step % 2 == 0 ? -3.0f : 2.0f;
            addCheckerCutOut(t, {x, 1.0f, 0.0f}, {1.0f, 0, 0}, {0, 0, -1.0f});
            t.camera({0, 2, 3}, {0, 0, -4});
            t.light(pointLight({0.0f, 3.0f, -1.0f}, 10.0f));
            t.light(spotLight({0.5f, 4.0f, -0.5f}, {0.0f, -1.0f, -0.2f}, 12.0f, 60.0f));
            t.light(directionalLight({0.2f, -1.0f, -0.3f}));
            ShadowSettings settings = noFilter(256);
            settings.pointProjection = projection;
            const Frame fresh(t.scene, settings);
            ShadowMaps next =
                ShadowMaps::render(fresh.scene, fresh.geometry, fresh.view, settings, &previous);
            ASSERT_EQ(next.faceCount(), fresh.maps.faceCount()) << "step " << step;
            for (size_t f = 0; f < next.faceCount(); ++f)
                EXPECT_EQ(next.face(f).depth, fresh.maps.face(f).depth)
                    << "step " << step << ", face " << f;
            previous = std::move(next);
        }
    }
}

} // namespace
