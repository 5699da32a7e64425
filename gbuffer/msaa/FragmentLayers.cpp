#include "gbuffer/msaa/FragmentLayers.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <tbb/parallel_for.h>

#include "gbuffer/msaa/UniformPixels.h"

namespace gbuffer {

const char* complexDetectionName(ComplexDetection detection) {
    return detection == ComplexDetection::Primitive ? "primitive" : "discontinuity";
}

bool parseComplexDetection(const std::string& text, ComplexDetection& detection) {
    if (text == "primitive")
        detection = ComplexDetection::Primitive;
    else if (text == "discontinuity")
        detection = ComplexDetection::Discontinuity;
    else
        return false;
    return true;
}

namespace {

// Moves values[first] to the front, the ones before it one place up (std::rotate's effect; its
// inlined form on these 8-entry arrays draws a false -Wstringop-overflow from GCC 12).
template <class T> void moveToFront(T* values, int first) {
    const T value = values[first];
    for (int k = first; k > 0; --k)
        values[k] = values[k - 1];
    values[0] = value;
}

} // namespace

void FragmentLayers::build(const VisibilityPass& visibility, const FragmentLayerOptions& options) {
    const CameraView& view = visibility.view();
    const int samples = visibility.sampleCount();
    if (samples < 2 || visibility.centreDepths().empty())
        throw std::invalid_argument("FragmentLayers: the visibility pass was not multisampled");
    if (samples != 2 && samples != 4 && samples != 8)
        throw std::invalid_argument("FragmentLayers: " + std::to_string(samples) +
                                    " samples per pixel (2, 4 or 8 are built)");
    const float clear = view.clearDepth();
    // The planes are kept between builds of one size, sample count and clear value (the upper
    // layers are then "none" except where the last build wrote, which is reset below).
    if (view.width != mWidth || view.height != mHeight || samples != mSamples ||
        !(clear == mClearDepth)) {
        mLayers.clear();
        mLayerCount = 0;
        mUpperColumns.assign(size_t(view.height), {});
    }
    mOptions = options;
    mSamples = samples;
    mWidth = view.width;
    mHeight = view.height;
    mClearDepth = clear;
    const size_t pixels = pixelCount();
    const std::span<const uint32_t> sampleCodes = visibility.codes();
    const std::span<const float> sampleDepths = visibility.centreDepths();

    // Layer 0 is written at every entry by every build; the layers above are made when a row
    // first needs them (below) and kept: "none" everywhere, then written where they have
    // fragments and reset where the last build wrote.
    mLayers.resize(size_t(samples));
    const auto makeLayer = [&](Layer& layer) {
        layer.codes.assign(pixels, VisibilityPass::kNoTriangle);
        layer.depths.assign(pixels, clear);
        layer.coverage.assign(pixels, 0);
    };
    if (mLayers[0].codes.empty())
        makeLayer(mLayers[0]);
    // Whether upper layer k exists: read by every row, set once under `makeLock` by the first
    // row that needs it (the planes are then complete before any row writes into them).
    std::array<std::atomic<bool>, raster::kMaxSamples> made{};
    for (size_t k = 0; k < mLayers.size(); ++k)
        made[k].store(!mLayers[k].codes.empty(), std::memory_order_relaxed);
    std::mutex makeLock;
    const auto ensureLayer = [&](int k) {
        if (made[size_t(k)].load(std::memory_order_acquire))
            return;
        const std::lock_guard<std::mutex> lock(makeLock);
        if (!made[size_t(k)].load(std::memory_order_relaxed)) {
            makeLayer(mLayers[size_t(k)]);
            made[size_t(k)].store(true, std::memory_order_release);
        }
    };
    mBackground.resize(pixels);
    mComplex.resize(pixels);
    mRowLayers.resize(size_t(mHeight));
    std::vector<Counts> rowCounts(static_cast<size_t>(mHeight));
    const float nearer = view.reversedZ() ? 1.0f : 0.0f;
    const bool mergeSmooth = options.detection == ComplexDetection::Discontinuity;
    const int lastLayerCount = mLayerCount;
    // The merge test's inputs: each triangle's material, and the pixel centres' NDC per column
    // and row computed once (ndcOfPixel's divisions per fragment were a fifth of the test's cost).
    const uint32_t* triangleMaterial = visibility.geometry().triangleMaterial.data();
    std::vector<float> ndcXOfColumn;
    if (mergeSmooth)
        for (int x = 0; x < mWidth; ++x)
            ndcXOfColumn.push_back(view.ndcOfPixel(x, 0).x);

    // One row; `kSamples` is the sample count as a constant, so that the loops over a mixed
    // pixel's samples are unrolled.
    auto buildRow = [&](int y, auto kSamples) {
        constexpr size_t kStride = decltype(kSamples)::value;
        // The planes as local pointers: the byte planes' stores could otherwise alias the
        // vectors' own fields and force a reload of every pointer per pixel.
        const size_t rowStart = size_t(y) * size_t(mWidth);
        const uint32_t* rowCodes = sampleCodes.data() + rowStart * kStride;
        const float* rowDepths = sampleDepths.data() + rowStart * kStride;
        uint32_t* mainCodes = mLayers[0].codes.data() + rowStart;
        float* mainDepths = mLayers[0].depths.data() + rowStart;
        uint8_t* mainCoverage = mLayers[0].coverage.data() + rowStart;
        uint8_t* background = mBackground.data() + rowStart;
        uint8_t* complex = mComplex.data() + rowStart;
        // What the last build left in this row's upper layers goes back to "none".
        std::vector<uint32_t>& upperColumns = mUpperColumns[size_t(y)];
        for (int k = 1; k < lastLayerCount; ++k) {
            Layer& layer = mLayers[size_t(k)];
            for (const uint32_t x : upperColumns) {
                layer.codes[rowStart + x] = VisibilityPass::kNoTriangle;
                layer.depths[rowStart + x] = clear;
                layer.coverage[rowStart + x] = 0;
            }
        }
        upperColumns.clear();
        int rowLayers = 1;
        Counts counts; // local: the byte planes' stores could alias a reference's fields
        // The merge test's surfaces, one reader for main fragments and one for the others: along
        // an edge both keep showing the same two triangles, so each reuses its corners (bitwise
        // surfaceAt()).
        VisibilityPass::RowSurfaces mainSurfaces(visibility, y), otherSurfaces(visibility, y);
        const float ndcY = view.ndcOfPixel(0, y).y;
        // Most pixels: every sample shows one triangle (or none), what the search below finds
        // for them, written into layer 0 at every pixel on SIMD lanes (UniformPixels.h); the
        // others are listed and rewritten here one by one.
        thread_local std::vector<uint32_t> mixed;
        mixed.resize(size_t(mWidth) + kMixedPixelSlack);
        UniformRowArgs rowArgs;
        rowArgs.codes = rowCodes;
        rowArgs.centreDepths = rowDepths;
        rowArgs.pixels = mWidth;
        rowArgs.samples = int(kStride);
        rowArgs.noTriangle = VisibilityPass::kNoTriangle;
        rowArgs.clear = clear;
        rowArgs.nearerClear = std::nextafter(clear, nearer);
        rowArgs.mainCodes = mainCodes;
        rowArgs.mainDepths = mainDepths;
        rowArgs.mainCoverage = mainCoverage;
        rowArgs.background = background;
        rowArgs.complex = complex;
        rowArgs.mixed = mixed.data();
        const UniformRowResult uniform = writeUniformRow(rowArgs);
        counts.coveredPixels += uniform.coveredUniformPixels;
        counts.fragments += uniform.coveredUniformPixels;
        for (int i = 0; i < uniform.mixedCount; ++i) {
            const int x = int(mixed[size_t(i)]);
            const uint32_t* pixelCodes = rowCodes + size_t(x) * kStride;
            uint32_t code[raster::kMaxSamples];
            uint8_t mask[raster::kMaxSamples];
            float depth[raster::kMaxSamples];
            int count = 0, backgroundSamples = 0;
            for (size_t s = 0; s < kStride; ++s) {
                const uint32_t c = pixelCodes[s];
                if (c == VisibilityPass::kNoTriangle) {
                    ++backgroundSamples;
                    continue;
                }
                int k = 0;
                while (k < count && code[k] != c)
                    ++k;
                if (k == count) {
                    code[k] = c;
                    mask[k] = 0;
                    depth[k] = rowDepths[size_t(x) * kStride + s];
                    if (depth[k] == clear)
                        depth[k] = std::nextafter(clear, nearer);
                    ++count;
                }
                mask[k] = uint8_t(mask[k] | 1u << s);
            }
            // The main fragment: most samples, ties to the earliest (stable order).
            int first = 0;
            for (int k = 1; k < count; ++k)
                if (std::popcount(mask[k]) > std::popcount(mask[first]))
                    first = k;
            if (first != 0) {
                moveToFront(code, first);
                moveToFront(mask, first);
                moveToFront(depth, first);
            }
            if (mergeSmooth && count > 1) {
                // The test's cheap parts first (view depth, material), the surfaces' normals only
                // for a fragment that passes both: the same outcome, without the surfaces at a
                // silhouette.
                const float ndcX = ndcXOfColumn[size_t(x)];
                const float firstDepth = view.viewDepthOfNdc(ndcX, ndcY, depth[0]);
                const uint32_t firstMaterial =
                    triangleMaterial[VisibilityPass::triangleOf(code[0])];
                const Surface* firstSurface = nullptr;
                int kept = 1;
                for (int k = 1; k < count; ++k) {
                    const float otherDepth = view.viewDepthOfNdc(ndcX, ndcY, depth[k]);
                    bool smooth =
                        std::abs(otherDepth - firstDepth) <= options.depthTolerance * firstDepth &&
                        triangleMaterial[VisibilityPass::triangleOf(code[k])] == firstMaterial;
                    if (smooth) {
                        if (!firstSurface)
                            firstSurface = &mainSurfaces.at(code[0], x);
                        smooth = glm::dot(otherSurfaces.at(code[k], x).normalView,
                                          firstSurface->normalView) >= options.normalCosine;
                    }
                    if (smooth) {
                        mask[0] = uint8_t(mask[0] | mask[k]);
                        ++counts.mergedFragments;
                        continue;
                    }
                    code[kept] = code[k];
                    mask[kept] = mask[k];
                    depth[kept] = depth[k];
                    ++kept;
                }
                count = kept;
            }
            mainCodes[x] = count > 0 ? code[0] : VisibilityPass::kNoTriangle;
            mainDepths[x] = count > 0 ? depth[0] : clear;
            mainCoverage[x] = count > 0 ? mask[0] : 0;
            // The extra fragments straight into the layers above, in order.
            for (int k = 1; k < count; ++k) {
                if (k >= rowLayers)
                    ensureLayer(k);
                Layer& layer = mLayers[size_t(k)];
                layer.codes[rowStart + size_t(x)] = code[k];
                layer.depths[rowStart + size_t(x)] = depth[k];
                layer.coverage[rowStart + size_t(x)] = mask[k];
            }
            if (count > 1) {
                upperColumns.push_back(uint32_t(x));
                rowLayers = std::max(rowLayers, count);
            }
            background[x] = uint8_t(backgroundSamples);
            complex[x] = 0;
            if (count > 0) {
                ++counts.coveredPixels;
                counts.fragments += uint64_t(count);
                counts.partialPixels += backgroundSamples > 0;
                if (count > 1 || backgroundSamples > 0) {
                    complex[x] = 1;
                    ++counts.complexPixels;
                }
            }
        }
        mRowLayers[size_t(y)] = rowLayers;
        rowCounts[size_t(y)] = counts;
    };
    tbb::parallel_for(0, mHeight, [&](int y) {
        switch (samples) {
        case 2:
            return buildRow(y, std::integral_constant<size_t, 2>{});
        case 4:
            return buildRow(y, std::integral_constant<size_t, 4>{});
        default: // 8, checked above
            return buildRow(y, std::integral_constant<size_t, 8>{});
        }
    });
    mCounts = Counts{};
    for (const Counts& row : rowCounts) {
        mCounts.coveredPixels += row.coveredPixels;
        mCounts.complexPixels += row.complexPixels;
        mCounts.fragments += row.fragments;
        mCounts.mergedFragments += row.mergedFragments;
        mCounts.partialPixels += row.partialPixels;
    }
    mLayerCount = *std::max_element(mRowLayers.begin(), mRowLayers.end());
}

double FragmentLayers::storedBytes(double bytesPerPixel) const {
    // Main surfaces for every pixel, one byte of fragment count and flags per pixel, and per
    // extra fragment its surface plus its coverage byte.
    const double extra = double(mCounts.fragments) - double(mCounts.coveredPixels);
    return bytesPerPixel * double(pixelCount()) + double(pixelCount()) +
           extra * (bytesPerPixel + 1.0);
}

} // namespace gbuffer
