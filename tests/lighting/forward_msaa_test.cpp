// Hardware-style MSAA of the forward stages (`forward` with and without pre-pass,
// `forward-multipass`, `tiled-forward`; lighting/passes/ForwardGeometry.h): they rasterize at the
// frame's sample count, shade each fragment once and resolve their per-sample colour, and are
// shaded once on the full frame by MultisampleShading (no layers). Checked on atrium, glass
// (alpha-masked fence, blended panes) and DamagedHelmet at 4 samples with primitive detection:
// - the resolved image equals brute's layered resolve within float rounding (1e-5 of the peak:
//   a sample's value is bitwise brute's layer value, the resolve sums in another order);
// - at every pixel, every light that contributes to a fragment of some layer is among the lights
//   the stage traced there (the union of its visible fragments' lists), and lightsEvaluated
//   counts at least the layers' contributing lights;
// - forward:prepass=1 shades exactly the layers' fragments (msaa_shaded_fragments);
// - 1 and 2 threads give bitwise the same image and counts.
// The `_a2c` cases draw the alpha-masked materials with alpha-to-coverage (glass's fence and ghost
// pane, foliage's leaf cards; raster/AlphaToCoverage.h) in the G-buffer pass and in the forward
// stages' own draws, where all of the above must hold too; and a forward draw without pre-pass
// leaves at every sample bitwise the code the G-buffer pass's draw left there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <tbb/task_arena.h>

#include "lighting/MultisampleShading.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/lists/ContributingLights.h"
#include "lighting/passes/ForwardGeometry.h"
#include "scenes/SceneLoader.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

namespace {

constexpr int kWidth = 192;
constexpr int kHeight = 108;
constexpr int kSamples = 4;

struct SceneCase {
    const char* name;
    const char* scene;
    int lights;
    bool alphaToCoverage = false;
};

const SceneCase kScenes[] = {
    {"atrium", "atrium", 300},
    {"glass", "glass", 200},
    {"helmet", TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", 64},
    {"glass_a2c", "glass", 200, true},
    {"foliage_a2c", "foliage", 200, true},
};

const std::vector<std::string> kForwardStages = {"forward", "forward:prepass=1",
                                                 "forward-multipass", "tiled-forward"};

scenes::Scene loadCase(const SceneCase& c) {
    scenes::SceneRequest request;
    request.lightCount = c.lights;
    request.seed = 5;
    const std::string source = c.scene;
    return source.ends_with(".gltf") ? scenes::loadScene(source, request)
                                     : scenes::buildProceduralScene(c.scene, request);
}

std::unique_ptr<lighting::PreparedScene> prepareMultisampled(const SceneCase& c, int samples) {
    lighting::Multisampling multisampling;
    multisampling.samples = samples;
    multisampling.alphaToCoverage = c.alphaToCoverage;
    multisampling.layers.detection = gbuffer::ComplexDetection::Primitive;
    return std::make_unique<lighting::PreparedScene>(
        loadCase(c), kWidth, kHeight, false,
        gbuffer::GBufferLayout::lossless(gbuffer::DepthConvention::Reversed), multisampling);
}

const lighting::PreparedScene& cachedFrame(int sceneIndex) {
    static std::unique_ptr<lighting::PreparedScene> frames[std::size(kScenes)];
    auto& frame = frames[sceneIndex];
    if (!frame)
        frame = prepareMultisampled(kScenes[sceneIndex], kSamples);
    return *frame;
}

// Brute's layered resolve of each scene, shaded once.
const lighting::StageResult& bruteResolve(int sceneIndex) {
    static std::unique_ptr<lighting::StageResult> results[std::size(kScenes)];
    auto& result = results[sceneIndex];
    if (!result) {
        result = std::make_unique<lighting::StageResult>();
        lighting::MultisampleShading shading;
        shading.shade(*lighting::makeStage("brute"), cachedFrame(sceneIndex), *result);
    }
    return *result;
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
    size_t bad = 0;
    std::string first;
    for (int ch = 0; ch < 3; ++ch)
        for (size_t pixel = 0; pixel < a.radiance[ch].size(); ++pixel)
            if (!(std::abs(a.radiance[ch][pixel] - b.radiance[ch][pixel]) <= relative * peak) &&
                bad++ == 0)
                first = "pixel " + std::to_string(pixel % size_t(a.width)) + "," +
                        std::to_string(pixel / size_t(a.width)) + " channel " + std::to_string(ch) +
                        ": " + std::to_string(a.radiance[ch][pixel]) + " vs " +
                        std::to_string(b.radiance[ch][pixel]);
    if (bad == 0)
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << bad << " values differ (peak " << peak << "), first " << first;
}

class ForwardMsaa : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(ForwardMsaa, ResolvesLikeBrutesLayersAndEvaluatesEveryContributingLight) {
    const auto& [spec, sceneIndex] = GetParam();
    const lighting::PreparedScene& frame = cachedFrame(sceneIndex);
    ASSERT_TRUE(frame.multisample);
    ASSERT_EQ(frame.inputs.samples, kSamples);
    ASSERT_GE(frame.layerCount(), 2) << "the scene must have complex pixels";
    const auto stage = lighting::makeStage(spec);
    ASSERT_TRUE(stage->multisamplesNatively());

    lighting::MultisampleShading shading;
    lighting::StageResult resolved;
    resolved.traceLights = true;
    shading.shade(*stage, frame, resolved);
    const lighting::StageResult& brute = bruteResolve(sceneIndex);
    EXPECT_TRUE(closeImages(resolved, brute, 1e-5f)) << spec << " on " << kScenes[sceneIndex].name;
    EXPECT_GT(peakOf(resolved), 0.0f);
    EXPECT_EQ(resolved.parameters.at("msaa"), std::to_string(kSamples));
    EXPECT_EQ(resolved.parameters.at("msaa_shading"), "native");
    EXPECT_EQ(brute.parameters.at("msaa_shading"), "layers");

    // Per pixel: the contributing lights of every layer's (opaque) fragment.
    std::vector<std::vector<uint32_t>> needed(size_t(kWidth) * kHeight);
    std::vector<uint32_t> neededCount(needed.size(), 0);
    const gbuffer::FragmentLayers& layers = frame.multisample->layers;
    for (int k = 0; k < frame.layerCount(); ++k) {
        const lighting::StageInputs inputs = frame.layerInputs(k);
        lighting::ContributingLights contributing;
        contributing.build(*inputs.gbuffer, inputs.lights->lights);
        for (size_t pixel = 0; pixel < needed.size(); ++pixel) {
            if (layers.codes(k)[pixel] == gbuffer::VisibilityPass::kNoTriangle)
                continue;
            const auto lights = contributing.lightsOf(pixel);
            neededCount[pixel] += uint32_t(lights.size());
            std::vector<uint32_t> merged;
            std::set_union(needed[pixel].begin(), needed[pixel].end(), lights.begin(), lights.end(),
                           std::back_inserter(merged));
            needed[pixel] = std::move(merged);
        }
    }
    ASSERT_EQ(resolved.lightTrace.size(), needed.size());
    size_t badPixels = 0, tracedPixels = 0, coveredPixels = 0;
    for (size_t pixel = 0; pixel < needed.size(); ++pixel) {
        const std::vector<uint32_t>& trace = resolved.lightTrace[pixel];
        tracedPixels += !trace.empty();
        coveredPixels += layers.codes(0)[pixel] != gbuffer::VisibilityPass::kNoTriangle;
        const bool ascending = std::adjacent_find(trace.begin(), trace.end(), [](auto a, auto b) {
                                   return a >= b;
                               }) == trace.end();
        const bool includes =
            std::includes(trace.begin(), trace.end(), needed[pixel].begin(), needed[pixel].end());
        const bool counted = resolved.lightsEvaluated[pixel] >= neededCount[pixel] &&
                             resolved.lightsEvaluated[pixel] >= trace.size();
        if (!(ascending && includes && counted) && badPixels++ < 5)
            ADD_FAILURE() << spec << " on " << kScenes[sceneIndex].name << ", pixel "
                          << pixel % kWidth << "," << pixel / kWidth << ": traced " << trace.size()
                          << " lights (needs " << needed[pixel].size() << "), evaluated "
                          << resolved.lightsEvaluated[pixel] << " (layers " << neededCount[pixel]
                          << ")";
    }
    EXPECT_EQ(badPixels, 0u);
    EXPECT_GT(tracedPixels, coveredPixels / 2) << "the trace is filled where lights reach";

    if (spec == "forward:prepass=1")
        EXPECT_EQ(resolved.parameters.at("shaded_fragments"),
                  brute.parameters.at("msaa_shaded_fragments"))
            << "the pre-pass shades each visible (pixel, triangle) once: the layers' fragments";
}

INSTANTIATE_TEST_SUITE_P(ForwardStages, ForwardMsaa,
                         ::testing::Combine(::testing::ValuesIn(kForwardStages),
                                            ::testing::Range(0, int(std::size(kScenes)))),
                         [](const auto& info) {
                             std::string name = std::get<0>(info.param) + "_" +
                                                kScenes[std::get<1>(info.param)].name;
                             for (char& ch : name)
                                 if (!std::isalnum(static_cast<unsigned char>(ch)))
                                     ch = '_';
                             return name;
                         });

TEST(ForwardMsaaThreads, SameImageAndCountsForOneAndTwoThreads) {
    for (const std::string& spec : kForwardStages)
        for (int sceneIndex : {1, 2, 4}) {
            lighting::StageResult images[2];
            for (int t = 0; t < 2; ++t)
                tbb::task_arena(t + 1).execute([&] {
                    auto frame = prepareMultisampled(kScenes[sceneIndex], kSamples);
                    lighting::MultisampleShading shading;
                    shading.shade(*lighting::makeStage(spec), *frame, images[t]);
                });
            EXPECT_TRUE(stagecheck::bitwiseEqualImages(images[0], images[1])) << spec;
            EXPECT_EQ(images[0].lightsEvaluated, images[1].lightsEvaluated) << spec;
            EXPECT_EQ(images[0].parameters, images[1].parameters) << spec;
        }
}

// The sample codes of a forward draw without pre-pass (the visibility draw's state, every
// fragment applied to the samples it keeps, later ones replacing earlier ones) against the
// G-buffer pass's (from its fragment layers: with primitive detection each layer's coverage is
// exactly the samples that show its code).
std::vector<uint32_t> forwardSampleCodes(const lighting::PreparedScene& frame) {
    lighting::ForwardGeometry forward;
    forward.prepare(frame.inputs);
    forward.clearDepth();
    const int samples = forward.samples();
    std::vector<uint32_t> codes(size_t(kWidth) * kHeight * size_t(samples),
                                gbuffer::VisibilityPass::kNoTriangle);
    const gbuffer::VisibilityPass& visibility = forward.visibility();
    forward.draw(visibility.triangles(), visibility.drawState(), [&](const raster::Fragment& f) {
        for (int s = 0; s < samples; ++s)
            if (f.coverage >> s & 1u)
                codes[(size_t(f.y) * kWidth + size_t(f.x)) * size_t(samples) + size_t(s)] =
                    gbuffer::VisibilityPass::code(f.triangle, f.frontFacing);
    });
    return codes;
}

std::vector<uint32_t> layerSampleCodes(const lighting::PreparedScene& frame) {
    const gbuffer::FragmentLayers& layers = frame.multisample->layers;
    const int samples = layers.samples();
    std::vector<uint32_t> codes(layers.pixelCount() * size_t(samples),
                                gbuffer::VisibilityPass::kNoTriangle);
    for (int k = 0; k < layers.layerCount(); ++k)
        for (size_t pixel = 0; pixel < layers.pixelCount(); ++pixel)
            for (int s = 0; s < samples; ++s)
                if (layers.coverage(k)[pixel] >> s & 1u)
                    codes[pixel * size_t(samples) + size_t(s)] = layers.codes(k)[pixel];
    return codes;
}

TEST(ForwardMsaaAlphaToCoverage, NativeDrawKeepsTheGBufferDrawsSamples) {
    for (int sceneIndex : {3, 4})
        for (int samples : {2, 4, 8}) {
            const auto frame = prepareMultisampled(kScenes[sceneIndex], samples);
            const std::vector<uint32_t> forward = forwardSampleCodes(*frame);
            ASSERT_EQ(forward, layerSampleCodes(*frame))
                << kScenes[sceneIndex].name << ", " << samples << " samples";
            // And alpha-to-coverage did change the samples against the alpha test.
            SceneCase tested = kScenes[sceneIndex];
            tested.alphaToCoverage = false;
            const auto testedFrame = prepareMultisampled(tested, samples);
            const std::vector<uint32_t> testedCodes = forwardSampleCodes(*testedFrame);
            EXPECT_EQ(testedCodes, layerSampleCodes(*testedFrame));
            size_t differ = 0;
            for (size_t i = 0; i < forward.size(); ++i)
                differ += forward[i] != testedCodes[i];
            EXPECT_GT(differ, forward.size() / 200) << kScenes[sceneIndex].name << ", " << samples;
        }
}

TEST(ForwardMsaaSamples, TwoAndEightSamplesResolveLikeBrute) {
    for (int samples : {2, 8}) {
        auto frame = prepareMultisampled(kScenes[1], samples);
        lighting::MultisampleShading a, b;
        lighting::StageResult forward, brute;
        a.shade(*lighting::makeStage("forward:prepass=1"), *frame, forward);
        b.shade(*lighting::makeStage("brute"), *frame, brute);
        EXPECT_TRUE(closeImages(forward, brute, 1e-5f)) << samples;
        EXPECT_EQ(forward.parameters.at("shaded_fragments"),
                  brute.parameters.at("msaa_shaded_fragments"))
            << samples;
    }
}

} // namespace
