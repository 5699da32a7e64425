#include "lighting/lists/ContributingLights.h"

#include <tbb/parallel_for.h>

namespace lighting {

void ContributingLights::build(const gbuffer::GBuffer& gb,
                               const std::vector<LightInView<float>>& lights) {
    mWidth = gb.width();
    mHeight = gb.height();
    const int width = mWidth;
    mCounts.assign(size_t(width) * mHeight, 0);
    mRowLists.resize(size_t(mHeight));
    // Rows in parallel: each row's lists into its own vector, each pixel's count into
    // mCounts[pixel] (written by that row's task only); then concatenated in pixel order.
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
            mCounts[size_t(y) * width + x] = uint32_t(row.size() - before);
        }
    });
    mLists.assign(mCounts, mRowLists);
}

} // namespace lighting
