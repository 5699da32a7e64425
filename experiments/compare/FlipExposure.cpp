// FlipExposure: where HDR-ꟻLIP's exposures come from (EGSR 2021, section 3): the tone mapper's
// input that it maps to 0.85, and the reference's maximum and median luminance.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "experiments/compare/FlipInternal.h"

namespace experiments::compare::flip {

namespace {

// An exposure bracket wider than this many stops is unusual (a reference spanning 2^32 in
// luminance); it is computed, but the cost grows with it, so a warning says so.
constexpr int kManyExposures = 32;
// More exposures than this are refused: finite float luminances span at most 2^277, so only a
// given count or range can ask for more, and it would run for hours.
constexpr int kMaxExposures = 1024;

std::string numberText(float v) {
    std::ostringstream text;
    text << v;
    return text.str();
}

} // namespace

float toneMapperInputForTarget() {
    // (c0 x^2 + c1 x + c2) / (c3 x^2 + c4 x + c5) = t  <=>  a x^2 + b x + c = 0 with a = c0 -
    // t c3, and so on; the larger root. In float, as the reference implementation.
    const float t = kExposureTargetValue;
    const float a = kAces[0] - t * kAces[3];
    const float b = kAces[1] - t * kAces[4];
    const float c = kAces[2] - t * kAces[5];
    if (a == 0.0f)
        return -c / b;
    const float half = -0.5f * (b / a);
    return half + std::sqrt(half * half - c / a);
}

bool luminanceStatistics(const float* r, const float* g, const float* b, std::size_t count,
                         const unsigned char* valid, ExposureStatistics& out) {
    out = {};
    std::vector<float> luminances;
    luminances.reserve(count);
    for (std::size_t i = 0; i < count; ++i)
        if (!valid || valid[i]) {
            const float luminance = kLuminanceWeights[0] * std::max(r[i], 0.0f) +
                                    kLuminanceWeights[1] * std::max(g[i], 0.0f) +
                                    kLuminanceWeights[2] * std::max(b[i], 0.0f);
            // Channels near FLT_MAX can sum past it: the largest float keeps log2 finite.
            luminances.push_back(std::min(luminance, std::numeric_limits<float>::max()));
        }
    out.pixelsCounted = luminances.size();
    if (luminances.empty())
        return false;
    out.maxLuminance = *std::max_element(luminances.begin(), luminances.end());
    if (!(out.maxLuminance > 0.0f))
        return false;
    // The upper median (element n / 2 of the sorted values), as NVIDIA's tool takes it.
    auto median = [](std::vector<float>& values) {
        const auto middle = values.begin() + values.size() / 2;
        std::nth_element(values.begin(), middle, values.end());
        return *middle;
    };
    out.medianLuminance = median(luminances);
    if (!(out.medianLuminance > 0.0f)) {
        // Over half the pixels are black: the published stop exposure would be log2(x / 0).
        // The median of the lit pixels is what a viewer's eye adapts to in such a frame.
        std::erase_if(luminances, [](float v) { return !(v > 0.0f); });
        out.medianLuminance = median(luminances);
        out.usedPositiveMedian = true;
    }
    return true;
}

ExposureBracket exposureBracket(const LuminanceSource& reference, const LuminanceSource& test,
                                std::optional<float> givenStart, std::optional<float> givenStop,
                                std::optional<int> givenCount, std::vector<std::string>& warnings) {
    for (const std::optional<float>& given : {givenStart, givenStop})
        if (given && !std::isfinite(*given))
            throw std::invalid_argument("ꟻLIP: the start and stop exposures must be finite");
    if (givenCount && *givenCount < 1)
        throw std::invalid_argument("ꟻLIP: the exposure count must be at least 1, not " +
                                    std::to_string(*givenCount));
    float start = 0.0f, stop = 0.0f;
    if (!givenStart || !givenStop) {
        ExposureStatistics stats;
        const char* source = "reference";
        bool found = luminanceStatistics(reference.r, reference.g, reference.b, reference.count,
                                         reference.valid, stats);
        if (!found) {
            source = "test";
            found = luminanceStatistics(test.r, test.g, test.b, test.count, test.valid, stats);
        }
        if (!found) {
            warnings.push_back("neither image has a pixel of positive luminance (both are black "
                               "where finite): exposures 0 to 0");
        } else {
            if (std::string(source) == "test")
                warnings.push_back("the reference has no pixel of positive luminance: the "
                                   "exposures come from the test image's luminance");
            if (stats.usedPositiveMedian)
                warnings.push_back(
                    std::string("the ") + source +
                    " image's median luminance is 0 (over half its pixels are black): the stop "
                    "exposure uses the median of its positive luminances, " +
                    numberText(stats.medianLuminance) + ", instead of log2(x / 0)");
            const float target = toneMapperInputForTarget();
            start = std::log2(target / stats.maxLuminance);
            stop = std::log2(target / stats.medianLuminance);
        }
    }
    ExposureBracket bracket;
    bracket.start = givenStart.value_or(start);
    bracket.stop = givenStop.value_or(stop);
    if (bracket.start > bracket.stop)
        throw std::invalid_argument("ꟻLIP: the start exposure (" + numberText(bracket.start) +
                                    ") is above the stop exposure (" + numberText(bracket.stop) +
                                    ")");
    const float range = bracket.stop - bracket.start;
    if (!givenCount && !(range <= float(kMaxExposures)))
        throw std::invalid_argument("ꟻLIP: exposures " + numberText(bracket.start) + " to " +
                                    numberText(bracket.stop) + " would take over " +
                                    std::to_string(kMaxExposures) + " exposures");
    bracket.count = givenCount.value_or(static_cast<int>(std::max(2.0f, std::ceil(range))));
    if (bracket.count > kMaxExposures)
        throw std::invalid_argument("ꟻLIP: at most " + std::to_string(kMaxExposures) +
                                    " exposures, not " + std::to_string(bracket.count));
    if (bracket.count > kManyExposures)
        warnings.push_back(std::to_string(bracket.count) + " exposures (the reference spans 2^" +
                           numberText(bracket.stop - bracket.start) +
                           " in luminance): the cost grows with the count");
    return bracket;
}

} // namespace experiments::compare::flip
