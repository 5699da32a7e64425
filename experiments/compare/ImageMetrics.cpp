// ImageMetrics.h: the error figures in plain double loops over the planar radiance (no
// ImageBufAlgo: its statistics treat NaN differently from function to function, and a NaN beauty
// once came out as rmse 0), with non-finite pixels counted first.
#include "experiments/compare/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

namespace experiments {

namespace {

uint64_t countNonFinitePixels(const lighting::StageResult& image) {
    uint64_t count = 0;
    const size_t pixels = size_t(image.width) * image.height;
    for (size_t i = 0; i < pixels; ++i)
        count += !(std::isfinite(image.radiance[0][i]) && std::isfinite(image.radiance[1][i]) &&
                   std::isfinite(image.radiance[2][i]));
    return count;
}

} // namespace

ErrorMetrics compareImages(const lighting::StageResult& image,
                           const lighting::StageResult& reference) {
    ErrorMetrics metrics;
    metrics.nonFinitePixels = countNonFinitePixels(image);
    metrics.referenceNonFinitePixels = countNonFinitePixels(reference);
    constexpr double kInf = std::numeric_limits<double>::infinity();
    if (metrics.nonFinitePixels > 0 || metrics.referenceNonFinitePixels > 0) {
        // OpenImageIO's statistics skip or propagate NaN depending on the function: a NaN beauty
        // once reported rmse 0. Nothing is measured instead.
        metrics.rmse = metrics.relativeRmse = metrics.maxAbs = kInf;
        metrics.relativeMean = metrics.p99Abs = kInf;
        metrics.psnr = -kInf;
        return metrics;
    }
    // Sums in double over every sample (float sums of squares overflow past ~1.8e19 per sample).
    const size_t pixels = size_t(image.width) * image.height;
    std::vector<float> difference(pixels * 3);
    double sumSquares = 0.0, sumAbs = 0.0, referenceSquares = 0.0, referenceAbs = 0.0, peak = -kInf;
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < pixels; ++i) {
            const double a = image.radiance[c][i], b = reference.radiance[c][i];
            const double d = std::abs(a - b);
            difference[3 * i + size_t(c)] = float(d);
            sumSquares += d * d;
            sumAbs += d;
            referenceSquares += b * b;
            referenceAbs += std::abs(b);
            peak = std::max(peak, b);
            metrics.maxAbs = std::max(metrics.maxAbs, d);
        }
    const double samples = double(std::max<size_t>(1, difference.size()));
    metrics.rmse = std::sqrt(sumSquares / samples);
    const double referenceRms = std::sqrt(referenceSquares / samples);
    const bool identical = metrics.maxAbs == 0.0;
    // Ratios to a zero reference are infinite unless there is nothing to compare.
    metrics.relativeRmse = identical            ? 0.0
                           : referenceRms > 0.0 ? metrics.rmse / referenceRms
                                                : kInf;
    metrics.relativeMean = identical ? 0.0 : referenceAbs > 0.0 ? sumAbs / referenceAbs : kInf;
    // In logarithms, so that a tiny but non-zero rmse cannot overflow peak / rmse into +inf.
    if (identical)
        metrics.psnr = kInf;
    else if (metrics.rmse == 0.0) // differences so small that their squares underflow
        metrics.psnr = peak > 0.0 ? 20.0 * (std::log10(peak) - std::log10(metrics.maxAbs)) : -kInf;
    else
        metrics.psnr = peak > 0.0 ? 20.0 * (std::log10(peak) - std::log10(metrics.rmse)) : -kInf;
    if (!difference.empty()) {
        const size_t rank = std::min(difference.size() - 1,
                                     size_t(std::ceil(0.99 * double(difference.size()))) - 1);
        std::nth_element(difference.begin(), difference.begin() + std::ptrdiff_t(rank),
                         difference.end());
        metrics.p99Abs = difference[rank];
    }
    return metrics;
}

std::string nonFiniteNote(const ErrorMetrics& error) {
    if (error.nonFinitePixels == 0 && error.referenceNonFinitePixels == 0)
        return "";
    std::string note = "the error figures are unreliable: ";
    if (error.nonFinitePixels > 0)
        note +=
            "the image has " + std::to_string(error.nonFinitePixels) + " pixels with NaN or Inf";
    if (error.nonFinitePixels > 0 && error.referenceNonFinitePixels > 0)
        note += " and ";
    if (error.referenceNonFinitePixels > 0)
        note += "the reference has " + std::to_string(error.referenceNonFinitePixels) +
                " pixels with NaN or Inf";
    return note + " (rmse and the relative figures are reported as inf, psnr as -inf)";
}

std::string errorConcentrationNote(const ErrorMetrics& error) {
    if (!(error.relativeRmse > 0.1 && error.p99Abs < 0.01 * error.maxAbs))
        return "";
    std::ostringstream note;
    note << std::scientific << std::setprecision(2)
         << "the error sits in under 1% of the samples: 99% are within " << error.p99Abs
         << " of the reference, the largest is " << error.maxAbs << "; see error.png";
    return note.str();
}

} // namespace experiments
