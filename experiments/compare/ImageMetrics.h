// ImageMetrics: the error of an image against its reference, as every command that compares
// computes it (render --compare-reference, diff, sweep rows through RunMetrics): RMSE, relative
// RMSE, PSNR, the largest and the 99th-percentile absolute difference, the relative mean, and the
// mean HDR-ꟻLIP. Pure functions of two images; never run inside a stage's timed passes.
// Thread safety: values; compareImages runs on the calling thread.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "lighting/ShadingStage.h"

namespace experiments {

// Output names of the error figures, shared by stats.json, diff.json and the sweep's result
// columns (RunMetrics.h has the run's other figures in the same namespace).
namespace metric {
inline constexpr const char* kRmse = "rmse";
inline constexpr const char* kRelativeRmse = "relative_rmse";
inline constexpr const char* kPsnr = "psnr";
inline constexpr const char* kMaxAbs = "max_abs";
inline constexpr const char* kRelativeMean = "relative_mean";
inline constexpr const char* kP99Abs = "p99_abs";
inline constexpr const char* kFlip = "flip";
inline constexpr const char* kFlipWeightedMedian = "flip_weighted_median";
inline constexpr const char* kFlipP95 = "flip_p95";
inline constexpr const char* kFlipP99 = "flip_p99";
inline constexpr const char* kFlipUnavailable = "flip_unavailable";
inline constexpr const char* kNonFinitePixels = "non_finite_pixels";
inline constexpr const char* kReferenceNonFinitePixels = "reference_non_finite_pixels";
} // namespace metric

// Over all pixels and the three colour channels. The figures agree with each other and with the
// pixels (issue 32, class 3): identical finite images give rmse 0, relative figures 0 and psnr
// +inf; any difference gives rmse > 0 and a finite psnr (-inf when the reference's peak is not
// positive); a difference against an all-zero reference gives relative figures of +inf, never 0.
// When either image holds a non-finite sample (NaN or Inf, counted per pixel below) nothing can be
// measured: the error figures are +inf and psnr -inf, never a perfect score.
struct ErrorMetrics {
    double rmse = 0.0;
    double relativeRmse = 0.0; // rmse / rms of the reference
    double maxAbs = 0.0;
    double psnr = 0.0;          // dB, peak = the reference's maximum channel value
    double relativeMean = 0.0;  // mean |image - reference| / mean |reference|
    double p99Abs = 0.0;        // 99th percentile of |image - reference|
    std::optional<double> flip; // mean HDR-ꟻLIP (FlipMetric.h); nullopt when not computed
    std::optional<double> flipWeightedMedian, flipP95, flipP99; // its percentiles (Flip.h)
    std::string flipUnavailable;           // why flip is missing ("" when computed)
    uint64_t nonFinitePixels = 0;          // pixels of the image with a NaN or Inf channel
    uint64_t referenceNonFinitePixels = 0; // the same in the reference
};

ErrorMetrics compareImages(const lighting::StageResult& image,
                           const lighting::StageResult& reference);

// A note when the error is large but sits in under 1% of the samples (relative RMSE above 0.1
// while the 99th percentile is below 1% of the largest error): a sharp highlight that a
// reduced-resolution stage (inferred) misplaces dominates the RMSE of a dark frame while 99% of
// the samples are nearly exact, and a relative RMSE near 1 would read as a broken image. Empty
// otherwise.
std::string errorConcentrationNote(const ErrorMetrics& error);

// Why the error figures cannot be trusted ("the image has 3 pixels with NaN or Inf ..."), or ""
// when both images are finite. Printed in the summary and written beside the figures.
std::string nonFiniteNote(const ErrorMetrics& error);

} // namespace experiments
