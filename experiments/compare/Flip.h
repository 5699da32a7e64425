// Flip: NVIDIA's perceptual image difference ꟻLIP, computed natively, for comparing a render with
// its reference: HDR-ꟻLIP (Andersson et al., "Visualizing Errors in Rendered High Dynamic Range
// Images", Eurographics 2021) for linear radiance, LDR-ꟻLIP (Andersson et al., "FLIP: A Difference
// Evaluator for Alternating Images", HPG 2020) for display-referred images. Written from the
// papers' equations; it reproduces NVIDIA's FLIP v1.6 on ../shared/flip (means to 1e-4, every
// pixel to 1e-3; tests/experiments/compare/flip_test.cpp).
//
// Conventions
// - Images are planar linear RGB (the testbed's R, G, B planes), row 0 at the top, row-major,
//   width * height floats per plane. The reference is the second argument.
// - Viewing conditions: pixelsPerDegree, default 67.0206451 = a 0.7 m wide 3840-pixel display
//   seen from 0.7 m (NVIDIA's default). It sets the filters' widths: 10 pixels of radius for the
//   colour filters and 9 for the feature detectors at the default.
// - HDR (default): the images are radiance. Each is exposed by 2^e for exposures e from start to
//   stop (the count given or max(2, ceil(stop - start)), evenly spaced), tone mapped by ACES
//   (Narkowicz's fit) and clamped to [0, 1]; LDR-ꟻLIP is computed per exposure and the map is the
//   per-pixel maximum. Unless given, start and stop come from the reference's luminance (Rec. 709
//   weights): start puts its maximum, stop its median at the tone mapper's output 0.85.
// - LDR: the images are LINEAR display RGB, clamped to [0, 1]. (NVIDIA's tool takes sRGB-encoded
//   LDR files and decodes them first; we take the decoded values, so pass linear RGB.)
// - Negative values are clamped to 0 (radiance cannot be negative; a warning counts them).
// - Non-finite pixels (NaN or +-Inf in any channel, of either image) are counted per image
//   (nonFiniteTest, nonFiniteReference) and get error 1, the maximum, in the map. For the filters,
//   which spread each pixel over its neighbours, such a pixel is replaced by the other image's
//   pixel when that is finite, else by black, so that it neither poisons its neighbours with NaN
//   nor adds a difference of its own beyond its own pixel. Non-finite reference pixels take no
//   part in the exposure statistics. The map and every figure are always finite.
// - Zero median luminance (e.g. a black frame with a few emissive pixels): the published stop
//   exposure log2(x / median) would be infinite. Then the median of the POSITIVE luminances is used
//   instead, i.e. the stop exposure shows the frame's typical lit content at 0.85, with a warning.
//   A reference with no positive luminance at all takes its statistics from the test image (with
//   a warning); when neither has any, both images are black wherever finite and the exposures are
//   0 to 0 (the map is then 0 except at non-finite pixels).
// - Statistics over the map: mean; weightedMedian as NVIDIA's tool prints it (the error values
//   sorted ascending, the first whose running sum exceeds half the total: the median of the
//   histogram weighted by error, 0 for an all-zero map); p95 and p99 as NVIDIA's pooling code
//   defines an unweighted percentile (the sorted value at 0-based index ceil(p n), at most n - 1);
//   max. Sums are taken in double.
//
// Errors: std::invalid_argument for an empty image, null planes, different sizes, a
// pixelsPerDegree that is not finite or outside (0, 10000], a non-finite exposure, start > stop,
// or an exposure count below 1 or above 1024 (given, or from a given range; the reference's own
// luminance range, at most 2^277 in floats, always fits).
//
// Thread safety and determinism: a pure function of its arguments (no file I/O, no shared state);
// safe to call from several threads. It runs on TBB (rows in parallel) in the caller's arena, so
// tbb::global_control or a task_arena sets its threads. Results are bitwise the same for every
// thread count: every pixel is computed by the same operations whatever the split, and sums are
// taken over fixed blocks of rows, added in order.
//
// Cost: linear in pixels times exposures (HDR: ceil(log2(max / median)) of the reference, at
// least 2: 3 for the atrium at 320x180, 5 at 1280x720). A 1280x720 pair on this project's 2-core
// machine takes about 0.2 s for HDR-ꟻLIP with 5 exposures on 2 threads and 0.08 s for LDR-ꟻLIP
// (README.md of experiments/compare; tests/bench/flip_bench.cpp). Memory: the map plus about
// four floats per pixel while it runs (six more planes when a pixel is not finite) and a ring of
// filtered rows per thread (1.5 MB at 1280 pixels wide).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace experiments::compare {

// A view of a planar linear RGB image; the planes must outlive the call.
struct FlipImage {
    int width = 0, height = 0;
    const float* r = nullptr;
    const float* g = nullptr;
    const float* b = nullptr;
};

enum class FlipMode { Hdr, Ldr };

// NVIDIA's default viewing conditions: 0.7 m from a 0.7 m wide display of 3840 pixels.
inline constexpr double kDefaultPixelsPerDegree = 67.0206451;

struct FlipOptions {
    FlipMode mode = FlipMode::Hdr;
    double pixelsPerDegree = kDefaultPixelsPerDegree;
    // HDR only (ignored with a warning in LDR mode); each computed from the reference when unset.
    std::optional<float> startExposure, stopExposure;
    std::optional<int> exposureCount;
};

struct FlipResult {
    std::vector<float> errorMap; // width * height values in [0, 1], row 0 at the top
    double mean = 0.0;
    double weightedMedian = 0.0;
    double p95 = 0.0, p99 = 0.0;
    double max = 0.0;
    // The exposures used (HDR only; LDR: 0, 0 and a count of 0).
    float startExposure = 0.0f, stopExposure = 0.0f;
    int exposureCount = 0;
    double pixelsPerDegree = kDefaultPixelsPerDegree;
    std::size_t nonFiniteTest = 0, nonFiniteReference = 0; // pixels with NaN/Inf in any channel
    std::vector<std::string> warnings; // what was clamped, replaced or fallen back on, and why
};

// ꟻLIP of `test` against `reference`. Throws std::invalid_argument (see above).
FlipResult computeFlip(const FlipImage& test, const FlipImage& reference,
                       const FlipOptions& options = {});

} // namespace experiments::compare
