// Test helpers for exact stages: the identity check (at every pixel, every contributing light is
// AMONG the lights the stage evaluated there, not merely as many lights) and a bitwise image
// comparison. Counts can hide a dropped light behind a non-contributing one that was evaluated
// instead; the identity check cannot be fooled that way. The evaluated lights come from the
// stage's light trace (StageResult::traceLights), the contributing ones from
// lighting::ContributingLights on the same G-buffer; for blended fragments from the stage's
// blendedTrace and BlendedPass::contributingLights on each fragment's surface. Also the relative
// RMSE the approximate and multisampled stages' tests measure with.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "lighting/ShadingStage.h"
#include "lighting/lists/ContributingLights.h"
#include "lighting/passes/BlendedPass.h"

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

// Per pixel, the blended fragments a stage composites there (lighting/passes/BlendedPass.h), each
// with its contributing lights (every light tested on the fragment's surface, ascending), over the
// opaque depth `inputs.gbuffer` holds: the expectation of the blended identity check.
using BlendedFragments = std::vector<std::vector<lighting::StageResult::BlendedFragmentTrace>>;
inline BlendedFragments blendedContributingLights(const lighting::StageInputs& inputs) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    BlendedFragments fragments(size_t(gb.width()) * size_t(gb.height()));
    lighting::BlendedPass pass;
    if (!pass.prepare(inputs))
        return fragments;
    pass.forEachFragment(gb.depth(), [&](const raster::Fragment& fragment, uint32_t triangle,
                                         const gbuffer::Surface& surface, float) {
        const std::span<const uint32_t> lights = pass.contributingLights(surface);
        fragments[size_t(fragment.y) * size_t(gb.width()) + size_t(fragment.x)].push_back(
            {triangle, fragment.frontFacing, {lights.begin(), lights.end()}});
    });
    return fragments;
}

// The identity check of blended fragments: at every pixel the stage traced (blendedTrace) the
// same fragments as `expected` (by triangle and facing; any order, since the reference sorts
// per pixel), each fragment's traced lights include its contributing ones, the opaque and
// blended traces together never list more lights than lightsEvaluated counts, and with
// `ascending` each fragment's lights are strictly ascending. Failures name up to five pixels.
inline ::testing::AssertionResult
everyBlendedContributingLightEvaluated(const lighting::StageResult& result,
                                       const BlendedFragments& expected, bool ascending) {
    if (result.blendedTrace.size() != expected.size())
        return ::testing::AssertionFailure()
               << "the stage left no blended light trace (" << result.blendedTrace.size()
               << " lists for " << expected.size() << " pixels)";
    std::ostringstream failures;
    size_t badPixels = 0, missingPairs = 0, fragmentCount = 0;
    using Trace = lighting::StageResult::BlendedFragmentTrace;
    const auto byTriangle = [](const Trace* a, const Trace* b) {
        return a->triangle != b->triangle ? a->triangle < b->triangle
                                          : a->frontFacing < b->frontFacing;
    };
    std::vector<const Trace*> traced, wanted;
    std::vector<uint32_t> evaluated, missing;
    for (size_t pixel = 0; pixel < expected.size(); ++pixel) {
        std::string problem;
        traced.clear();
        wanted.clear();
        size_t tracedLights =
            pixel < result.lightTrace.size() ? result.lightTrace[pixel].size() : 0;
        for (const Trace& t : result.blendedTrace[pixel]) {
            traced.push_back(&t);
            tracedLights += t.lights.size();
        }
        for (const Trace& t : expected[pixel])
            wanted.push_back(&t);
        fragmentCount += wanted.size();
        std::sort(traced.begin(), traced.end(), byTriangle);
        std::sort(wanted.begin(), wanted.end(), byTriangle);
        if (tracedLights > result.lightsEvaluated[pixel])
            problem = "traces " + std::to_string(tracedLights) + " lights but counts " +
                      std::to_string(result.lightsEvaluated[pixel]);
        const bool sameFragments =
            traced.size() == wanted.size() &&
            std::equal(traced.begin(), traced.end(), wanted.begin(), [](auto* a, auto* b) {
                return a->triangle == b->triangle && a->frontFacing == b->frontFacing;
            });
        if (!sameFragments)
            problem += (problem.empty() ? "" : "; ") + std::to_string(traced.size()) +
                       " blended fragments traced, " + std::to_string(wanted.size()) + " expected";
        for (size_t i = 0; sameFragments && i < wanted.size(); ++i) {
            const std::vector<uint32_t>& lights = traced[i]->lights;
            if (ascending &&
                std::adjacent_find(lights.begin(), lights.end(),
                                   [](uint32_t a, uint32_t b) { return a >= b; }) != lights.end())
                problem += (problem.empty() ? "" : "; ") + std::string("triangle ") +
                           std::to_string(wanted[i]->triangle) + ": lights not ascending";
            evaluated.assign(lights.begin(), lights.end());
            std::sort(evaluated.begin(), evaluated.end());
            missing.clear();
            std::set_difference(wanted[i]->lights.begin(), wanted[i]->lights.end(),
                                evaluated.begin(), evaluated.end(), std::back_inserter(missing));
            missingPairs += missing.size();
            if (!missing.empty()) {
                problem += (problem.empty() ? "" : "; ") + std::string("triangle ") +
                           std::to_string(wanted[i]->triangle) + ": " +
                           std::to_string(missing.size()) + " of " +
                           std::to_string(wanted[i]->lights.size()) +
                           " contributing lights not evaluated (";
                for (size_t k = 0; k < missing.size() && k < 4; ++k)
                    problem += (k ? " " : "") + std::to_string(missing[k]);
                problem += missing.size() > 4 ? " ...)" : ")";
            }
        }
        if (!problem.empty() && badPixels++ < 5)
            failures << "\n  pixel (" << pixel % size_t(result.width) << ", "
                     << pixel / size_t(result.width) << "): " << problem;
    }
    if (badPixels == 0)
        return ::testing::AssertionSuccess() << fragmentCount << " blended fragments checked";
    return ::testing::AssertionFailure()
           << badPixels << " pixels fail, " << missingPairs
           << " contributing (blended fragment, light) pairs dropped:" << failures.str();
}

// RMSE over every pixel and channel divided by the RMS of `truth` (a black truth divides by
// 1e-30: an image that differs from it never scores 0).
inline double relativeRmse(const lighting::StageResult& image, const lighting::StageResult& truth) {
    double error = 0.0, energy = 0.0;
    for (int c = 0; c < 3; ++c)
        for (size_t p = 0; p < truth.radiance[c].size(); ++p) {
            const double d = double(image.radiance[c][p]) - double(truth.radiance[c][p]);
            error += d * d;
            energy += double(truth.radiance[c][p]) * double(truth.radiance[c][p]);
        }
    return std::sqrt(error / std::max(energy, 1e-30));
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
