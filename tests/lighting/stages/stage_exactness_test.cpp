// Every stage registered as Exact, on atrium, wall (with lights behind it), spheres, atrium
// with spot lights and the DamagedHelmet glTF model (metallic-roughness materials with textures
// and a normal map), with the shading kernel's scalar path and its widest vector target (`--isa
// scalar` and `auto`): the same image as `brute` on the same ISA, BITWISE for stages that sum in
// ascending light order (StageInfo::ascendingLightOrder) when they run the same arithmetic as
// brute (on accumulateLights, or on the scalar ISA), within 1e-5 of the image's peak otherwise;
// and the identity check: at every pixel every contributing light is among the lights the stage
// evaluated there (its light trace, LightIdentity.h), which implies evaluated >= oracle, and the
// same for every blended fragment (on glass: each fragment the stage composited, with the lights
// it evaluated for it, against the fragment's contributing lights). New
// stages are covered as soon as they are registered; nothing here names them. `ideal` must also
// evaluate exactly the oracle's count at every pixel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <span>
#include <stdexcept>

#include <tbb/task_arena.h>

#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/kernel/ShadingPacket.h"
#include "lighting/lists/ContributingLights.h"
#include "lighting/lists/EveryLight.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/PassNames.h"
#include "scenes/SceneLoader.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

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
    // MASK and BLEND materials (transparency_test.cpp); last: the IdealStage suite leaves it out.
    {"glass", "glass", 200, {}},
};
// The scenes of the IdealStage suite: all but glass, whose blended pass has its own timed pass
// and its own lists (lighting/passes/BlendedPass.h).
constexpr int kIdealSceneCount = int(std::size(kScenes)) - 1;

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
// The ISAs every case runs on: the scalar path and the widest vector target of this CPU.
const lighting::kernel::KernelIsa kIsas[] = {lighting::kernel::KernelIsa::scalar(),
                                             lighting::kernel::KernelIsa::best()};

struct PreparedCase {
    std::unique_ptr<lighting::PreparedScene> prepared;
    std::vector<uint32_t> oracle;
    lighting::ContributingLights contributing;
    stagecheck::BlendedFragments blended; // per pixel: blended fragments, contributing lights
    lighting::StageResult brute[std::size(kIsas)];
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
    slot->contributing.build(*slot->prepared->inputs.gbuffer,
                             slot->prepared->inputs.lights->lights);
    slot->blended = stagecheck::blendedContributingLights(slot->prepared->inputs);
    for (size_t isa = 0; isa < std::size(kIsas); ++isa) {
        slot->prepared->inputs.isa = kIsas[isa];
        lighting::makeStage("brute")->shade(slot->prepared->inputs, slot->brute[isa]);
    }
    slot->prepared->inputs.isa = kIsas[0];
    return *slot;
}

std::vector<std::string> exactStageNames() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        if (info.kind == lighting::StageKind::Exact)
            names.push_back(info.name);
    // Exact variants whose lists come from other code than their stage's default: the adaptive
    // cluster grid (culling/AdaptiveClusterGrid.h) on every scene, spots and blended glass too.
    names.push_back("clustered:grid=adaptive");
    return names;
}

const lighting::StageInfo& stageInfo(const std::string& spec) {
    static const std::vector<lighting::StageInfo> infos = lighting::stageInfos();
    const std::string name = spec.substr(0, spec.find(':'));
    for (const lighting::StageInfo& info : infos)
        if (info.name == name)
            return info;
    throw std::runtime_error("no stage " + name);
}

class ExactStage : public ::testing::TestWithParam<std::tuple<std::string, int, int>> {};

TEST_P(ExactStage, MatchesBruteAndEvaluatesEveryContributingLight) {
    const auto& [stageName, sceneIndex, isaIndex] = GetParam();
    const SceneCase& c = kScenes[sceneIndex];
    const PreparedCase& f = prepared(c);
    const bool ascending = stageInfo(stageName).ascendingLightOrder;
    lighting::StageInputs inputs = f.prepared->inputs;
    inputs.isa = kIsas[isaIndex];
    const lighting::StageResult& brute = f.brute[isaIndex];
    const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(stageName);
    const lighting::StageResult result = stagecheck::shadeTraced(*stage, inputs);
    ASSERT_EQ(result.width, kWidth);
    ASSERT_EQ(result.height, kHeight);
    // Stages on accumulateLights record the ISA that ran, as brute does: the requested one, since
    // every scene here fits the packet path (packet-decodable layouts; the kernel shades both
    // material models, so the helmet's metallic-roughness materials run vectorised too).
    const std::string ran = brute.parameters.at("isa");
    EXPECT_EQ(ran, kIsas[isaIndex].name());
    const auto isa = result.parameters.find("isa");
    const bool onKernel = isa != result.parameters.end();
    if (onKernel)
        EXPECT_EQ(isa->second, ran);
    const bool sameArithmetic = onKernel || ran == lighting::kernel::KernelIsa::scalar().name();

    EXPECT_TRUE(stagecheck::everyContributingLightEvaluated(result, f.contributing, ascending))
        << stageName << " on " << c.name;
    EXPECT_TRUE(stagecheck::everyBlendedContributingLightEvaluated(result, f.blended, ascending))
        << stageName << " on " << c.name << " (blended fragments)";
    if (ascending && sameArithmetic) {
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(result, brute))
            << stageName << " on " << c.name << " (ascending light order: bitwise brute's)";
    } else {
        float peak = 0.0f;
        for (int ch = 0; ch < 3; ++ch)
            for (float v : brute.radiance[ch])
                peak = std::max(peak, v);
        ASSERT_GT(peak, 0.0f);
        int imageFailures = 0;
        for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel)
            for (int ch = 0; ch < 3; ++ch) {
                const float difference =
                    std::abs(result.radiance[ch][pixel] - brute.radiance[ch][pixel]);
                if (!(difference <= 1e-5f * peak) && imageFailures++ < 5)
                    ADD_FAILURE() << stageName << " on " << c.name << ": pixel (" << pixel % kWidth
                                  << ", " << pixel / kWidth << ") channel " << ch
                                  << " differs from brute by " << difference << " (peak " << peak
                                  << ")";
            }
        EXPECT_EQ(imageFailures, 0);
    }

    // The counts, as the runner reports them: never fewer than the oracle.
    uint64_t evaluated = 0, oracle = 0;
    int droppedLights = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        evaluated += result.lightsEvaluated[pixel];
        oracle += f.oracle[pixel];
        if (result.lightsEvaluated[pixel] < f.oracle[pixel] && droppedLights++ < 5)
            ADD_FAILURE() << stageName << " on " << c.name << ": pixel (" << pixel % kWidth << ", "
                          << pixel / kWidth << ") evaluated " << result.lightsEvaluated[pixel]
                          << " lights but " << f.oracle[pixel] << " contribute";
    }
    EXPECT_EQ(droppedLights, 0);
    RecordProperty("culling_efficiency",
                   std::to_string(double(oracle) / std::max<uint64_t>(evaluated, 1)));

    // The trace is a test hook only: with it off the stage gives the same image and counts
    // (checked on the cheapest scene; the determinism test runs every stage untraced).
    if (std::string(c.name) != "spheres")
        return;
    lighting::StageResult untraced;
    stage->shade(inputs, untraced);
    EXPECT_TRUE(untraced.lightTrace.empty());
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(untraced, result)) << stageName << " untraced";
    EXPECT_EQ(untraced.lightsEvaluated, result.lightsEvaluated) << stageName << " untraced";
}

INSTANTIATE_TEST_SUITE_P(AllExactStages, ExactStage,
                         ::testing::Combine(::testing::ValuesIn(exactStageNames()),
                                            ::testing::Range(0, int(std::size(kScenes))),
                                            ::testing::Range(0, int(std::size(kIsas)))),
                         [](const auto& info) {
                             std::string name = std::get<0>(info.param) + "_" +
                                                kScenes[std::get<1>(info.param)].name + "_" +
                                                (std::get<2>(info.param) == 0 ? "scalar" : "auto");
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c)))
                                     c = '_';
                             return name;
                         });

// `ideal` shades exactly the contributing lights on either ISA (on the kernel: the packet's
// union list with per-light lane masks): evaluated == oracle at every pixel (the oracle counted
// by lighting/Oracle.h, a loop independent of the ideal stage's lists), bitwise brute's image on
// the same ISA, its one timed pass is the shading, and the list-building time is recorded as an
// untimed parameter.
class IdealStage : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(IdealStage, EvaluatesExactlyTheOracleAndTimesOnlyTheShading) {
    const auto& [sceneIndex, isaIndex] = GetParam();
    const SceneCase& c = kScenes[sceneIndex];
    const PreparedCase& f = prepared(c);
    lighting::StageInputs inputs = f.prepared->inputs;
    inputs.isa = kIsas[isaIndex];
    lighting::StageResult result;
    lighting::makeStage("ideal")->shade(inputs, result);
    ASSERT_EQ(result.lightsEvaluated.size(), f.oracle.size());
    uint64_t oracleTotal = 0;
    int mismatches = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        oracleTotal += f.oracle[pixel];
        if (result.lightsEvaluated[pixel] != f.oracle[pixel] && mismatches++ < 5)
            ADD_FAILURE() << c.name << ": pixel (" << pixel % kWidth << ", " << pixel / kWidth
                          << ") evaluated " << result.lightsEvaluated[pixel] << ", oracle "
                          << f.oracle[pixel];
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(oracleTotal, 0u);
    EXPECT_EQ(result.parameters.at("isa"), f.brute[isaIndex].parameters.at("isa"));
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(result, f.brute[isaIndex])) << c.name;
    ASSERT_EQ(result.timingsMs.size(), 1u);
    EXPECT_EQ(result.timingsMs[0].first, lighting::pass::kShading);
    EXPECT_EQ(result.parameters.count("untimed_list_build_ms"), 1u);
    EXPECT_EQ(result.parameters["contributing_pairs"], std::to_string(oracleTotal));
    // A packet pays each light of its lanes' union once: between the largest lane's count and
    // the sum of its lanes' counts.
    const uint64_t packetPairs = std::stoull(result.parameters.at("packet_light_pairs"));
    EXPECT_LE(packetPairs, oracleTotal);
    EXPECT_GE(packetPairs * lighting::kernel::kPacketLanes, oracleTotal);
}

INSTANTIATE_TEST_SUITE_P(Scenes, IdealStage,
                         ::testing::Combine(::testing::Range(0, kIdealSceneCount),
                                            ::testing::Range(0, int(std::size(kIsas)))),
                         [](const auto& info) {
                             return std::string(kScenes[std::get<0>(info.param)].name) + "_" +
                                    (std::get<1>(info.param) == 0 ? "scalar" : "auto");
                         });

// The cone bound must cut work: on atrium with spot lights, tiled evaluates markedly fewer lights
// than it would with the range spheres of point lights at the same places.
// The oracle's light grid (lighting/lists/LightGrid.h) is exact: its counts equal brute force's
// at every pixel, on every scene case (points, spots, directional and ambient lights, glTF, blended
// fragments).
TEST(Oracle, GridCountsEqualBruteForceOnEveryScene) {
    for (const SceneCase& c : kScenes) {
        SCOPED_TRACE(c.name);
        const PreparedCase& f = prepared(c);
        EXPECT_EQ(f.oracle, lighting::countContributingLightsBrute(f.prepared->inputs));
    }
}

// ContributingLights (the lists `ideal` shades and the identity checks use) tests only the light
// grid's candidates: the same lists, light by light and in the same order, as testing every
// light, on every scene case (point, spot, directional and ambient lights; open and closed
// scenes).
TEST(ContributingLightLists, GridListsEqualBruteForceOnEveryScene) {
    for (const SceneCase& c : kScenes) {
        SCOPED_TRACE(c.name);
        const PreparedCase& f = prepared(c);
        const lighting::StageInputs& inputs = f.prepared->inputs;
        lighting::ContributingLights grid, brute;
        grid.build(*inputs.gbuffer, inputs.lights->lights);
        brute.buildBrute(*inputs.gbuffer, inputs.lights->lights);
        ASSERT_GT(brute.pairCount(), 0u);
        ASSERT_EQ(grid.pairCount(), brute.pairCount());
        for (size_t pixel = 0; pixel < size_t(kWidth) * kHeight; ++pixel) {
            const std::span<const uint32_t> a = grid.lightsOf(pixel), b = brute.lightsOf(pixel);
            ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()))
                << "pixel " << pixel % kWidth << "," << pixel / kWidth;
        }
    }
}

// The reference stage evaluates only the light grid's candidates: its image and counts are
// bitwise those of the loop over every light, on every scene case.
TEST(ReferenceStage, GridImageIsBitwiseTheEveryLightLoop) {
    for (const SceneCase& c : kScenes) {
        SCOPED_TRACE(c.name);
        const PreparedCase& f = prepared(c);
        f.prepared->addExactSurface(); // the G-buffer stays bitwise the same
        const lighting::StageInputs& inputs = f.prepared->inputs;
        ASSERT_NE(inputs.exact, nullptr);
        lighting::StageResult withGrid, everyLight;
        lighting::makeStage("reference")->shade(inputs, withGrid);
        const gbuffer::ExactSurface& exact = *inputs.exact;
        lighting::shadeWithEveryLight(
            exact.width, exact.height, inputs.lights->lightsExact,
            [&exact](int x, int y, gbuffer::BasicSurface<double>& s) {
                return exact.surfaceAt(x, y, s);
            },
            everyLight);
        lighting::BlendedPass blended;
        if (blended.prepare(inputs))
            blended.compositeExact(inputs.gbuffer->depth(), everyLight);
        for (int channel = 0; channel < 3; ++channel)
            EXPECT_EQ(withGrid.radiance[channel], everyLight.radiance[channel]) << channel;
        EXPECT_EQ(withGrid.lightsOracle, everyLight.lightsOracle);
    }
}

// Many small lights (the count the grid exists for), at a small size so brute force stays quick.
TEST(Oracle, GridCountsEqualBruteForceWithTwentyThousandLights) {
    scenes::SceneRequest request;
    request.lightCount = 20000;
    request.seed = 5;
    lighting::PreparedScene frame(scenes::buildProceduralScene("atrium", request), 96, 54);
    const std::vector<uint32_t> grid = lighting::countContributingLights(frame.inputs);
    EXPECT_EQ(grid, lighting::countContributingLightsBrute(frame.inputs));
    uint64_t total = 0;
    for (uint32_t count : grid)
        total += count;
    EXPECT_GT(total, 0u) << "lights reach the surfaces";
}

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
