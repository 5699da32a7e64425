// The ray-traced shadow visibility (lighting/shadows/RayVisibility.h, Embree in float) against
// closed-form cases and against the double-precision brute-force oracle
// (lighting/shadows/ExactRayCast.h): hand-made scenes whose answer is known, then random scenes
// where the two must agree on every ray the oracle calls robust (ExactVerdict), then the batched
// query against the single one and across thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <tbb/task_arena.h>

#include "lighting/shadows/ExactRayCast.h"
#include "lighting/shadows/RayVisibility.h"

namespace {

using gbuffer::SceneGeometry;
using lighting::shadows::classifyShadowRayExact;
using lighting::shadows::ExactVerdict;
using lighting::shadows::RayVisibility;
using lighting::shadows::segmentBlockedExact;
using lighting::shadows::ShadowRay;

void addTriangle(SceneGeometry& geometry, const glm::dvec3& a, const glm::dvec3& b,
                 const glm::dvec3& c) {
    for (const glm::dvec3& p : {a, b, c}) {
        geometry.indices.push_back(uint32_t(geometry.positionWorldExact.size()));
        geometry.positionWorldExact.push_back(p);
        geometry.positionWorld.push_back(glm::vec3(p));
    }
}

// The parallelogram corner, corner + u, corner + u + v, corner + v (two triangles).
void addQuad(SceneGeometry& geometry, const glm::dvec3& corner, const glm::dvec3& u,
             const glm::dvec3& v) {
    addTriangle(geometry, corner, corner + u, corner + u + v);
    addTriangle(geometry, corner, corner + u + v, corner + v);
}

// An axis-aligned box's six faces.
void addBox(SceneGeometry& geometry, const glm::dvec3& low, const glm::dvec3& high) {
    const glm::dvec3 size = high - low;
    const glm::dvec3 x(size.x, 0, 0), y(0, size.y, 0), z(0, 0, size.z);
    addQuad(geometry, low, x, y);
    addQuad(geometry, low + z, x, y);
    addQuad(geometry, low, y, z);
    addQuad(geometry, low + x, y, z);
    addQuad(geometry, low, x, z);
    addQuad(geometry, low + y, x, z);
}

// Every way of asking: Embree single, Embree batched (a packet of one), the double oracle.
void expectOccluded(const SceneGeometry& geometry, const RayVisibility& visibility,
                    const ShadowRay& ray, bool expected, const char* what) {
    EXPECT_EQ(visibility.occluded(ray), expected) << what << " (Embree, single)";
    uint8_t batched = 2;
    visibility.occluded(std::span<const ShadowRay>(&ray, 1), std::span<uint8_t>(&batched, 1));
    EXPECT_EQ(batched, expected ? 1 : 0) << what << " (Embree, batched)";
    EXPECT_EQ(segmentBlockedExact(geometry, ray), expected) << what << " (exact)";
}

TEST(RayVisibility, QuadBetweenPointAndLightBlocksIt) {
    SceneGeometry geometry;
    addQuad(geometry, {-1, 1, -1}, {2, 0, 0}, {0, 0, 2}); // y = 1, |x|, |z| <= 1
    const RayVisibility visibility(geometry);
    EXPECT_EQ(visibility.triangleCount(), 2u);
    EXPECT_EQ(visibility.droppedTriangleCount(), 0u);
    EXPECT_GT(visibility.embreeBytes(), 0u); // at least the buffers
    const glm::dvec3 up(0, 1, 0);
    EXPECT_TRUE(visibility.occluded(glm::dvec3(0), up, {0, 2, 0}));
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0, 0, 0}, up, {0, 2, 0}), true,
                   "light straight above the quad");
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0.3, 0, -0.2}, up, {-0.5, 3, 0.7}),
                   true, "oblique through the quad");
    // The segment to (3, 2, 0) crosses y = 1 at x = 1.5: beside the quad.
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0, 0, 0}, up, {3, 2, 0}), false,
                   "beside the quad");
    // A light below the quad: nothing in between.
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0, 0, 0}, up, {0, 0.9, 0}), false,
                   "light below the quad");
}

// The origin offset is along the normal: a plane lit at 1 degree of elevation does not shadow
// itself, anywhere on it (near the world origin and 100 m away), axis-aligned or tilted (a
// tilted plane's float vertices leave it by rounding), toward a near light, a far one and the sun.
TEST(RayVisibility, PlaneIsNotSelfShadowedAtGrazingOneDegree) {
    const double elevation = 1.0 * std::numbers::pi / 180.0;
    std::mt19937 random(29);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const bool tilted : {false, true}) {
        // An orthonormal frame (tangent, normal, bitangent): the plane spans tangent and bitangent.
        glm::dvec3 normal(0, 1, 0), tangent(1, 0, 0);
        if (tilted) {
            normal = glm::normalize(glm::dvec3(0.31, 0.87, -0.38));
            tangent = glm::normalize(glm::cross(normal, glm::dvec3(0.2, 0.1, 1.0)));
        }
        const glm::dvec3 bitangent = glm::cross(tangent, normal);
        const glm::dvec3 centre = tilted ? glm::dvec3(40.0, -7.0, 25.0) : glm::dvec3(0.0);
        SceneGeometry geometry;
        // 300 m square in 10 x 10 quads (so points near the origin lie on triangles of a few
        // tens of metres, as a floor does).
        for (int i = -5; i < 5; ++i)
            for (int j = -5; j < 5; ++j)
                addQuad(geometry, centre + tangent * (30.0 * i) + bitangent * (30.0 * j),
                        tangent * 30.0, bitangent * 30.0);
        const RayVisibility visibility(geometry);
        int checked = 0;
        for (int k = 0; k < 400; ++k) {
            const double scale = k % 2 ? 1.0 : 100.0; // near the centre, far from it
            const double along = (unit(random) - 0.5) * 2.0 * scale;
            const double across = (unit(random) - 0.5) * 2.0 * scale;
            const glm::dvec3 surface = centre + tangent * along + bitangent * across;
            const double azimuth = 2.0 * std::numbers::pi * unit(random);
            const glm::dvec3 toLight =
                (tangent * std::cos(azimuth) + bitangent * std::sin(azimuth)) *
                    std::cos(elevation) +
                normal * std::sin(elevation);
            for (const double distance : {2.0, 40.0}) {
                expectOccluded(geometry, visibility,
                               ShadowRay::toPoint(surface, normal, surface + toLight * distance),
                               false, tilted ? "tilted plane" : "plane");
                ++checked;
            }
            expectOccluded(geometry, visibility, ShadowRay::directional(surface, normal, -toLight),
                           false, tilted ? "tilted plane, directional" : "plane, directional");
            // The same light from below the plane: the plane itself is in the way.
            const glm::dvec3 below = toLight - 2.0 * normal * glm::dot(normal, toLight);
            expectOccluded(geometry, visibility,
                           ShadowRay::toPoint(surface, normal, surface + below * 40.0), true,
                           tilted ? "tilted plane, light below" : "plane, light below");
        }
        EXPECT_EQ(checked, 800);
    }
}

TEST(RayVisibility, LightBehindTheSurfaceIsBlockedByIt) {
    SceneGeometry geometry;
    addQuad(geometry, {-2, 0, -2}, {4, 0, 0}, {0, 0, 4}); // y = 0
    const RayVisibility visibility(geometry);
    // Lit side up, light below: the surface's own triangle blocks it.
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0, 0, 0}, {0, 1, 0}, {0.5, -1, 0}),
                   true, "light behind the surface");
    // The same point seen from below (a two-sided surface, normal flipped toward the viewer).
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0, 0, 0}, {0, -1, 0}, {0.5, -1, 0}),
                   false, "underside lit from below");
    // A shading normal that leans toward a light just below the plane: the plane still blocks.
    expectOccluded(
        geometry, visibility,
        ShadowRay::toPoint({0, 0, 0}, glm::normalize(glm::dvec3(1, 0.2, 0)), {3, -0.01, 0}), true,
        "tilted shading normal, light below the geometric plane");
}

TEST(RayVisibility, DirectionalLightUnderARoof) {
    SceneGeometry geometry;
    addQuad(geometry, {-50, 0, -50}, {100, 0, 0}, {0, 0, 100}); // ground
    addQuad(geometry, {-5, 3, -5}, {10, 0, 0}, {0, 0, 10});     // roof, 3 m up
    const RayVisibility visibility(geometry);
    const glm::dvec3 up(0, 1, 0);
    const glm::dvec3 sun(0.3, -1.0, 0.2); // the direction the light travels: down
    expectOccluded(geometry, visibility, ShadowRay::directional({0, 0, 0}, up, sun), true,
                   "under the roof");
    expectOccluded(geometry, visibility, ShadowRay::directional({4.5, 0, 4.5}, up, sun), true,
                   "under the roof's edge, the sun behind it");
    // Toward the sun from (20, 0, 0): y = 3 at x = 19.1, far from the roof.
    expectOccluded(geometry, visibility, ShadowRay::directional({20, 0, 0}, up, sun), false,
                   "in the open");
    // The roof's top is in the sun.
    expectOccluded(geometry, visibility, ShadowRay::directional({0, 3, 0}, up, sun), false,
                   "on the roof");
    // Light travelling up (from below the ground): the ground blocks it.
    expectOccluded(geometry, visibility, ShadowRay::directional({20, 0, 0}, up, {0, 1, 0}), true,
                   "light from below the ground");
    EXPECT_TRUE(visibility.occludedDirectional(glm::dvec3(0), up, sun));
    EXPECT_FALSE(visibility.occludedDirectional(glm::dvec3(20, 0, 0), up, sun));
}

// A pole 1 cm thick, 10 m from the world origin: a ray through it is blocked, a ray 1 mm beside
// it is not.
TEST(RayVisibility, ThinPoleBlocksARayThroughIt) {
    SceneGeometry geometry;
    const glm::dvec3 pole(10.0, 0.0, 10.0);
    addBox(geometry, pole + glm::dvec3(-0.005, 0, -0.005), pole + glm::dvec3(0.005, 3, 0.005));
    addQuad(geometry, {7, -1, 5}, {0, 0, 10}, {0, 4, 0}); // a wall at x = 7 facing +x
    const RayVisibility visibility(geometry);
    EXPECT_EQ(visibility.triangleCount(), 14u);
    const glm::dvec3 normal(1, 0, 0);
    for (const double z : {-0.004, 0.0, 0.0049}) {
        const glm::dvec3 surface(7, 1, 10 + z), light(13, 1.2, 10 + z);
        expectOccluded(geometry, visibility, ShadowRay::toPoint(surface, normal, light), true,
                       "through the pole");
    }
    for (const double z : {-0.006, 0.0051, 0.02}) {
        const glm::dvec3 surface(7, 1, 10 + z), light(13, 1.2, 10 + z);
        expectOccluded(geometry, visibility, ShadowRay::toPoint(surface, normal, light), false,
                       "beside the pole");
    }
    // Above the pole's top (3 m): the segment passes over it.
    expectOccluded(geometry, visibility, ShadowRay::toPoint({7, 3.2, 10}, normal, {13, 3.2, 10}),
                   false, "over the pole");
}

// The segment stops short of the light: a light on a wall or just in front of it is not
// shadowed by the wall; a light just behind it is.
TEST(RayVisibility, RayEndsBeforeAWallAtTheLight) {
    SceneGeometry geometry;
    addQuad(geometry, {5, -2, -2}, {0, 4, 0}, {0, 0, 4}); // x = 5
    const RayVisibility visibility(geometry);
    const glm::dvec3 surface(0, 0, 0), normal(1, 0, 0);
    expectOccluded(geometry, visibility, ShadowRay::toPoint(surface, normal, {5, 0.5, 0.2}), false,
                   "light exactly on the wall");
    expectOccluded(geometry, visibility, ShadowRay::toPoint(surface, normal, {4.999, 0.5, 0.2}),
                   false, "light 1 mm in front of the wall");
    expectOccluded(geometry, visibility, ShadowRay::toPoint(surface, normal, {5.001, 0.5, 0.2}),
                   true, "light 1 mm behind the wall");
    // A point on the wall itself lit from in front: its own wall does not block it.
    expectOccluded(geometry, visibility, ShadowRay::toPoint({5, 0, 0}, -normal, {0, 1, 0}), false,
                   "on the wall, lit from in front");
    // The light within the offsets of the surface: nothing can be in between.
    expectOccluded(geometry, visibility, ShadowRay::toPoint(surface, normal, surface), false,
                   "light at the surface point");
}

TEST(RayVisibility, DegenerateTrianglesAreDroppedWithoutHarm) {
    SceneGeometry geometry;
    addQuad(geometry, {-1, 1, -1}, {2, 0, 0}, {0, 0, 2});
    addTriangle(geometry, {0, 2, 0}, {0, 2, 0}, {1, 2, 0});         // repeated vertex
    addTriangle(geometry, {0, 2, 0}, {1, 2, 0}, {2, 2, 0});         // collinear
    addTriangle(geometry, {0, 2, 0}, {1e-50, 2, 0}, {0, 2, 1e-50}); // collapses in float
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double infinity = std::numeric_limits<double>::infinity();
    addTriangle(geometry, {nan, 2, 0}, {1, 2, 0}, {0, 2, 1});
    addTriangle(geometry, {infinity, 2, 0}, {1, 2, 0}, {0, 2, 1});
    geometry.indices.insert(geometry.indices.end(), {0, 1, 1000}); // index out of range
    const RayVisibility visibility(geometry);
    EXPECT_EQ(visibility.triangleCount(), 2u);
    EXPECT_EQ(visibility.droppedTriangleCount(), 6u);
    expectOccluded(geometry, visibility, ShadowRay::toPoint({0, 0, 0}, {0, 1, 0}, {0, 3, 0}), true,
                   "the quad still blocks");
    expectOccluded(geometry, visibility, ShadowRay::toPoint({5, 0, 0}, {0, 1, 0}, {5, 3, 0}), false,
                   "nothing else does");

    // Nothing usable at all, and nothing at all: an empty BVH that blocks nothing.
    SceneGeometry degenerateOnly;
    addTriangle(degenerateOnly, {0, 2, 0}, {0, 2, 0}, {1, 2, 0});
    for (const SceneGeometry* g : {&degenerateOnly, new SceneGeometry()}) {
        const RayVisibility empty(*g);
        EXPECT_EQ(empty.triangleCount(), 0u);
        expectOccluded(*g, empty, ShadowRay::toPoint({0, 0, 0}, {0, 1, 0}, {0, 3, 0}), false,
                       "empty scene");
        expectOccluded(*g, empty, ShadowRay::directional({0, 0, 0}, {0, 1, 0}, {0, -1, 0}), false,
                       "empty scene, directional");
        if (g != &degenerateOnly)
            delete g;
    }
}

// Three draws in a fixed order: the order in which a function's arguments are evaluated is
// unspecified (gcc and clang would build different scenes from the same seed).
template <class Distribution> glm::dvec3 draw3(Distribution& distribution, std::mt19937& random) {
    const double x = distribution(random);
    const double y = distribution(random);
    const double z = distribution(random);
    return {x, y, z};
}

// A random scene: `triangleCount` triangles of 0.1 to 2 m around `centre` in a 10 m box, a few
// of them degenerate (a repeated vertex: dropped) or nearly so (collinear in double, slivers once
// rounded to float: kept).
SceneGeometry randomScene(std::mt19937& random, int triangleCount, const glm::dvec3& centre) {
    std::uniform_real_distribution<double> box(-5.0, 5.0);
    std::uniform_real_distribution<double> size(0.1, 2.0);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    SceneGeometry geometry;
    const auto randomVector = [&] { return draw3(unit, random); };
    for (int t = 0; t < triangleCount; ++t) {
        const glm::dvec3 c = centre + draw3(box, random);
        const double s = size(random);
        const glm::dvec3 a = c + randomVector() * s;
        const glm::dvec3 b = c + randomVector() * s;
        if (t % 50 == 7)
            addTriangle(geometry, a, b, b); // repeated vertex
        else if (t % 50 == 19)
            addTriangle(geometry, a, b, a + (b - a) * 0.375); // collinear but for rounding
        else
            addTriangle(geometry, a, b, c + randomVector() * s);
    }
    return geometry;
}

double magnitude(const SceneGeometry& geometry) {
    double m = 0.0;
    for (const glm::dvec3& p : geometry.positionWorldExact)
        m = std::max({m, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    return m;
}

// Rays of every kind a renderer asks: from points on the scene's triangles (either side, toward
// point lights and directional ones; some blocked by their own triangle) and from points in the
// air with random normals.
std::vector<ShadowRay> randomRays(std::mt19937& random, const SceneGeometry& geometry, int rayCount,
                                  const glm::dvec3& centre) {
    std::uniform_real_distribution<double> box(-6.0, 6.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<uint32_t> triangle(0, geometry.triangleCount() - 1);
    std::vector<ShadowRay> rays;
    const auto inBox = [&] { return centre + draw3(box, random); };
    const auto direction = [&] { return glm::normalize(draw3(unit, random) - 0.5); };
    while (int(rays.size()) < rayCount) {
        const double kind = unit(random);
        if (kind < 0.6) {
            const uint32_t t = triangle(random);
            const glm::dvec3 a = geometry.positionWorldExact[geometry.indices[3 * t]];
            const glm::dvec3 b = geometry.positionWorldExact[geometry.indices[3 * t + 1]];
            const glm::dvec3 c = geometry.positionWorldExact[geometry.indices[3 * t + 2]];
            glm::dvec3 normal = glm::cross(b - a, c - a);
            if (!(glm::length(normal) > 1e-6))
                continue; // the degenerate ones: no surface to stand on
            normal = glm::normalize(normal) * (unit(random) < 0.5 ? 1.0 : -1.0);
            double u = unit(random), v = unit(random);
            if (u + v > 1.0) {
                u = 1.0 - u;
                v = 1.0 - v;
            }
            const glm::dvec3 surface = a + (b - a) * u + (c - a) * v;
            if (kind < 0.4)
                rays.push_back(ShadowRay::toPoint(surface, normal, inBox()));
            else
                rays.push_back(ShadowRay::directional(surface, normal, direction()));
        } else {
            const glm::dvec3 surface = inBox();
            const glm::dvec3 normal = direction();
            rays.push_back(ShadowRay::toPoint(surface, normal, inBox()));
        }
    }
    return rays;
}

// 2^-18 of the scene's largest coordinate: 64 float ulps of it, several times the error of
// Embree's float test (vertices and ray rounded to 2^-24, a few operations), and below the
// origin offset (2^-14 of the point's magnitude, at least 2^-14 m) wherever the scene's
// magnitude is below 16 times the point's (or 16 m), as in these scenes.
constexpr double kToleranceRelative = 1.0 / 262144.0;

TEST(RayVisibility, AgreesWithTheExactOracleOnRandomScenes) {
    std::mt19937 random(2029);
    int total = 0, withinTolerance = 0, blocked = 0, clear = 0, disagreements = 0;
    // Near the world origin, and 100 m away (float's ulps 64 times coarser).
    for (const glm::dvec3 centre : {glm::dvec3(0.0), glm::dvec3(0.0, 1.5, 0.0),
                                    glm::dvec3(100.0, 20.0, -60.0), glm::dvec3(-3.0, 0.0, 7.0)}) {
        const SceneGeometry geometry = randomScene(random, 300, centre);
        const RayVisibility visibility(geometry);
        EXPECT_EQ(visibility.droppedTriangleCount(), 6u); // the repeated vertices
        const double tolerance = kToleranceRelative * magnitude(geometry);
        for (const ShadowRay& ray : randomRays(random, geometry, 2500, centre)) {
            ++total;
            const ExactVerdict verdict = classifyShadowRayExact(geometry, ray, tolerance);
            const bool embree = visibility.occluded(ray);
            const bool exact = segmentBlockedExact(geometry, ray);
            if (verdict == ExactVerdict::WithinTolerance) {
                ++withinTolerance;
                continue;
            }
            // The verdict and the oracle's plain answer agree (the verdict is the answer plus
            // a margin).
            EXPECT_EQ(exact, verdict == ExactVerdict::Blocked);
            (verdict == ExactVerdict::Blocked ? blocked : clear) += 1;
            if (embree != exact) {
                ++disagreements;
                if (disagreements <= 5)
                    ADD_FAILURE() << "Embree says " << embree << ", exact " << exact
                                  << ": surface (" << ray.surfaceWorld.x << ", "
                                  << ray.surfaceWorld.y << ", " << ray.surfaceWorld.z << ")";
            }
        }
    }
    std::printf("[ray visibility] %d random rays: %d blocked, %d clear, %d within the tolerance "
                "band (2^-18 of the scene's magnitude), %d disagreements outside it\n",
                total, blocked, clear, withinTolerance, disagreements);
    EXPECT_EQ(total, 10000);
    EXPECT_EQ(disagreements, 0);
    // The band excludes few rays, and both answers are common: the comparison is not vacuous.
    EXPECT_LT(withinTolerance, total / 100);
    EXPECT_GT(blocked, total / 5);
    EXPECT_GT(clear, total / 5);
}

TEST(RayVisibility, BatchedEqualsSingle) {
    std::mt19937 random(77);
    const SceneGeometry geometry = randomScene(random, 300, glm::dvec3(1.0, -2.0, 0.5));
    const RayVisibility visibility(geometry);
    // Not a multiple of the packet size (16), with some rays that can block nothing mixed in.
    std::vector<ShadowRay> rays = randomRays(random, geometry, 10007, glm::dvec3(1.0, -2.0, 0.5));
    for (size_t i = 0; i < rays.size(); i += 97)
        rays[i].lightWorld = rays[i].surfaceWorld;
    for (size_t i = 5; i < rays.size(); i += 101)
        rays[i] = ShadowRay::directional(rays[i].surfaceWorld, rays[i].normalWorld, glm::dvec3(0));
    std::vector<uint8_t> batched(rays.size(), 7);
    visibility.occluded(rays, batched);
    size_t blocked = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(batched[i], visibility.occluded(rays[i]) ? 1 : 0) << "ray " << i;
        blocked += batched[i];
    }
    EXPECT_GT(blocked, rays.size() / 5);
    EXPECT_LT(blocked, rays.size() * 4 / 5);
    // Empty batch; mismatched sizes are an error.
    visibility.occluded(std::span<const ShadowRay>(), std::span<uint8_t>());
    EXPECT_THROW(visibility.occluded(rays, std::span<uint8_t>(batched.data(), 3)),
                 std::invalid_argument);
}

// Built and queried in a 1-thread arena and in a 2-thread one: the same answers, bit for bit.
TEST(RayVisibility, AnswersDoNotDependOnTheThreadCount) {
    std::mt19937 random(4);
    const SceneGeometry geometry = randomScene(random, 400, glm::dvec3(0.0));
    const std::vector<ShadowRay> rays = randomRays(random, geometry, 20000, glm::dvec3(0.0));
    std::vector<std::vector<uint8_t>> results;
    for (const int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            const RayVisibility visibility(geometry);
            results.emplace_back(rays.size());
            visibility.occluded(rays, results.back());
        });
    }
    EXPECT_EQ(results[0], results[1]);
}

} // namespace
