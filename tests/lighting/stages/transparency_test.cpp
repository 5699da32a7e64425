// Transparency (glTF alphaMode) across every stage, on the built-in `glass` scene (a MASK fence
// with cut-out stripes, a MASK pane whose alpha is below its cutoff, three overlapping BLEND
// panes, one cutting through another): see lighting/README.md, "Transparency".
// - MASK: a cut-out surface is seen through identically by every stage: each stage's image of
//   `glass` equals, bitwise, its image of `glass` without the invisible pane's instance; the
//   fence keeps about half of its area (its stripes), and no pixel shows the invisible pane.
// - BLEND: every stage renders the blended panes (its image differs from the opaque-only
//   image), the stages' error against the reference is within a stated bound, and the
//   reference's per-pixel exact sort makes brute agree with it to float precision when no pane
//   intersects another (only the sorting order, per triangle against per pixel, separates
//   them); the blend pass is reported as its own pass.
// Exactness against brute (bitwise, evaluated >= oracle, the identity check) on `glass` is in
// stage_exactness_test.cpp with the other scenes; 1 vs 7 threads here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "gbuffer/visibility/AlphaCoverage.h"
#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/passes/PassNames.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

namespace {

constexpr int kWidth = 256;
constexpr int kHeight = 144;
constexpr int kLightCount = 120;

scenes::Scene glass() {
    scenes::SceneRequest request;
    request.lightCount = kLightCount;
    request.seed = 7;
    return scenes::buildProceduralScene("glass", request);
}

uint32_t materialNamed(const scenes::Scene& scene, const std::string& name) {
    for (uint32_t m = 0; m < scene.materials.size(); ++m)
        if (scene.materials[m].name == name)
            return m;
    throw std::runtime_error("no material " + name);
}

// The scene without the instances whose mesh has material `name`.
scenes::Scene without(scenes::Scene scene, const std::string& name) {
    const uint32_t material = materialNamed(scene, name);
    std::erase_if(scene.instances, [&](const scenes::Instance& instance) {
        return scene.meshes[instance.mesh].material == material;
    });
    return scene;
}

// Every blended material made opaque: the image of the panes as opaque surfaces.
scenes::Scene opaque(scenes::Scene scene) {
    for (scenes::Material& material : scene.materials)
        if (material.alphaMode == scenes::AlphaMode::Blend)
            material.alphaMode = scenes::AlphaMode::Opaque;
    return scene;
}

std::vector<std::string> allStageNames() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        names.push_back(info.name);
    return names;
}

lighting::StageResult render(const lighting::PreparedScene& frame, const std::string& stage) {
    lighting::StageResult result;
    lighting::makeStage(stage)->shade(frame.inputs, result);
    return result;
}

using stagecheck::relativeRmse;

const lighting::PreparedScene& glassFrame() {
    static const auto frame =
        std::make_unique<lighting::PreparedScene>(glass(), kWidth, kHeight, true);
    return *frame;
}

const lighting::StageResult& glassReference() {
    static const lighting::StageResult reference = render(glassFrame(), "reference");
    return reference;
}

// ---------------------------------------------------------------------------------------------
// MASK

TEST(AlphaMask, CutOutSurfacesAreNotInTheVisibilityBuffer) {
    const lighting::PreparedScene& frame = glassFrame();
    const scenes::Scene& scene = frame.scene;
    const uint32_t ghost = materialNamed(scene, "ghost");
    const uint32_t fence = materialNamed(scene, "fence");
    size_t fencePixels = 0, fenceArea = 0;
    // The fence's projected area without the alpha test: the same scene with the fence opaque.
    scenes::Scene solid = glass();
    solid.materials[fence].alphaMode = scenes::AlphaMode::Opaque;
    solid.materials[ghost].alphaMode = scenes::AlphaMode::Opaque;
    lighting::PreparedScene solidFrame(std::move(solid), kWidth, kHeight, true);
    size_t ghostPixelsWhenOpaque = 0;
    // The visible triangle of each pixel, as the visibility draw recorded it.
    auto materialAt = [](const lighting::PreparedScene& f, size_t pixel) {
        const uint32_t triangle = f.exact->triangle[pixel];
        return triangle == gbuffer::ExactSurface::kNoTriangle
                   ? UINT32_MAX
                   : f.geometry.triangleMaterial[triangle];
    };
    for (size_t pixel = 0; pixel < size_t(kWidth) * kHeight; ++pixel) {
        EXPECT_NE(materialAt(frame, pixel), ghost) << "pixel " << pixel;
        fencePixels += materialAt(frame, pixel) == fence ? 1 : 0;
        fenceArea += materialAt(solidFrame, pixel) == fence ? 1 : 0;
        ghostPixelsWhenOpaque += materialAt(solidFrame, pixel) == ghost ? 1 : 0;
    }
    // Half the stripes are cut out (bilinear filtering moves the edges by under a texel).
    ASSERT_GT(fenceArea, 500u);
    EXPECT_GT(ghostPixelsWhenOpaque, 500u);
    const double kept = double(fencePixels) / double(fenceArea);
    EXPECT_GT(kept, 0.35);
    EXPECT_LT(kept, 0.65);
    std::cout << "[measured] fence pixels kept: " << fencePixels << " of " << fenceArea << "\n";
}

TEST(AlphaMask, AlphaIsTheFactorTimesTheTexture) {
    scenes::Scene scene = glass();
    gbuffer::AlphaCoverage coverage;
    coverage.build(scene);
    EXPECT_TRUE(coverage.active());
    EXPECT_TRUE(coverage.anyBlend());
    EXPECT_EQ(coverage.rule(materialNamed(scene, "fence")),
              gbuffer::AlphaCoverage::Rule::TestTexture);
    EXPECT_EQ(coverage.rule(materialNamed(scene, "ghost")), gbuffer::AlphaCoverage::Rule::Discard);
    EXPECT_EQ(coverage.rule(materialNamed(scene, "glass-blue")),
              gbuffer::AlphaCoverage::Rule::Discard);
    EXPECT_EQ(coverage.rule(materialNamed(scene, "ground")), gbuffer::AlphaCoverage::Rule::Keep);
    // A factor at the cutoff is kept (alpha >= cutoff).
    scene.materials[materialNamed(scene, "ghost")].baseColorFactor.a = 0.5f;
    coverage.build(scene);
    EXPECT_EQ(coverage.rule(materialNamed(scene, "ghost")), gbuffer::AlphaCoverage::Rule::Keep);
    // No MASK or BLEND material: inactive (the draws take the fragment function without a test).
    for (scenes::Material& material : scene.materials)
        material.alphaMode = scenes::AlphaMode::Opaque;
    coverage.build(scene);
    EXPECT_FALSE(coverage.active());
}

class EveryStageOnGlass : public ::testing::TestWithParam<std::string> {};

// Every stage sees through the cut-out pane as if it were not there.
TEST_P(EveryStageOnGlass, SeesThroughTheCutOutPane) {
    const std::string& stage = GetParam();
    lighting::PreparedScene withoutGhost(without(glass(), "ghost"), kWidth, kHeight, true);
    const lighting::StageResult a = render(glassFrame(), stage);
    const lighting::StageResult b = render(withoutGhost, stage);
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(a, b)) << stage;
}

// The blended panes change every stage's image, within the stated bound of the reference, and
// the blend pass is timed under its own name.
// Bounds: 1.25x the largest measured relative RMSE of the stages of each kind on this frame
// ([measured] below; Release, 2026-12-02): every exact stage 0.0214 (bitwise brute's image: the
// per-triangle order against the reference's per-pixel sort, where the green pane cuts through
// the blue one; 3.1e-6 without that pane), light-prepass 0.0259, inferred 0.0816 (its stipple
// layers are lit at a quarter of its L-buffer's samples).
constexpr double kExactStageBound = 1.25 * 0.0214;
constexpr double kApproximateStageBound = 1.25 * 0.0816;

TEST_P(EveryStageOnGlass, BlendsThePanesWithinTheBound) {
    const std::string& stage = GetParam();
    lighting::PreparedScene opaqueFrame(opaque(glass()), kWidth, kHeight, true);
    const lighting::StageResult blended = render(glassFrame(), stage);
    const lighting::StageResult solid = render(opaqueFrame, stage);
    EXPECT_FALSE(stagecheck::bitwiseEqualImages(blended, solid)) << stage;
    const auto blend =
        std::find_if(blended.timingsMs.begin(), blended.timingsMs.end(),
                     [](const auto& timing) { return timing.first == lighting::pass::kBlend; });
    EXPECT_NE(blend, blended.timingsMs.end()) << stage << " reports no blend pass";
    const double error = relativeRmse(blended, glassReference());
    std::cout << "[measured] " << stage << " relative RMSE against the reference: " << error
              << "\n";
    bool exact = false;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        if (info.name == stage)
            exact = info.kind == lighting::StageKind::Exact;
    if (stage != "reference")
        EXPECT_LE(error, exact ? kExactStageBound : kApproximateStageBound) << stage;
}

TEST_P(EveryStageOnGlass, BitwiseTheSameOn1And7Threads) {
    const std::string& stage = GetParam();
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 7);
    lighting::StageResult one, seven;
    tbb::task_arena(1).execute([&] { one = render(glassFrame(), stage); });
    tbb::task_arena(7).execute([&] { seven = render(glassFrame(), stage); });
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(one, seven)) << stage;
    EXPECT_EQ(one.lightsEvaluated, seven.lightsEvaluated) << stage;
    EXPECT_EQ(one.lightsOracle, seven.lightsOracle) << stage;
}

// The blended surfaces are shaded on the light kernel like the opaque ones, and the SIMT cost
// model counts them: against the same scene without its blended panes (whose opaque pass is the
// same, the panes never being in it), a stage's lane slots and kernel work grow; for an exact
// stage by at least the blended fragments' contributing lights (each costs a lane slot), and
// the whole frame's lane slots are at least the oracle's evaluations (simt_efficiency <= 1).
TEST_P(EveryStageOnGlass, BlendedFragmentsRunOnTheKernelAndPayLaneSlots) {
    const std::string& stage = GetParam();
    if (stage == "reference")
        GTEST_SKIP() << "the reference is scalar double by design";
    scenes::Scene panesRemoved = glass();
    std::erase_if(panesRemoved.instances, [&](const scenes::Instance& instance) {
        const uint32_t material = panesRemoved.meshes[instance.mesh].material;
        return panesRemoved.materials[material].alphaMode == scenes::AlphaMode::Blend;
    });
    lighting::PreparedScene opaqueOnly(std::move(panesRemoved), kWidth, kHeight, true);
    const lighting::StageResult withPanes = render(glassFrame(), stage);
    const lighting::StageResult withoutPanes = render(opaqueOnly, stage);
    auto counter = [&](const lighting::StageResult& result, const char* key) {
        const auto value = result.parameters.find(key);
        EXPECT_NE(value, result.parameters.end()) << stage << " records no " << key;
        return value == result.parameters.end() ? uint64_t(0) : std::stoull(value->second);
    };
    auto total = [](const std::vector<uint32_t>& counts) {
        uint64_t sum = 0;
        for (uint32_t count : counts)
            sum += count;
        return sum;
    };
    const uint64_t oracle = total(lighting::countContributingLights(glassFrame().inputs));
    const uint64_t blendedOracle =
        oracle - total(lighting::countContributingLights(opaqueOnly.inputs));
    const uint64_t slots = counter(withPanes, "simt_lane_slots");
    const uint64_t opaqueSlots = counter(withoutPanes, "simt_lane_slots");
    std::cout << "[measured] " << stage << " on glass: lane slots " << slots << " (" << opaqueSlots
              << " without the panes), oracle " << oracle << " (" << blendedOracle
              << " on blended fragments)\n";
    EXPECT_GT(blendedOracle, 0u);
    EXPECT_GT(slots, opaqueSlots) << stage;
    EXPECT_GT(counter(withPanes, "packet_groups"), counter(withoutPanes, "packet_groups")) << stage;
    EXPECT_GT(counter(withPanes, "packet_lights_shaded"),
              counter(withoutPanes, "packet_lights_shaded"))
        << stage;
    bool exact = false;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        if (info.name == stage)
            exact = info.kind == lighting::StageKind::Exact;
    // An exact stage shades every blended fragment with every light contributing there (the
    // approximate ones light fewer samples: inferred's stippled L-buffer).
    if (exact) {
        EXPECT_GE(slots, opaqueSlots + blendedOracle) << stage;
        EXPECT_GE(slots, oracle) << stage << ": simt_efficiency above 1";
    }
}

INSTANTIATE_TEST_SUITE_P(AllStages, EveryStageOnGlass, ::testing::ValuesIn(allStageNames()),
                         [](const auto& info) {
                             std::string name = info.param;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

// Blended metallic-roughness surfaces keep their own model through inferred's stipple: the
// stippled samples carry the Fresnel-edge sum and the composite combines the split as the opaque
// material pass does (c_diff diffuse + f0 specular + edge). Measured relative RMSE against the
// reference (256x144, 120 lights, metal panes of roughness 0.35): brute 0.0349 (the sorting
// artefacts, stronger on specular panes), inferred 0.134 (its half-resolution light of a fast
// varying specular); combining the panes as Blinn-Phong (albedo x diffuse + intensity x
// specular, no edge term), as the composite did, gave inferred 0.267. Bounds 1.25x measured.
TEST(Blend, InferredLightsMetallicRoughnessPanesByTheirModel) {
    scenes::Scene metal = glass();
    for (scenes::Material& material : metal.materials)
        if (material.alphaMode == scenes::AlphaMode::Blend) {
            material.model = scenes::MaterialModel::MetallicRoughness;
            material.metallic = 1.0f;
            material.roughness = 0.35f;
        }
    lighting::PreparedScene frame(std::move(metal), kWidth, kHeight, true);
    const lighting::StageResult reference = render(frame, "reference");
    const double inferred = relativeRmse(render(frame, "inferred"), reference);
    const double brute = relativeRmse(render(frame, "brute"), reference);
    std::cout << "[measured] metal panes, relative RMSE against the reference: inferred "
              << inferred << ", brute " << brute << "\n";
    EXPECT_LE(brute, 1.25 * 0.0349);
    EXPECT_LE(inferred, 1.25 * 0.134);
}

// Without intersecting panes the per-triangle order is the per-pixel order at almost every
// pixel: brute then agrees with the reference to float precision; with the tilted pane cutting
// through the blue one, the sorting artefacts show.
TEST(Blend, BruteMatchesTheReferenceWhereTheOrderAgrees) {
    lighting::PreparedScene separate(without(glass(), "glass-green"), kWidth, kHeight, true);
    const double separateError =
        relativeRmse(render(separate, "brute"), render(separate, "reference"));
    const double crossingError = relativeRmse(render(glassFrame(), "brute"), glassReference());
    std::cout << "[measured] brute vs reference, relative RMSE: separate panes " << separateError
              << ", crossing panes " << crossingError << "\n";
    EXPECT_LT(separateError, 1e-4);
    EXPECT_GT(crossingError, 10.0 * separateError);
}

// The reference's composite does not depend on the order the triangles are submitted in.
TEST(Blend, ReferenceIsIndependentOfSubmissionOrder) {
    scenes::Scene reversed = glass();
    std::reverse(reversed.instances.begin(), reversed.instances.end());
    lighting::PreparedScene frame(std::move(reversed), kWidth, kHeight, true);
    const lighting::StageResult image = render(frame, "reference");
    const lighting::StageResult& reference = glassReference();
    // The opaque surfaces are the same triangles in another order (ties in depth aside, none in
    // this scene), so the whole image is bitwise the same.
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(image, reference));
}

// The oracle counts the blended fragments' lights: brute's own count equals the runner's.
TEST(Blend, OracleCountsBlendedFragments) {
    const lighting::PreparedScene& frame = glassFrame();
    const lighting::StageResult brute = render(frame, "brute");
    const std::vector<uint32_t> oracle = lighting::countContributingLights(frame.inputs);
    EXPECT_EQ(brute.lightsOracle, oracle);
    lighting::PreparedScene opaqueFrame(opaque(glass()), kWidth, kHeight, true);
    uint64_t blendedTotal = 0, opaqueTotal = 0;
    for (uint32_t count : oracle)
        blendedTotal += count;
    for (uint32_t count : lighting::countContributingLights(opaqueFrame.inputs))
        opaqueTotal += count;
    EXPECT_GT(blendedTotal, opaqueTotal);
}

} // namespace
