#include "experiments/RunMetrics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "experiments/ImageOutput.h"
#include "lighting/PassNames.h"

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

// The sum of counts over the pixels marked in mask (every pixel when mask is empty).
uint64_t sum(const std::vector<uint32_t>& counts, const std::vector<uint8_t>& mask) {
    uint64_t total = 0;
    for (size_t i = 0; i < counts.size(); ++i)
        if (mask.empty() || mask[i])
            total += counts[i];
    return total;
}

// The stage's own time per repetition: every pass but the G-buffer's, the exact surface's and
// the total.
PassTiming stageTiming(const std::vector<PassTiming>& passes) {
    PassTiming stage;
    stage.pass = pass::kStage;
    for (const PassTiming& timing : passes) {
        if (timing.pass == lighting::pass::kGBuffer ||
            timing.pass == lighting::pass::kExactSurface || timing.pass == pass::kTotal)
            continue;
        if (stage.samplesMs.size() < timing.samplesMs.size())
            stage.samplesMs.resize(timing.samplesMs.size(), 0.0);
        for (size_t r = 0; r < timing.samplesMs.size(); ++r)
            stage.samplesMs[r] += timing.samplesMs[r];
    }
    return stage;
}

} // namespace

double PassTiming::medianMs() const {
    if (samplesMs.empty())
        return 0.0;
    std::vector<double> sorted = samplesMs;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}
double PassTiming::minMs() const {
    return samplesMs.empty() ? 0.0 : *std::min_element(samplesMs.begin(), samplesMs.end());
}
double PassTiming::maxMs() const {
    return samplesMs.empty() ? 0.0 : *std::max_element(samplesMs.begin(), samplesMs.end());
}

void addRepetition(std::vector<PassTiming>& passes,
                   const std::vector<std::pair<std::string, double>>& repetition) {
    // Pairs, not structured bindings: the lambdas capture the name, which clang 14 (the
    // sanitizer and fuzzer builds) refuses for bindings.
    std::vector<std::pair<std::string, double>> merged;
    for (const std::pair<std::string, double>& timing : repetition) {
        auto it = std::find_if(merged.begin(), merged.end(),
                               [&](const auto& m) { return m.first == timing.first; });
        if (it == merged.end())
            merged.push_back(timing);
        else
            it->second += timing.second;
    }
    for (const std::pair<std::string, double>& timing : merged) {
        auto it = std::find_if(passes.begin(), passes.end(),
                               [&](const PassTiming& t) { return t.pass == timing.first; });
        if (it == passes.end()) {
            passes.push_back({timing.first, {}});
            it = passes.end() - 1;
        }
        it->samplesMs.push_back(timing.second);
    }
}

RunMetrics measureRun(std::vector<PassTiming> passes, const std::vector<uint32_t>& evaluated,
                      const std::vector<uint32_t>& oracle, const std::vector<uint8_t>& litPixels,
                      double bytesPerPixel, double allocatedBytesPerPixel,
                      std::optional<ErrorMetrics> error) {
    RunMetrics metrics;
    metrics.stage = stageTiming(passes);
    metrics.passes = std::move(passes);
    metrics.lightEvaluations = sum(evaluated, litPixels);
    metrics.oracleLightEvaluations = sum(oracle, litPixels);
    metrics.countedPixels = litPixels.empty()
                                ? uint64_t(evaluated.size())
                                : uint64_t(std::count(litPixels.begin(), litPixels.end(), 1));
    if (metrics.countedPixels < evaluated.size())
        metrics.lightCountsNote =
            "the stage lights " + std::to_string(metrics.countedPixels) + " of the " +
            std::to_string(evaluated.size()) +
            " pixels (its reduced-resolution samples) and filters the rest; light evaluations "
            "and the oracle are both counted over those pixels, so culling efficiency compares "
            "the same samples";
    metrics.cullingEfficiency =
        metrics.lightEvaluations > 0
            ? double(metrics.oracleLightEvaluations) / double(metrics.lightEvaluations)
            : 1.0;
    metrics.bytesPerPixel = bytesPerPixel;
    metrics.allocatedBytesPerPixel = allocatedBytesPerPixel;
    metrics.error = error;
    return metrics;
}

void RunMetrics::setSimtModel(const std::map<std::string, std::string>& stageParameters) {
    const auto slots = stageParameters.find(metric::kSimtLaneSlots);
    if (slots == stageParameters.end()) {
        simtLaneSlots.reset();
        simtEfficiency.reset();
        return;
    }
    simtLaneSlots = std::stoull(slots->second);
    simtEfficiency =
        *simtLaneSlots > 0 ? double(oracleLightEvaluations) / double(*simtLaneSlots) : 1.0;
}

std::vector<NamedFigure> RunMetrics::errorFigures() const {
    if (!error)
        return {};
    return {{metric::kRmse, error->rmse},
            {metric::kRelativeRmse, error->relativeRmse},
            {metric::kPsnr, error->psnr},
            {metric::kMaxAbs, error->maxAbs},
            {metric::kRelativeMean, error->relativeMean},
            {metric::kP99Abs, error->p99Abs},
            {metric::kFlip, error->flip ? *error->flip : std::numeric_limits<double>::quiet_NaN()}};
}

std::vector<std::string> runFigureColumns() {
    std::vector<std::string> columns = {metric::kLightEvaluations,  metric::kOracleLightEvaluations,
                                        metric::kCullingEfficiency, metric::kCountedPixels,
                                        metric::kSimtLaneSlots,     metric::kSimtEfficiency,
                                        metric::kBytesPerPixel};
    RunMetrics withError;
    withError.error = ErrorMetrics{};
    for (const NamedFigure& figure : withError.errorFigures())
        columns.push_back(figure.name);
    columns.push_back(metric::kFlipUnavailable);
    return columns;
}

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
