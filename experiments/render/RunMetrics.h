// RunMetrics: the figures of one render, computed once (at the end of runRender) and written by
// both of its outputs: stats.json (RenderCommand.h statsJson) and a sweep's results row
// (SweepRunner.cpp). The names below are the names in both files; a figure is renamed here or
// nowhere.
//
// What is measured:
//   passes        one PassTiming per pass in execution order: gbuffer, exact_surface (reference
//                 stage only), the stage's own passes (lighting/passes/PassNames.h), total
//                 (G-buffer plus the stage's passes). Samples are the timed repetitions, after the
//                 warm-up runs.
//   stage         the stage's own passes summed per repetition (total without the G-buffer pass):
//                 what papers that exclude the G-buffer pass report (Örtegren's "Total").
//   light evaluations   lights the stage evaluated, summed over pixels; the oracle's count is the
//                 lights that contribute (DESIGN.md); culling efficiency = oracle / evaluated (1
//                 when nothing was evaluated). Both are summed over the same pixels: every pixel,
//                 or for a stage that lights at reduced resolution (inferred) the pixels it lit
//                 (StageResult::lightingSamples); counted_pixels says how many, and
//                 light_counts_note says why when that is not the whole image.
//   SIMT cost model     lane slots a SIMT GPU would spend on the stage's light evaluations (warps
//                 of 32 or 64 lanes pay every lane for each light any lane evaluates; reported by
//                 the stages on lighting/passes/LightAccumulation.h as the parameter
//                 simt_lane_slots, lighting/README.md); simt efficiency = oracle evaluations / lane
//                 slots. Both null for stages without the model.
//   bytes per pixel     the layout's bits as a GPU packs them, and what this run allocates.
//   CPU load      process CPU seconds per wall second over the timed repetitions, against the
//                 threads (CpuLoad.h): whether the machine was loaded while the times were taken.
//   error         against the double-precision reference, when compared (compareImages), and
//                 the mean HDR-ꟻLIP (FlipMetric.h), null with flip_unavailable saying why when
//                 the package is missing.
// Thread safety: values; compareImages runs ImageBufAlgo on the calling thread's pool.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "experiments/compare/ImageMetrics.h"
#include "experiments/render/CpuLoad.h"
#include "lighting/ShadingStage.h"

namespace experiments {

// Output names shared by stats.json and the sweep's result columns.
namespace metric {
inline constexpr const char* kLightEvaluations = "light_evaluations";
inline constexpr const char* kOracleLightEvaluations = "oracle_light_evaluations";
inline constexpr const char* kCullingEfficiency = "culling_efficiency";
inline constexpr const char* kCountedPixels = "counted_pixels";
inline constexpr const char* kSimtLaneSlots = "simt_lane_slots";
inline constexpr const char* kSimtEfficiency = "simt_efficiency";
inline constexpr const char* kBytesPerPixel = "bytes_per_pixel";
inline constexpr const char* kAllocatedBytesPerPixel = "allocated_bytes_per_pixel";
// Anti-aliasing (--msaa, gbuffer/msaa/FragmentLayers.h): the fraction of covered pixels that are
// complex, the surfaces shaded per covered pixel (1 without MSAA), and the G-buffer's bytes in
// total: as a compressed store holds them (main surface per pixel, extra surfaces at complex
// pixels) and as the testbed allocates them (full planes per layer).
inline constexpr const char* kComplexFraction = "complex_fraction";
inline constexpr const char* kSurfacesPerPixel = "surfaces_per_covered_pixel";
inline constexpr const char* kGBufferBytes = "gbuffer_bytes";
inline constexpr const char* kGBufferAllocatedBytes = "gbuffer_allocated_bytes";
// Shadows (--shadows maps, lighting/shadows): the maps' bytes, and the fraction of pixel-light
// pairs whose shadow-map visibility disagrees with the ray-traced truth (ShadowError.h); null
// without shadows (and the fraction without a reference).
inline constexpr const char* kShadowMapBytes = "shadow_map_bytes";
inline constexpr const char* kShadowMisclassified = "shadow_misclassified";
// Memory of the run: the estimate it was checked against before allocating (MemoryEstimate.h)
// and the measured peak resident set of the process that rendered it; a sweep job's peak
// excludes the reference it rendered first (resetPeakResident).
inline constexpr const char* kMemoryEstimateBytes = "memory_estimate_bytes";
inline constexpr const char* kPeakRssBytes = "peak_rss_bytes";
// The fraction of pixels that show a surface (Coverage.h): 0 flags an image of the background.
inline constexpr const char* kCoveredFraction = "covered_fraction";
} // namespace metric

// Passes the runner adds around the stage's (lighting/passes/PassNames.h has the frame's passes).
namespace pass {
inline constexpr const char* kStage = "stage"; // the stage's own passes summed
inline constexpr const char* kTotal = "total"; // G-buffer, the stage's passes and post_aa
} // namespace pass

// One pass's times over the timed repetitions.
struct PassTiming {
    std::string pass;
    std::vector<double> samplesMs;
    double medianMs() const;
    double minMs() const;
    double maxMs() const;
};

// A named figure of a run, in output order.
struct NamedFigure {
    const char* name;
    double value;
};

struct RunMetrics {
    std::vector<PassTiming> passes; // execution order, total last
    PassTiming stage;               // pass::kStage; no samples when the stage reports no pass
    double oracleMs = 0.0;          // measurement, not part of the stage
    double referenceMs = 0.0;
    double flipMs = 0.0;
    // Lights that contribute at a covered (non-background) pixel, from the oracle: the mean and
    // the 99th percentile (nearest rank); what the light generator's density means
    // (--light-density). Zero when no pixel is covered.
    double oracleLightsPerCoveredPixelMean = 0.0;
    uint32_t oracleLightsPerCoveredPixelP99 = 0;
    // CPU time against wall time over the timed repetitions (CpuLoad.h): in stats.json, not in
    // the sweep's columns (each job's stats.json has it).
    CpuLoad cpuLoad;
    uint64_t lightEvaluations = 0;
    uint64_t oracleLightEvaluations = 0;
    double cullingEfficiency = 1.0;
    uint64_t countedPixels = 0;  // pixels the two counts are summed over
    std::string lightCountsNote; // why countedPixels is not the whole image ("" when it is)
    std::optional<uint64_t> simtLaneSlots; // absent: the stage does not run the SIMT model
    std::optional<double> simtEfficiency;  // oracle / lane slots (1 when no slot was spent)

    // Sets the SIMT figures from a stage's parameters (simt_lane_slots) and the oracle count.
    void setSimtModel(const std::map<std::string, std::string>& stageParameters);
    double bytesPerPixel = 0.0;
    double allocatedBytesPerPixel = 0.0;
    // Shadow figures (see metric::kShadowMapBytes); empty without shadows / without a reference.
    std::optional<double> shadowMapBytes;
    std::optional<double> shadowMisclassified;
    // Anti-aliasing figures (see metric::kComplexFraction); samples 1 without MSAA.
    int msaaSamples = 1;
    double complexFraction = 0.0;
    double surfacesPerCoveredPixel = 1.0;
    double gbufferBytes = 0.0;
    double gbufferAllocatedBytes = 0.0;
    std::optional<ErrorMetrics> error;

    // rmse, relative_rmse, psnr, max_abs, relative_mean, p99_abs, flip (empty without a
    // reference); psnr is +inf for identical images, flip NaN when unavailable.
    std::vector<NamedFigure> errorFigures() const;
};

// Adds one repetition's pass times (in the stage's order; a pass reported twice is summed) to
// `passes`, keeping the passes' first-seen order.
void addRepetition(std::vector<PassTiming>& passes,
                   const std::vector<std::pair<std::string, double>>& repetition);

// The metrics of a run from what it measured: the timed passes, the per-pixel counts of the
// stage and the oracle, the pixels the stage lit (StageResult::lightingSamples; empty = all), the
// layout's sizes, and the error when compared.
RunMetrics measureRun(std::vector<PassTiming> passes, const std::vector<uint32_t>& evaluated,
                      const std::vector<uint32_t>& oracle, const std::vector<uint8_t>& litPixels,
                      double bytesPerPixel, double allocatedBytesPerPixel,
                      std::optional<ErrorMetrics> error);

// The sweep's metric column names that a RunMetrics fills, after the time columns, in table order:
// light_evaluations, oracle_light_evaluations, culling_efficiency, counted_pixels,
// simt_lane_slots, simt_efficiency, bytes_per_pixel, then the error figures and flip_unavailable
// (text).
std::vector<std::string> runFigureColumns();

} // namespace experiments
