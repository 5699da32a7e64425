// The render plan and the metrics record: planRender decides the layout the run uses and refuses
// bad input before any rendering; measureRun derives the stage's time, the light counts and the
// culling efficiency from what a run measured; the table columns are RunMetrics' names.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "experiments/render/RenderJob.h"
#include "experiments/render/RunMetrics.h"
#include "experiments/sweep/ResultsTable.h"
#include "experiments/sweep/SweepJobRun.h"
#include "lighting/StageRegistry.h"

namespace {

using experiments::PassTiming;
using experiments::RenderOptions;
using experiments::RunMetrics;

RenderOptions tinySpheres() {
    RenderOptions options;
    options.scene = "spheres";
    options.stage = "tiled";
    options.lights = 8;
    options.width = 96;
    options.height = 54;
    options.threads = 2;
    return options;
}

TEST(RenderPlan, DecidesTheLayoutAndStageTheRunUses) {
    RenderOptions options = tinySpheres();
    options.normals = "octahedral:16";
    options.depth = "unorm24";
    experiments::RenderPlan plan = experiments::planRender(options);
    EXPECT_EQ(plan.stage->name(), "tiled");
    EXPECT_EQ(plan.threads, 2);
    const std::string normals = plan.layout.normals.text();
    const double bytes = plan.layout.bytesPerPixel();
    EXPECT_EQ(normals, "octahedral:16");
    const experiments::RenderRun run = experiments::runRender(std::move(plan));
    EXPECT_EQ(run.gbuffer().layout().normals.text(), normals);
    EXPECT_EQ(run.gbuffer().layout().depth.text(), "unorm24");
    EXPECT_EQ(run.metrics.bytesPerPixel, bytes);
}

TEST(RenderPlan, RefusesBadInputBeforeRendering) {
    RenderOptions options = tinySpheres();
    options.layout = "no-such-preset";
    EXPECT_THROW(experiments::planRender(options), experiments::UsageError);
    options = tinySpheres();
    options.normals = "octahedral:7";
    EXPECT_THROW(experiments::planRender(options), experiments::UsageError);
    options = tinySpheres();
    options.stage = "tiled:tile=0";
    EXPECT_THROW(experiments::planRender(options), lighting::StageError);
    options = tinySpheres();
    options.width = 0;
    EXPECT_THROW(experiments::planRender(options), experiments::UsageError);
}

TEST(RunMetrics, StageTimeExcludesTheRunnersPassesAndEfficiencyIsOracleOverEvaluated) {
    std::vector<PassTiming> passes;
    experiments::addRepetition(
        passes,
        {{"gbuffer", 10.0}, {"cull", 1.0}, {"shading", 2.0}, {"shading", 0.5}, {"total", 13.5}});
    experiments::addRepetition(
        passes, {{"gbuffer", 12.0}, {"cull", 3.0}, {"shading", 4.0}, {"total", 19.0}});
    ASSERT_EQ(passes.size(), 4u);
    EXPECT_EQ(passes[2].pass, "shading");
    EXPECT_EQ(passes[2].samplesMs, (std::vector<double>{2.5, 4.0})); // reported twice: summed
    const RunMetrics metrics =
        experiments::measureRun(passes, {3, 0, 5}, {1, 0, 3}, {}, 7.0, 8.0, std::nullopt);
    EXPECT_EQ(metrics.stage.pass, "stage");
    EXPECT_EQ(metrics.stage.samplesMs, (std::vector<double>{3.5, 7.0}));
    EXPECT_EQ(metrics.stage.medianMs(), 5.25);
    EXPECT_EQ(metrics.lightEvaluations, 8u);
    EXPECT_EQ(metrics.oracleLightEvaluations, 4u);
    EXPECT_EQ(metrics.cullingEfficiency, 0.5);
    EXPECT_EQ(metrics.countedPixels, 3u);
    EXPECT_TRUE(metrics.lightCountsNote.empty());
    EXPECT_EQ(metrics.bytesPerPixel, 7.0);
    EXPECT_EQ(metrics.allocatedBytesPerPixel, 8.0);
    EXPECT_TRUE(metrics.errorFigures().empty());
    // Nothing evaluated: nothing wasted.
    EXPECT_EQ(experiments::measureRun({}, {0}, {0}, {}, 0, 0, std::nullopt).cullingEfficiency, 1.0);
}

// A reduced-resolution stage lights some pixels only: both counts are summed over those, so the
// oracle at the pixels it only filtered does not make its efficiency exceed 1.
TEST(RunMetrics, ReducedResolutionCountsOnlyTheLitPixels) {
    const RunMetrics metrics =
        experiments::measureRun({}, {4, 0, 0, 6}, {2, 5, 5, 3}, {1, 0, 0, 1}, 0, 0, std::nullopt);
    EXPECT_EQ(metrics.lightEvaluations, 10u);
    EXPECT_EQ(metrics.oracleLightEvaluations, 5u);
    EXPECT_EQ(metrics.cullingEfficiency, 0.5);
    EXPECT_EQ(metrics.countedPixels, 2u);
    EXPECT_NE(metrics.lightCountsNote.find("2 of the 4 pixels"), std::string::npos)
        << metrics.lightCountsNote;
}

// ꟻLIP is a figure beside the others; unavailable, it is NaN (null in the outputs).
// inferred on a dark frame (spheres, 16 lights, 640x360): relative RMSE 0.53 from one misplaced
// highlight (max 11.3) while 99% of the samples are within 7.9e-5.
TEST(RunMetrics, AnErrorInUnderOnePercentOfTheSamplesIsSaidToBeSo) {
    experiments::ErrorMetrics concentrated;
    concentrated.relativeRmse = 0.53;
    concentrated.maxAbs = 11.3;
    concentrated.p99Abs = 7.9e-5;
    EXPECT_EQ(experiments::errorConcentrationNote(concentrated),
              "the error sits in under 1% of the samples: 99% are within 7.90e-05 of the "
              "reference, the largest is 1.13e+01; see error.png");
    experiments::ErrorMetrics spread = concentrated; // a broken image: large everywhere
    spread.p99Abs = 0.5;
    EXPECT_EQ(experiments::errorConcentrationNote(spread), "");
    experiments::ErrorMetrics small = concentrated; // an exact stage: nothing to explain
    small.relativeRmse = 4.6e-5;
    EXPECT_EQ(experiments::errorConcentrationNote(small), "");
}

TEST(RunMetrics, FlipIsAnErrorFigureAndNaNWhenUnavailable) {
    RunMetrics metrics;
    metrics.error = experiments::ErrorMetrics{};
    metrics.error->flipUnavailable = "images differ in size";
    // The mean and its percentiles, in this order, last among the error figures.
    auto figure = [&](const std::string& name) {
        for (const experiments::NamedFigure& f : metrics.errorFigures())
            if (name == f.name)
                return f.value;
        ADD_FAILURE() << "no figure " << name;
        return 0.0;
    };
    const std::vector<experiments::NamedFigure> figures = metrics.errorFigures();
    ASSERT_GE(figures.size(), 4u);
    EXPECT_EQ(std::string(figures[figures.size() - 4].name), "flip");
    EXPECT_EQ(std::string(figures.back().name), "flip_p99");
    for (const char* name : {"flip", "flip_weighted_median", "flip_p95", "flip_p99"})
        EXPECT_TRUE(std::isnan(figure(name))) << name;
    metrics.error->flip = 0.25;
    metrics.error->flipWeightedMedian = 0.5;
    metrics.error->flipP95 = 0.75;
    metrics.error->flipP99 = 0.875;
    EXPECT_EQ(figure("flip"), 0.25);
    EXPECT_EQ(figure("flip_weighted_median"), 0.5);
    EXPECT_EQ(figure("flip_p95"), 0.75);
    EXPECT_EQ(figure("flip_p99"), 0.875);
}

TEST(RunMetrics, TheTableColumnsAreTheRecordsFigures) {
    const std::vector<std::string> columns = experiments::metricColumns({});
    const std::vector<std::string> figures = experiments::runFigureColumns();
    EXPECT_EQ(columns, figures);
    EXPECT_EQ(figures, (std::vector<std::string>{"light_evaluations",
                                                 "oracle_light_evaluations",
                                                 "culling_efficiency",
                                                 "counted_pixels",
                                                 "simt_lane_slots",
                                                 "simt_efficiency",
                                                 "bytes_per_pixel",
                                                 "complex_fraction",
                                                 "surfaces_per_covered_pixel",
                                                 "gbuffer_bytes",
                                                 "gbuffer_allocated_bytes",
                                                 "shadow_map_bytes",
                                                 "shadow_misclassified",
                                                 "memory_estimate_bytes",
                                                 "peak_rss_bytes",
                                                 "covered_fraction",
                                                 "rmse",
                                                 "relative_rmse",
                                                 "psnr",
                                                 "max_abs",
                                                 "relative_mean",
                                                 "p99_abs",
                                                 "flip",
                                                 "flip_weighted_median",
                                                 "flip_p95",
                                                 "flip_p99",
                                                 "flip_unavailable",
                                                 "non_finite_pixels",
                                                 "reference_non_finite_pixels"}));
}

// Issue 32 (class 3): a sweep's row counts the non-finite pixels of the image and of its
// reference, as stats.json does, so that a null (inf) error figure in the table says why; without
// a reference both are null.
TEST(RunMetrics, SweepRowsCountNonFinitePixels) {
    RunMetrics metrics;
    nlohmann::ordered_json row = experiments::metricColumnsOf(metrics);
    EXPECT_TRUE(row.at("non_finite_pixels").is_null());
    EXPECT_TRUE(row.at("reference_non_finite_pixels").is_null());
    metrics.error = experiments::ErrorMetrics{};
    metrics.error->nonFinitePixels = 3;
    metrics.error->referenceNonFinitePixels = 1;
    metrics.error->rmse = std::numeric_limits<double>::infinity();
    row = experiments::metricColumnsOf(metrics);
    EXPECT_EQ(row.at("non_finite_pixels"), 3);
    EXPECT_EQ(row.at("reference_non_finite_pixels"), 1);
    EXPECT_TRUE(row.at("rmse").is_null()); // inf: unreliable, and the counts say why
}

} // namespace
