// `tiled` and `tiled-backface` on hard hand-built cases (the exactness suite already covers the
// procedural scenes): lights centred on tile corners, crossing the near plane, around or behind
// the camera, of zero range, covering the whole screen; a depth discontinuity inside tiles; a
// grazing floor; lights behind a wall (back-face culling must remove some). Every case checks
// the two properties of an exact stage against `brute` on the same frame: the image is bitwise
// equal (ascending light lists), and at every pixel evaluated >= contributing (the oracle).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferPass.h"
#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/TileFrusta.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 180;

// A prepared frame plus the oracle and brute's image for its current lights.
struct TestScene : lighting::PreparedScene {
    std::vector<uint32_t> oracle;
    lighting::StageResult brute;
    TestScene(scenes::Scene scene, int width, int height)
        : lighting::PreparedScene(std::move(scene), width, height) {}
};

// Rasterizes the scene's G-buffer only (lights can be changed afterwards with setLights).
std::unique_ptr<TestScene> rasterize(scenes::Scene scene, int width = kWidth,
                                     int height = kHeight) {
    return std::make_unique<TestScene>(std::move(scene), width, height);
}

void setLights(TestScene& f, const std::vector<scenes::Light>& lights) {
    f.setLights(lights);
    f.oracle = lighting::countContributingLights(f.inputs);
    lighting::makeStage("brute")->shade(f.inputs, f.brute);
}

// Runs `spec` on the frame and checks it against brute: bitwise image, evaluated >= oracle.
// Returns the result for further checks.
lighting::StageResult expectExact(const TestScene& f, const std::string& spec,
                                  const std::string& what) {
    lighting::StageResult result;
    lighting::makeStage(spec)->shade(f.inputs, result);
    EXPECT_EQ(result.width, f.view.width);
    EXPECT_EQ(result.height, f.view.height);
    int imageFailures = 0, dropped = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        for (int ch = 0; ch < 3; ++ch)
            if (result.radiance[ch][pixel] != f.brute.radiance[ch][pixel] && imageFailures++ < 3)
                ADD_FAILURE() << spec << " on " << what << ": pixel (" << pixel % f.view.width
                              << ", " << pixel / f.view.width << ") channel " << ch << ": "
                              << result.radiance[ch][pixel] << " vs brute "
                              << f.brute.radiance[ch][pixel];
        if (result.lightsEvaluated[pixel] < f.oracle[pixel] && dropped++ < 3)
            ADD_FAILURE() << spec << " on " << what << ": pixel (" << pixel % f.view.width << ", "
                          << pixel / f.view.width << ") evaluated " << result.lightsEvaluated[pixel]
                          << " but " << f.oracle[pixel] << " contribute";
    }
    EXPECT_EQ(imageFailures, 0) << spec << " on " << what;
    EXPECT_EQ(dropped, 0) << spec << " on " << what;
    return result;
}

const char* const kSpecs[] = {
    "tiled",          "tiled:mask=1",          "tiled:vfc=0,tile=8",
    "tiled-backface", "tiled-backface:mask=1", "tiled-backface:tile=32,vfc=0",
    "tiled:tile=7"};

void expectAllExact(const TestScene& f, const std::string& what) {
    uint64_t oracleTotal = 0;
    for (uint32_t n : f.oracle)
        oracleTotal += n;
    ASSERT_GT(oracleTotal, 0u) << what << ": the case lights nothing, so it tests nothing";
    for (const char* spec : kSpecs)
        expectExact(f, spec, what);
}

uint64_t totalEvaluated(const lighting::StageResult& r) {
    uint64_t total = 0;
    for (uint32_t n : r.lightsEvaluated)
        total += n;
    return total;
}

scenes::Light pointLight(const glm::vec3& positionWorld, float rangeMetres) {
    scenes::Light light;
    light.positionWorld = positionWorld;
    light.rangeMetres = rangeMetres;
    light.intensity = 2.0f;
    light.color = {1.0f, 0.9f, 0.8f};
    return light;
}

glm::vec3 worldFromView(const gbuffer::CameraView& view, const glm::vec3& pView) {
    return glm::vec3(glm::inverse(view.viewFromWorld) * glm::vec4(pView, 1.0f));
}

// The wall scene without generated lights: its frame plus its camera's view.
std::unique_ptr<TestScene> wallScene() {
    scenes::SceneRequest request;
    request.lightCount = 0;
    return rasterize(scenes::buildProceduralScene("wall", request));
}

void appendQuad(scenes::Mesh& mesh, const glm::vec3& corner, const glm::vec3& u,
                const glm::vec3& v) {
    const uint32_t base = uint32_t(mesh.positions.size());
    const glm::vec3 normal = glm::normalize(glm::cross(u, v));
    for (const glm::vec3& p : {corner, corner + u, corner + u + v, corner + v}) {
        mesh.positions.push_back(p);
        mesh.normals.push_back(normal);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
        mesh.indices.push_back(base + i);
}

// A narrow foreground column (z = -3) in front of a far wall (z = -10), camera at the origin:
// tiles along the column's edges hold both depths.
scenes::Scene twoPlaneScene() {
    scenes::Scene scene;
    scene.name = "two-planes";
    scene.materials.push_back({});
    scene.meshes.emplace_back();
    appendQuad(scene.meshes[0], {-12, -7, -10}, {24, 0, 0}, {0, 14, 0});
    appendQuad(scene.meshes[0], {-0.35f, -4, -3}, {0.7f, 0, 0}, {0, 8, 0});
    scene.instances.push_back({});
    scenes::Camera camera;
    camera.name = "front";
    camera.verticalFovRadians = 1.0f;
    scene.cameras.push_back(camera);
    return scene;
}

TEST(TiledStage, LightsCentredOnTileCorners) {
    auto f = wallScene();
    const gbuffer::CameraView& view = f->view;
    const auto& depth = f->gbuffer->depth();
    std::vector<scenes::Light> lights;
    for (int tile : {8, 16, 32})
        for (int j = 1; j * tile < kHeight; j += 3)
            for (int i = 1; i * tile < kWidth; i += 3) {
                const int x = i * tile, y = j * tile;
                const float d = depth[size_t(y) * kWidth + x];
                if (d == view.clearDepth())
                    continue;
                // The exact pixel corner (x, y) at the surface's depth, pulled 5% towards the eye.
                const glm::vec2 ndc(float(x) / kWidth * 2 - 1, 1 - float(y) / kHeight * 2);
                const glm::vec4 p = view.viewFromClip * glm::vec4(ndc, d, 1.0f);
                const glm::vec3 pView = glm::vec3(p) / p.w * 0.95f;
                lights.push_back(
                    pointLight(worldFromView(view, pView), 0.3f + 0.1f * float(i % 4)));
            }
    ASSERT_GT(lights.size(), 20u);
    setLights(*f, lights);
    expectAllExact(*f, "lights on tile corners");
}

TEST(TiledStage, LightsAtNearPlaneAroundAndBehindCamera) {
    auto f = wallScene();
    const gbuffer::CameraView& view = f->view;
    std::vector<scenes::Light> lights = {
        pointLight(worldFromView(view, {0.0f, 0.0f, -view.nearMetres}), 6.0f), // crosses near
        pointLight(worldFromView(view, {0.3f, -0.2f, -0.05f}), 4.0f),          // eye inside
        pointLight(worldFromView(view, {0.0f, 0.0f, 0.0f}), 12.0f),            // at the eye
        pointLight(worldFromView(view, {0.0f, 0.0f, 3.0f}), 9.0f),             // behind, reaches
        pointLight(worldFromView(view, {1.0f, 0.0f, 5.0f}), 1.0f),             // behind, not
        pointLight(worldFromView(view, {-2.0f, 1.0f, 1.0f}), 10.0f),           // beside
    };
    setLights(*f, lights);
    expectAllExact(*f, "near plane, eye inside, behind the camera");
}

TEST(TiledStage, ZeroRangeAndScreenCoveringLights) {
    auto f = wallScene();
    const gbuffer::CameraView& view = f->view;
    std::vector<scenes::Light> lights;
    lights.push_back(pointLight(worldFromView(view, {0.0f, 0.0f, -9.0f}), 0.0f));
    lights.push_back(pointLight({0.0f, 2.0f, 0.5f}, 0.0f));   // on the wall's face, zero range
    lights.push_back(pointLight({0.0f, 3.0f, 4.0f}, 200.0f)); // every pixel
    lights.push_back(pointLight({1.0f, 2.5f, 0.15f}, 2.0f));  // exactly on the wall's face
    lights.push_back(pointLight({-3.0f, 0.0f, 2.0f}, 1.5f));  // exactly on the floor
    setLights(*f, lights);
    expectAllExact(*f, "zero-range and screen-covering lights");
}

TEST(TiledStage, DepthDiscontinuityInsideTiles) {
    auto f = rasterize(twoPlaneScene());
    std::vector<scenes::Light> lights;
    for (float x = -1.5f; x <= 1.5f; x += 0.25f) {
        lights.push_back(pointLight({x, 0.5f, -6.5f}, 3.6f));   // between: reaches the far wall
        lights.push_back(pointLight({x, -1.0f, -2.5f}, 0.7f));  // just in front of the column
        lights.push_back(pointLight({x, 1.0f, -3.5f}, 0.6f));   // just behind it (its back)
        lights.push_back(pointLight({x, -2.0f, -9.5f}, 0.45f)); // near the far wall
    }
    setLights(*f, lights);
    expectAllExact(*f, "column before a far wall");
}

TEST(TiledStage, GrazingFloor) {
    scenes::SceneRequest request;
    request.lightCount = 0;
    scenes::Scene scene = scenes::buildProceduralScene("wall", request);
    // Camera 4 cm above the floor looking along it, nearly parallel.
    scene.cameras[0].positionWorld = {-15.0f, 0.04f, 8.0f};
    scene.cameras[0].forwardWorld = glm::normalize(glm::vec3(1.0f, -0.01f, -0.3f));
    auto f = rasterize(std::move(scene));
    std::vector<scenes::Light> lights;
    for (int i = 0; i < 40; ++i) {
        const float along = -13.0f + 0.7f * float(i);
        lights.push_back(pointLight({along, 0.02f + 0.05f * float(i % 3), 8.0f - 0.2f * float(i)},
                                    1.0f + 0.1f * float(i % 5)));
        lights.push_back(
            pointLight({along, -0.3f, 7.0f - 0.2f * float(i)}, 0.5f)); // under the floor
    }
    setLights(*f, lights);
    expectAllExact(*f, "grazing floor");
}

TEST(TiledStage, BackfaceCullsLightsBehindTheWall) {
    scenes::SceneRequest request;
    request.lightCount = 400;
    request.seed = 5;
    request.options = {{"behind", "200"}};
    auto f = rasterize(scenes::buildProceduralScene("wall", request));
    const std::vector<scenes::Light> lights = f->scene.lights;
    setLights(*f, lights);
    const lighting::StageResult tiled = expectExact(*f, "tiled", "wall behind=200");
    const lighting::StageResult backface = expectExact(*f, "tiled-backface", "wall behind=200");
    expectExact(*f, "tiled-backface:mask=1", "wall behind=200");
    EXPECT_LT(totalEvaluated(backface), totalEvaluated(tiled));
    ASSERT_TRUE(backface.parameters.count("backface_rejected"));
    EXPECT_GT(std::stoull(backface.parameters.at("backface_rejected")), 0u);
    EXPECT_LT(std::stoull(backface.parameters.at("tile_light_pairs")),
              std::stoull(tiled.parameters.at("tile_light_pairs")));
}

TEST(TiledStage, SameResultForAnyThreadCount) {
    scenes::SceneRequest request;
    request.lightCount = 300;
    request.options = {{"behind", "100"}};
    auto f = rasterize(scenes::buildProceduralScene("wall", request));
    const std::vector<scenes::Light> lights = f->scene.lights;
    setLights(*f, lights);
    for (const char* spec : {"tiled:mask=1", "tiled-backface"}) {
        lighting::StageResult one, many;
        tbb::task_arena(1).execute([&] { lighting::makeStage(spec)->shade(f->inputs, one); });
        lighting::makeStage(spec)->shade(f->inputs, many);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_EQ(one.radiance[ch], many.radiance[ch]) << spec;
        EXPECT_EQ(one.lightsEvaluated, many.lightsEvaluated) << spec;
        EXPECT_EQ(one.parameters, many.parameters) << spec;
    }
}

TEST(TiledStage, OptionsParseAndAreRecorded) {
    EXPECT_NO_THROW(lighting::makeStage("tiled:tile=32"));
    EXPECT_NO_THROW(lighting::makeStage("tiled-backface:tile=4,vfc=0,mask=1"));
    EXPECT_THROW(lighting::makeStage("tiled:tile=3"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("tiled:tile=129"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("tiled-backface:mask=2"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("tiled:backface=1"), lighting::StageError);

    scenes::SceneRequest request;
    request.lightCount = 100;
    auto f = rasterize(scenes::buildProceduralScene("spheres", request), 160, 90);
    const std::vector<scenes::Light> lights = f->scene.lights;
    setLights(*f, lights);
    const lighting::StageResult r = expectExact(*f, "tiled:tile=32,mask=1,vfc=0", "spheres");
    EXPECT_EQ(r.parameters.at("tile"), "32");
    EXPECT_EQ(r.parameters.at("mask"), "1");
    EXPECT_EQ(r.parameters.at("vfc"), "0");
    EXPECT_EQ(r.parameters.at("vfc_culled"), "0");
    ASSERT_EQ(r.timingsMs.size(), 2u);
    EXPECT_EQ(r.timingsMs[0].first, "cull");
    EXPECT_EQ(r.timingsMs[1].first, "shading");
}

TEST(TileFrusta, DepthRangeMaskCoversEverySampleBin) {
    const float minDepth = 2.0f, maxDepth = 7.5f;
    const float perMetre = lighting::depthBinsPerMetre(minDepth, maxDepth);
    for (float low = 1.0f; low < 8.0f; low += 0.37f)
        for (float high = low; high < 9.0f; high += 0.29f) {
            const uint32_t mask = lighting::depthRangeMask(low, high, minDepth, maxDepth);
            for (float d = std::max(low, minDepth); d <= std::min(high, maxDepth); d += 0.013f)
                EXPECT_TRUE(mask & (1u << lighting::depthBin(d, minDepth, perMetre)))
                    << low << " " << high << " " << d;
        }
    EXPECT_EQ(lighting::depthRangeMask(0.0f, 100.0f, 1.0f, 1.0f), 1u); // flat tile: one bin
}

} // namespace
