// Shadow-casting sets (lighting/shadows/ShadowCasterSets.h) against brute force:
// - the volume never drops a point that can shadow a visible receiver: points on random segments
//   from the light (or towards a directional light) to random points of the view frustum are
//   kept, for lights inside and outside the frustum (O'Rorke's two cases);
// - objects that cannot cast into the view are excluded (behind the camera, beyond the light);
// - an excluded object never changes the image: on generated scenes every light's visibility at
//   every covered pixel is bitwise the same with the sets on and off, while the sets exclude
//   objects (so the comparison is not vacuous).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/shadows/ShadowCasterSets.h"
#include "lighting/shadows/ShadowMaps.h"
#include "scenes/Scene.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

scenes::Camera testCamera() {
    scenes::Camera camera;
    camera.positionWorld = {0.0f, 1.5f, 0.0f};
    camera.forwardWorld = glm::normalize(glm::vec3(0.0f, -0.2f, -1.0f));
    camera.upWorld = {0.0f, 1.0f, 0.0f};
    camera.verticalFovRadians = glm::radians(60.0f);
    camera.nearMetres = 0.1f;
    camera.farMetres = 30.0f;
    return camera;
}

scenes::Aabb pointBox(const glm::dvec3& p) {
    scenes::Aabb box;
    box.extend(glm::vec3(p));
    return box;
}

scenes::Aabb boxOf(const glm::vec3& lo, const glm::vec3& hi) {
    scenes::Aabb box;
    box.min = lo;
    box.max = hi;
    return box;
}

// A random point of the frustum given by its 8 corners (near then far; trilinear).
glm::dvec3 randomFrustumPoint(const std::vector<glm::dvec3>& c, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double x = u(rng), y = u(rng), z = u(rng);
    auto face = [&](size_t base) {
        const glm::dvec3 bottom = glm::mix(c[base], c[base + 1], x);
        const glm::dvec3 top = glm::mix(c[base + 2], c[base + 3], x);
        return glm::mix(bottom, top, y);
    };
    return glm::mix(face(0), face(4), z);
}

struct VolumeCase {
    const char* name;
    scenes::Light light;
    bool lightInFrustum;
};

std::vector<VolumeCase> volumeCases() {
    std::vector<VolumeCase> cases;
    scenes::Light inside;
    inside.type = scenes::LightType::Point;
    inside.positionWorld = {0.5f, 1.0f, -8.0f};
    inside.rangeMetres = 10.0f;
    cases.push_back({"point inside", inside, true});
    scenes::Light behind = inside;
    behind.positionWorld = {2.0f, 3.0f, 6.0f}; // behind the camera
    cases.push_back({"point behind the camera", behind, false});
    scenes::Light side = inside;
    side.type = scenes::LightType::Spot;
    side.positionWorld = {25.0f, 2.0f, -5.0f};
    side.directionWorld = {-1.0f, 0.0f, 0.0f};
    cases.push_back({"spot beside the frustum", side, false});
    scenes::Light sun;
    sun.type = scenes::LightType::Directional;
    sun.directionWorld = glm::normalize(glm::vec3(0.3f, -1.0f, 0.4f));
    cases.push_back({"directional", sun, false});
    return cases;
}

TEST(ShadowCasterSets, EverySegmentFromTheLightToTheViewIsKept) {
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(testCamera(), 320, 180);
    const std::vector<glm::dvec3> corners = lighting::frustumCornersWorld(view, 0.5, 25.0);
    const double sweep = 100.0;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const VolumeCase& c : volumeCases()) {
        const lighting::CasterVolume volume = lighting::casterVolume(corners, c.light, sweep);
        EXPECT_FALSE(volume.unbounded) << c.name;
        EXPECT_EQ(volume.lightInFrustum, c.lightInFrustum) << c.name;
        for (int i = 0; i < 20000; ++i) {
            const glm::dvec3 receiver = randomFrustumPoint(corners, rng);
            const glm::dvec3 occluder =
                c.light.type == scenes::LightType::Directional
                    ? receiver - u(rng) * sweep * glm::dvec3(c.light.directionWorld)
                    : glm::mix(receiver, glm::dvec3(c.light.positionWorld), u(rng));
            ASSERT_TRUE(volume.mayContain(pointBox(occluder), 1e-6))
                << c.name << ": dropped a point between a visible receiver and the light";
        }
    }
}

TEST(ShadowCasterSets, ObjectsThatCannotCastIntoTheViewAreExcluded) {
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(testCamera(), 320, 180);
    const std::vector<glm::dvec3> corners = lighting::frustumCornersWorld(view, 0.5, 25.0);
    const std::vector<VolumeCase> cases = volumeCases();
    // Light inside the frustum: the hull is the frustum; a box behind the camera cannot cast.
    const lighting::CasterVolume inside = lighting::casterVolume(corners, cases[0].light, 100.0);
    EXPECT_FALSE(inside.mayContain(boxOf({-1, 0, 3}, {1, 2, 4}), 0.0));
    EXPECT_TRUE(inside.mayContain(boxOf({-1, 0, -6}, {1, 1, -5}), 0.0));
    // ... but a margin wider than the gap keeps it.
    EXPECT_TRUE(inside.mayContain(boxOf({-1, 0, 3}, {1, 2, 4}), 10.0));
    // Light behind the camera: a box between the light and the camera may cast, one beyond the
    // light (farther from the view) may not.
    const lighting::CasterVolume behind = lighting::casterVolume(corners, cases[1].light, 100.0);
    EXPECT_TRUE(behind.mayContain(boxOf({0.8f, 2.0f, 3.0f}, {1.2f, 2.4f, 3.4f}), 0.0));
    EXPECT_FALSE(behind.mayContain(boxOf({3.0f, 4.0f, 9.0f}, {4.0f, 5.0f, 10.0f}), 0.0));
    // Directional: a box "below" the view (the sun shines from above) cannot cast onto it.
    const lighting::CasterVolume sun = lighting::casterVolume(corners, cases[3].light, 100.0);
    EXPECT_FALSE(sun.mayContain(boxOf({-1, -60, -10}, {1, -50, -8}), 0.0));
    EXPECT_TRUE(sun.mayContain(boxOf({-1, 10, -10}, {1, 11, -8}), 0.0));
}

// Every light's visibility at every covered pixel, sets on against sets off.
struct SetsComparison {
    uint64_t lookups = 0;
    uint64_t differing = 0;
    uint64_t casterObjects = 0; // summed over lights, sets on
    uint64_t allObjects = 0;    // the same with every object
    uint64_t trianglesOn = 0, trianglesOff = 0;
};

// yawRadians turns the scene's camera about the vertical axis (objects then sit just outside
// the view in other places).
SetsComparison compareSets(const std::string& sceneName, int lights, lighting::ShadowFilter filter,
                           int mapSize, float yawRadians = 0.0f,
                           const std::map<std::string, std::string>& options = {}, int width = 192,
                           int height = 108, lighting::StageResult* imageOn = nullptr,
                           lighting::StageResult* imageOff = nullptr) {
    scenes::SceneRequest request;
    request.lightCount = lights;
    request.seed = 11;
    request.options = options;
    scenes::Scene scene = scenes::buildProceduralScene(sceneName, request);
    if (yawRadians != 0.0f) {
        scenes::Camera& camera = scene.cameras.front();
        const glm::mat3 turn(glm::rotate(glm::mat4(1.0f), yawRadians, glm::vec3(0, 1, 0)));
        camera.forwardWorld = glm::normalize(turn * camera.forwardWorld);
        camera.upWorld = glm::normalize(turn * camera.upWorld);
    }
    const lighting::PreparedScene frame(std::move(scene), width, height);
    lighting::ShadowSettings settings;
    settings.mapSize = mapSize;
    settings.filter = filter;
    settings.casterSets = true;
    const lighting::ShadowMaps on =
        lighting::ShadowMaps::render(frame.scene, frame.geometry, frame.view, settings);
    settings.casterSets = false;
    const lighting::ShadowMaps off =
        lighting::ShadowMaps::render(frame.scene, frame.geometry, frame.view, settings);
    SetsComparison result;
    for (const lighting::ShadowLightStats& light : on.stats().lights) {
        result.casterObjects += light.casterObjects;
        result.trianglesOn += light.trianglesDrawn;
    }
    for (const lighting::ShadowLightStats& light : off.stats().lights) {
        result.allObjects += light.casterObjects;
        result.trianglesOff += light.trianglesDrawn;
    }
    const gbuffer::GBuffer& gb = *frame.gbuffer;
    for (int y = 0; y < gb.height(); ++y)
        for (int x = 0; x < gb.width(); ++x) {
            if (!gb.covered(size_t(y) * size_t(gb.width()) + size_t(x)))
                continue;
            const gbuffer::Surface s = gb.decode(x, y);
            for (size_t light = 0; light < frame.scene.lights.size(); ++light) {
                const uint32_t shadow = on.shadowOf(light);
                if (shadow == lighting::ShadowMaps::kNoShadow)
                    continue;
                ++result.lookups;
                const float a = on.visibility(shadow, s.positionView, s.normalView);
                const float b = off.visibility(off.shadowOf(light), s.positionView, s.normalView);
                result.differing += a != b;
            }
        }
    // The images themselves (brute shades every light at every pixel through the kernel's
    // vector lookup), when asked for.
    if (imageOn && imageOff) {
        lighting::StageInputs inputs = frame.inputs;
        inputs.shadows = &on;
        lighting::makeStage("brute")->shade(inputs, *imageOn);
        inputs.shadows = &off;
        lighting::makeStage("brute")->shade(inputs, *imageOff);
    }
    return result;
}

TEST(ShadowCasterSets, AnExcludedObjectNeverChangesTheImage) {
    struct Case {
        const char* scene;
        int lights;
        lighting::ShadowFilter filter;
        int mapSize;
    };
    for (const Case& c : {Case{"atrium", 48, lighting::ShadowFilter::Poisson, 256},
                          Case{"atrium", 48, lighting::ShadowFilter::None, 128},
                          Case{"wall", 32, lighting::ShadowFilter::Pcf5, 256},
                          Case{"spheres", 32, lighting::ShadowFilter::Pcf3, 512}}) {
        const SetsComparison r = compareSets(c.scene, c.lights, c.filter, c.mapSize);
        std::cout << "[measured] " << c.scene << " " << lighting::formatShadowFilter(c.filter)
                  << " " << c.mapSize << "^2: casting-set objects " << r.casterObjects << " of "
                  << r.allObjects << " (summed over lights), triangles drawn " << r.trianglesOn
                  << " of " << r.trianglesOff << ", " << r.lookups << " lookups compared\n";
        EXPECT_GT(r.lookups, 10000u) << c.scene;
        EXPECT_EQ(r.differing, 0u) << c.scene << ": an excluded object changed a lookup";
        EXPECT_LE(r.casterObjects, r.allObjects) << c.scene;
        EXPECT_LE(r.trianglesOn, r.trianglesOff) << c.scene;
    }
}

// The margin (ShadowMaps.cpp: PCF reach + one texel + the normal offset, in the widest texel)
// matters where texels are large: with 16^2 to 32^2 maps a texel spans metres, and a filtered
// lookup at a receiver near the edge of the view reads texels that only objects outside the
// hull of the frustum and the light cover. Turned cameras put objects just outside the view.
TEST(ShadowCasterSets, CoarseFilteredMapsKeepCastersWithinTheFilterReach) {
    uint64_t lookups = 0, excludedObjects = 0;
    for (int mapSize : {16, 32})
        for (float yaw : {0.0f, 0.6f, -0.6f, 1.6f, 3.1f})
            for (lighting::ShadowFilter filter :
                 {lighting::ShadowFilter::Pcf5, lighting::ShadowFilter::Poisson}) {
                const SetsComparison r = compareSets("atrium", 24, filter, mapSize, yaw);
                EXPECT_EQ(r.differing, 0u)
                    << mapSize << "^2, yaw " << yaw << ", " << lighting::formatShadowFilter(filter)
                    << ": an excluded object changed a lookup";
                lookups += r.lookups;
                excludedObjects += r.allObjects - r.casterObjects;
            }
    std::cout << "[measured] coarse maps: " << lookups << " lookups, " << excludedObjects
              << " objects excluded (summed over lights and cases)\n";
    EXPECT_GT(excludedObjects, 0u) << "the sets must exclude something for the test to bite";
}

TEST(ShadowCasterSets, ExcludeObjectsOnAScene) {
    // Not vacuous: on atrium (many instances, lights all over the building) the sets leave out
    // objects for some light.
    const SetsComparison r = compareSets("atrium", 48, lighting::ShadowFilter::Pcf3, 256);
    EXPECT_LT(r.casterObjects, r.allObjects);
    EXPECT_LT(r.trianglesOn, r.trianglesOff);
}

} // namespace

namespace {

// The range test: a box the light's range sphere misses is out of the set even inside the hull
// (a light inside the frustum: the hull is the frustum), one touching it is in; directional
// lights have no range.
TEST(ShadowCasterSets, ObjectsBeyondTheLightsRangeAreExcluded) {
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(testCamera(), 320, 180);
    const std::vector<glm::dvec3> corners = lighting::frustumCornersWorld(view, 0.5, 25.0);
    scenes::Light light;
    light.type = scenes::LightType::Point;
    light.positionWorld = {0.5f, 1.0f, -8.0f};
    light.rangeMetres = 2.0f;
    const lighting::CasterVolume volume = lighting::casterVolume(corners, light, 100.0);
    ASSERT_TRUE(volume.lightInFrustum);
    const scenes::Aabb farInView = boxOf({-1, 0, -16}, {1, 1, -15});
    const scenes::Aabb justTouching = boxOf({2.5f, 0.5f, -9}, {3.5f, 1.5f, -7}); // 2.0 m away
    EXPECT_TRUE(volume.mayContain(farInView, 0.0)) << "inside the hull";
    EXPECT_FALSE(volume.mayCast(farInView, 0.0)) << "but 7 m beyond a 2 m range";
    EXPECT_TRUE(volume.mayCast(justTouching, 0.0));
    scenes::Light sun;
    sun.type = scenes::LightType::Directional;
    sun.directionWorld = {0.0f, -1.0f, 0.0f};
    EXPECT_TRUE(lighting::casterVolume(corners, sun, 100.0).mayCast(farInView, 0.0));
}

// Measured 1.57% (3.17 of 202 objects per light); the bound leaves room for a change of the
// scene's layout, not for a regression to the hull alone (about half the objects: 57% on the
// measured configuration) or to every object.
constexpr double kClutteredWallMaxFraction = 0.05;

// Issue 29's target on a scene with many objects: the wall with street-furniture clutter
// (scenes/procedural/README.md), lights on both sides. A small configuration of the measured one
// (lighting/shadows/README.md: 1000 lights, 1280x720, 202 objects, 1.9-3.6% of them per light).
// The image with the sets is bitwise the image without them, and the sets are small: a set that
// regressed to the hull alone (every object in view, about half of them here) or to every
// object fails the bound.
TEST(ShadowCasterSets, ClutteredWallSetsAreSmallAndTheImageIsTheSame) {
    lighting::StageResult imageOn, imageOff;
    const int lights = 64;
    const SetsComparison r =
        compareSets("wall", lights, lighting::ShadowFilter::Pcf3, 128, 0.0f,
                    {{"behind", "32"}, {"clutter", "200"}}, 160, 90, &imageOn, &imageOff);
    const double objects = 202.0;
    const double fraction = double(r.casterObjects) / (double(lights) * objects);
    std::cout << "[measured] cluttered wall 160x90, " << lights
              << " lights: casting-set objects per light " << double(r.casterObjects) / lights
              << " of " << objects << " (" << 100.0 * fraction << "%), triangles drawn "
              << r.trianglesOn << " of " << r.trianglesOff << ", " << r.lookups
              << " lookups compared\n";
    EXPECT_EQ(r.allObjects, uint64_t(lights) * 202u);
    EXPECT_GT(r.lookups, 10000u);
    EXPECT_EQ(r.differing, 0u) << "an excluded object changed a lookup";
    EXPECT_LT(fraction, kClutteredWallMaxFraction);
    for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(imageOn.radiance[c].size(), imageOff.radiance[c].size());
        EXPECT_EQ(std::memcmp(imageOn.radiance[c].data(), imageOff.radiance[c].data(),
                              imageOn.radiance[c].size() * sizeof(float)),
                  0)
            << "channel " << c << ": the image with the sets differs from the one without";
    }
}

} // namespace

namespace {

// instanceBoundsFromChunks (what the shadow maps use) against instanceBounds, triangle by
// triangle: bitwise the same boxes on every procedural scene, for chunks of one triangle, of a
// size that straddles instances often (7), the maps' 64 and one chunk holding everything; a
// chunk list that does not cover the triangles is refused.
TEST(ShadowCasterSets, InstanceBoundsFromChunksAreTheTriangleBounds) {
    for (const std::string& name : scenes::proceduralSceneNames()) {
        scenes::SceneRequest request;
        request.lightCount = 4;
        const scenes::Scene scene = scenes::buildProceduralScene(name, request);
        const gbuffer::SceneGeometry geometry = gbuffer::SceneGeometry::build(scene);
        const std::vector<scenes::Aabb> expected =
            lighting::instanceBounds(geometry, scene.instances.size());
        const uint32_t triangles = geometry.triangleCount();
        for (uint32_t perChunk : {1u, 7u, 64u, std::max(triangles, 1u)}) {
            std::vector<scenes::Aabb> chunks((triangles + perChunk - 1) / perChunk);
            for (uint32_t t = 0; t < triangles; ++t)
                for (int k = 0; k < 3; ++k)
                    chunks[t / perChunk].extend(
                        geometry.positionWorld[geometry.indices[3 * t + k]]);
            const std::vector<scenes::Aabb> derived = lighting::instanceBoundsFromChunks(
                geometry, scene.instances.size(), chunks, perChunk);
            ASSERT_EQ(derived.size(), expected.size());
            for (size_t i = 0; i < expected.size(); ++i) {
                EXPECT_EQ(0, std::memcmp(&derived[i], &expected[i], sizeof(scenes::Aabb)))
                    << name << ", chunks of " << perChunk << ", instance " << i;
            }
        }
        if (triangles > 1) {
            const std::vector<scenes::Aabb> tooFew(1);
            EXPECT_THROW(
                lighting::instanceBoundsFromChunks(geometry, scene.instances.size(), tooFew, 1),
                std::invalid_argument)
                << name;
        }
    }
}

} // namespace
