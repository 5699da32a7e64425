#include "lighting/lists/ContributingLights.h"

#include <algorithm>
#include <numeric>

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/lists/LightGrid.h"

namespace lighting {

template <class Candidates>
void ContributingLights::buildFrom(const gbuffer::GBuffer& gb,
                                   const std::vector<LightInView<float>>& lights,
                                   const Candidates& candidates) {
    mWidth = gb.width();
    mHeight = gb.height();
    const int width = mWidth;
    mCounts.assign(size_t(width) * mHeight, 0);
    mRowLists.resize(size_t(mHeight));
    // Rows in parallel: each row's lists into its own vector, each pixel's count into
    // mCounts[pixel] (written by that row's task only); then concatenated in pixel order.
    tbb::parallel_for(0, mHeight, [&](int y) {
        std::vector<uint32_t>& row = mRowLists[size_t(y)];
        std::vector<uint32_t> tested;
        row.clear();
        for (int x = 0; x < width; ++x) {
            gbuffer::Surface point;
            if (!gb.surfaceAt(x, y, point))
                continue;
            const glm::vec3 toViewer = glm::normalize(-point.positionView);
            const size_t before = row.size();
            candidates(point.positionView, tested);
            for (uint32_t light : tested)
                if (contributes(evaluateLight(point, toViewer, lights[light])))
                    row.push_back(light);
            mCounts[size_t(y) * width + x] = uint32_t(row.size() - before);
        }
    });
    mLists.assign(mCounts, mRowLists);
}

void ContributingLights::build(const gbuffer::GBuffer& gb,
                               const std::vector<LightInView<float>>& lights) {
    const auto box = surfaceBox<gbuffer::Surface>(
        gb.width(), gb.height(),
        [&gb](int x, int y, gbuffer::Surface& s) { return gb.surfaceAt(x, y, s); });
    LightGrid grid;
    if (box)
        grid.build(boundingSpheresView(lights), box->first, box->second);
    // The grid's bounded candidates and the unbounded lights are each ascending and disjoint:
    // merged, they are ascending, the order the lists (and `ideal`'s sums) need.
    buildFrom(gb, lights, [&grid](glm::vec3 pointView, std::vector<uint32_t>& tested) {
        const std::span<const uint32_t> bounded = grid.candidatesAt(pointView);
        const std::span<const uint32_t> everywhere = grid.everywhere();
        tested.resize(bounded.size() + everywhere.size());
        std::merge(bounded.begin(), bounded.end(), everywhere.begin(), everywhere.end(),
                   tested.begin());
    });
}

void ContributingLights::buildBrute(const gbuffer::GBuffer& gb,
                                    const std::vector<LightInView<float>>& lights) {
    buildFrom(gb, lights, [&lights](glm::vec3, std::vector<uint32_t>& tested) {
        if (tested.size() != lights.size()) {
            tested.resize(lights.size());
            std::iota(tested.begin(), tested.end(), 0u);
        }
    });
}

} // namespace lighting
