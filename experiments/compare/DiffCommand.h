// DiffCommand: `testbed diff A.exr B.exr --out DIR` compares two renders (any EXRs with beauty
// channels R, G, B; typically two `testbed render` outputs) and writes an image-diff report:
//   DIR/index.html     the page: metrics, A and B side by side, |A - B| in false colour with its
//                      colour bar, per-channel statistics (no network, no external scripts)
//   DIR/diff.json      the same figures: {"a", "b", "width", "height", "metrics": {...},
//                      "channels": [{"name", "a": {min,max,mean,nan,inf}, "b": {...},
//                      "difference": {min,max,mean}, "abs_difference": {max,mean}}],
//                      "only_in_a", "only_in_b"}
//   DIR/a.png, b.png   tone-mapped previews of the beauty (experiments/output/ImageOutput.h)
//   DIR/absdiff.png    max over R,G,B of |A - B|, turbo colour map from 0 to max_abs with a colour
//                      bar (matplotlib, experiments/plots/report.py diff)
//   DIR/absdiff.exr    |A - B| per beauty channel as float32 R, G, B, for inspection in a viewer
//   DIR/flip.png       the HDR-ꟻLIP map of A against B (magma, 0..1, with a legend; FlipMetric.h);
//                      images that cannot be compared (different sizes) have none, and the page and
//                      diff.json say why
//
// B is the reference of the metrics, which are the sweep's error metrics (experiments::
// compareImages on the beauty R, G, B, through OpenImageIO's ImageBufAlgo), so a diff of a job's
// render.exr against the reference gives the figures of results.json:
//   rmse, max_abs, relative_rmse, psnr   PSNR's peak is B's largest channel value; inf when equal
//   relative_mean                        mean |A - B| / |mean B| over the R, G, B samples
//   p99_abs                              99th percentile of |A - B| over the R, G, B samples
//                                        (nearest rank)
//   mean_abs                             mean of |A - B| over the R, G, B samples
//   flip, flip_weighted_median,          HDR-ꟻLIP of A against B (experiments/compare/Flip.h):
//   flip_p95, flip_p99                   mean, weighted median and percentiles (null when the
//                                        images cannot be compared, with flip_unavailable saying
//                                        why); flip_parameters say what was assumed
// Per-channel statistics cover every channel present in both files (N.X, Z, albedo.R,
// lights.evaluated, ...), through ImageBufAlgo::computePixelStats on A, B, A - B and |A - B|;
// min/max/mean are over the finite values, nan/inf count the others.
//
// Inputs must be linear colour: OpenEXR files whose R, G, B are half or float and whose colour
// space tag (a string attribute named *colorspace, which some writers add; OpenEXR itself has
// none and means linear), when present, names a linear space (linear, lin_srgb, scene_linear,
// ACEScg, ...). A PNG or JPEG (a tone-mapped, display-encoded preview), an EXR with
// integer beauty channels or one tagged sRGB or log is refused, not converted: its values are not
// radiance, and undoing a tone map is not possible.
//
// Errors (one line "testbed: error: ...", exit code 1, nothing written): unreadable file, an input
// that is not linear EXR (above), images of different sizes, beauty channel missing, python3 with
// matplotlib missing.
// Thread safety: the functions share no state.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/compare/ImageMetrics.h"

namespace experiments {

struct DiffCommandOptions {
    std::filesystem::path a;
    std::filesystem::path b; // the reference
    std::filesystem::path out = "diff";
    std::filesystem::path plotsScript; // empty = experiments/plots/report.py
    std::string python;                // empty = found as for `testbed report`
    float exposure = 1.0f;             // linear factor applied before tone mapping
};

// The sweep's error metrics (RunMetrics.h) plus the mean absolute difference.
struct DiffMetrics : ErrorMetrics {
    double meanAbs = 0.0; // mean |A - B| over the R, G, B samples
};

struct ChannelStatistics {
    std::string name;
    double minA = 0, maxA = 0, meanA = 0, minB = 0, maxB = 0, meanB = 0;
    long nanA = 0, infA = 0, nanB = 0, infB = 0;
    double minDifference = 0, maxDifference = 0, meanDifference = 0; // A - B
    double maxAbsDifference = 0, meanAbsDifference = 0;              // |A - B|
};

struct ImageDiff {
    int width = 0;
    int height = 0;
    DiffMetrics metrics;
    std::vector<ChannelStatistics> channels; // in A's channel order
    std::vector<std::string> onlyInA, onlyInB;
    // Images for the report: beauty planes of A and B, |A - B| per beauty channel, and the
    // maximum over R, G, B of |A - B| (width * height each, row 0 at the top).
    std::vector<float> beautyA[3], beautyB[3], absDifference[3], maxAbsDifference;
    std::vector<float> flipMap;    // HDR-ꟻLIP per pixel; empty when unavailable
    nlohmann::json flipParameters; // null when unavailable
};

// Reads both files and compares them. Throws std::runtime_error naming the file and the problem
// (unreadable, not linear EXR, sizes differ, R/G/B missing).
ImageDiff diffImageFiles(const std::filesystem::path& a, const std::filesystem::path& b);

// Checks the byte count of every attribute of an OpenEXR header against the bytes the file has
// left, before any reader opens it: OpenEXR allocates each attribute's declared count first, so a
// 4 KB file declaring a 1.7 GB attribute made a 1.7 GB allocation. diffImageFiles calls it; code
// that opens an image outside it (exr_fuzzer's size check) must call it first. Throws
// std::runtime_error naming the file and the attribute; files that are not EXR pass.
void checkExrAttributeSizes(const std::filesystem::path& path);

nlohmann::json diffJson(const ImageDiff& diff, const std::filesystem::path& a,
                        const std::filesystem::path& b);

// Writes DIR (see above); returns the exit code.
int runDiffCommand(const DiffCommandOptions& options);

} // namespace experiments
