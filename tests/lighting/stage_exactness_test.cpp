// Every stage registered as Exact, on atrium, wall (with lights behind it), spheres and the
// DamagedHelmet glTF model (metallic-roughness materials with textures and a normal map): the same
// image as `brute` (max abs difference <= 1e-5 of the image's peak) and, at every pixel, at
// least as many lights evaluated as contribute (the oracle). New stages are covered as soon as
// they are registered; nothing here names them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include <tbb/task_arena.h>

#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/ProceduralScenes.h"
#include "scenes/SceneLoader.h"

namespace {

struct SceneCase {
    const char* name;
    const char* scene;
    int lights;
    std::map<std::string, std::string> options;
    bool spots = false; // turn the generated point lights into spot lights of varied cones
};

// Small images keep the suite fast; light counts are high enough that culling matters.
constexpr int kWidth = 256;
constexpr int kHeight = 144;

const SceneCase kScenes[] = {
    {"atrium", "atrium", 300, {}},
    {"wall_behind", "wall", 400, {{"behind", "200"}}},
    {"spheres", "spheres", 200, {}},
    {"atrium_spots", "atrium", 300, {}, true},
    {"helmet", TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", 64, {}},
    {"helmet_spots", TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", 64, {}, true},
};

// Deterministic spot lights from the generated point lights: axes spread over the lower
// hemisphere, outer half-angles from 5 to 100 degrees (both sides of the 45- and 90-degree cases
// of the cone bound in LightBounds.h), inner cone at 80% of the outer.
void makeSpots(scenes::Scene& scene) {
    int index = 0;
    for (scenes::Light& light : scene.lights) {
        if (light.type != scenes::LightType::Point)
            continue;
        const float a = 2.399963f * float(index); // golden angle: spread without clumping
        light.type = scenes::LightType::Spot;
        light.directionWorld = glm::normalize(
            glm::vec3(std::cos(a), -0.2f - 0.8f * float(index % 5) / 4.0f, std::sin(a)));
        const float outer = glm::radians(5.0f + 95.0f * float(index % 11) / 10.0f);
        light.spotOuterCos = std::cos(outer);
        light.spotInnerCos = std::cos(0.8f * outer);
        light.rangeMetres *= 1.5f; // spots reach farther: more pixels to cull correctly
        ++index;
    }
}

// One frame per scene case, its oracle and brute's image, shared by every stage's test.
struct PreparedCase {
    std::unique_ptr<lighting::PreparedScene> prepared;
    std::vector<uint32_t> oracle;
    lighting::StageResult brute;
};

const PreparedCase& prepared(const SceneCase& c) {
    static std::map<std::string, std::unique_ptr<PreparedCase>> cache;
    auto& slot = cache[c.name];
    if (slot)
        return *slot;
    slot = std::make_unique<PreparedCase>();
    scenes::SceneRequest request;
    request.lightCount = c.lights;
    request.seed = 3;
    request.options = c.options;
    const std::string source = c.scene;
    scenes::Scene scene = source.ends_with(".gltf")
                              ? scenes::loadScene(source, request)
                              : scenes::buildProceduralScene(c.scene, request);
    if (c.spots)
        makeSpots(scene);
    slot->prepared = std::make_unique<lighting::PreparedScene>(std::move(scene), kWidth, kHeight);
    slot->oracle = lighting::countContributingLights(slot->prepared->inputs);
    lighting::makeStage("brute")->shade(slot->prepared->inputs, slot->brute);
    return *slot;
}

std::vector<std::string> exactStageNames() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        if (info.kind == lighting::StageKind::Exact)
            names.push_back(info.name);
    return names;
}

class ExactStage : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(ExactStage, MatchesBruteAndNeverDropsALight) {
    const auto& [stageName, sceneIndex] = GetParam();
    const SceneCase& c = kScenes[sceneIndex];
    const PreparedCase& f = prepared(c);
    lighting::StageResult result;
    lighting::makeStage(stageName)->shade(f.prepared->inputs, result);
    ASSERT_EQ(result.width, kWidth);
    ASSERT_EQ(result.height, kHeight);

    float peak = 0.0f;
    for (int ch = 0; ch < 3; ++ch)
        for (float v : f.brute.radiance[ch])
            peak = std::max(peak, v);
    ASSERT_GT(peak, 0.0f);
    uint64_t evaluated = 0, oracle = 0;
    int imageFailures = 0, droppedLights = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        evaluated += result.lightsEvaluated[pixel];
        oracle += f.oracle[pixel];
        for (int ch = 0; ch < 3; ++ch) {
            const float difference =
                std::abs(result.radiance[ch][pixel] - f.brute.radiance[ch][pixel]);
            if (!(difference <= 1e-5f * peak) && imageFailures++ < 5)
                ADD_FAILURE() << stageName << " on " << c.name << ": pixel (" << pixel % kWidth
                              << ", " << pixel / kWidth << ") channel " << ch
                              << " differs from brute by " << difference << " (peak " << peak
                              << ")";
        }
        if (result.lightsEvaluated[pixel] < f.oracle[pixel] && droppedLights++ < 5)
            ADD_FAILURE() << stageName << " on " << c.name << ": pixel (" << pixel % kWidth << ", "
                          << pixel / kWidth << ") evaluated " << result.lightsEvaluated[pixel]
                          << " lights but " << f.oracle[pixel] << " contribute";
    }
    EXPECT_EQ(imageFailures, 0);
    EXPECT_EQ(droppedLights, 0);
    RecordProperty("culling_efficiency",
                   std::to_string(double(oracle) / std::max<uint64_t>(evaluated, 1)));
}

INSTANTIATE_TEST_SUITE_P(AllExactStages, ExactStage,
                         ::testing::Combine(::testing::ValuesIn(exactStageNames()),
                                            ::testing::Range(0, int(std::size(kScenes)))),
                         [](const auto& info) {
                             std::string name = std::get<0>(info.param) + "_" +
                                                kScenes[std::get<1>(info.param)].name;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

// The cone bound must cut work: on atrium with spot lights, tiled evaluates markedly fewer lights
// than it would with the range spheres of point lights at the same places.
TEST(SpotBounds, ConeBoundsCullMoreThanRangeSpheres) {
    const PreparedCase& spots = prepared(kScenes[3]);
    lighting::StageResult withCones;
    lighting::makeStage("tiled")->shade(spots.prepared->inputs, withCones);
    scenes::SceneRequest request;
    request.lightCount = kScenes[3].lights;
    request.seed = 3;
    scenes::Scene scene = scenes::buildProceduralScene("atrium", request);
    makeSpots(scene);
    for (scenes::Light& light : scene.lights)
        if (light.type == scenes::LightType::Spot)
            light.spotOuterCos = -1.0f; // whole sphere, same range
    lighting::PreparedScene spheres(std::move(scene), kWidth, kHeight);
    lighting::StageResult withSpheres;
    lighting::makeStage("tiled")->shade(spheres.inputs, withSpheres);
    uint64_t cones = 0, rangeSpheres = 0;
    for (size_t pixel = 0; pixel < withCones.lightsEvaluated.size(); ++pixel) {
        cones += withCones.lightsEvaluated[pixel];
        rangeSpheres += withSpheres.lightsEvaluated[pixel];
    }
    EXPECT_LT(double(cones), 0.8 * double(rangeSpheres)) << cones << " vs " << rangeSpheres;
}

// `deferred`'s cone proxies (the default, spot=cone) must cut work against its sphere proxies on
// the same spots, and neither may drop a light (the image is checked for the default above).
TEST(SpotBounds, DeferredConeProxiesEvaluateFewerLightsThanSpheres) {
    const PreparedCase& spots = prepared(kScenes[3]);
    uint64_t evaluated[2] = {0, 0};
    const char* stages[2] = {"deferred:spot=cone", "deferred:spot=sphere"};
    for (int k = 0; k < 2; ++k) {
        lighting::StageResult result;
        lighting::makeStage(stages[k])->shade(spots.prepared->inputs, result);
        int dropped = 0;
        for (size_t pixel = 0; pixel < result.lightsEvaluated.size(); ++pixel) {
            evaluated[k] += result.lightsEvaluated[pixel];
            dropped += result.lightsEvaluated[pixel] < spots.oracle[pixel];
        }
        EXPECT_EQ(dropped, 0) << stages[k];
    }
    EXPECT_LT(double(evaluated[0]), 0.95 * double(evaluated[1]))
        << evaluated[0] << " vs " << evaluated[1];
}

TEST(StageRegistry, EveryStageRejectsUnknownOptions) {
    for (const lighting::StageInfo& info : lighting::stageInfos())
        EXPECT_THROW(lighting::makeStage(info.name + ":no_such_option=1"), lighting::StageError)
            << info.name;
    EXPECT_THROW(lighting::makeStage("no-such-stage"), lighting::StageError);
}

} // namespace
