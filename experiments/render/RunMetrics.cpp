#include "experiments/render/RunMetrics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "experiments/output/ImageOutput.h"
#include "lighting/passes/PassNames.h"

namespace experiments {

namespace {

// The sum of counts over the pixels marked in mask (every pixel when mask is empty).
uint64_t sum(const std::vector<uint32_t>& counts, const std::vector<uint8_t>& mask) {
    uint64_t total = 0;
    for (size_t i = 0; i < counts.size(); ++i)
        if (mask.empty() || mask[i])
            total += counts[i];
    return total;
}

// The stage's own time per repetition: every pass but the G-buffer's, the exact surface's, the
// post-process anti-aliasing's (the runner's, after the stage) and the total.
PassTiming stageTiming(const std::vector<PassTiming>& passes) {
    PassTiming stage;
    stage.pass = pass::kStage;
    for (const PassTiming& timing : passes) {
        if (timing.pass == lighting::pass::kGBuffer ||
            timing.pass == lighting::pass::kExactSurface ||
            timing.pass == lighting::pass::kPostAa || timing.pass == pass::kTotal)
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
    constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();
    return {{metric::kRmse, error->rmse},
            {metric::kRelativeRmse, error->relativeRmse},
            {metric::kPsnr, error->psnr},
            {metric::kMaxAbs, error->maxAbs},
            {metric::kRelativeMean, error->relativeMean},
            {metric::kP99Abs, error->p99Abs},
            {metric::kFlip, error->flip.value_or(kMissing)},
            {metric::kFlipWeightedMedian, error->flipWeightedMedian.value_or(kMissing)},
            {metric::kFlipP95, error->flipP95.value_or(kMissing)},
            {metric::kFlipP99, error->flipP99.value_or(kMissing)}};
}

std::vector<std::string> runFigureColumns() {
    std::vector<std::string> columns = {
        metric::kLightEvaluations,    metric::kOracleLightEvaluations, metric::kCullingEfficiency,
        metric::kCountedPixels,       metric::kSimtLaneSlots,          metric::kSimtEfficiency,
        metric::kBytesPerPixel,       metric::kComplexFraction,        metric::kSurfacesPerPixel,
        metric::kGBufferBytes,        metric::kGBufferAllocatedBytes,  metric::kShadowMapBytes,
        metric::kShadowMisclassified, metric::kMemoryEstimateBytes,    metric::kPeakRssBytes,
        metric::kCoveredFraction};
    RunMetrics withError;
    withError.error = ErrorMetrics{};
    for (const NamedFigure& figure : withError.errorFigures())
        columns.push_back(figure.name);
    columns.push_back(metric::kFlipUnavailable);
    // How many pixels of the image and of its reference hold a NaN or Inf channel: when either
    // is non-zero the error figures of the row are inf (null in the table) and unreliable.
    columns.push_back(metric::kNonFinitePixels);
    columns.push_back(metric::kReferenceNonFinitePixels);
    return columns;
}

} // namespace experiments
