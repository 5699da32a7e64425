// Test helpers for exact stages: the identity check (at every pixel, every contributing light is
// AMONG the lights the stage evaluated there, not merely as many lights) and a bitwise image
// comparison. Counts can hide a dropped light behind a non-contributing one that was evaluated
// instead; the identity check cannot be fooled that way. The evaluated lights come from the
// stage's light trace (StageResult::traceLights), the contributing ones from
// lighting::ContributingLights on the same G-buffer.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "lighting/ContributingLights.h"
#include "lighting/ShadingStage.h"

namespace stagecheck {

// Shades with the light trace on.
inline lighting::StageResult shadeTraced(lighting::ShadingStage& stage,
                                         const lighting::StageInputs& inputs) {
    lighting::StageResult result;
    result.traceLights = true;
    stage.shade(inputs, result);
    return result;
}

// Success when, at every pixel, every light of `contributing` is in result.lightTrace (and the
// trace never lists more lights than lightsEvaluated counts). With `ascending`, each pixel's trace
// must also be strictly ascending (the order the sum was made in). Failures name up to five
// pixels and the lights missing there.
inline ::testing::AssertionResult
everyContributingLightEvaluated(const lighting::StageResult& result,
                                const lighting::ContributingLights& contributing, bool ascending) {
    const size_t pixelCount = size_t(contributing.width()) * contributing.height();
    if (result.lightTrace.size() != pixelCount)
        return ::testing::AssertionFailure()
               << "the stage left no light trace (" << result.lightTrace.size() << " lists for "
               << pixelCount << " pixels)";
    std::ostringstream failures;
    size_t badPixels = 0, missingPairs = 0;
    std::vector<uint32_t> evaluated;
    for (size_t pixel = 0; pixel < pixelCount; ++pixel) {
        const std::vector<uint32_t>& trace = result.lightTrace[pixel];
        const auto needed = contributing.lightsOf(pixel);
        std::string problem;
        if (trace.size() > result.lightsEvaluated[pixel])
            problem = "traces " + std::to_string(trace.size()) + " lights but counts " +
                      std::to_string(result.lightsEvaluated[pixel]);
        if (ascending && std::adjacent_find(trace.begin(), trace.end(), [](uint32_t a, uint32_t b) {
                             return a >= b;
                         }) != trace.end())
            problem += (problem.empty() ? "" : "; ") + std::string("lights not ascending");
        evaluated.assign(trace.begin(), trace.end());
        std::sort(evaluated.begin(), evaluated.end());
        std::vector<uint32_t> missing;
        std::set_difference(needed.begin(), needed.end(), evaluated.begin(), evaluated.end(),
                            std::back_inserter(missing));
        missingPairs += missing.size();
        if (!missing.empty()) {
            problem += (problem.empty() ? "" : "; ") + std::to_string(missing.size()) + " of " +
                       std::to_string(needed.size()) + " contributing lights not evaluated (";
            for (size_t i = 0; i < missing.size() && i < 4; ++i)
                problem += (i ? " " : "") + std::to_string(missing[i]);
            problem += missing.size() > 4 ? " ...)" : ")";
        }
        if (!problem.empty() && badPixels++ < 5)
            failures << "\n  pixel (" << pixel % contributing.width() << ", "
                     << pixel / contributing.width() << "): " << problem << " (evaluated "
                     << trace.size() << ")";
    }
    if (badPixels == 0)
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << badPixels << " pixels fail, " << missingPairs
           << " contributing (pixel, light) pairs dropped:" << failures.str();
}

// Success when every radiance value has the same bits in both images; failures name up to five
// pixels with both values.
inline ::testing::AssertionResult bitwiseEqualImages(const lighting::StageResult& image,
                                                     const lighting::StageResult& expected) {
    std::ostringstream failures;
    size_t differing = 0;
    for (int ch = 0; ch < 3; ++ch) {
        if (image.radiance[ch].size() != expected.radiance[ch].size())
            return ::testing::AssertionFailure() << "image sizes differ";
        for (size_t pixel = 0; pixel < expected.radiance[ch].size(); ++pixel) {
            const float a = image.radiance[ch][pixel], b = expected.radiance[ch][pixel];
            if (std::bit_cast<uint32_t>(a) != std::bit_cast<uint32_t>(b) && differing++ < 5)
                failures << "\n  pixel (" << pixel % expected.width << ", "
                         << pixel / expected.width << ") channel " << ch << ": " << a << " vs " << b
                         << " (difference " << a - b << ")";
        }
    }
    if (differing == 0)
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << differing << " values differ:" << failures.str();
}

} // namespace stagecheck
