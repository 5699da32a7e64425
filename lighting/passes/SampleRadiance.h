// SampleRadiance: the per-sample colour buffer of the forward stages' hardware-style MSAA
// (inputs.samples > 1) and of the blended pass in a layered multisampled run (BlendedPass.h):
// linear HDR R, G, B per sample, pixel-major like the rasterizer's depth (plane[(y * width + x) *
// samples + s]), and its resolve into a StageResult.
//
// How it is written (FragmentShading.h): a fragment is shaded ONCE (its surface at the pixel
// centre, raster/Rasterizer.h) and its result is applied to each sample of its coverage mask
// (FragmentApply: Replace overwrites those samples, Add adds to them, Over composites over them).
// Background samples stay zero. Resolve: a pixel's radiance is the mean of its samples, summed in
// sample order and divided by the sample count, the box filter of hardware resolves.
//
// Light trace (StageResult::traceLights, tests only): one list per sample, written as the
// pixel's list is without multisampling (Replace assigns, Add appends); the resolve gives each
// pixel the ascending union of its samples' lists: the lights of the fragments that ended up
// visible in some sample. lightsEvaluated stays per pixel and per fragment (FragmentShading).
//
// Filled on demand (resetUnfilled(), the blended pass of a layered multisampled frame,
// BlendedPass.h): the planes are sized but not cleared, and a pixel's samples all take the
// radiance the StageResult holds at that pixel when the first fragment is applied there
// (fillOnce()); only those pixels are ever read (filled()), so a frame pays for the pixels its
// blended fragments touch, not for the screen.
//
// Memory: 12 bytes per sample (1280x720 at 4 samples: 44 MB), cleared per frame by reset().
// Thread safety: each sample is written by the task owning its pixel's raster tile; reset() and
// resolve() from the stage's thread (resolve is parallel over rows, deterministic).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "lighting/ShadingStage.h"

namespace lighting {

class SampleRadiance {
public:
    // Sizes and zeroes the planes for width x height pixels of `samples` samples; with `tracing`
    // one empty light list per sample, else none.
    void reset(int width, int height, int samples, bool tracing);
    // Sizes the planes without clearing them and marks every pixel unfilled (see the file
    // comment); no light trace.
    void resetUnfilled(int width, int height, int samples);
    bool fillsOnDemand() const { return !mFilled.empty(); }
    // Filled on demand: on the pixel's first call, sets its samples to `result`'s radiance there.
    void fillOnce(size_t pixelIndex, const StageResult& result) {
        if (mFilled[pixelIndex])
            return;
        mFilled[pixelIndex] = 1;
        for (int c = 0; c < 3; ++c)
            std::fill_n(pixel(c, pixelIndex), mSamples, result.radiance[c][pixelIndex]);
    }
    bool filled(size_t pixelIndex) const { return mFilled[pixelIndex] != 0; }
    // "Over" at the samples of `coverage`: sample = alpha * lit + (1 - alpha) * sample, after
    // fillOnce() when filled on demand (the blended composite, BlendedPass.h).
    void over(size_t pixelIndex, unsigned coverage, const glm::vec3& lit, float alpha,
              const StageResult& result) {
        if (fillsOnDemand())
            fillOnce(pixelIndex, result);
        for (int c = 0; c < 3; ++c) {
            float* sample = pixel(c, pixelIndex);
            for (int s = 0; s < mSamples; ++s)
                if (coverage >> s & 1u)
                    sample[s] = alpha * lit[c] + (1.0f - alpha) * sample[s];
        }
    }
    int samples() const { return mSamples; }
    // The first of the pixel's samples in channel `channel`.
    float* pixel(int channel, size_t pixelIndex) {
        return mPlanes[channel].data() + pixelIndex * size_t(mSamples);
    }
    bool tracing() const { return !mTrace.empty(); }
    std::vector<uint32_t>& traceOf(size_t pixelIndex, int sample) {
        return mTrace[pixelIndex * size_t(mSamples) + size_t(sample)];
    }
    // Writes the resolved radiance (and, when tracing, each pixel's union of lights) into
    // `result` (sized already), replacing what it held; timed as pass::kResolve.
    void resolve(StageResult& result) const;

private:
    int mSamples = 1;
    size_t mPixelCount = 0;
    int mWidth = 0;
    std::vector<float> mPlanes[3];
    std::vector<std::vector<uint32_t>> mTrace;
    std::vector<uint8_t> mFilled; // filled on demand only: per pixel
};

} // namespace lighting
