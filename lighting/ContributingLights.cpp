#include "lighting/ContributingLights.h"

#include <algorithm>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace lighting {

void ContributingLights::build(const gbuffer::GBuffer& gb,
                               const std::vector<LightInView<float>>& lights) {
    mWidth = gb.width();
    mHeight = gb.height();
    const int width = mWidth;
    mOffsets.assign(size_t(width) * mHeight + 1, 0);
    mRowLists.resize(size_t(mHeight));
    // Pass 1, rows in parallel: each row's lists into its own vector, each pixel's count into
    // mOffsets[pixel + 1] (written by that row's task only).
    tbb::parallel_for(0, mHeight, [&](int y) {
        std::vector<uint32_t>& row = mRowLists[size_t(y)];
        row.clear();
        for (int x = 0; x < width; ++x) {
            gbuffer::Surface point;
            if (!gb.surfaceAt(x, y, point))
                continue;
            const glm::vec3 toViewer = glm::normalize(-point.positionView);
            const size_t before = row.size();
            for (uint32_t light = 0; light < lights.size(); ++light)
                if (contributes(evaluateLight(point, toViewer, lights[light])))
                    row.push_back(light);
            mOffsets[size_t(y) * width + x + 1] = uint32_t(row.size() - before);
        }
    });
    // Pass 2: prefix sum in pixel order, then each row's lists copied to its place.
    uint64_t total = 0;
    for (size_t pixel = 1; pixel < mOffsets.size(); ++pixel) {
        total += mOffsets[pixel];
        if (total >= uint64_t(UINT32_MAX))
            throw std::length_error("ContributingLights: too many (pixel, light) pairs");
        mOffsets[pixel] = uint32_t(total);
    }
    mIndices.resize(size_t(total));
    tbb::parallel_for(0, mHeight, [&](int y) {
        const std::vector<uint32_t>& row = mRowLists[size_t(y)];
        std::copy(row.begin(), row.end(), mIndices.begin() + mOffsets[size_t(y) * width]);
    });
}

} // namespace lighting
