// accumulateLights (lighting/passes/LightAccumulation.h), through the stages that shade with it, on
// the kernel's scalar path and its widest vector target: 1, 2 and 7 threads give bitwise the same
// image, counts and SIMT lane slots; the scalar path is the per-pixel loop's image bitwise (a
// layout the packet decoder refuses is gathered pixel by pixel, then shaded on the kernel); the
// vector path stays within a few ulps of it (the figure is printed), and on metallic-roughness
// scenes (DamagedHelmet, and atrium with half its materials metallic-roughness) it is the scalar
// path bitwise but for the Blinn-Phong lanes' pow (figures printed); the SIMT model's bounds hold.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <memory>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferLayout.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/SceneLoader.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using lighting::kernel::KernelIsa;

const char* const kKernelStages[] = {"brute",          "tiled",     "tiled:tile=6",
                                     "tiled-backface", "clustered", "light-indexed"};

lighting::PreparedScene& atrium() {
    static std::unique_ptr<lighting::PreparedScene> frame = [] {
        scenes::SceneRequest request;
        request.lightCount = 200;
        request.seed = 5;
        return std::make_unique<lighting::PreparedScene>(
            scenes::buildProceduralScene("atrium", request), 203, 117); // edge packets and warps
    }();
    return *frame;
}

lighting::StageResult shade(const char* stage, lighting::StageInputs inputs, KernelIsa isa,
                            int threads, int warpLanes = 32) {
    inputs.isa = isa;
    inputs.simtWarpLanes = warpLanes;
    lighting::StageResult result;
    tbb::task_arena(threads).execute([&] { lighting::makeStage(stage)->shade(inputs, result); });
    return result;
}

bool bitwiseSame(const lighting::StageResult& a, const lighting::StageResult& b) {
    for (int c = 0; c < 3; ++c)
        if (std::memcmp(a.radiance[c].data(), b.radiance[c].data(),
                        a.radiance[c].size() * sizeof(float)) != 0)
            return false;
    return a.lightsEvaluated == b.lightsEvaluated;
}

// Distance in units in the last place between two finite floats of the same sign.
int64_t ulps(float a, float b) {
    int32_t ia, ib;
    std::memcpy(&ia, &a, 4);
    std::memcpy(&ib, &b, 4);
    return std::abs(int64_t(ia) - int64_t(ib));
}

TEST(LightAccumulation, DeterministicForAnyThreadCountOnEveryIsa) {
    for (const KernelIsa& isa : {KernelIsa::scalar(), KernelIsa::best()})
        for (const char* stage : kKernelStages) {
            const lighting::StageResult one = shade(stage, atrium().inputs, isa, 1);
            EXPECT_EQ(one.parameters.at("isa"), isa.name()) << stage;
            for (int threads : {2, 7}) {
                const lighting::StageResult many = shade(stage, atrium().inputs, isa, threads);
                EXPECT_TRUE(bitwiseSame(one, many))
                    << stage << " " << isa.name() << " 1 vs " << threads << " threads";
                EXPECT_EQ(one.parameters.at("simt_lane_slots"),
                          many.parameters.at("simt_lane_slots"))
                    << stage;
            }
        }
}

TEST(LightAccumulation, VectorPathWithinAFewUlpsOfTheScalarPath) {
    const lighting::StageResult scalar = shade("brute", atrium().inputs, KernelIsa::scalar(), 2);
    const lighting::StageResult vector = shade("brute", atrium().inputs, KernelIsa::best(), 2);
    int64_t worst = 0;
    for (int c = 0; c < 3; ++c)
        for (size_t p = 0; p < scalar.radiance[c].size(); ++p)
            worst = std::max(worst, ulps(scalar.radiance[c][p], vector.radiance[c][p]));
    std::cout << "[measured] brute atrium 203x117 200 lights, " << KernelIsa::best().name()
              << " vs scalar: worst " << worst << " ulps\n";
    EXPECT_LE(worst, 16);
    EXPECT_EQ(scalar.lightsEvaluated, vector.lightsEvaluated);
    EXPECT_EQ(scalar.lightsOracle, vector.lightsOracle);
}

lighting::PreparedScene& helmet() {
    static std::unique_ptr<lighting::PreparedScene> frame = [] {
        scenes::SceneRequest request;
        request.lightCount = 64;
        request.seed = 3;
        return std::make_unique<lighting::PreparedScene>(
            scenes::loadScene(TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", request), 203,
            117);
    }();
    return *frame;
}

// Atrium with every other material metallic-roughness: packets of either model and mixed ones.
lighting::PreparedScene& mixedAtrium() {
    static std::unique_ptr<lighting::PreparedScene> frame = [] {
        scenes::SceneRequest request;
        request.lightCount = 200;
        request.seed = 5;
        scenes::Scene scene = scenes::buildProceduralScene("atrium", request);
        for (size_t i = 0; i < scene.materials.size(); i += 2) {
            scene.materials[i].model = scenes::MaterialModel::MetallicRoughness;
            scene.materials[i].roughness = 0.05f + 0.15f * float(i);
            scene.materials[i].metallic = i % 4 == 0 ? 1.0f : 0.0f;
        }
        return std::make_unique<lighting::PreparedScene>(std::move(scene), 203, 117);
    }();
    return *frame;
}

// Vector vs scalar path of brute on a metallic-roughness frame: the ISA that ran, the worst
// difference relative to the image's peak (and in ulps), identical counts, determinism.
void expectVectorMatchesScalar(const char* name, const lighting::PreparedScene& frame,
                               bool expectBitwise) {
    const lighting::StageResult scalar = shade("brute", frame.inputs, KernelIsa::scalar(), 2);
    const lighting::StageResult vector = shade("brute", frame.inputs, KernelIsa::best(), 2);
    EXPECT_EQ(scalar.parameters.at("isa"), "scalar");
    EXPECT_EQ(vector.parameters.at("isa"), KernelIsa::best().name()) << "packet path expected";
    float peak = 0.0f, worstDifference = 0.0f;
    int64_t worstUlps = 0;
    for (int c = 0; c < 3; ++c)
        for (size_t p = 0; p < scalar.radiance[c].size(); ++p) {
            peak = std::max(peak, scalar.radiance[c][p]);
            worstDifference =
                std::max(worstDifference, std::abs(scalar.radiance[c][p] - vector.radiance[c][p]));
            worstUlps = std::max(worstUlps, ulps(scalar.radiance[c][p], vector.radiance[c][p]));
        }
    ASSERT_GT(peak, 0.0f);
    std::cout << "[measured] brute " << name << " 203x117, " << KernelIsa::best().name()
              << " vs scalar: worst difference " << worstDifference / peak << " of the peak ("
              << worstUlps << " ulps), bitwise " << (bitwiseSame(scalar, vector) ? "yes" : "no")
              << "\n";
    EXPECT_LE(worstDifference, 1e-5f * peak);
    if (expectBitwise) {
        EXPECT_TRUE(bitwiseSame(scalar, vector));
    }
    EXPECT_EQ(scalar.lightsEvaluated, vector.lightsEvaluated);
    EXPECT_EQ(scalar.lightsOracle, vector.lightsOracle);
    for (const char* stage : kKernelStages) {
        const lighting::StageResult one = shade(stage, frame.inputs, KernelIsa::best(), 1);
        EXPECT_TRUE(bitwiseSame(one, shade(stage, frame.inputs, KernelIsa::best(), 7)))
            << stage << " on " << name;
    }
}

// The helmet is metallic-roughness everywhere: no pow, so the vector path is the scalar path
// bitwise (MetallicRoughness.h's float operations, in its order, on both).
TEST(LightAccumulation, MetallicRoughnessHelmetVectorPathIsTheScalarPath) {
    expectVectorMatchesScalar("DamagedHelmet", helmet(), true);
}

TEST(LightAccumulation, MixedModelsVectorPathWithinAFewUlpsOfTheScalarPath) {
    expectVectorMatchesScalar("atrium, half the materials metallic-roughness", mixedAtrium(),
                              false);
}

// A layout the packet decoder refuses (octahedral normal codes) is decoded pixel by pixel and
// still shaded on the kernel on the requested ISA: it says so (isa, gbuffer_decode, the packet
// counters), every exact stage still gives brute's image bitwise there, and the scalar ISA is
// bitwise the per-pixel evaluateLight loop (the reference layout's scalar image decodes the same
// surfaces only when the codec is lossless, so that is checked on the stage pair instead).
TEST(LightAccumulation, LayoutsThePacketDecoderRefusesAreGatheredAndShadedOnTheKernel) {
    gbuffer::GBufferLayout layout = gbuffer::GBufferLayout::reference();
    layout.normals = gbuffer::NormalCodecSpec::parse("octahedral:16");
    layout.name = "octahedral-test";
    scenes::SceneRequest request;
    request.lightCount = 100;
    request.seed = 5;
    lighting::PreparedScene frame(scenes::buildProceduralScene("atrium", request), 96, 64, false,
                                  layout);
    const lighting::StageResult brute = shade("brute", frame.inputs, KernelIsa::best(), 2);
    const lighting::StageResult bruteScalar = shade("brute", frame.inputs, KernelIsa::scalar(), 2);
    EXPECT_EQ(brute.parameters.at("isa"), KernelIsa::best().name());
    EXPECT_EQ(bruteScalar.parameters.at("isa"), "scalar");
    for (const char* stage : kKernelStages) {
        const lighting::StageResult result = shade(stage, frame.inputs, KernelIsa::best(), 2);
        EXPECT_EQ(result.parameters.at("isa"), KernelIsa::best().name()) << stage;
        EXPECT_EQ(result.parameters.at("gbuffer_decode"), "per-pixel") << stage;
        EXPECT_GT(std::stoull(result.parameters.at("packet_lights_shaded")), 0u) << stage;
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(0, std::memcmp(result.radiance[c].data(), brute.radiance[c].data(),
                                     brute.radiance[c].size() * sizeof(float)))
                << stage;
        const lighting::StageResult scalar = shade(stage, frame.inputs, KernelIsa::scalar(), 2);
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(0, std::memcmp(scalar.radiance[c].data(), bruteScalar.radiance[c].data(),
                                     brute.radiance[c].size() * sizeof(float)))
                << stage << " scalar";
        for (const char* counter :
             {"packet_groups", "packet_lights_skipped_at_range",
              "packet_lights_skipped_at_cone_or_facing", "packet_lights_shaded", "simt_lane_slots"})
            EXPECT_EQ(result.parameters.at(counter), scalar.parameters.at(counter))
                << stage << " " << counter;
    }
    // The reference layout goes through the packet decoder.
    EXPECT_EQ(shade("brute", atrium().inputs, KernelIsa::best(), 2).parameters.at("gbuffer_decode"),
              "packet");
}

// Lane slots: at least the evaluations (a warp pays at least what its lanes evaluate); a 64-lane
// warp pays at least what its two 32-lane halves pay; brute pays every light in every warp.
TEST(LightAccumulation, SimtLaneSlotsBounds) {
    for (const char* stage : kKernelStages) {
        const lighting::StageResult w32 = shade(stage, atrium().inputs, KernelIsa::best(), 2, 32);
        const lighting::StageResult w64 = shade(stage, atrium().inputs, KernelIsa::best(), 2, 64);
        uint64_t evaluated = 0;
        for (uint32_t n : w32.lightsEvaluated)
            evaluated += n;
        const uint64_t slots32 = std::stoull(w32.parameters.at("simt_lane_slots"));
        const uint64_t slots64 = std::stoull(w64.parameters.at("simt_lane_slots"));
        EXPECT_GE(slots32, evaluated) << stage;
        EXPECT_GE(slots64, slots32) << stage;
        EXPECT_EQ(w64.parameters.at("simt_warp"), "64");
        if (std::strcmp(stage, "brute") == 0)
            EXPECT_EQ(slots32 % (32 * atrium().lights.size()), 0u);
        else
            EXPECT_LT(slots32, std::stoull(shade("brute", atrium().inputs, KernelIsa::best(), 2)
                                               .parameters.at("simt_lane_slots")))
                << stage;
    }
}

} // namespace
