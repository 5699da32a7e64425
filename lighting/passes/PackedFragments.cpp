#include "lighting/passes/PackedFragments.h"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "gbuffer/visibility/VisibilityPass.h"

namespace lighting {

void PackedFragments::build(const gbuffer::FragmentLayers& layers) {
    mWidth = layers.width();
    const int height = layers.height();
    // Rows in parallel: each row's count, the offsets, then each row's fragments at its offset.
    auto forEachFragment = [&](int y, const auto& visit) {
        for (const uint32_t x : layers.upperColumns(y)) {
            const size_t pixel = size_t(y) * size_t(mWidth) + x;
            for (int k = 1; k < layers.layerCount(); ++k)
                if (layers.codes(k)[pixel] != gbuffer::VisibilityPass::kNoTriangle)
                    visit(pixel, k);
        }
    };
    mRowFirst.assign(size_t(height) + 1, 0);
    tbb::parallel_for(0, height, [&](int y) {
        size_t count = 0;
        forEachFragment(y, [&](size_t, int) { ++count; });
        mRowFirst[size_t(y) + 1] = count;
    });
    for (int y = 0; y < height; ++y)
        mRowFirst[size_t(y) + 1] += mRowFirst[size_t(y)];
    const size_t total = mRowFirst[size_t(height)];
    mPixels.resize(total);
    mLayers.resize(total);
    mOrder.resize(total);
    tbb::parallel_for(0, height, [&](int y) {
        size_t i = mRowFirst[size_t(y)];
        forEachFragment(y, [&](size_t pixel, int k) {
            mPixels[i] = uint32_t(pixel);
            mLayers[i++] = uint8_t(k);
        });
    });

    // Shading order: per band of block rows (in parallel), a counting sort of its fragments by
    // block column (stable, so list order within a block).
    const int blocksX = (mWidth + kBlockPixels - 1) / kBlockPixels;
    const int bands = (height + kBlockPixels - 1) / kBlockPixels;
    tbb::parallel_for(0, bands, [&](int band) {
        const size_t begin = mRowFirst[size_t(band * kBlockPixels)];
        const size_t end = mRowFirst[size_t(std::min((band + 1) * kBlockPixels, height))];
        std::vector<size_t> next(size_t(blocksX) + 1, begin);
        for (size_t i = begin; i < end; ++i)
            ++next[size_t(x(i)) / kBlockPixels + 1];
        for (size_t b = 1; b < next.size(); ++b)
            next[b] += next[b - 1] - begin;
        for (size_t i = begin; i < end; ++i)
            mOrder[next[size_t(x(i)) / kBlockPixels]++] = uint32_t(i);
    });
}

} // namespace lighting
