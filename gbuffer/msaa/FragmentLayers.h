// FragmentLayers: a multisampled visibility buffer turned into what deferred shading stores and
// shades, after Lauritzen ("Deferred Rendering for Current and Future Rendering Pipelines",
// SIGGRAPH 2010): one surface per pixel where the pixel is SIMPLE (all its samples show one
// surface) and one surface per distinct surface where it is COMPLEX (an edge).
//
// Model. The rasterizer covers and depth-tests each sample and evaluates attributes once per pixel
// and triangle at the pixel centre (raster/Rasterizer.h), so the samples of a pixel that show the
// same triangle have bitwise the same surface: shading it once and weighting it by its sample
// count is exactly shading each of those samples. A pixel's FRAGMENTS are therefore its distinct
// visibility codes, each with its coverage mask (which samples show it); background samples are
// nobody's. Layer 0 holds every pixel's main fragment (the one with the most samples, ties to the
// lowest sample index; background where no sample is covered); layer k >= 1 holds the k-th other
// fragment of the pixels that have one. Layer 0 is a full-screen G-buffer as at one sample; the
// layers above are empty except at complex pixels, so a stage that skips background (every tile
// or cluster without a covered pixel) pays for complex pixels only: the per-tile MSAA choice of
// the survey falls out of the data. A pixel's resolved radiance is sum_k weight(k) radiance_k,
// weight = covered samples / samples (1 for layer 0 of an uncovered pixel, whose whole area is
// background).
//
// Complex-pixel detection (ComplexDetection):
//   primitive      a pixel is complex when its samples show more than one triangle or some sample
//                  is background: exact, but every shared edge of a tessellated mesh is an edge;
//   discontinuity  as primitive, but a fragment whose centre view depth is within depthTolerance
//                  (relative) of the main fragment's, whose normal is within normalCosine of it
//                  and whose material is the same is merged into the main fragment (its samples
//                  shaded with the main surface): the depth + normal test of Lauritzen and of the
//                  post-process filters, which leaves a smooth mesh's interior edges simple. An
//                  approximation: measured against the supersampled reference like any other.
//
// Memory: the layers are stored as full planes (the stages read G-buffers by pixel), but what a
// compressed store needs is counted too (storedBytes): the main fragment's bytes per pixel, one
// byte per pixel (fragment count and flags) and the layer's bytes plus a coverage byte per extra
// fragment; allocatedBytes is what the full planes take.
//
// Cost: layer 0 is written at every pixel; the layers above only at the pixels that have an extra
// fragment (upperColumns) and at those the last build left, which are reset to "none": the planes
// are kept between builds of one size, so an upper layer's cost follows the complex pixels, not
// the screen. One pass: a pixel's extra fragments go straight into their layers (a layer is made,
// "none" everywhere, by the first row that needs it), with no per-pixel scratch copy.
//
// Deterministic: built per pixel from the visibility buffer; parallel over rows (TBB).
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gbuffer/visibility/VisibilityPass.h"

namespace gbuffer {

enum class ComplexDetection { Primitive, Discontinuity };
const char* complexDetectionName(ComplexDetection detection);
// "primitive" or "discontinuity"; false for anything else.
bool parseComplexDetection(const std::string& text, ComplexDetection& detection);

struct FragmentLayerOptions {
    ComplexDetection detection = ComplexDetection::Primitive;
    // discontinuity: merge when |d_k - d_0| <= depthTolerance * d_0 (view depths at the centre)
    // and dot(n_k, n_0) >= normalCosine (cos 10 degrees) and the materials are equal.
    float depthTolerance = 0.01f;
    float normalCosine = 0.9848f;
};

class FragmentLayers {
public:
    // Builds the layers from the last multisampled draw of `visibility` (sampleCount() > 1).
    void build(const VisibilityPass& visibility, const FragmentLayerOptions& options);

    int samples() const { return mSamples; }
    int width() const { return mWidth; }
    int height() const { return mHeight; }
    size_t pixelCount() const { return size_t(mWidth) * size_t(mHeight); }
    int layerCount() const { return mLayerCount; }
    const FragmentLayerOptions& options() const { return mOptions; }

    // Layer `layer`'s visibility code per pixel (kNoTriangle where the layer has no fragment).
    std::span<const uint32_t> codes(int layer) const { return mLayers[size_t(layer)].codes; }
    // Its depth per pixel: the fragment's plane at the pixel centre (the view's clear depth where
    // the layer has no fragment; a fragment whose extrapolated centre depth rounds to the clear
    // value, a silhouette against the far plane, is moved one float step nearer so that it stays
    // covered).
    std::span<const float> depths(int layer) const { return mLayers[size_t(layer)].depths; }
    // Its coverage mask per pixel (0 where the layer has no fragment).
    std::span<const uint8_t> coverage(int layer) const { return mLayers[size_t(layer)].coverage; }
    // The weight of the layer's fragment in the pixel's resolve (see the file comment).
    float weight(int layer, size_t pixel) const {
        const uint8_t mask = mLayers[size_t(layer)].coverage[pixel];
        if (layer == 0 && mask == 0)
            return 1.0f;
        return float(std::popcount(mask)) / float(mSamples);
    }
    // Samples of the pixel that show no surface.
    float backgroundWeight(size_t pixel) const {
        return float(mBackground[pixel]) / float(mSamples);
    }
    // The columns x of row y whose pixels have a fragment in some layer above 0, ascending: for
    // k >= 1, codes(k) is kNoTriangle (and depths(k) the clear depth, coverage(k) 0) everywhere
    // else. What the upper layers' consumers walk instead of the screen (their cost follows the
    // complex pixels); valid until the next build.
    std::span<const uint32_t> upperColumns(int y) const { return mUpperColumns[size_t(y)]; }

    // Complex: covered by some sample, and not all samples show one surface (after merging).
    bool complex(size_t pixel) const { return mComplex[pixel] != 0; }
    std::span<const uint8_t> complexMask() const { return mComplex; }

    struct Counts {
        uint64_t coveredPixels = 0;   // some sample covered
        uint64_t complexPixels = 0;   // of those, complex
        uint64_t fragments = 0;       // fragments over all layers (surfaces to shade)
        uint64_t mergedFragments = 0; // discontinuity: fragments merged into the main one
        uint64_t partialPixels = 0;   // covered pixels with some background sample
    };
    const Counts& counts() const { return mCounts; }
    double complexFraction() const {
        return mCounts.coveredPixels ? double(mCounts.complexPixels) / double(mCounts.coveredPixels)
                                     : 0.0;
    }
    // Bytes a compressed store of the layers would hold with `bytesPerPixel` per stored surface
    // (see the file comment), and what the full planes of every layer hold.
    double storedBytes(double bytesPerPixel) const;
    double allocatedBytes(double bytesPerPixel) const {
        return bytesPerPixel * double(pixelCount()) * double(layerCount());
    }

private:
    struct Layer {
        std::vector<uint32_t> codes;
        std::vector<float> depths;
        std::vector<uint8_t> coverage;
    };
    FragmentLayerOptions mOptions;
    int mSamples = 1;
    int mWidth = 0;
    int mHeight = 0;
    std::vector<Layer> mLayers; // one per sample; made when first needed, the first mLayerCount
                                // are this build's
    int mLayerCount = 0;
    float mClearDepth = 0.0f;                         // the view's, at the last build
    std::vector<std::vector<uint32_t>> mUpperColumns; // per row (upperColumns)
    std::vector<uint8_t> mBackground;                 // background samples per pixel
    std::vector<uint8_t> mComplex;
    Counts mCounts;
    std::vector<int> mRowLayers; // per row, the most fragments of a pixel
};

} // namespace gbuffer
