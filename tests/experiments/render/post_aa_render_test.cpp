// --post-aa in the runner (lighting/postaa/PostAa.h, experiments/render/): the option is checked,
// edge-blur adds depth and normals to the layout of a stage that does not read them (and says
// why), the filter runs after the stage as the timed pass post_aa (in the total, not in the
// stage's time), changes the image the error is measured on, is bitwise the same for any thread
// count, and is recorded in stats.json.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "experiments/render/RenderCommand.h"
#include "experiments/render/RenderJob.h"
#include "lighting/passes/PassNames.h"

namespace {

using experiments::planRender;
using experiments::RenderOptions;
using experiments::RenderRun;
using experiments::runRender;

RenderOptions small(const char* stage, const char* postAa, int threads = 0) {
    RenderOptions options;
    options.scene = "atrium";
    options.stage = stage;
    options.lights = 32;
    options.seed = 3;
    options.width = 160;
    options.height = 90;
    options.threads = threads;
    options.postAa = postAa;
    return options;
}

bool bitwiseEqual(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

bool hasPass(const RenderRun& run, const char* pass) {
    return std::any_of(run.metrics.passes.begin(), run.metrics.passes.end(),
                       [&](const experiments::PassTiming& t) { return t.pass == pass; });
}

TEST(PostAaRender, BadModeIsRefusedNamingTheOptionAndTheValidNames) {
    RenderOptions options = small("tiled", "smaa");
    try {
        experiments::validate(options);
        ADD_FAILURE() << "--post-aa smaa accepted";
    } catch (const experiments::UsageError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("option 'post-aa'"), std::string::npos) << message;
        EXPECT_NE(message.find("'smaa'"), std::string::npos) << message;
        EXPECT_NE(message.find("none, edge-blur, fxaa"), std::string::npos) << message;
    }
    experiments::setRenderOption(options, "post-aa", "fxaa"); // the sweep's key
    EXPECT_NO_THROW(experiments::validate(options));
    EXPECT_EQ(options.postAa, "fxaa");
}

TEST(PostAaRender, EdgeBlurAddsDepthAndNormalsToAForwardStagesLayout) {
    const experiments::RenderPlan plain = planRender(small("forward", "none"));
    EXPECT_FALSE(plain.layout.provides(gbuffer::Channel::Normal));
    const experiments::RenderPlan fxaa = planRender(small("forward", "fxaa"));
    EXPECT_FALSE(fxaa.layout.provides(gbuffer::Channel::Normal));
    const experiments::RenderPlan blurred = planRender(small("forward", "edge-blur"));
    EXPECT_TRUE(blurred.layout.provides(gbuffer::Channel::Normal));
    EXPECT_TRUE(blurred.requirements.channels.empty()) << "the stage's own requirements";
    for (gbuffer::Channel channel : {gbuffer::Channel::Depth, gbuffer::Channel::Normal}) {
        const std::string reason = blurred.layout.reasons.at(channel);
        EXPECT_EQ(reason.rfind("--post-aa edge-blur (not the stage) reads", 0), 0u) << reason;
    }
    // A stage that reads normals itself keeps its own reasons.
    const experiments::RenderPlan tiled = planRender(small("tiled", "edge-blur"));
    EXPECT_EQ(tiled.layout.reasons.at(gbuffer::Channel::Normal).find("--post-aa"),
              std::string::npos);
}

TEST(PostAaRender, RunsAfterTheStageAsATimedPassAndFiltersTheImage) {
    RenderOptions none = small("tiled", "none");
    none.compareReference = true;
    const RenderRun plain = runRender(planRender(none));
    EXPECT_FALSE(hasPass(plain, lighting::pass::kPostAa));
    EXPECT_TRUE(plain.postAaEdges.empty());
    for (const char* mode : {"edge-blur", "fxaa"}) {
        SCOPED_TRACE(mode);
        RenderOptions options = small("tiled", mode);
        options.compareReference = true;
        options.repetitions = 2;
        const RenderRun run = runRender(planRender(options));
        ASSERT_TRUE(hasPass(run, lighting::pass::kPostAa));
        // The stage's time leaves the filter out; the total has it.
        const experiments::PassTiming* total = nullptr;
        const experiments::PassTiming* gbufferPass = nullptr;
        const experiments::PassTiming* postAa = nullptr;
        for (const experiments::PassTiming& t : run.metrics.passes) {
            total = t.pass == experiments::pass::kTotal ? &t : total;
            gbufferPass = t.pass == lighting::pass::kGBuffer ? &t : gbufferPass;
            postAa = t.pass == lighting::pass::kPostAa ? &t : postAa;
        }
        ASSERT_TRUE(total && gbufferPass && postAa);
        for (size_t r = 0; r < total->samplesMs.size(); ++r)
            EXPECT_NEAR(run.metrics.stage.samplesMs[r] + gbufferPass->samplesMs[r] +
                            postAa->samplesMs[r],
                        total->samplesMs[r], 1e-9 * total->samplesMs[r])
                << "repetition " << r;
        // The image differs from the unfiltered one at some pixels, at edges only.
        ASSERT_EQ(run.postAaEdges.size(), run.result.radiance[0].size());
        size_t changed = 0, changedWithoutEdge = 0;
        for (size_t i = 0; i < run.postAaEdges.size(); ++i) {
            const bool differs = run.result.radiance[0][i] != plain.result.radiance[0][i];
            changed += differs;
            changedWithoutEdge += differs && run.postAaEdges[i] == 0.0f;
        }
        EXPECT_GT(changed, 0u);
        EXPECT_EQ(changedWithoutEdge, 0u);
        // The error is measured on the filtered image, against the same (unfiltered) reference.
        ASSERT_TRUE(run.metrics.error && plain.metrics.error);
        EXPECT_NE(run.metrics.error->rmse, plain.metrics.error->rmse);
        const nlohmann::json stats = experiments::statsJson(run);
        EXPECT_EQ(stats["post_aa"]["mode"], mode);
        EXPECT_FALSE(stats["post_aa"]["parameters"].empty());
        EXPECT_GT(stats["post_aa"]["filtered_pixels"].get<size_t>(), 0u);
        EXPECT_TRUE(stats["timings_ms"].contains(lighting::pass::kPostAa));
    }
    EXPECT_EQ(experiments::statsJson(plain)["post_aa"]["mode"], "none");
}

TEST(PostAaRender, BitwiseTheSameOnOneAndTwoThreads) {
    for (const char* mode : {"edge-blur", "fxaa"}) {
        const RenderRun one = runRender(planRender(small("forward", mode, 1)));
        const RenderRun two = runRender(planRender(small("forward", mode, 2)));
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(bitwiseEqual(one.result.radiance[c], two.result.radiance[c])) << mode;
        EXPECT_TRUE(bitwiseEqual(one.postAaEdges, two.postAaEdges)) << mode;
    }
}

} // namespace
