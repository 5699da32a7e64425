#include "lighting/passes/PackedFragments.h"

#include <algorithm>

#include "gbuffer/visibility/VisibilityPass.h"

namespace lighting {

void PackedFragments::build(const gbuffer::FragmentLayers& layers) {
    mWidth = layers.width();
    mPixels.clear();
    mLayers.clear();
    mRowFirst.assign(size_t(layers.height()) + 1, 0);
    for (int y = 0; y < layers.height(); ++y) {
        mRowFirst[size_t(y)] = mPixels.size();
        for (const uint32_t x : layers.upperColumns(y)) {
            const size_t pixel = size_t(y) * size_t(mWidth) + x;
            for (int k = 1; k < layers.layerCount(); ++k)
                if (layers.codes(k)[pixel] != gbuffer::VisibilityPass::kNoTriangle) {
                    mPixels.push_back(uint32_t(pixel));
                    mLayers.push_back(uint8_t(k));
                }
        }
    }
    mRowFirst[size_t(layers.height())] = mPixels.size();

    // Shading order: per band of block rows, a counting sort of its fragments by block column
    // (stable, so list order within a block).
    mOrder.resize(mPixels.size());
    const int blocksX = (mWidth + kBlockPixels - 1) / kBlockPixels;
    std::vector<size_t> next(size_t(blocksX) + 1);
    for (int band = 0; band < layers.height(); band += kBlockPixels) {
        const size_t begin = mRowFirst[size_t(band)];
        const size_t end = mRowFirst[size_t(std::min(band + kBlockPixels, layers.height()))];
        std::fill(next.begin(), next.end(), begin);
        for (size_t i = begin; i < end; ++i)
            ++next[size_t(mPixels[i] % uint32_t(mWidth)) / kBlockPixels + 1];
        for (size_t b = 1; b < next.size(); ++b)
            next[b] += next[b - 1] - begin;
        for (size_t i = begin; i < end; ++i)
            mOrder[next[size_t(mPixels[i] % uint32_t(mWidth)) / kBlockPixels]++] = uint32_t(i);
    }
}

} // namespace lighting
