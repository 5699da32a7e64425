// EdgeBlur: the deferred renderers' post-process anti-aliasing of S.T.A.L.K.E.R. (Shishkovtsov,
// "Deferred Shading in S.T.A.L.K.E.R.", GPU Gems 2 ch. 9, 2005) and Tabula Rasa (Koonce,
// "Deferred Shading in Tabula Rasa", GPU Gems 3 ch. 19, 2008): find geometric edges in the
// G-buffer (depth and normal discontinuities), then blur the shaded image there and only there.
// README.md in this folder gives the algorithm, where it departs from the published filters, and
// the parameters' reasons.
//
// Per pixel:
//   1. edge weight w in [0, 1] (the `edges` plane): w = 1 - (1 - depthEdge) (1 - normalEdge),
//      S.T.A.L.K.E.R.'s `w = 1 - de * ne` with continuous terms as Tabula Rasa's weight:
//      - depthEdge: along x and along y, the second difference of the reciprocal view depth
//        |1/dL + 1/dR - 2/dC| relative to 1/dC, ramped from depthRampStart to depthRampEnd; zero
//        on every plane (1/d is affine in screen space), large at a step;
//      - normalEdge: over the 4 neighbours, 1 - dot(nC, nN) ramped from the cosines
//        normalCosineStart (no edge) to normalCosineEnd (full edge).
//      Background (no surface: infinitely far) against a covered neighbour is a full edge, on
//      both sides of the silhouette; background among background has no edge. An axis with no
//      neighbour on one side (the image border) has no depth term.
//   2. blur: the mean of 4 bilinear taps at the diagonal offsets (+-s, +-s), s = w * kernelPixels
//      (S.T.A.L.K.E.R.'s taps moved from the centre towards the diagonal neighbours by w), i.e.
//      the 3x3 weights centre (1-s)^2, edge neighbours s(1-s)/2, corners s^2/4 (clamped at the
//      border); at w = 1 and kernelPixels = 0.25: 0.5625, 0.09375, 0.015625; at w = 0 the pixel
//      unchanged (copied, bitwise).
//
// Threading: tbb::parallel_for over rows; each output pixel depends on the inputs only, so the
// result is bitwise the same for any thread count. Cost: one pass over the G-buffer's depth and
// normals (SurfacePlanes), then 9 reads of each plane per pixel.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "lighting/postaa/PostAaImage.h"

namespace lighting::postaa {

struct EdgeBlurParameters {
    // Relative second difference of 1/depth where the depth edge starts and where it is full.
    // 0.01 is a 1% kink in 1/depth over two pixels: below what the depth formats' rounding makes
    // on a plane (unorm16 at 10 m: ~0.2%), above it on a true step (an object 10 cm in front of a
    // wall 10 m away makes ~1%).
    float depthRampStart = 0.01f;
    float depthRampEnd = 0.05f;
    // Cosine between neighbouring normals where the normal edge starts (18 degrees) and where it
    // is full (37 degrees): a smooth mesh's per-pixel normal change stays well below the first.
    float normalCosineStart = 0.95f;
    float normalCosineEnd = 0.80f;
    // Diagonal tap offset at full weight, pixels, in [0, 1] (0.5 would make each tap the mean of
    // a 2x2 block, the whole filter the 3x3 tent (1 2 1)/4 x (1 2 1)/4). Both pixels of an edge
    // are blurred, each towards the other, so less is needed than one pixel's blur: on a hard
    // half-plane edge (tests/lighting/postaa, five slopes from 0.12 to 2.5) the RMSE against the
    // exact coverage, relative to the aliased image's, is 0.56-0.68 at 0.25, 0.58-0.70 at 0.2,
    // 0.84-1.12 at 0.5 (worse than no filter at 45 degrees), 0.90-1.84 at 1.
    float kernelPixels = 0.25f;

    // Every parameter as text, for stats.json.
    std::map<std::string, std::string> describe() const;
};

// What the edge test reads from the G-buffer: reciprocal view depth and the normal of every
// pixel, extracted once per frame.
struct SurfacePlanes {
    int width = 0;
    int height = 0;
    std::vector<float> inverseDepth; // 1 / view depth in metres; 0 = background (no surface)
    std::vector<float> normal[3];    // unit normals (any one space: only their dots are used);
                                     // empty when the layout has no normals (no normal term)

    // Reads the G-buffer: depth through its DepthDecoder, normals from its float planes or
    // through decode() for encoded layouts. Parallel (TBB), deterministic.
    void extract(const gbuffer::GBuffer& gbuffer);
};

// The edge weight of every pixel (step 1 above) into `edges` (width x height).
void edgeWeights(const SurfacePlanes& surface, const EdgeBlurParameters& parameters, float* edges);

// The whole filter: edge weights into out.edges, the blurred radiance into out.rgb. `in` must
// have the surface's size; `out` must not alias `in`. Parallel (TBB), deterministic.
void edgeBlur(const SurfacePlanes& surface, const EdgeBlurParameters& parameters,
              const RadianceIn& in, const RadianceOut& out);

} // namespace lighting::postaa
