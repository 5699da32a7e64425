// Faces outside the view (ShadowSettings::cullFacesOutsideView, ShadowMaps.cpp
// perspectiveFaceOutsideView): a cube or spot face whose pyramid misses the camera's frustum is
// left empty. Checked three ways:
// - the geometry: lights behind, beside and in front of the camera leave exactly the faces one
//   can count by hand;
// - the definition: no point of the camera's frustum (its boundary, corners and near plane
//   included) within a light's range selects a face left empty (ShadowMaps::faceOf), on
//   generated scenes with turned cameras;
// - the image: every light's visibility at every covered pixel, and the brute stage's image
//   through the kernel's vector lookup, are bitwise the same with the cull on and off, while the
//   cull leaves faces empty (so the comparison is not vacuous).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/shadows/ShadowMaps.h"
#include "scenes/Scene.h"
#include "scenes/mesh/MeshBuilder.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using lighting::ShadowMaps;
using lighting::ShadowSettings;

// A ground square and a box under a camera at the origin looking down world -Z (60 degrees
// vertically, 16:9), with the given lights.
scenes::Scene sceneWithLights(const std::vector<scenes::Light>& lights) {
    scenes::Scene scene;
    scene.name = "face-cull";
    scene.materials.emplace_back();
    scene.meshes.emplace_back();
    scene.instances.push_back({0, glm::mat4(1.0f)});
    scenes::appendQuad(scene.meshes[0], {-20.0f, -1.0f, 20.0f}, {40.0f, 0.0f, 0.0f},
                       {0.0f, 0.0f, -40.0f}, 4, 4);
    scenes::Aabb box;
    box.min = {-0.5f, -1.0f, -6.0f};
    box.max = {0.5f, 0.0f, -5.0f};
    scenes::appendBox(scene.meshes[0], box, 1e6f);
    scenes::Camera camera;
    camera.positionWorld = {0.0f, 0.0f, 0.0f};
    camera.forwardWorld = {0.0f, 0.0f, -1.0f};
    camera.upWorld = {0.0f, 1.0f, 0.0f};
    camera.verticalFovRadians = glm::radians(60.0f);
    camera.nearMetres = 0.1f;
    camera.farMetres = 50.0f;
    scene.cameras = {camera};
    scene.lights = lights;
    for (scenes::Light& light : scene.lights)
        light.castsShadows = true;
    return scene;
}

scenes::Light pointLight(const glm::vec3& position, float range) {
    scenes::Light l;
    l.type = scenes::LightType::Point;
    l.positionWorld = position;
    l.rangeMetres = range;
    return l;
}

scenes::Light spotLight(const glm::vec3& position, const glm::vec3& direction, float range) {
    scenes::Light l = pointLight(position, range);
    l.type = scenes::LightType::Spot;
    l.directionWorld = glm::normalize(direction);
    l.spotOuterCos = std::cos(glm::radians(30.0f));
    l.spotInnerCos = std::cos(glm::radians(25.0f));
    return l;
}

// The face flags of one light: cube faces in the order +X, -X, +Y, -Y, +Z, -Z (ShadowMaps.cpp); 1 =
// left empty.
std::vector<int> outsideFlags(const ShadowMaps& maps, uint32_t shadow) {
    std::vector<int> flags;
    for (size_t f = 0; f < maps.faceCountOf(shadow); ++f)
        flags.push_back(maps.face(maps.firstFace(shadow) + f).outsideView ? 1 : 0);
    return flags;
}

TEST(ShadowFaceCull, LeavesEmptyExactlyTheFacesThatLookAwayFromTheView) {
    const std::vector<scenes::Light> lights = {
        // Behind the camera, out of reach of the near plane: every face.
        pointLight({0.0f, 0.0f, 5.0f}, 3.0f),
        // Just behind the camera, reaching into the view: only -Z looks into it (the frustum is
        // narrower than 90 degrees, so the side faces' pyramids pass beside it).
        pointLight({0.0f, 0.0f, 1.0f}, 10.0f),
        // In the middle of the view: every face sees part of the frustum.
        pointLight({0.0f, 0.0f, -10.0f}, 3.0f),
        // Beside the view, its sphere wholly beyond the frustum's right plane: every face.
        pointLight({40.0f, 0.0f, -10.0f}, 5.0f),
        // Spots: one pointing away from the view behind the camera, one into it.
        spotLight({0.0f, 0.0f, 2.0f}, {0.0f, 0.0f, 1.0f}, 10.0f),
        spotLight({0.0f, 0.0f, 2.0f}, {0.0f, 0.0f, -1.0f}, 10.0f),
    };
    const scenes::Scene scene = sceneWithLights(lights);
    const gbuffer::SceneGeometry geometry = gbuffer::SceneGeometry::build(scene);
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(scene.cameras[0], 320, 180);
    ShadowSettings settings;
    settings.mapSize = 64;
    const ShadowMaps maps = ShadowMaps::render(scene, geometry, view, settings);
    ASSERT_EQ(maps.shadowCount(), lights.size());
    EXPECT_EQ(outsideFlags(maps, 0), (std::vector<int>{1, 1, 1, 1, 1, 1}));
    EXPECT_EQ(outsideFlags(maps, 1), (std::vector<int>{1, 1, 1, 1, 1, 0}));
    EXPECT_EQ(outsideFlags(maps, 2), (std::vector<int>{0, 0, 0, 0, 0, 0}));
    EXPECT_EQ(outsideFlags(maps, 3), (std::vector<int>{1, 1, 1, 1, 1, 1}));
    EXPECT_EQ(outsideFlags(maps, 4), (std::vector<int>{1}));
    EXPECT_EQ(outsideFlags(maps, 5), (std::vector<int>{0}));
    EXPECT_EQ(maps.stats().facesOutsideView, 6u + 5u + 6u + 1u);
    // An empty face is neither drawn nor stored.
    for (size_t f = 0; f < maps.faceCount(); ++f)
        if (maps.face(f).outsideView) {
            EXPECT_TRUE(maps.face(f).empty);
            EXPECT_TRUE(maps.face(f).depth.empty());
        }
    EXPECT_EQ(maps.stats().lights[0].bytes, 0u);
    EXPECT_EQ(maps.stats().lights[0].trianglesDrawn, 0u);

    // Off: every face drawn.
    settings.cullFacesOutsideView = false;
    const ShadowMaps all = ShadowMaps::render(scene, geometry, view, settings);
    EXPECT_EQ(all.stats().facesOutsideView, 0u);
    for (size_t f = 0; f < all.faceCount(); ++f)
        EXPECT_FALSE(all.face(f).empty) << "face " << f;
}

// A generated scene's frame with its camera turned about the vertical axis by yawRadians.
std::unique_ptr<lighting::PreparedScene> turnedFrame(const std::string& sceneName, int lights,
                                                     float yawRadians, int width, int height) {
    scenes::SceneRequest request;
    request.lightCount = lights;
    request.seed = 5;
    scenes::Scene scene = scenes::buildProceduralScene(sceneName, request);
    scenes::Camera& camera = scene.cameras.front();
    const glm::mat3 turn(glm::rotate(glm::mat4(1.0f), yawRadians, glm::vec3(0, 1, 0)));
    camera.forwardWorld = glm::normalize(turn * camera.forwardWorld);
    camera.upWorld = glm::normalize(turn * camera.upWorld);
    return std::make_unique<lighting::PreparedScene>(std::move(scene), width, height);
}

// A coordinate in [lo, hi] that lands on either bound a third of the time.
double boundaryBiased(double lo, double hi, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double u = unit(rng);
    if (u < 1.0 / 6.0)
        return lo;
    if (u < 2.0 / 6.0)
        return hi;
    return lo + (hi - lo) * unit(rng);
}

TEST(ShadowFaceCull, NoPointOfTheViewWithinALightsRangeSelectsAFaceLeftEmpty) {
    uint64_t checked = 0, facesOutside = 0, faces = 0;
    for (const char* sceneName : {"atrium", "wall", "spheres"})
        for (const float yaw : {0.0f, 1.2f, 2.6f, -1.9f}) {
            const auto frame = turnedFrame(sceneName, 48, yaw, 160, 90);
            const gbuffer::CameraView& view = frame->view;
            ShadowSettings settings;
            settings.mapSize = 32;
            const ShadowMaps maps =
                ShadowMaps::render(frame->scene, frame->geometry, view, settings);
            facesOutside += maps.stats().facesOutsideView;
            faces += maps.stats().faceCount;
            const double tanX = 1.0 / double(view.clipFromView[0][0]);
            const double tanY = 1.0 / double(view.clipFromView[1][1]);
            std::mt19937 rng(uint32_t(checked + 17));
            for (size_t light = 0; light < frame->scene.lights.size(); ++light) {
                const uint32_t shadow = maps.shadowOf(light);
                if (shadow == ShadowMaps::kNoShadow)
                    continue;
                const scenes::Light& l = frame->scene.lights[light];
                if (l.type == scenes::LightType::Directional)
                    continue;
                const glm::dvec3 centre(view.viewFromWorldExact *
                                        glm::dvec4(glm::dvec3(l.positionWorld), 1.0));
                const double range = l.rangeMetres;
                // View depths the light's sphere spans, within the frustum's.
                const double d0 = std::max(double(view.nearMetres), -centre.z - range);
                const double d1 = std::min(double(view.farMetres), -centre.z + range);
                if (!(d1 >= d0))
                    continue;
                std::uniform_real_distribution<double> depthOf(d0, d1);
                for (int k = 0; k < 4000; ++k) {
                    // At this depth, the part of the frustum's slice the sphere's box spans
                    // (its sides on the frustum's side planes where the box crosses them).
                    const double d = k % 10 == 0 ? d0 : depthOf(rng);
                    const double x0 = std::max(-tanX * d, centre.x - range);
                    const double x1 = std::min(tanX * d, centre.x + range);
                    const double y0 = std::max(-tanY * d, centre.y - range);
                    const double y1 = std::min(tanY * d, centre.y + range);
                    if (!(x1 >= x0 && y1 >= y0))
                        continue;
                    const glm::dvec3 p(boundaryBiased(x0, x1, rng), boundaryBiased(y0, y1, rng),
                                       -d);
                    if (glm::length(p - centre) > range)
                        continue;
                    const size_t f = maps.faceOf(shadow, glm::vec3(p));
                    ++checked;
                    ASSERT_FALSE(f != SIZE_MAX && maps.face(f).outsideView)
                        << sceneName << " yaw " << yaw << " light " << light << ": the point ("
                        << p.x << ", " << p.y << ", " << p.z << ") selects face " << f
                        << ", left empty";
                }
            }
        }
    std::cout << "[measured] " << checked << " frustum points checked; " << facesOutside << " of "
              << faces << " faces left empty\n";
    EXPECT_GT(checked, 100000u);
    EXPECT_GT(facesOutside, 0u) << "the cull must leave faces empty for the test to bite";
}

TEST(ShadowFaceCull, TheImageIsBitwiseTheSameWithEveryFaceDrawn) {
    uint64_t facesOutside = 0;
    for (const char* sceneName : {"atrium", "wall"})
        for (const float yaw : {0.0f, 2.6f}) {
            SCOPED_TRACE(std::string(sceneName) + " yaw " + std::to_string(yaw));
            const auto frame = turnedFrame(sceneName, 32, yaw, 192, 108);
            ShadowSettings settings;
            settings.mapSize = 128;
            const ShadowMaps culled =
                ShadowMaps::render(frame->scene, frame->geometry, frame->view, settings);
            settings.cullFacesOutsideView = false;
            const ShadowMaps every =
                ShadowMaps::render(frame->scene, frame->geometry, frame->view, settings);
            facesOutside += culled.stats().facesOutsideView;
            const gbuffer::GBuffer& gb = *frame->gbuffer;
            uint64_t lookups = 0, differing = 0;
            for (int y = 0; y < gb.height(); ++y)
                for (int x = 0; x < gb.width(); ++x) {
                    if (!gb.covered(size_t(y) * size_t(gb.width()) + size_t(x)))
                        continue;
                    const gbuffer::Surface s = gb.decode(x, y);
                    for (size_t light = 0; light < frame->scene.lights.size(); ++light) {
                        const uint32_t shadow = culled.shadowOf(light);
                        if (shadow == ShadowMaps::kNoShadow)
                            continue;
                        ++lookups;
                        differing +=
                            culled.visibility(shadow, s.positionView, s.normalView) !=
                            every.visibility(every.shadowOf(light), s.positionView, s.normalView);
                    }
                }
            EXPECT_GT(lookups, 10000u);
            EXPECT_EQ(differing, 0u);
            // The brute stage's image, every light at every pixel through the vector lookup.
            lighting::StageResult imageCulled, imageEvery;
            lighting::StageInputs inputs = frame->inputs;
            inputs.shadows = &culled;
            lighting::makeStage("brute")->shade(inputs, imageCulled);
            inputs.shadows = &every;
            lighting::makeStage("brute")->shade(inputs, imageEvery);
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(imageCulled.radiance[c], imageEvery.radiance[c]) << "channel " << c;
        }
    EXPECT_GT(facesOutside, 0u) << "the cull must leave faces empty for the test to bite";
}

} // namespace
