#include "lighting/passes/SampleRadiance.h"

#include <algorithm>
#include <iterator>

#include <tbb/parallel_for.h>

#include "lighting/passes/PassNames.h"

namespace lighting {

void SampleRadiance::reset(int width, int height, int samples, bool tracing) {
    mSamples = samples;
    mWidth = width;
    mPixelCount = size_t(width) * size_t(height);
    for (std::vector<float>& plane : mPlanes)
        plane.assign(mPixelCount * size_t(samples), 0.0f);
    mTrace.clear();
    if (tracing)
        mTrace.resize(mPixelCount * size_t(samples));
    mFilled.clear();
}

void SampleRadiance::resetUnfilled(int width, int height, int samples) {
    mSamples = samples;
    mWidth = width;
    mPixelCount = size_t(width) * size_t(height);
    for (std::vector<float>& plane : mPlanes)
        plane.resize(mPixelCount * size_t(samples));
    mTrace.clear();
    mFilled.assign(mPixelCount, 0);
}

void SampleRadiance::resolve(StageResult& result) const {
    PassTimer timer(result, pass::kResolve);
    const int height = mWidth > 0 ? int(mPixelCount / size_t(mWidth)) : 0;
    const size_t stride = size_t(mSamples);
    const float invSamples = 1.0f / float(mSamples);
    tbb::parallel_for(0, height, [&](int y) {
        std::vector<uint32_t> merged, next;
        for (size_t pixel = size_t(y) * size_t(mWidth); pixel < size_t(y + 1) * size_t(mWidth);
             ++pixel) {
            for (int c = 0; c < 3; ++c) {
                const float* samples = mPlanes[c].data() + pixel * stride;
                float sum = 0.0f;
                for (size_t s = 0; s < stride; ++s)
                    sum += samples[s];
                result.radiance[c][pixel] = sum * invSamples;
            }
            if (mTrace.empty() || !result.tracing())
                continue;
            merged.clear();
            for (size_t s = 0; s < stride; ++s) {
                std::vector<uint32_t> sorted = mTrace[pixel * stride + s];
                std::sort(sorted.begin(), sorted.end());
                next.clear();
                std::set_union(merged.begin(), merged.end(), sorted.begin(), sorted.end(),
                               std::back_inserter(next));
                merged.swap(next);
            }
            merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
            result.lightTrace[pixel] = merged;
        }
    });
}

} // namespace lighting
