#include "gbuffer/msaa/FragmentLayers.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <tbb/parallel_for.h>

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

// Positive view depth of NDC depth `depth` at pixel (x, y)'s centre.
float viewDepthAt(const CameraView& view, int x, int y, float depth) {
    const glm::vec2 ndc = view.ndcOfPixel(x, y);
    const glm::vec4 p = view.viewFromClip * glm::vec4(ndc.x, ndc.y, depth, 1.0f);
    return -p.z / p.w;
}

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
    const size_t stride = size_t(samples);
    const std::span<const uint32_t> sampleCodes = visibility.codes();
    const std::span<const float> sampleDepths = visibility.centreDepths();

    if (mLayers.empty()) {
        // Layer 0: every entry is written by every build.
        mLayers.resize(1);
        mLayers[0].codes.resize(pixels);
        mLayers[0].depths.resize(pixels);
        mLayers[0].coverage.resize(pixels);
    }
    // Per pixel with an extra fragment, its fragments in order (the main one first), at most
    // `samples` of them: what the upper layers get once their count is known. Scratch kept
    // between frames and only resized: every entry read is written first.
    mScratchCode.resize(pixels * stride);
    mScratchMask.resize(pixels * stride);
    mScratchDepth.resize(pixels * stride);
    mScratchCount.resize(pixels);
    mBackground.resize(pixels);
    mComplex.resize(pixels);
    mRowLayers.resize(size_t(mHeight));
    std::vector<Counts> rowCounts(static_cast<size_t>(mHeight));
    const float nearer = view.reversedZ() ? 1.0f : 0.0f;
    const bool mergeSmooth = options.detection == ComplexDetection::Discontinuity;
    const int lastLayerCount = mLayerCount;
    Layer& main = mLayers[0];

    const uint8_t allSamples = uint8_t((1u << samples) - 1u);
    // One row; `kSamples` is the sample count as a constant, so that the per-pixel loops over a
    // pixel's samples (the uniformity test first) are unrolled.
    auto buildRow = [&](int y, auto kSamples) {
        constexpr size_t kStride = decltype(kSamples)::value;
        // What the last build left in this row's upper layers goes back to "none".
        std::vector<uint32_t>& upperColumns = mUpperColumns[size_t(y)];
        for (const uint32_t x : upperColumns) {
            const size_t pixel = size_t(y) * mWidth + x;
            for (int k = 1; k < lastLayerCount; ++k) {
                Layer& layer = mLayers[size_t(k)];
                layer.codes[pixel] = VisibilityPass::kNoTriangle;
                layer.depths[pixel] = clear;
                layer.coverage[pixel] = 0;
            }
        }
        upperColumns.clear();
        int rowLayers = 1;
        Counts counts; // local: the byte planes' stores could alias a reference's fields
        // The merge test's surfaces, one reader for main fragments and one for the others: along
        // an edge both keep showing the same two triangles, so each reuses its corners (bitwise
        // surfaceAt()).
        VisibilityPass::RowSurfaces mainSurfaces(visibility, y), otherSurfaces(visibility, y);
        for (int x = 0; x < mWidth; ++x) {
            const size_t pixel = size_t(y) * mWidth + size_t(x);
            // Most pixels: every sample shows one triangle (or none), what the search below
            // finds for them, written straight into layer 0 (no fragment arrays).
            const uint32_t* pixelCodes = &sampleCodes[pixel * kStride];
            bool uniform = true;
            for (size_t s = 1; s < kStride; ++s)
                uniform &= pixelCodes[s] == pixelCodes[0];
            if (uniform) {
                const bool covered = pixelCodes[0] != VisibilityPass::kNoTriangle;
                const float centre = sampleDepths[pixel * kStride];
                main.codes[pixel] = pixelCodes[0];
                main.depths[pixel] = !covered          ? clear
                                     : centre == clear ? std::nextafter(clear, nearer)
                                                       : centre;
                main.coverage[pixel] = covered ? allSamples : 0;
                mBackground[pixel] = covered ? 0 : uint8_t(samples);
                mComplex[pixel] = 0;
                counts.coveredPixels += covered;
                counts.fragments += covered;
                continue;
            }
            uint32_t code[raster::kMaxSamples];
            uint8_t mask[raster::kMaxSamples];
            float depth[raster::kMaxSamples];
            int count = 0, background = 0;
            for (size_t s = 0; s < kStride; ++s) {
                const uint32_t c = pixelCodes[s];
                if (c == VisibilityPass::kNoTriangle) {
                    ++background;
                    continue;
                }
                int k = 0;
                while (k < count && code[k] != c)
                    ++k;
                if (k == count) {
                    code[k] = c;
                    mask[k] = 0;
                    depth[k] = sampleDepths[pixel * kStride + s];
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
            moveToFront(code, first);
            moveToFront(mask, first);
            moveToFront(depth, first);
            if (mergeSmooth && count > 1) {
                const Surface& firstSurface = mainSurfaces.at(code[0], x);
                const float firstDepth = viewDepthAt(view, x, y, depth[0]);
                int kept = 1;
                for (int k = 1; k < count; ++k) {
                    const Surface& other = otherSurfaces.at(code[k], x);
                    const float otherDepth = viewDepthAt(view, x, y, depth[k]);
                    const bool smooth =
                        std::abs(otherDepth - firstDepth) <= options.depthTolerance * firstDepth &&
                        glm::dot(other.normalView, firstSurface.normalView) >=
                            options.normalCosine &&
                        other.material == firstSurface.material;
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
            main.codes[pixel] = count > 0 ? code[0] : VisibilityPass::kNoTriangle;
            main.depths[pixel] = count > 0 ? depth[0] : clear;
            main.coverage[pixel] = count > 0 ? mask[0] : 0;
            if (count > 1) {
                upperColumns.push_back(uint32_t(x));
                rowLayers = std::max(rowLayers, count);
                mScratchCount[pixel] = uint8_t(count);
                std::copy(code, code + count, &mScratchCode[pixel * kStride]);
                std::copy(mask, mask + count, &mScratchMask[pixel * kStride]);
                std::copy(depth, depth + count, &mScratchDepth[pixel * kStride]);
            }
            mBackground[pixel] = uint8_t(background);
            mComplex[pixel] = 0;
            if (count > 0) {
                ++counts.coveredPixels;
                counts.fragments += uint64_t(count);
                counts.partialPixels += background > 0;
                if (count > 1 || background > 0) {
                    mComplex[pixel] = 1;
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
    while (int(mLayers.size()) < mLayerCount) {
        // A layer first needed now: "none" everywhere, then written where it has fragments.
        Layer& layer = mLayers.emplace_back();
        layer.codes.assign(pixels, VisibilityPass::kNoTriangle);
        layer.depths.assign(pixels, clear);
        layer.coverage.assign(pixels, 0);
    }
    // The extra fragments into the upper layers, at the pixels that have them only.
    tbb::parallel_for(0, mHeight, [&](int y) {
        for (const uint32_t x : mUpperColumns[size_t(y)]) {
            const size_t pixel = size_t(y) * mWidth + x;
            for (int k = 1; k < mScratchCount[pixel]; ++k) {
                Layer& layer = mLayers[size_t(k)];
                const size_t entry = pixel * stride + size_t(k);
                layer.codes[pixel] = mScratchCode[entry];
                layer.depths[pixel] = mScratchDepth[entry];
                layer.coverage[pixel] = mScratchMask[entry];
            }
        }
    });
}

double FragmentLayers::storedBytes(double bytesPerPixel) const {
    // Main surfaces for every pixel, one byte of fragment count and flags per pixel, and per
    // extra fragment its surface plus its coverage byte.
    const double extra = double(mCounts.fragments) - double(mCounts.coveredPixels);
    return bytesPerPixel * double(pixelCount()) + double(pixelCount()) +
           extra * (bytesPerPixel + 1.0);
}

} // namespace gbuffer
