// End-to-end renders in process: determinism across thread counts, brute against the
// double-precision reference, the oracle, and refusal of bad input before any work.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "experiments/render/RenderCommand.h"
#include "experiments/render/RenderJob.h"
#include "lighting/passes/PassNames.h"

namespace {

using experiments::PassTiming;
using experiments::planRender;
using experiments::RenderOptions;
using experiments::renderReference;
using experiments::RenderRun;
using experiments::runRender;

RenderOptions smallAtrium(int threads, const char* isa = "auto") {
    RenderOptions options;
    options.isa = isa;
    options.scene = "atrium";
    options.stage = "brute";
    options.lights = 64;
    options.seed = 7;
    options.width = 320;
    options.height = 180;
    options.threads = threads;
    // These tests hold stages to the pixel-centre reference (exactness, conservative culling);
    // the supersampled one has its own test below.
    options.referenceSpp = 1;
    return options;
}

template <class A, class B> bool bitwiseEqual(const A& a, const B& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

// Every decoded G-buffer value of two runs, compared bit for bit.
bool sameDecodedGBuffer(const gbuffer::GBuffer& a, const gbuffer::GBuffer& b) {
    if (a.width() != b.width() || a.height() != b.height())
        return false;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            const gbuffer::Surface sa = a.decode(x, y), sb = b.decode(x, y);
            if (std::memcmp(&sa.positionView, &sb.positionView, sizeof(glm::vec3)) != 0 ||
                std::memcmp(&sa.normalView, &sb.normalView, sizeof(glm::vec3)) != 0 ||
                std::memcmp(&sa.albedo, &sb.albedo, sizeof(glm::vec3)) != 0 ||
                sa.specularIntensity != sb.specularIntensity ||
                sa.specularPower != sb.specularPower)
                return false;
        }
    return true;
}

// On the kernel's scalar path and on its widest vector target alike.
class RenderJobIsa : public ::testing::TestWithParam<const char*> {};

TEST_P(RenderJobIsa, BitwiseIdenticalForAnyThreadCount) {
    const RenderRun one = runRender(planRender(smallAtrium(1, GetParam())));
    for (int threads : {2, 7}) {
        const RenderRun many = runRender(planRender(smallAtrium(threads, GetParam())));
        EXPECT_TRUE(bitwiseEqual(one.gbuffer().depth(), many.gbuffer().depth())) << threads;
        EXPECT_TRUE(sameDecodedGBuffer(one.gbuffer(), many.gbuffer())) << threads;
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(bitwiseEqual(one.result.radiance[c], many.result.radiance[c])) << threads;
        EXPECT_TRUE(bitwiseEqual(one.result.lightsEvaluated, many.result.lightsEvaluated));
        EXPECT_TRUE(bitwiseEqual(one.oracle, many.oracle));
        EXPECT_EQ(one.prepared->rasterStats.samplesPassed,
                  many.prepared->rasterStats.samplesPassed);
        EXPECT_EQ(one.metrics.simtLaneSlots, many.metrics.simtLaneSlots);
    }
}

TEST_P(RenderJobIsa, BruteMatchesReferenceOnAtrium) {
    RenderOptions options = smallAtrium(0, GetParam());
    options.compareReference = true;
    const RenderRun run = runRender(planRender(options));
    ASSERT_TRUE(run.metrics.error.has_value());
    EXPECT_LT(run.metrics.error->relativeRmse, 1e-4) << "rmse " << run.metrics.error->rmse;
    std::cout << "[measured] brute (isa " << GetParam() << ") vs reference relative RMSE "
              << run.metrics.error->relativeRmse << "\n";
    // The SIMT model: a warp pays at least what its lanes evaluate, and every lane pays for every
    // light under brute force (all 32 lanes of every warp with a covered pixel).
    ASSERT_TRUE(run.metrics.simtLaneSlots.has_value());
    EXPECT_GE(*run.metrics.simtLaneSlots, run.metrics.lightEvaluations);
    EXPECT_EQ(*run.metrics.simtLaneSlots % (32 * run.scene().lights.size()), 0u);
    EXPECT_GT(*run.metrics.simtEfficiency, 0.0);
    EXPECT_LE(*run.metrics.simtEfficiency, run.metrics.cullingEfficiency);
    EXPECT_GT(run.metrics.error->relativeRmse, 0.0) << "float and double should differ a little";
    // The scene is lit: not a black image compared with a black image.
    double sum = 0.0;
    for (float v : run.reference.radiance[1])
        sum += v;
    EXPECT_GT(sum / run.reference.radiance[1].size(), 1e-3);
}

// Issue 14's "brute vs reference relative RMSE below 1e-5", stated for what brute can be held to:
// the shading of the G-buffer's surface. The reference shades the exact surface (double ray
// against the pixel's own triangle, gbuffer/visibility/ExactSurface.h); the G-buffer holds the same
// triangle's plane at the pixel centre from float-transformed vertices, and where that plane is
// nearly edge-on to the view ray the intersection is ill-conditioned, so its depth can be off by
// far more than rounding (atrium, 320x180, 256 lights: one pixel, (123, 98), 2.25% off, makes the
// whole-image relative RMSE 2.45e-5; without it 1.7e-6). Measured here: the relative RMSE (RMSE
// over pixels and channels / RMS of the reference over the same) over the pixels whose decoded
// G-buffer position lies within 1e-4 (relative) of the exact one, below 1e-5; and those that do
// not are few (at most 1 in 10,000 covered pixels) and all are reported. The whole-image figure is
// printed too.
// |cos| of the angle between the view ray to `point` (view space) and triangle t's geometric
// normal: near 0 when the triangle is seen edge-on.
double viewRayCosine(const lighting::PreparedScene& prepared, uint32_t t, const glm::dvec3& point) {
    const gbuffer::SceneGeometry& geometry = prepared.geometry;
    const glm::dmat4& viewFromWorld = prepared.gbuffer->view().viewFromWorldExact;
    glm::dvec3 p[3];
    for (int i = 0; i < 3; ++i)
        p[i] =
            glm::dvec3(viewFromWorld *
                       glm::dvec4(geometry.positionWorldExact[geometry.indices[3 * t + i]], 1.0));
    const glm::dvec3 normal = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    return std::abs(glm::dot(normal, glm::normalize(point)));
}

TEST(RenderJob, BruteMatchesReferenceOnTheGBufferSurface) {
    RenderOptions options = smallAtrium(0);
    options.lights = 256;
    options.seed = 1;
    options.compareReference = true;
    const RenderRun run = runRender(planRender(options));
    ASSERT_TRUE(run.prepared->exact);
    const gbuffer::ExactSurface& exact = *run.prepared->exact;
    const gbuffer::GBuffer& gb = run.gbuffer();
    double differenceAll = 0.0, referenceAll = 0.0, differenceKept = 0.0, referenceKept = 0.0;
    size_t covered = 0, apart = 0;
    for (int y = 0; y < gb.height(); ++y)
        for (int x = 0; x < gb.width(); ++x) {
            const size_t pixel = size_t(y) * gb.width() + x;
            double difference = 0.0, reference = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double r = run.reference.radiance[c][pixel];
                const double d = double(run.result.radiance[c][pixel]) - r;
                difference += d * d;
                reference += r * r;
            }
            differenceAll += difference;
            referenceAll += reference;
            gbuffer::Surface surface;
            bool keep = true;
            if (gb.surfaceAt(x, y, surface)) {
                ++covered;
                ASSERT_TRUE(exact.covered(pixel)) << x << " " << y;
                const glm::dvec3 truth = exact.positionView[pixel];
                const double offset = glm::length(glm::dvec3(surface.positionView) - truth);
                if (offset > 1e-4 * glm::length(truth)) {
                    keep = false;
                    ++apart;
                    std::cout << "[measured] pixel (" << x << ", " << y << "): G-buffer position "
                              << offset / glm::length(truth)
                              << " (relative) from the exact surface, |cos| of the view ray "
                              << "to its triangle's plane normal "
                              << viewRayCosine(*run.prepared, exact.triangle[pixel], truth)
                              << ", pixel error "
                              << std::sqrt(difference / std::max(reference, 1e-300))
                              << " (relative)\n";
                }
            }
            if (keep) {
                differenceKept += difference;
                referenceKept += reference;
            }
        }
    const double whole = std::sqrt(differenceAll / referenceAll);
    const double kept = std::sqrt(differenceKept / referenceKept);
    std::cout << "[measured] brute vs reference relative RMSE: whole image " << whole << ", on the "
              << covered - apart << " of " << covered
              << " covered pixels whose G-buffer surface is the exact one " << kept << "\n";
    // The whole-image figure is the metric the runner reports (RunMetrics' relativeRmse).
    ASSERT_TRUE(run.metrics.error.has_value());
    EXPECT_NEAR(whole, run.metrics.error->relativeRmse, 1e-3 * whole);
    EXPECT_LT(kept, 1e-5);
    EXPECT_GT(kept, 0.0) << "float and double should differ a little";
    EXPECT_LE(apart * 10000, covered);
}

INSTANTIATE_TEST_SUITE_P(ScalarAndAuto, RenderJobIsa, ::testing::Values("scalar", "auto"));

TEST(RenderJob, BruteEvaluatesEveryLightAndCountsTheOracle) {
    const RenderRun run = runRender(planRender(smallAtrium(0)));
    const uint32_t lightCount = uint32_t(run.scene().lights.size());
    uint64_t covered = 0, oracle = 0;
    for (size_t pixel = 0; pixel < run.oracle.size(); ++pixel) {
        const bool isCovered = run.gbuffer().covered(pixel);
        covered += isCovered;
        EXPECT_EQ(run.result.lightsEvaluated[pixel], isCovered ? lightCount : 0u);
        EXPECT_LE(run.oracle[pixel], run.result.lightsEvaluated[pixel]);
        oracle += run.oracle[pixel];
    }
    EXPECT_GT(covered, run.oracle.size() / 2);
    EXPECT_GT(oracle, covered);              // more than the ambient light somewhere
    EXPECT_LT(oracle, covered * lightCount); // the falloff has finite support
}

// Culling on a lossy G-buffer must stay conservative for the surface it shades: the normal cone
// of tiled-backface, the depth bounds of tiled and clustered come from decoded values, and the
// oracle is counted on the same decoded surface.
TEST(RenderJob, CullingStaysConservativeOnLossyLayouts) {
    for (const char* stage : {"tiled-backface", "clustered", "deferred", "light-indexed"})
        for (const auto& [normals, depth] :
             {std::pair{"octahedral:16", "unorm16"}, std::pair{"pixel-view:16", "f16-linear"},
              std::pair{"xy-z:16", "unorm24"}}) {
            RenderOptions options = smallAtrium(0);
            options.scene = "wall";
            options.sceneOptions["behind"] = "24";
            options.stage = stage;
            options.normals = normals;
            options.depth = depth;
            const RenderRun run = runRender(planRender(options));
            EXPECT_EQ(run.gbuffer().layout().normals.text(), normals);
            size_t dropped = 0;
            for (size_t pixel = 0; pixel < run.oracle.size(); ++pixel)
                dropped += run.result.lightsEvaluated[pixel] < run.oracle[pixel];
            EXPECT_EQ(dropped, 0u) << stage << " " << normals << " " << depth;
        }
}

// Every stage's light counts are on the same footing: summed over the pixels the stage lit, so
// that culling efficiency never exceeds 1 and no lit pixel wastes a negative number of lights.
// inferred lights only its reduced-resolution samples (1 in scale^2 pixels): it says so.
TEST(RenderJob, ReducedResolutionStagesCountTheSamePixelsAsTheOracle) {
    for (const char* stage : {"inferred", "inferred:scale=4", "light-prepass", "tiled"}) {
        RenderOptions options = smallAtrium(0);
        options.stage = stage;
        const RenderRun run = runRender(planRender(options));
        const experiments::RunMetrics& m = run.metrics;
        EXPECT_LE(m.cullingEfficiency, 1.0) << stage;
        EXPECT_GE(m.lightEvaluations, m.oracleLightEvaluations) << stage;
        const std::vector<uint8_t>& lit = run.result.lightingSamples;
        size_t negative = 0;
        for (size_t pixel = 0; pixel < run.oracle.size(); ++pixel)
            if (lit.empty() || lit[pixel])
                negative += run.result.lightsEvaluated[pixel] < run.oracle[pixel];
        EXPECT_EQ(negative, 0u) << stage;
        const bool reduced = std::string(stage).rfind("inferred", 0) == 0;
        const int scale = std::string(stage) == "inferred:scale=4" ? 4 : 2;
        EXPECT_EQ(m.countedPixels,
                  reduced ? uint64_t((320 / scale) * (180 / scale)) : uint64_t(320 * 180))
            << stage;
        EXPECT_EQ(m.lightCountsNote.empty(), !reduced) << stage;
    }
}

// Issue 4's acceptance check at test size: spheremap:16 costs more error than
// octahedral-precise:32 and fewer bytes per pixel than float32.
TEST(RenderJob, NormalEncodingsTradeBytesForError) {
    auto render = [](const char* normals) {
        RenderOptions options = smallAtrium(0);
        options.compareReference = true;
        options.normals = normals;
        return runRender(planRender(options));
    };
    const RenderRun spheremap = render("spheremap:16");
    const RenderRun octahedral = render("octahedral-precise:32");
    const RenderRun exact = render("float32:96");
    ASSERT_TRUE(spheremap.metrics.error && octahedral.metrics.error && exact.metrics.error);
    EXPECT_GT(spheremap.metrics.error->rmse, octahedral.metrics.error->rmse);
    EXPECT_GT(octahedral.metrics.error->rmse, exact.metrics.error->rmse);
    EXPECT_LT(spheremap.gbuffer().layout().bytesPerPixel(),
              exact.gbuffer().layout().bytesPerPixel());
    EXPECT_GT(spheremap.metrics.error->p99Abs, 0.0);
    EXPECT_LE(spheremap.metrics.error->p99Abs, spheremap.metrics.error->maxAbs);
}

TEST(RenderJob, RepetitionsRecordEveryPassAndAGivenReferenceIsReused) {
    RenderOptions options = smallAtrium(0);
    options.stage = "tiled";
    options.warmup = 1;
    options.repetitions = 3;
    const lighting::StageResult reference = renderReference(options);
    const RenderRun run = runRender(planRender(options), {}, &reference);
    ASSERT_TRUE(run.metrics.error.has_value());
    EXPECT_EQ(run.prepared->exact, nullptr) << "the given reference must not be rendered again";
    std::vector<std::string> passes;
    for (const PassTiming& timing : run.metrics.passes) {
        passes.push_back(timing.pass);
        EXPECT_EQ(timing.samplesMs.size(), 3u) << timing.pass;
        EXPECT_LE(timing.minMs(), timing.medianMs());
        EXPECT_LE(timing.medianMs(), timing.maxMs());
    }
    EXPECT_EQ(passes, (std::vector<std::string>{"gbuffer", "cull", "shading", "total"}));
    // The same reference rendered inside the job gives the same error.
    options.compareReference = true;
    const RenderRun inside = runRender(planRender(options));
    EXPECT_EQ(inside.metrics.error->rmse, run.metrics.error->rmse);
}

// Issue 16: the reference's exact surface used to be computed inside every timed G-buffer pass
// (and inflated it) when only --compare-reference needed it. Counted, not timed: the stage's
// passes compute no exact surface; the reference computes it once, afterwards, and is the same
// image as a reference rendered on its own.
TEST(RenderJob, TheReferenceWorkStaysOutOfTheTimedPasses) {
    RenderOptions options = smallAtrium(0);
    options.stage = "tiled";
    options.warmup = 1;
    options.repetitions = 3;
    options.compareReference = true;
    const RenderRun run = runRender(planRender(options));
    EXPECT_EQ(run.prepared->exactSurfacePasses, 1) << "only the reference's, after the timing";
    EXPECT_EQ(run.prepared->gbufferTimings.exactMs, 0.0) << "the last timed pass";
    for (const PassTiming& timing : run.metrics.passes)
        EXPECT_NE(timing.pass, "exact_surface");
    EXPECT_TRUE(bitwiseEqual(run.reference.radiance[1], renderReference(options).radiance[1]));
    // The reference stage reads the exact surface itself: computed in each of its 4 passes.
    options.stage = "reference";
    const RenderRun reference = runRender(planRender(options));
    EXPECT_EQ(reference.prepared->exactSurfacePasses, 4);
}

// --reference-spp above 1: every stage, `reference` itself included, is compared with the same
// supersampled image, the one renderReference gives (as a sweep's cached reference).
TEST(RenderJob, EveryStageIsMeasuredAgainstTheSameSupersampledReference) {
    RenderOptions options = smallAtrium(0);
    options.width = 96;
    options.height = 54;
    options.referenceSpp = 4;
    options.compareReference = true;
    const lighting::StageResult truth = renderReference(options);
    for (const char* stage : {"tiled", "reference"}) {
        SCOPED_TRACE(stage);
        options.stage = stage;
        const RenderRun run = runRender(planRender(options));
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(bitwiseEqual(run.reference.radiance[c], truth.radiance[c]));
        ASSERT_TRUE(run.metrics.error.has_value());
        // Aliased edges against the anti-aliased truth: no longer the float rounding alone.
        EXPECT_GT(run.metrics.error->relativeRmse, 1e-3);
    }
    options.referenceSpp = 1;
    options.stage = "tiled";
    const lighting::StageResult centre = renderReference(options);
    EXPECT_FALSE(bitwiseEqual(centre.radiance[1], truth.radiance[1]));
}

// `--shadows maps` end to end: the maps are rendered and timed as their own pass, the stage
// shades them, the reference ray-traces the same lights, and the run reports the maps' bytes and
// the misclassification; the shadowed image is closer to the shadowed reference than the
// unshadowed one (whose reference is unshadowed) is to it.
TEST(RenderJob, ShadowMapsAreRenderedShadedAndMeasured) {
    RenderOptions options = smallAtrium(1);
    options.stage = "tiled";
    options.compareReference = true;
    options.referenceSpp = 1;
    options.shadows = "maps";
    options.shadowMapSize = 256;
    options.shadowLights = "8";
    const RenderRun run = runRender(planRender(options));
    ASSERT_TRUE(run.shadowMaps);
    EXPECT_EQ(run.shadowMaps->shadowCount(), 8u);
    ASSERT_TRUE(run.shadowError);
    EXPECT_GT(run.shadowError->pairs, 0u);
    EXPECT_GT(run.shadowError->truthShadowed, 0u);
    EXPECT_LT(run.shadowError->misclassifiedFraction(), 0.05);
    ASSERT_TRUE(run.metrics.shadowMapBytes);
    EXPECT_EQ(*run.metrics.shadowMapBytes, double(run.shadowMaps->stats().totalBytes));
    bool timed = false;
    for (const PassTiming& pass : run.metrics.passes)
        timed |= pass.pass == lighting::pass::kShadowMaps;
    EXPECT_TRUE(timed);
    // Against the shadowed reference, shadows make the image closer than no shadows would.
    RenderOptions unshadowed = options;
    unshadowed.shadows = "off";
    const RenderRun plain = runRender(planRender(unshadowed), {}, &run.reference);
    EXPECT_LT(run.metrics.error->relativeRmse, 0.5 * plain.metrics.error->relativeRmse);
    EXPECT_FALSE(plain.shadowMaps);
    EXPECT_FALSE(plain.metrics.shadowMapBytes);

    // A forward stage's G-buffer holds depth alone: its misclassification is measured on the
    // surface it shades (lossless), not on a made-up normal (it was 38% on the atrium when read
    // from the depth-only G-buffer), so it comes out as the same maps' on tiled's surface, to
    // within the normal encoding's effect on the facing test and the slope bias.
    RenderOptions forward = options;
    forward.stage = "forward";
    const RenderRun forwardRun = runRender(planRender(forward), {}, &run.reference);
    ASSERT_TRUE(forwardRun.shadowError);
    EXPECT_EQ(forwardRun.shadowError->pairs, run.shadowError->pairs);
    EXPECT_NEAR(forwardRun.shadowError->misclassifiedFraction(),
                run.shadowError->misclassifiedFraction(),
                0.2 * run.shadowError->misclassifiedFraction() + 1e-4);
}

// `--oracle visibility`: at every pixel at most the unshadowed oracle's count, fewer in all on
// an interior (the atrium's floors and pillars block lights), and a stage's evaluations are then
// further from the oracle (culling efficiency lower), with or without shadows.
TEST(RenderJob, VisibilityOracleCountsOnlyLightsThatReachTheSurface) {
    RenderOptions options = smallAtrium(1);
    options.stage = "tiled";
    const RenderRun unshadowed = runRender(planRender(options));
    options.oracle = "visibility";
    const RenderRun visible = runRender(planRender(options));
    ASSERT_EQ(visible.oracle.size(), unshadowed.oracle.size());
    uint64_t all = 0, reaching = 0;
    for (size_t pixel = 0; pixel < visible.oracle.size(); ++pixel) {
        EXPECT_LE(visible.oracle[pixel], unshadowed.oracle[pixel]) << "pixel " << pixel;
        all += unshadowed.oracle[pixel];
        reaching += visible.oracle[pixel];
    }
    std::printf("atrium 320x180, 64 lights: %llu contributing pixel-light pairs, %llu reach "
                "(%.1f%%)\n",
                (unsigned long long)all, (unsigned long long)reaching, 100.0 * reaching / all);
    EXPECT_LT(reaching, all);
    EXPECT_GT(reaching, 0u);
    EXPECT_LT(visible.metrics.cullingEfficiency, unshadowed.metrics.cullingEfficiency);
    // The image does not depend on the oracle.
    EXPECT_EQ(visible.result.radiance[1], unshadowed.result.radiance[1]);
}

struct BadCase {
    const char* name;
    RenderOptions options;
};
// Keeps gtest from printing the options' bytes into every test name.
void PrintTo(const BadCase& c, std::ostream* os) {
    *os << c.name;
}

class BadInput : public ::testing::TestWithParam<BadCase> {};

RenderOptions with(void (*change)(RenderOptions&)) {
    RenderOptions options = smallAtrium(1);
    change(options);
    return options;
}

TEST_P(BadInput, IsRefusedBeforeAnyWork) {
    const std::filesystem::path out =
        std::filesystem::path(::testing::TempDir()) / ("bad_input_" + std::string(GetParam().name));
    std::filesystem::remove_all(out);
    experiments::RenderCommandOptions options;
    options.render = GetParam().options;
    options.out = out;
    testing::internal::CaptureStderr();
    const int code = experiments::runRenderCommand(options);
    const std::string message = testing::internal::GetCapturedStderr();
    EXPECT_EQ(code, 1);
    EXPECT_NE(message.find("testbed: error:"), std::string::npos) << message;
    EXPECT_FALSE(std::filesystem::exists(out / "render.exr"));
    EXPECT_FALSE(std::filesystem::exists(out / "stats.json"));
}

INSTANTIATE_TEST_SUITE_P(
    Cli, BadInput,
    ::testing::Values(
        BadCase{"unknown_scene", with([](RenderOptions& o) { o.scene = "nosuchscene"; })},
        BadCase{"missing_file", with([](RenderOptions& o) { o.scene = "/nonexistent/x.gltf"; })},
        BadCase{"unknown_stage", with([](RenderOptions& o) { o.stage = "nosuchstage"; })},
        BadCase{"stage_option", with([](RenderOptions& o) { o.stage = "brute:tile=3"; })},
        BadCase{"zero_width", with([](RenderOptions& o) { o.width = 0; })},
        BadCase{"negative_height", with([](RenderOptions& o) { o.height = -5; })},
        BadCase{"absurd_size", with([](RenderOptions& o) { o.width = o.height = 100000; })},
        BadCase{"negative_lights", with([](RenderOptions& o) { o.lights = -1; })},
        BadCase{"scene_option", with([](RenderOptions& o) { o.sceneOptions["nosuch"] = "1"; })},
        BadCase{"reference_spp_not_square", with([](RenderOptions& o) { o.referenceSpp = 8; })},
        BadCase{"reference_spp_too_many", with([](RenderOptions& o) { o.referenceSpp = 1024; })},
        BadCase{"reference_spp_zero", with([](RenderOptions& o) { o.referenceSpp = 0; })},
        BadCase{"shadows_mode", with([](RenderOptions& o) { o.shadows = "rays"; })},
        BadCase{"oracle_mode", with([](RenderOptions& o) { o.oracle = "occlusion"; })},
        BadCase{"visibility_oracle_msaa", with([](RenderOptions& o) {
                    o.oracle = "visibility";
                    o.msaa = 4;
                })},
        BadCase{"shadow_map_size", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowMapSize = 100000;
                })},
        BadCase{"shadow_bias", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowBias = "0.01";
                })},
        BadCase{"shadow_filter", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowFilter = "pcf7";
                })},
        BadCase{"shadow_point", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowPoint = "octahedral";
                })},
        BadCase{"shadow_depth_format", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowDepthFormat = "unorm24";
                })},
        BadCase{"shadow_lights", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowLights = "-2";
                })},
        BadCase{"shadow_cascades", with([](RenderOptions& o) {
                    o.shadows = "maps";
                    o.shadowCascades = 9;
                })}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(RenderCommand, UnwritableOutputFolderIsRefused) {
    const std::filesystem::path file =
        std::filesystem::path(::testing::TempDir()) / "a_regular_file";
    std::ofstream(file) << "x";
    experiments::RenderCommandOptions options;
    options.render = smallAtrium(1);
    options.out = file / "sub";
    testing::internal::CaptureStderr();
    EXPECT_EQ(experiments::runRenderCommand(options), 1);
    const std::string message = testing::internal::GetCapturedStderr();
    EXPECT_NE(message.find("a_regular_file"), std::string::npos) << message;
}

TEST(RenderCommand, StatsRecordTheStagesResolvedOptions) {
    const std::filesystem::path out =
        std::filesystem::path(::testing::TempDir()) / "render_stage_options";
    std::filesystem::remove_all(out);
    experiments::RenderCommandOptions options;
    options.render = smallAtrium(1);
    options.render.stage = "tiled:vfc=off,tile=032";
    options.out = out;
    testing::internal::CaptureStdout();
    ASSERT_EQ(experiments::runRenderCommand(options), 0);
    testing::internal::GetCapturedStdout();
    std::ifstream statsFile(out / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    // The spec as given, and every option of the table with defaults filled in, canonical.
    EXPECT_EQ(stats["stage"], "tiled:vfc=off,tile=032");
    EXPECT_EQ(
        stats["stage_options"],
        nlohmann::json(
            {{"tile", "32"}, {"vfc", "0"}, {"mask", "0"}, {"assign", "loop"}, {"hier", "0"}}));
    // What the stage ran with agrees with what is recorded.
    for (const auto& [key, value] : stats["stage_options"].items())
        EXPECT_EQ(stats["stage_parameters"][key], value) << key;
}

// Per-light shadow settings (a JSON light's "shadow") in stats.json: each per_light entry
// reports the settings its maps were rendered and looked up with, the light's own where it has
// them and the global flags' elsewhere; the maps' bytes follow each light's own size.
TEST(RenderCommand, StatsRecordEachLightsShadowSettings) {
    for (const std::string depthFormat : {"float32", "unorm16"}) {
        SCOPED_TRACE(depthFormat);
        const std::filesystem::path folder =
            std::filesystem::path(::testing::TempDir()) / ("render_light_shadow_" + depthFormat);
        std::filesystem::remove_all(folder);
        std::filesystem::create_directories(folder);
        const nlohmann::json scene = {{"objects", {{{"procedural", "spheres"}}}},
                                      {"lights",
                                       {{{"type", "spot"},
                                         {"position", {0, 6, 0}},
                                         {"direction", {0, -1, 0}},
                                         {"range", 20},
                                         {"innerConeDegrees", 30},
                                         {"outerConeDegrees", 40},
                                         {"castsShadows", true},
                                         {"shadow",
                                          {{"mapSize", 128},
                                           {"bias", {0.02, 3}},
                                           {"filter", "pcf5"},
                                           {"normalOffset", 0.5}}}},
                                        {{"type", "point"},
                                         {"position", {2, 3, 1}},
                                         {"range", 15},
                                         {"castsShadows", true}}}}};
        std::ofstream(folder / "scene.json") << scene.dump(2);
        experiments::RenderCommandOptions options;
        options.render.scene = (folder / "scene.json").string();
        options.render.stage = "brute";
        options.render.width = 96;
        options.render.height = 64;
        options.render.shadows = "maps";
        options.render.shadowMapSize = 64;
        options.render.shadowFilter = "poisson";
        options.render.shadowPoint = "dual-paraboloid";
        options.render.shadowDepthFormat = depthFormat;
        options.out = folder / "out";
        testing::internal::CaptureStdout();
        ASSERT_EQ(experiments::runRenderCommand(options), 0);
        testing::internal::GetCapturedStdout();
        std::ifstream statsFile(folder / "out" / "stats.json");
        const nlohmann::json stats = nlohmann::json::parse(statsFile);
        const nlohmann::json& shadows = stats["shadows"];
        EXPECT_EQ(shadows["map_size"], 64);
        EXPECT_EQ(shadows["filter"], "poisson");
        EXPECT_EQ(shadows["point_projection"], "dual-paraboloid");
        EXPECT_EQ(shadows["depth_format"], depthFormat);
        const int texelBytes = depthFormat == "unorm16" ? 2 : 4;
        ASSERT_EQ(shadows["per_light"].size(), 2u);
        const nlohmann::json& spot = shadows["per_light"][0];
        EXPECT_EQ(spot["map_size"], 128);
        EXPECT_EQ(spot["filter"], "pcf5");
        EXPECT_FLOAT_EQ(spot["bias_constant_m"].get<float>(), 0.02f);
        EXPECT_FLOAT_EQ(spot["bias_slope_texels"].get<float>(), 3.0f);
        EXPECT_FLOAT_EQ(spot["normal_offset_texels"].get<float>(), 0.5f);
        EXPECT_EQ(spot["bytes"], 128 * 128 * texelBytes);
        const nlohmann::json& point = shadows["per_light"][1];
        EXPECT_EQ(point["map_size"], 64);
        EXPECT_EQ(point["filter"], "poisson");
        EXPECT_EQ(point["bias_constant_m"], shadows["bias_constant_m"]);
        EXPECT_EQ(point["faces"], 2);
        EXPECT_EQ(point["bytes"], 2 * 64 * 64 * texelBytes);
        // Both lights' faces are drawn (a paraboloid face is never left out; the spot is in
        // view), and the total is the lights' sum.
        EXPECT_EQ(spot["faces_outside_view"], 0);
        EXPECT_EQ(point["faces_outside_view"], 0);
        EXPECT_EQ(shadows["faces_outside_view"], 0);
        // The sets' size per light and as a fraction of the scene's objects.
        const double perLight =
            0.5 * (spot["caster_objects"].get<double>() + point["caster_objects"].get<double>());
        EXPECT_DOUBLE_EQ(shadows["caster_objects_per_light"].get<double>(), perLight);
        EXPECT_DOUBLE_EQ(shadows["caster_objects_fraction"].get<double>(),
                         perLight / shadows["objects"].get<double>());
    }
}

TEST(RenderCommand, WritesEveryOutputWithTheContractChannels) {
    const std::filesystem::path out = std::filesystem::path(::testing::TempDir()) / "render_ok";
    std::filesystem::remove_all(out);
    experiments::RenderCommandOptions options;
    options.render = smallAtrium(2);
    options.render.compareReference = true;
    options.out = out;
    testing::internal::CaptureStdout();
    ASSERT_EQ(experiments::runRenderCommand(options), 0);
    testing::internal::GetCapturedStdout();
    for (const char* file : {"render.exr", "preview.png", "heatmap.png", "error.png", "stats.json"})
        EXPECT_TRUE(std::filesystem::is_regular_file(out / file)) << file;

    auto input = OIIO::ImageInput::open((out / "render.exr").string());
    ASSERT_TRUE(input);
    const std::vector<std::string> expected = {"R",
                                               "G",
                                               "B",
                                               "N.X",
                                               "N.Y",
                                               "N.Z",
                                               "Z",
                                               "albedo.R",
                                               "albedo.G",
                                               "albedo.B",
                                               "lights.evaluated",
                                               "lights.oracle",
                                               "lights.wasted",
                                               "error.R",
                                               "error.G",
                                               "error.B"};
    for (const std::string& name : expected) {
        const auto& names = input->spec().channelnames;
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    }
    EXPECT_EQ(input->spec().width, 320);

    std::ifstream statsFile(out / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    for (const char* key : {"scene", "stage", "width", "height", "threads", "triangles", "lights",
                            "timings_ms", "light_evaluations", "oracle_light_evaluations", "error"})
        EXPECT_TRUE(stats.contains(key)) << key;
    for (const char* pass : {"gbuffer", "shading", "total"})
        EXPECT_TRUE(stats["timings_ms"].contains(pass)) << pass;
    // One timed run without warm-up: the figures say they are a cold frame.
    EXPECT_EQ(stats["timings"]["figure"], "cold frame (no warm-up, one repetition)");
    for (const char* metric : {"rmse", "max_abs", "psnr", "relative_mean", "p99_abs", "flip",
                               "flip_weighted_median", "flip_p95", "flip_p99", "flip_unavailable"})
        EXPECT_TRUE(stats["error"].contains(metric)) << metric;
    // ꟻLIP (native, always computed with a reference): numbers, its map and its parameters.
    ASSERT_TRUE(stats["error"]["flip"].is_number()) << stats["error"].dump();
    EXPECT_LE(stats["error"]["flip_p95"].get<double>(), stats["error"]["flip_p99"].get<double>());
    EXPECT_EQ(stats["error"]["flip_unavailable"], "");
    EXPECT_TRUE(std::filesystem::is_regular_file(out / "flip.png"));
    EXPECT_TRUE(stats["error"].contains("flip_parameters"));
    // The layout: every plane with name, format and bits, and the bytes per pixel they add up to.
    int bits = 0;
    for (const auto& plane : stats["layout"]["planes"]) {
        for (const char* key : {"name", "format", "bits"})
            EXPECT_TRUE(plane.contains(key)) << key;
        bits += plane["bits"].get<int>();
    }
    EXPECT_DOUBLE_EQ(stats["bytes_per_pixel"].get<double>(), bits / 8.0);
    EXPECT_GE(stats["triangles"].get<uint64_t>(), 250000u);
}

} // namespace

namespace {

nlohmann::json readJson(const std::filesystem::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

// `render --view all`: one render per view of the scene, each in its folder, the views listed in
// views.json in the scene's order, and each stats.json naming its view; the default view's
// render is bitwise the render without --view.
TEST(RenderCommand, EveryViewRendersIntoItsOwnFolder) {
    const std::filesystem::path out = std::filesystem::path(::testing::TempDir()) / "render_views";
    std::filesystem::remove_all(out);
    experiments::RenderCommandOptions options;
    options.render = smallAtrium(2);
    options.render.scene = "spheres";
    options.render.width = 96;
    options.render.height = 54;
    options.render.view = experiments::kEveryView;
    options.out = out;
    testing::internal::CaptureStdout();
    ASSERT_EQ(experiments::runRenderCommand(options), 0);
    testing::internal::GetCapturedStdout();
    const nlohmann::json views = readJson(out / "views.json");
    ASSERT_EQ(views.size(), 4u);
    EXPECT_EQ(views[0]["view"], "front");
    for (const nlohmann::json& view : views) {
        const std::filesystem::path folder = out / view["folder"].get<std::string>();
        EXPECT_TRUE(std::filesystem::is_regular_file(folder / "render.exr")) << folder;
        EXPECT_EQ(readJson(folder / "stats.json")["view"], view["view"]) << folder;
    }

    const RenderRun byDefault = [&] {
        RenderOptions plain = options.render;
        plain.view.clear();
        return runRender(planRender(plain));
    }();
    const RenderRun front = [&] {
        RenderOptions named = options.render;
        named.view = "front";
        return runRender(planRender(named));
    }();
    for (int c = 0; c < 3; ++c)
        EXPECT_TRUE(bitwiseEqual(byDefault.result.radiance[c], front.result.radiance[c]));
    const RenderRun above = [&] {
        RenderOptions named = options.render;
        named.view = "above";
        return runRender(planRender(named));
    }();
    EXPECT_FALSE(bitwiseEqual(byDefault.result.radiance[0], above.result.radiance[0]));
}

TEST(RenderCommand, UnknownViewIsRefusedListingTheViews) {
    experiments::RenderCommandOptions options;
    options.render = smallAtrium(1);
    options.render.view = "roof";
    options.out = std::filesystem::path(::testing::TempDir()) / "render_bad_view";
    testing::internal::CaptureStderr();
    EXPECT_EQ(experiments::runRenderCommand(options), 1);
    const std::string message = testing::internal::GetCapturedStderr();
    EXPECT_NE(message.find("no view 'roof'"), std::string::npos) << message;
    EXPECT_NE(message.find("nave, far-end, gallery, overhead"), std::string::npos) << message;
}

} // namespace
