// Multisampled frames (lighting/MultisampleShading.h) through every stage that takes them: per
// fragment layer, the stage's image and its evaluated lights against brute on the same layer
// (the exactness tests' identity check and bitwise image, per layer: "per-sample exactness", since
// a layer's fragment stands for its samples, shaded once); the resolved image against brute's
// resolve (bitwise for ascending-order stages); the resolve's arithmetic; determinism across
// thread counts; and the refusal of the stages that cannot take a multisampled frame. The scenes
// with alpha-masked materials are also drawn with alpha-to-coverage (raster/AlphaToCoverage.h:
// the `_a2c` cases), where the same must hold per sample, and the layers must be the same for 1,
// 2 and 4 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/MultisampleShading.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/lists/ContributingLights.h"
#include "lighting/passes/MaterialPass.h"
#include "lighting/passes/PackedFragments.h"
#include "scenes/SceneLoader.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

namespace {

constexpr int kWidth = 192;
constexpr int kHeight = 108;

struct SceneCase {
    const char* name;
    const char* scene;
    int lights;
    bool alphaToCoverage = false;
};

const SceneCase kScenes[] = {
    {"atrium", "atrium", 300},
    {"glass", "glass", 200}, // alpha-masked fence and blended panes
    {"helmet", TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", 64},
    {"glass_a2c", "glass", 200, true},     // the fence and the ghost pane as sample masks
    {"foliage_a2c", "foliage", 200, true}, // leaf cards as sample masks
};

scenes::Scene loadCase(const SceneCase& c) {
    scenes::SceneRequest request;
    request.lightCount = c.lights;
    request.seed = 5;
    const std::string source = c.scene;
    return source.ends_with(".gltf") ? scenes::loadScene(source, request)
                                     : scenes::buildProceduralScene(c.scene, request);
}

std::unique_ptr<lighting::PreparedScene> prepareMultisampled(const SceneCase& c, int samples,
                                                             gbuffer::ComplexDetection detection) {
    lighting::Multisampling multisampling;
    multisampling.samples = samples;
    multisampling.layers.detection = detection;
    multisampling.alphaToCoverage = c.alphaToCoverage;
    return std::make_unique<lighting::PreparedScene>(
        loadCase(c), kWidth, kHeight, false,
        gbuffer::GBufferLayout::lossless(gbuffer::DepthConvention::Reversed), multisampling);
}

const lighting::PreparedScene& cachedFrame(int sceneIndex) {
    static std::unique_ptr<lighting::PreparedScene> frames[std::size(kScenes)];
    auto& frame = frames[sceneIndex];
    if (!frame)
        frame = prepareMultisampled(kScenes[sceneIndex], 4, gbuffer::ComplexDetection::Primitive);
    return *frame;
}

std::vector<std::string> multisampledExactStages() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        if (info.kind == lighting::StageKind::Exact && info.msaaRefusal.empty() && !info.msaaNative)
            names.push_back(info.name);
    // The adaptive cluster grid: upper layers hold few samples, so most tiles store no cluster.
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

float peakOf(const lighting::StageResult& image) {
    float peak = 0.0f;
    for (int ch = 0; ch < 3; ++ch)
        for (float v : image.radiance[ch])
            peak = std::max(peak, v);
    return peak;
}

::testing::AssertionResult closeImages(const lighting::StageResult& a,
                                       const lighting::StageResult& b, float relative) {
    const float peak = std::max(peakOf(b), 1e-20f);
    for (int ch = 0; ch < 3; ++ch)
        for (size_t pixel = 0; pixel < a.radiance[ch].size(); ++pixel)
            if (!(std::abs(a.radiance[ch][pixel] - b.radiance[ch][pixel]) <= relative * peak))
                return ::testing::AssertionFailure()
                       << "pixel " << pixel % a.width << "," << pixel / a.width << " channel " << ch
                       << ": " << a.radiance[ch][pixel] << " vs " << b.radiance[ch][pixel];
    return ::testing::AssertionSuccess();
}

class MultisampledStage : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(MultisampledStage, EachLayerMatchesBruteAndTheResolveMatchesBrutesResolve) {
    const auto& [stageName, sceneIndex] = GetParam();
    const lighting::PreparedScene& frame = cachedFrame(sceneIndex);
    ASSERT_TRUE(frame.multisample);
    ASSERT_GE(frame.layerCount(), 2) << "the scene must have complex pixels";
    const bool ascending = stageInfo(stageName).ascendingLightOrder;
    const auto stage = lighting::makeStage(stageName);
    const auto brute = lighting::makeStage("brute");
    for (int k = 0; k < frame.layerCount(); ++k) {
        const lighting::StageInputs inputs = frame.layerInputs(k);
        lighting::ContributingLights contributing;
        contributing.build(*inputs.gbuffer, inputs.lights->lights);
        const lighting::StageResult result = stagecheck::shadeTraced(*stage, inputs);
        lighting::StageResult bruteResult;
        brute->shade(inputs, bruteResult);
        EXPECT_TRUE(stagecheck::everyContributingLightEvaluated(result, contributing, ascending))
            << stageName << " on " << kScenes[sceneIndex].name << ", layer " << k;
        if (ascending)
            EXPECT_TRUE(stagecheck::bitwiseEqualImages(result, bruteResult))
                << stageName << ", layer " << k;
        else
            EXPECT_TRUE(closeImages(result, bruteResult, 1e-5f)) << stageName << ", layer " << k;
    }
    lighting::MultisampleShading stageShading, bruteShading;
    lighting::StageResult resolved, bruteResolved;
    stageShading.shade(*stage, frame, resolved);
    bruteShading.shade(*brute, frame, bruteResolved);
    if (ascending)
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(resolved, bruteResolved)) << stageName;
    else
        EXPECT_TRUE(closeImages(resolved, bruteResolved, 1e-5f)) << stageName;
    EXPECT_EQ(resolved.parameters.at("msaa"), "4");
}

INSTANTIATE_TEST_SUITE_P(EveryStage, MultisampledStage,
                         ::testing::Combine(::testing::ValuesIn(multisampledExactStages()),
                                            ::testing::Range(0, int(std::size(kScenes)))),
                         [](const auto& info) {
                             std::string name = std::get<0>(info.param) + "_" +
                                                kScenes[std::get<1>(info.param)].name;
                             for (char& ch : name)
                                 if (!std::isalnum(static_cast<unsigned char>(ch)))
                                     ch = '_';
                             return name;
                         });

TEST(MultisampleResolve, IsTheCoverageWeightedSumOfTheLayers) {
    const lighting::PreparedScene& frame = cachedFrame(0);
    const gbuffer::FragmentLayers& layers = frame.multisample->layers;
    const auto brute = lighting::makeStage("brute");
    std::vector<lighting::StageResult> perLayer(size_t(frame.layerCount()));
    for (int k = 0; k < frame.layerCount(); ++k)
        brute->shade(frame.layerInputs(k), perLayer[size_t(k)]);
    lighting::MultisampleShading shading;
    lighting::StageResult resolved;
    shading.shade(*brute, frame, resolved);
    size_t partial = 0, complex = 0;
    for (size_t pixel = 0; pixel < layers.pixelCount(); ++pixel) {
        float coverage = layers.backgroundWeight(pixel);
        double expected[3] = {0, 0, 0};
        for (int k = 0; k < frame.layerCount(); ++k) {
            if (layers.codes(k)[pixel] == gbuffer::VisibilityPass::kNoTriangle)
                continue;
            coverage += layers.weight(k, pixel);
            for (int ch = 0; ch < 3; ++ch)
                expected[ch] += double(layers.weight(k, pixel)) *
                                double(perLayer[size_t(k)].radiance[ch][pixel]);
        }
        if (layers.codes(0)[pixel] != gbuffer::VisibilityPass::kNoTriangle)
            ASSERT_FLOAT_EQ(coverage, 1.0f) << "samples of pixel " << pixel << " not partitioned";
        partial += layers.backgroundWeight(pixel) > 0.0f &&
                   layers.codes(0)[pixel] != gbuffer::VisibilityPass::kNoTriangle;
        complex += layers.complex(pixel);
        for (int ch = 0; ch < 3; ++ch)
            ASSERT_NEAR(resolved.radiance[ch][pixel], expected[ch], 1e-5 * (1.0 + expected[ch]))
                << "pixel " << pixel;
    }
    EXPECT_GT(complex, 100u);
    // Every light evaluation of every layer is counted.
    uint64_t sum = 0, layered = 0;
    for (size_t pixel = 0; pixel < layers.pixelCount(); ++pixel) {
        sum += resolved.lightsEvaluated[pixel];
        for (const auto& layer : perLayer)
            layered += layer.lightsEvaluated[pixel];
    }
    EXPECT_EQ(sum, layered);
    (void)partial;
    // One timed run per layer (this scene has no blended material: no background run).
    ASSERT_EQ(shading.runMs().size(), size_t(frame.layerCount()));
    for (double ms : shading.runMs())
        EXPECT_GT(ms, 0.0);
}

TEST(MultisampleResolve, SameImageForAnyThreadCount) {
    // glass (blended: every stage runs the layers one by one) and atrium (`tiled` and
    // `clustered` take the packed run, PackedFragments.h).
    const std::pair<const char*, int> cases[] = {
        {"tiled", 1},          {"clustered", 1}, {"clustered:grid=adaptive", 1}, {"deferred", 1},
        {"light-prepass", 1},  {"inferred", 1},  {"inferred:scale=1", 1},        {"tiled", 0},
        {"tiled-backface", 0}, {"clustered", 0}};
    for (const auto& testCase : cases) {
        const char* const stageName = testCase.first; // named, not bound: lambdas capture it
        const int sceneIndex = testCase.second;
        lighting::StageResult images[2];
        for (int t = 0; t < 2; ++t)
            tbb::task_arena(t + 1).execute([&] {
                auto frame = prepareMultisampled(kScenes[sceneIndex], 8,
                                                 gbuffer::ComplexDetection::Primitive);
                lighting::MultisampleShading shading;
                shading.shade(*lighting::makeStage(stageName), *frame, images[t]);
            });
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(images[0], images[1])) << stageName;
        EXPECT_EQ(images[0].lightsEvaluated, images[1].lightsEvaluated) << stageName;
        EXPECT_EQ(images[0].parameters.at("simt_lane_slots"),
                  images[1].parameters.at("simt_lane_slots"))
            << stageName;
        EXPECT_EQ(images[0].parameters.at("msaa_shading"), sceneIndex == 0 ? "packed" : "layers")
            << stageName;
    }
}

TEST(MultisampleAlphaToCoverage, SameLayersAndImageForOneTwoAndFourThreads) {
    for (int samples : {2, 4, 8}) {
        std::vector<std::vector<uint8_t>> coverage(3);
        std::vector<std::vector<uint32_t>> codes(3);
        lighting::StageResult images[3];
        for (int t = 0; t < 3; ++t)
            tbb::task_arena(1 << t).execute([&] {
                auto frame =
                    prepareMultisampled(kScenes[4], samples, gbuffer::ComplexDetection::Primitive);
                const gbuffer::FragmentLayers& layers = frame->multisample->layers;
                for (int k = 0; k < layers.layerCount(); ++k) {
                    codes[t].insert(codes[t].end(), layers.codes(k).begin(), layers.codes(k).end());
                    coverage[t].insert(coverage[t].end(), layers.coverage(k).begin(),
                                       layers.coverage(k).end());
                }
                lighting::MultisampleShading shading;
                shading.shade(*lighting::makeStage("tiled"), *frame, images[t]);
            });
        for (int t = 1; t < 3; ++t) {
            EXPECT_EQ(codes[0], codes[t]) << samples << " samples, " << (1 << t) << " threads";
            EXPECT_EQ(coverage[0], coverage[t]) << samples << " samples, " << (1 << t);
            EXPECT_TRUE(stagecheck::bitwiseEqualImages(images[0], images[t])) << samples;
        }
    }
}

TEST(MultisampleAlphaToCoverage, PartialAlphaLeavesSamplesOfMaskedFragmentsUncovered) {
    // Against the alpha-tested frame: with alpha-to-coverage, more pixels of the foliage have a
    // partial fragment (some of its samples show the leaves, the others what lies behind).
    SceneCase tested = kScenes[4];
    tested.alphaToCoverage = false;
    const auto masked = prepareMultisampled(kScenes[4], 4, gbuffer::ComplexDetection::Primitive);
    const auto alphaTested = prepareMultisampled(tested, 4, gbuffer::ComplexDetection::Primitive);
    const uint64_t maskedComplex = masked->multisample->layers.counts().complexPixels;
    const uint64_t testedComplex = alphaTested->multisample->layers.counts().complexPixels;
    EXPECT_GT(maskedComplex, testedComplex + testedComplex / 10)
        << "alpha-to-coverage splits the pixels along the leaves' alpha ramps";
}

TEST(MultisampleResolve, TwoAndEightSamplesResolveLikeBrute) {
    for (int samples : {2, 8}) {
        auto frame = prepareMultisampled(kScenes[0], samples, gbuffer::ComplexDetection::Primitive);
        lighting::MultisampleShading a, b;
        lighting::StageResult tiled, brute;
        a.shade(*lighting::makeStage("tiled-backface"), *frame, tiled);
        b.shade(*lighting::makeStage("brute"), *frame, brute);
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(tiled, brute)) << samples;
        EXPECT_EQ(tiled.parameters.at("msaa"), std::to_string(samples));
    }
}

// The stages with a material pass (light-prepass, inferred) rasterize the scene again: on a
// multisampled frame at its sample count, once, on layer 0. Its fragments must be the G-buffer's
// layers bitwise, or a stage would combine one fragment's material with another's light.
TEST(MaterialPassLayers, AreTheGBuffersLayersBitwise) {
    for (int sceneIndex = 0; sceneIndex < int(std::size(kScenes)); ++sceneIndex) {
        const lighting::PreparedScene& frame = cachedFrame(sceneIndex);
        const gbuffer::FragmentLayers& layers = frame.multisample->layers;
        lighting::MaterialPass pass;
        for (int k = 0; k < frame.layerCount(); ++k) {
            pass.draw(frame.layerInputs(k));
            const std::span<const uint32_t> codes = pass.codes();
            EXPECT_TRUE(std::equal(codes.begin(), codes.end(), layers.codes(k).begin(),
                                   layers.codes(k).end()))
                << kScenes[sceneIndex].name << ", layer " << k;
        }
        lighting::StageInputs background = frame.inputs;
        background.fragmentLayer = lighting::StageInputs::kBackgroundRun;
        pass.draw(background);
        EXPECT_TRUE(pass.codes().empty()) << "the background run has no fragment";
        lighting::MaterialPass fresh;
        EXPECT_THROW(fresh.draw(frame.layerInputs(1)), std::logic_error)
            << "a layer above 0 before this frame's layer 0";
    }
}

// A multisampled frame of `c` whose lights are all white: the light pre-pass's monochrome
// specular then loses nothing (approximate_stages_test.cpp), so the stage is brute up to rounding
// on every layer and in the resolve.
std::unique_ptr<lighting::PreparedScene> whiteLightFrame(const SceneCase& c) {
    scenes::Scene scene = loadCase(c);
    for (scenes::Light& light : scene.lights)
        light.color = glm::vec3(1.0f);
    lighting::Multisampling multisampling;
    multisampling.samples = 4;
    return std::make_unique<lighting::PreparedScene>(
        std::move(scene), kWidth, kHeight, false,
        gbuffer::GBufferLayout::lossless(gbuffer::DepthConvention::Reversed), multisampling);
}

using stagecheck::relativeRmse;

TEST(MaterialPassStages, LightPrepassWithWhiteLightsResolvesLikeBrute) {
    for (const SceneCase& c : kScenes) {
        const auto frame = whiteLightFrame(c);
        ASSERT_GE(frame->layerCount(), 2) << c.name;
        const auto stage = lighting::makeStage("light-prepass");
        const auto brute = lighting::makeStage("brute");
        for (int k = 0; k < frame->layerCount(); ++k) {
            lighting::StageResult layer, bruteLayer;
            stage->shade(frame->layerInputs(k), layer);
            brute->shade(frame->layerInputs(k), bruteLayer);
            EXPECT_TRUE(closeImages(layer, bruteLayer, 1e-4f)) << c.name << ", layer " << k;
        }
        lighting::MultisampleShading stageShading, bruteShading;
        lighting::StageResult resolved, bruteResolved;
        stageShading.shade(*stage, *frame, resolved);
        bruteShading.shade(*brute, *frame, bruteResolved);
        EXPECT_TRUE(closeImages(resolved, bruteResolved, 1e-4f)) << c.name;
        EXPECT_EQ(resolved.parameters.at("msaa"), "4");
        EXPECT_EQ(resolved.parameters.at("msaa_shading"), "layers");
    }
}

// Inferred lights each edge pixel's far fragments through the DSF from the frame's one L-buffer
// (Kircher & Lawrance): its 4x image must be closer to brute's 4x resolve than its 1x image is
// (MSAA adds the edges' anti-aliasing), and its upper layers evaluate no light.
TEST(MaterialPassStages, InferredAntiAliasesEdgesFromOneLBuffer) {
    for (int sceneIndex = 0; sceneIndex < int(std::size(kScenes)); ++sceneIndex) {
        const lighting::PreparedScene& frame = cachedFrame(sceneIndex);
        lighting::MultisampleShading bruteShading;
        lighting::StageResult bruteResolved;
        bruteShading.shade(*lighting::makeStage("brute"), frame, bruteResolved);
        for (const char* spec : {"inferred:scale=1", "inferred"}) {
            const auto stage = lighting::makeStage(spec);
            lighting::StageResult oneSample; // layer 0 alone, as a 1x frame would shade it
            stage->shade(frame.inputs, oneSample);
            for (int k = 1; k < frame.layerCount(); ++k) {
                lighting::StageResult upper;
                stage->shade(frame.layerInputs(k), upper);
                uint64_t evaluated = 0;
                for (uint32_t n : upper.lightsEvaluated)
                    evaluated += n;
                EXPECT_EQ(evaluated, 0u) << spec << ", layer " << k;
            }
            // 1x: the whole pixel shows its main fragment (as a 1-sample frame shows one surface).
            const lighting::StageResult& unresolved = oneSample;
            lighting::MultisampleShading shading;
            lighting::StageResult resolved;
            shading.shade(*stage, frame, resolved);
            const double msaaError = relativeRmse(resolved, bruteResolved);
            const double oneSampleError = relativeRmse(unresolved, bruteResolved);
            std::cout << "[measured] " << spec << " on " << kScenes[sceneIndex].name
                      << ": relative RMSE vs brute's 4x resolve, 4x " << msaaError << ", 1x "
                      << oneSampleError << "\n";
            // Measured: scale=1 0.063 / 0.110 (atrium), 0.048 / 0.054 (glass), 0.18 / 0.30
            // (helmet); scale=2 0.12 / 0.16, 0.081 / 0.083, 0.39 / 0.53. Glass gains least: its
            // panes are stippled against layer 0 (InferredStage.cpp).
            EXPECT_LT(msaaError, oneSampleError) << spec << " on " << kScenes[sceneIndex].name;
        }
    }
}

uint64_t recordedCounter(const lighting::StageResult& result, const std::string& key) {
    const auto value = result.parameters.find(key);
    return value == result.parameters.end() ? 0 : std::stoull(value->second);
}

uint64_t sumOf(const std::vector<uint32_t>& counts) {
    uint64_t sum = 0;
    for (uint32_t count : counts)
        sum += count;
    return sum;
}

// The SIMT cost model over a multisampled frame counts every run's kernel work: the layers above
// the first and the blended surfaces' background run pay lane slots as layer 0 does. On glass
// (blended panes: a background run) each kernel counter of the resolved frame is the sum of the
// counters of the stage shading each layer and the background on its own, and a stage whose every
// evaluation is a lane of a warp (brute, tiled, clustered) pays at least one lane slot per light
// evaluation, so simt_efficiency cannot exceed culling_efficiency. Before the counters were summed
// the frame reported layer 0's lane slots alone: 4.9 M slots for 16.0 M evaluations (tiled,
// glass at 320x180, --msaa 4).
TEST(MultisampleKernelWork, LaneSlotsAreEveryRunsAndCoverEveryEvaluation) {
    const lighting::PreparedScene& frame = cachedFrame(1); // glass
    ASSERT_GE(frame.layerCount(), 2);
    for (const std::string stageName : {"brute", "tiled", "clustered"}) {
        const auto stage = lighting::makeStage(stageName);
        lighting::MultisampleShading shading;
        lighting::StageResult resolved;
        shading.shade(*stage, frame, resolved);
        ASSERT_EQ(resolved.parameters.at("msaa_background_run"), "1") << stageName;
        std::vector<lighting::StageResult> runs(size_t(frame.layerCount() + 1));
        for (int k = 0; k < frame.layerCount(); ++k)
            stage->shade(frame.layerInputs(k), runs[size_t(k)]);
        lighting::StageInputs background = frame.inputs;
        const gbuffer::GBuffer empty(frame.gbuffer->layout(), frame.view);
        background.gbuffer = &empty;
        background.fragmentLayer = lighting::StageInputs::kBackgroundRun;
        stage->shade(background, runs.back());
        for (const char* key : {"simt_lane_slots", "packet_groups", "packet_lights_shaded"}) {
            uint64_t sum = 0;
            for (const lighting::StageResult& run : runs)
                sum += recordedCounter(run, key);
            EXPECT_GT(recordedCounter(runs[1], key), 0u) << stageName << " " << key;
            EXPECT_EQ(recordedCounter(resolved, key), sum) << stageName << " " << key;
        }
        const uint64_t evaluated = sumOf(resolved.lightsEvaluated);
        EXPECT_GE(recordedCounter(resolved, "simt_lane_slots"), evaluated)
            << stageName << ": fewer lane slots than light evaluations";
    }
}

TEST(MultisampleStages, EveryStageSaysWhetherItTakesMultisampledFrames) {
    // The forward stages multisample natively (tests/lighting/forward_msaa_test.cpp); the other
    // stages that rasterize the scene themselves and the reference refuse, with a reason; the
    // G-buffer stages take them through the layers. StageInfo and the stage object agree.
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        const bool native = info.name.starts_with("forward") || info.name == "tiled-forward";
        const bool refused = info.name == "reference";
        EXPECT_EQ(!info.msaaRefusal.empty(), refused) << info.name;
        EXPECT_EQ(info.msaaNative, native) << info.name;
        EXPECT_EQ(lighting::makeStage(info.name)->multisamplesNatively(), native) << info.name;
    }
}

// The packed run (lighting/passes/PackedFragments.h): every fragment above layer 0 once, in row
// order for the resolve and in screen-block order for the packets.
TEST(PackedFragments, ListEveryUpperFragmentOnceInRowOrderAndShadeByBlocks) {
    const lighting::PreparedScene& frame = cachedFrame(0);
    const gbuffer::FragmentLayers& layers = frame.multisample->layers;
    lighting::PackedFragments fragments;
    fragments.build(layers);
    ASSERT_EQ(fragments.size(), layers.counts().fragments - layers.counts().coveredPixels);
    ASSERT_GT(fragments.size(), 100u);
    size_t expected = 0;
    for (int y = 0; y < layers.height(); ++y) {
        ASSERT_EQ(fragments.rowFirst(y), expected) << "row " << y;
        for (int x = 0; x < layers.width(); ++x) {
            const size_t pixel = size_t(y) * size_t(layers.width()) + size_t(x);
            for (int k = 1; k < layers.layerCount(); ++k) {
                if (layers.codes(k)[pixel] == gbuffer::VisibilityPass::kNoTriangle)
                    continue;
                ASSERT_EQ(fragments.pixel(expected), pixel);
                ASSERT_EQ(fragments.layer(expected), k);
                ++expected;
            }
        }
    }
    ASSERT_EQ(expected, fragments.size());
    // The shading order: a permutation, block by block (block rows, then block columns), list
    // order inside a block.
    const int block = lighting::PackedFragments::kBlockPixels;
    auto blockOf = [&](uint32_t i) {
        const uint32_t pixel = fragments.pixel(i);
        const int x = int(pixel % uint32_t(layers.width())),
                  y = int(pixel / uint32_t(layers.width()));
        return std::pair(y / block, x / block);
    };
    std::vector<bool> seen(fragments.size(), false);
    for (size_t j = 0; j < fragments.size(); ++j) {
        const uint32_t i = fragments.inShadingOrder(j);
        ASSERT_LT(i, fragments.size());
        ASSERT_FALSE(seen[i]) << "fragment " << i << " twice";
        seen[i] = true;
        if (j > 0) {
            const uint32_t previous = fragments.inShadingOrder(j - 1);
            ASSERT_TRUE(blockOf(previous) < blockOf(i) ||
                        (blockOf(previous) == blockOf(i) && previous < i))
                << "shading order at " << j;
        }
    }
}

// A frame of scene kScenes[sceneIndex] at 4x (primitive detection) in layout preset `layout`, or
// the lossless layout for "lossless" (cachedFrame): the packed run gathers its lanes from the
// vector decoder's 4x4 blocks where the layout fits the decoder, else with GBuffer::decode.
const lighting::PreparedScene& cachedLayoutFrame(int sceneIndex, const std::string& layout) {
    if (layout == "lossless")
        return cachedFrame(sceneIndex);
    static std::map<std::pair<int, std::string>, std::unique_ptr<lighting::PreparedScene>> frames;
    auto& frame = frames[{sceneIndex, layout}];
    if (!frame) {
        scenes::Scene scene = loadCase(kScenes[sceneIndex]);
        const gbuffer::GBufferLayout chosen = gbuffer::presetLayout(layout, scene);
        lighting::Multisampling multisampling;
        multisampling.samples = 4;
        frame = std::make_unique<lighting::PreparedScene>(std::move(scene), kWidth, kHeight, false,
                                                          chosen, multisampling);
    }
    return *frame;
}

class PackedFragmentStage
    : public ::testing::TestWithParam<std::tuple<std::string, int, std::string>> {};

// Each packed fragment is shaded as its own layer's run shades its pixel: brute's radiance there,
// bitwise (ascending lists), every contributing light evaluated (the trace), its evaluations the
// trace's length. The stages' lists differ from their per-layer runs' (tiles bounded over every
// layer, layer 0's cluster grid), never the image.
TEST_P(PackedFragmentStage, EveryFragmentIsBruteOnItsLayerWithEveryContributingLight) {
    const auto& [stageName, sceneIndex, layout] = GetParam();
    const lighting::PreparedScene& frame = cachedLayoutFrame(sceneIndex, layout);
    const gbuffer::FragmentLayers& layers = frame.multisample->layers;
    ASSERT_GE(frame.layerCount(), 2);
    const auto stage = lighting::makeStage(stageName);
    auto* packed = dynamic_cast<lighting::PackedFragmentShading*>(stage.get());
    ASSERT_NE(packed, nullptr) << stageName;
    lighting::StageResult main;
    stage->shade(frame.inputs, main); // layer 0 first, as in a frame
    lighting::PackedFragments fragments;
    fragments.build(layers);
    lighting::PackedFragmentRun run;
    run.frame = &frame.inputs;
    run.fragments = &fragments;
    for (int k = 0; k < frame.layerCount(); ++k)
        run.layerGBuffers.push_back(frame.layerInputs(k).gbuffer);
    lighting::StageResult result;
    result.traceLights = true;
    ASSERT_TRUE(packed->shadeFragments(run, result)) << stageName;
    ASSERT_EQ(result.width, int(fragments.size()));
    ASSERT_EQ(result.timingsMs.size(), 2u);
    EXPECT_EQ(result.timingsMs[1].first, "shading");

    const auto brute = lighting::makeStage("brute");
    std::vector<lighting::StageResult> bruteLayers(size_t(frame.layerCount()));
    std::vector<lighting::ContributingLights> contributing(size_t(frame.layerCount()));
    for (int k = 1; k < frame.layerCount(); ++k) {
        const lighting::StageInputs inputs = frame.layerInputs(k);
        brute->shade(inputs, bruteLayers[size_t(k)]);
        contributing[size_t(k)].build(*inputs.gbuffer, inputs.lights->lights);
    }
    size_t lit = 0;
    for (size_t i = 0; i < fragments.size(); ++i) {
        const size_t k = size_t(fragments.layer(i));
        const size_t pixel = fragments.pixel(i);
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(std::bit_cast<uint32_t>(result.radiance[c][i]),
                      std::bit_cast<uint32_t>(bruteLayers[k].radiance[c][pixel]))
                << stageName << ": fragment " << i << " (layer " << k << ", pixel " << pixel
                << ") channel " << c << ": " << result.radiance[c][i] << " vs brute "
                << bruteLayers[k].radiance[c][pixel];
        const std::vector<uint32_t>& trace = result.lightTrace[i];
        const std::span<const uint32_t> needed = contributing[k].lightsOf(pixel);
        ASSERT_TRUE(std::includes(trace.begin(), trace.end(), needed.begin(), needed.end()))
            << stageName << ": fragment " << i << " misses a contributing light";
        ASSERT_EQ(result.lightsEvaluated[i], trace.size());
        lit += needed.empty() ? 0 : 1;
    }
    EXPECT_GT(lit, fragments.size() / 4) << "too few lit fragments to mean anything";

    // Through MultisampleShading the frame takes the packed run (one run after layer 0).
    lighting::MultisampleShading shading;
    lighting::StageResult resolved;
    shading.shade(*stage, frame, resolved);
    EXPECT_EQ(resolved.parameters.at("msaa_shading"), "packed");
    EXPECT_EQ(shading.runMs().size(), 2u);
}

std::string
packedCaseName(const ::testing::TestParamInfo<std::tuple<std::string, int, std::string>>& info) {
    std::string name = std::get<0>(info.param) + "_" + kScenes[std::get<1>(info.param)].name + "_" +
                       std::get<2>(info.param);
    for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch)))
            ch = '_';
    return name;
}

INSTANTIATE_TEST_SUITE_P(TiledAndClustered, PackedFragmentStage,
                         ::testing::Combine(::testing::Values("tiled", "tiled-backface",
                                                              "tiled:mask=1", "tiled:hier=1",
                                                              "clustered", "clustered:assign=bvh"),
                                            ::testing::Values(0, 2), // atrium, helmet
                                            ::testing::Values("lossless")),
                         packedCaseName);
// Layouts the vector decoder does not read (normal codes, the visibility buffer): lanes decoded
// one by one.
INSTANTIATE_TEST_SUITE_P(OtherLayouts, PackedFragmentStage,
                         ::testing::Combine(::testing::Values("tiled", "clustered"),
                                            ::testing::Values(0, 2),
                                            ::testing::Values("compact", "visibility")),
                         packedCaseName);

// Where the packed run does not apply, the layers are run one by one: blended surfaces (each
// layer's run composites them over its own samples) and the adaptive cluster grid.
TEST(PackedFragments, BlendedScenesAndTheAdaptiveGridRunTheLayers) {
    for (const auto& [stageName, sceneIndex] : {std::pair<std::string, int>{"tiled", 1},
                                                {"clustered", 1},
                                                {"clustered:grid=adaptive", 0}}) {
        const lighting::PreparedScene& frame = cachedFrame(sceneIndex);
        const auto stage = lighting::makeStage(stageName);
        lighting::MultisampleShading shading;
        lighting::StageResult resolved;
        shading.shade(*stage, frame, resolved);
        EXPECT_EQ(resolved.parameters.at("msaa_shading"), "layers") << stageName;
    }
}

// `tiled`'s packed run keeps a tile's layer-0 list only for fragments inside layer 0's depth
// bounds for the tile. The frame's other fragments that lie outside them (behind a foreground
// surface that holds every main fragment of the tile) each get a light of their own, too small
// to reach the tile's main surfaces: every one must be evaluated where it contributes, so a list
// kept regardless of the bounds fails here.
TEST(PackedFragments, TiledCullsTheTilesWhoseFragmentsLeaveLayerZerosBounds) {
    for (const int sceneIndex : {0, 2}) { // atrium, helmet
        const lighting::PreparedScene& frame = cachedFrame(sceneIndex);
        const gbuffer::FragmentLayers& layers = frame.multisample->layers;
        lighting::PackedFragments fragments;
        fragments.build(layers);
        const lighting::TileGrid grid = lighting::TileGrid::make(kWidth, kHeight, 16);
        const std::vector<lighting::TileSurfaceBounds> frameBounds =
            lighting::computeTileSurfaceBounds(*frame.gbuffer, grid, {});
        lighting::LightList lights = frame.lights;
        size_t outside = 0;
        for (size_t i = 0; i < fragments.size(); ++i) {
            const uint32_t pixel = fragments.pixel(i);
            const int x = int(pixel % uint32_t(kWidth)), y = int(pixel / uint32_t(kWidth));
            const gbuffer::Surface s = frame.layerInputs(fragments.layer(i)).gbuffer->decode(x, y);
            const float depth = -s.positionView.z;
            const lighting::TileSurfaceBounds& b =
                frameBounds[size_t((y / 16) * grid.tileCountX + x / 16)];
            if (depth >= b.minDepthMetres && depth <= b.maxDepthMetres)
                continue;
            ++outside;
            // A light just off the surface, along its normal, reaching a few centimetres.
            lighting::LightInView<float> light;
            light.type = scenes::LightType::Point;
            light.positionView = s.positionView + 0.01f * s.normalView;
            light.radiance = glm::vec3(1.0f);
            light.rangeMetres = 0.03f;
            lights.lights.push_back(light);
            if (outside == 64)
                break;
        }
        ASSERT_GT(outside, 0u) << kScenes[sceneIndex].name
                               << ": no fragment outside its tile's layer-0 bounds to test";
        lighting::StageInputs frameInputs = frame.inputs;
        frameInputs.lights = &lights;
        const auto stage = lighting::makeStage("tiled");
        lighting::StageResult main;
        stage->shade(frameInputs, main);
        lighting::PackedFragmentRun run;
        run.frame = &frameInputs;
        run.fragments = &fragments;
        for (int k = 0; k < frame.layerCount(); ++k)
            run.layerGBuffers.push_back(frame.layerInputs(k).gbuffer);
        lighting::StageResult result;
        result.traceLights = true;
        ASSERT_TRUE(
            dynamic_cast<lighting::PackedFragmentShading&>(*stage).shadeFragments(run, result));
        std::vector<lighting::ContributingLights> contributing(size_t(frame.layerCount()));
        for (int k = 1; k < frame.layerCount(); ++k)
            contributing[size_t(k)].build(*frame.layerInputs(k).gbuffer, lights.lights);
        size_t reachedByOwnLight = 0;
        for (size_t i = 0; i < fragments.size(); ++i) {
            const std::span<const uint32_t> needed =
                contributing[size_t(fragments.layer(i))].lightsOf(fragments.pixel(i));
            const std::vector<uint32_t>& trace = result.lightTrace[i];
            ASSERT_TRUE(std::includes(trace.begin(), trace.end(), needed.begin(), needed.end()))
                << kScenes[sceneIndex].name << ": fragment " << i << " misses a light";
            reachedByOwnLight += !needed.empty() && needed.back() >= frame.lights.size();
        }
        EXPECT_GT(reachedByOwnLight, 0u) << kScenes[sceneIndex].name;
    }
}

} // namespace
