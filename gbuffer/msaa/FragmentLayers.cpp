#include "gbuffer/msaa/FragmentLayers.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

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

} // namespace

void FragmentLayers::build(const VisibilityPass& visibility, const FragmentLayerOptions& options) {
    const CameraView& view = visibility.view();
    const int samples = visibility.sampleCount();
    if (samples < 2 || visibility.centreDepths().empty())
        throw std::invalid_argument("FragmentLayers: the visibility pass was not multisampled");
    mOptions = options;
    mSamples = samples;
    mWidth = view.width;
    mHeight = view.height;
    const size_t pixels = pixelCount();
    const size_t stride = size_t(samples);
    const std::span<const uint32_t> sampleCodes = visibility.codes();
    const std::span<const float> sampleDepths = visibility.centreDepths();

    // Per pixel, its fragments in order of their first sample (the main one first after the
    // sort below): code, coverage and centre depth, at most `samples` of them.
    // Scratch kept between frames and only resized: every entry read is written first (a fresh
    // allocation and clear per frame cost more than the build itself, in page faults and memset).
    std::vector<uint32_t>& fragmentCode = mScratchCode;
    std::vector<uint8_t>& fragmentMask = mScratchMask;
    std::vector<float>& fragmentDepth = mScratchDepth;
    std::vector<uint8_t>& fragmentCount = mScratchCount;
    fragmentCode.resize(pixels * stride);
    fragmentMask.resize(pixels * stride);
    fragmentDepth.resize(pixels * stride);
    fragmentCount.resize(pixels);
    mBackground.resize(pixels);
    mComplex.resize(pixels);
    std::vector<Counts> rowCounts(static_cast<size_t>(mHeight));
    const float clear = view.clearDepth();
    const float nearer = view.reversedZ() ? 1.0f : 0.0f;
    const bool mergeSmooth = options.detection == ComplexDetection::Discontinuity;

    const uint8_t allSamples = uint8_t((1u << samples) - 1u);
    tbb::parallel_for(0, mHeight, [&](int y) {
        Counts& counts = rowCounts[size_t(y)];
        // The merge test's surfaces, one reader for main fragments and one for the others: along
        // an edge both keep showing the same two triangles, so each reuses its corners (bitwise
        // surfaceAt()).
        VisibilityPass::RowSurfaces mainSurfaces(visibility, y), otherSurfaces(visibility, y);
        for (int x = 0; x < mWidth; ++x) {
            const size_t pixel = size_t(y) * mWidth + size_t(x);
            uint32_t* code = &fragmentCode[pixel * stride];
            uint8_t* mask = &fragmentMask[pixel * stride];
            float* depth = &fragmentDepth[pixel * stride];
            int count = 0, background = 0;
            // Most pixels: every sample shows one triangle (or none), what the loop below finds
            // for them, without its search.
            const uint32_t* pixelCodes = &sampleCodes[pixel * stride];
            bool uniform = true;
            for (size_t s = 1; s < stride; ++s)
                uniform &= pixelCodes[s] == pixelCodes[0];
            if (uniform) {
                if (pixelCodes[0] == VisibilityPass::kNoTriangle) {
                    background = samples;
                } else {
                    code[0] = pixelCodes[0];
                    mask[0] = allSamples;
                    depth[0] = sampleDepths[pixel * stride];
                    if (depth[0] == clear)
                        depth[0] = std::nextafter(clear, nearer);
                    count = 1;
                }
            }
            for (size_t s = 0; s < (uniform ? 0 : stride); ++s) {
                const uint32_t c = sampleCodes[pixel * stride + s];
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
                    depth[k] = sampleDepths[pixel * stride + s];
                    if (depth[k] == clear)
                        depth[k] = std::nextafter(clear, nearer);
                    ++count;
                }
                mask[k] = uint8_t(mask[k] | 1u << s);
            }
            // The main fragment: most samples, ties to the earliest (stable order).
            int main = 0;
            for (int k = 1; k < count; ++k)
                if (std::popcount(mask[k]) > std::popcount(mask[main]))
                    main = k;
            std::rotate(code, code + main, code + main + 1);
            std::rotate(mask, mask + main, mask + main + 1);
            std::rotate(depth, depth + main, depth + main + 1);
            if (mergeSmooth && count > 1) {
                const Surface& first = mainSurfaces.at(code[0], x);
                const float firstDepth = viewDepthAt(view, x, y, depth[0]);
                int kept = 1;
                for (int k = 1; k < count; ++k) {
                    const Surface& other = otherSurfaces.at(code[k], x);
                    const float otherDepth = viewDepthAt(view, x, y, depth[k]);
                    const bool smooth =
                        std::abs(otherDepth - firstDepth) <= options.depthTolerance * firstDepth &&
                        glm::dot(other.normalView, first.normalView) >= options.normalCosine &&
                        other.material == first.material;
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
            fragmentCount[pixel] = uint8_t(count);
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
    });
    mCounts = Counts{};
    for (const Counts& row : rowCounts) {
        mCounts.coveredPixels += row.coveredPixels;
        mCounts.complexPixels += row.complexPixels;
        mCounts.fragments += row.fragments;
        mCounts.mergedFragments += row.mergedFragments;
        mCounts.partialPixels += row.partialPixels;
    }

    const int layers =
        std::max(1, int(*std::max_element(fragmentCount.begin(), fragmentCount.end())));
    mLayers.resize(size_t(layers));
    for (Layer& layer : mLayers) {
        layer.codes.resize(pixels);
        layer.depths.resize(pixels);
        layer.coverage.resize(pixels);
    }
    // Every entry of every layer written once: the fragment, or "none".
    tbb::parallel_for(0, mHeight, [&](int y) {
        for (int k = 0; k < layers; ++k) {
            Layer& layer = mLayers[size_t(k)];
            for (size_t pixel = size_t(y) * mWidth; pixel < size_t(y + 1) * mWidth; ++pixel) {
                const bool present = k < fragmentCount[pixel];
                const size_t entry = pixel * stride + size_t(k);
                layer.codes[pixel] = present ? fragmentCode[entry] : VisibilityPass::kNoTriangle;
                layer.depths[pixel] = present ? fragmentDepth[entry] : clear;
                layer.coverage[pixel] = present ? fragmentMask[entry] : 0;
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
