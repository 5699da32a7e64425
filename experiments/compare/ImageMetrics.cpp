#include "experiments/compare/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "experiments/output/ImageOutput.h"

namespace experiments {

namespace {

// The stage's radiance as a 3-channel float ImageBuf wrapping nothing: copied, planar to
// interleaved, because ImageBufAlgo works on interleaved pixels.
OIIO::ImageBuf toImageBuf(const lighting::StageResult& image) {
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buffer(spec);
    std::vector<float> interleaved(size_t(image.width) * image.height * 3);
    for (size_t i = 0; i < interleaved.size() / 3; ++i)
        for (int c = 0; c < 3; ++c)
            interleaved[3 * i + c] = image.radiance[c][i];
    buffer.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, interleaved.data());
    return buffer;
}

} // namespace

ErrorMetrics compareImages(const lighting::StageResult& image,
                           const lighting::StageResult& reference) {
    runImageLibraryOnTheCallingThread();
    const OIIO::ImageBuf a = toImageBuf(image), b = toImageBuf(reference);
    const auto comparison = OIIO::ImageBufAlgo::compare(a, b, 0.0f, 0.0f);
    const auto referenceStats = OIIO::ImageBufAlgo::computePixelStats(b);
    double peak = 0.0, sumSquares = 0.0;
    for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, double(referenceStats.max[size_t(c)]));
        const double rms = referenceStats.stddev[size_t(c)], mean = referenceStats.avg[size_t(c)];
        sumSquares += rms * rms + mean * mean;
    }
    ErrorMetrics metrics;
    metrics.rmse = comparison.rms_error;
    metrics.maxAbs = comparison.maxerror;
    const double referenceRms = std::sqrt(sumSquares / 3.0);
    metrics.relativeRmse = referenceRms > 0.0 ? metrics.rmse / referenceRms : 0.0;
    metrics.psnr = metrics.rmse > 0.0 && peak > 0.0 ? 20.0 * std::log10(peak / metrics.rmse)
                                                    : std::numeric_limits<double>::infinity();
    // Mean and percentile of |a - b| over every pixel and channel: the difference image comes from
    // ImageBufAlgo; the percentile is a selection over its values.
    const OIIO::ImageBuf difference = OIIO::ImageBufAlgo::absdiff(a, b);
    const auto differenceStats = OIIO::ImageBufAlgo::computePixelStats(difference);
    double meanDifference = 0.0, meanReference = 0.0;
    for (int c = 0; c < 3; ++c) {
        meanDifference += differenceStats.avg[size_t(c)] / 3.0;
        meanReference += std::abs(double(referenceStats.avg[size_t(c)])) / 3.0;
    }
    metrics.relativeMean = meanReference > 0.0 ? meanDifference / meanReference : 0.0;
    std::vector<float> values(size_t(image.width) * image.height * 3);
    difference.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, values.data());
    if (!values.empty()) {
        const size_t rank =
            std::min(values.size() - 1, size_t(std::ceil(0.99 * double(values.size()))) - 1);
        std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank), values.end());
        metrics.p99Abs = values[rank];
    }
    return metrics;
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
