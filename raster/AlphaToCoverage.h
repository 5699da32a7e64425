// AlphaToCoverage: the sample mask a fragment's alpha selects when alpha-to-coverage is on, as the
// output merger of MSAA hardware builds it (D3D11 AlphaToCoverageEnable, GL
// SAMPLE_ALPHA_TO_COVERAGE): with N samples per pixel, alpha in [0, 1] turns on
// round(alpha * N) of the pixel's N samples (ties up: alpha * N + 0.5 floored); alpha >= 1 turns
// on all of them (the fragment keeps its geometric coverage), alpha <= 0 or NaN none (discarded).
// The caller ANDs the mask with the fragment's geometric coverage (raster::Fragment::coverage), so
// a fragment never gains a sample it does not cover.
//
// Which samples. A fixed fill order per sample count says which sample turns on next as alpha
// grows (indices into standardSamplePattern(N), Rasterizer.h). The orders take roughly opposite
// samples in pairs, so that every even prefix spreads over the pixel instead of bunching on one
// side: 4x  {0, 3, 1, 2}          top (-2,-6) and bottom (2,6), then right and left;
//        8x  {7, 4, 3, 6, 2, 5, 0, 1}  the outer diagonal pair (7,-7)/(-5,5), the other
//                                    diagonal (-3,-5)/(3,7), the horizontal pair, the inner pair;
//        2x  {0, 1}.
// Per-pixel variation (a 2x2 dither). The order is rotated per pixel by
// kAlphaToCoverageDither2x2[y & 1][x & 1] * N / 4 places (the 2x2 Bayer matrix {{0, 2}, {3, 1}}):
// pixels (x, y) = (0,0), (1,0), (0,1), (1,1) of a quad rotate by 0, 2, 3, 1 at 4x, by 0, 4, 6, 2
// at 8x (whole pairs) and by 0, 1, 1, 0 at 2x (a checkerboard). The COUNT never changes
// (round(alpha * N) at every pixel, so a box-filtered resolve of a uniform partial alpha over a
// uniform background is the same at every pixel), only which samples carry it. Why vary it: where
// the fragment's geometric coverage is partial (a triangle edge across a leaf card), a fixed
// subset ANDed with the edge's samples biases the whole edge the same way (an edge that covers
// exactly the samples the subset leaves out vanishes along its length); rotating the subset over
// a 2x2 quad turns that bias into a 2-pixel alternation that the eye and ꟻLIP's filters average.
// Why not 4x4: with the count fixed there are at most N rotations of the order; the quad visits
// all 4 at 4x and at 8x the 4 that keep the pairs together, so a 4x4 period would only repeat
// them on a coarser, more visible grid.
// What it does not fix (as in hardware): two alpha-to-coverage surfaces of the same alpha over one
// pixel choose the same samples, so the front one hides the back one there instead of the two
// combining like blended layers.
//
// Deterministic and pure: a function of (alpha, N, x, y) only, so every draw that evaluates the
// same alpha at the same pixel keeps the same samples, for any thread count.
#pragma once

#include <cstdint>

namespace raster {

// The 2x2 Bayer matrix indexed [y & 1][x & 1]: the per-pixel rotation in quarters of the order.
inline constexpr uint8_t kAlphaToCoverageDither2x2[2][2] = {{0, 2}, {3, 1}};

// How many samples of `samples` (1, 2, 4 or 8) alpha turns on: round(alpha * samples), ties up,
// clamped to [0, samples]; NaN gives 0.
inline int alphaToCoverageCount(float alpha, int samples) {
    if (!(alpha > 0.0f))
        return 0;
    if (alpha >= 1.0f)
        return samples;
    const int count = int(alpha * float(samples) + 0.5f);
    return count > samples ? samples : count;
}

// The fill order of `samples` (1, 2, 4 or 8; anything else is treated as 1): position i is the
// sample that turns on i-th at the pixels whose rotation is 0.
inline const uint8_t* alphaToCoverageOrder(int samples) {
    static constexpr uint8_t kOne[] = {0};
    static constexpr uint8_t kTwo[] = {0, 1};
    static constexpr uint8_t kFour[] = {0, 3, 1, 2};
    static constexpr uint8_t kEight[] = {7, 4, 3, 6, 2, 5, 0, 1};
    switch (samples) {
    case 2:
        return kTwo;
    case 4:
        return kFour;
    case 8:
        return kEight;
    default:
        return kOne;
    }
}

// The samples (bit s = sample s of standardSamplePattern(samples)) that `alpha` keeps at pixel
// (x, y): alphaToCoverageCount(alpha, samples) of them, chosen by the rotated fill order. Not yet
// ANDed with any geometric coverage. Cost: a few integer operations and at most 8 iterations.
inline uint8_t alphaToCoverageMask(float alpha, int samples, int x, int y) {
    const int count = alphaToCoverageCount(alpha, samples);
    if (count >= samples)
        return uint8_t((1u << samples) - 1u);
    const uint8_t* order = alphaToCoverageOrder(samples);
    const int rotation = kAlphaToCoverageDither2x2[y & 1][x & 1] * samples / 4;
    unsigned mask = 0;
    for (int i = 0; i < count; ++i)
        mask |= 1u << order[(i + rotation) % samples];
    return uint8_t(mask);
}

} // namespace raster
