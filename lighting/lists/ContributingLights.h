// ContributingLights: per pixel of a G-buffer, the lights that contribute there: the lights whose
// radiance at the pixel's decoded surface is non-zero (Brdf.h contributes(), the definition the
// oracle counts with, lighting/Oracle.h), ascending.
// It is what a perfect exact culling method would produce: the `ideal` stage shades these lists,
// and the tests use them to check that every contributing light is among the lights a stage
// evaluated at each pixel (not only that it evaluated as many).
//
// Storage: one LightIndexLists (CSR, culling/LightIndexLists.h) over the pixels (row-major, y
// from the top). Background pixels have empty lists.
// build() evaluates only the candidates of a LightGrid (LightGrid.h: a superset of the lights
// that can contribute at a point), merged into ascending order with the unbounded lights, as the
// oracle counts; buildBrute() evaluates every light at every covered pixel (as `brute`). The two
// give the same lists (tests/lighting/stages/stage_exactness_test.cpp); build() is what lets
// `ideal` and the tests' identity checks run at 10^5 and 10^6 lights (brute force: 9.2e10
// evaluations per 1280x720 frame at 10^5).
// Cost: build: the grid (O(lights + light-cell pairs)) and the candidates near each pixel;
// buildBrute: every light at every covered pixel. Plus 4 bytes per contributing pair.
// Threads: rows in parallel, each pixel's list written by one task and concatenated in pixel
// order, so the lists never depend on the thread count. build() is not reentrant; the const
// queries are thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "lighting/brdf/Brdf.h"
#include "lighting/culling/LightIndexLists.h"

namespace lighting {

class ContributingLights {
public:
    // Lists the contributing lights of every pixel of `gb`; replaces the previous lists and
    // reuses their storage. Throws std::length_error beyond 2^32 - 1 pairs.
    void build(const gbuffer::GBuffer& gb, const std::vector<LightInView<float>>& lights);
    // The same lists by testing every light at every pixel (build's check).
    void buildBrute(const gbuffer::GBuffer& gb, const std::vector<LightInView<float>>& lights);

    int width() const { return mWidth; }
    int height() const { return mHeight; }
    std::span<const uint32_t> lightsOf(size_t pixel) const { return mLists[pixel]; }
    size_t pairCount() const { return mLists.pairCount(); }
    const LightIndexLists& lists() const { return mLists; }

private:
    // Lists, per covered pixel, the lights of candidates(point, out) that contribute (out: the
    // ascending light indices to test).
    template <class Candidates>
    void buildFrom(const gbuffer::GBuffer& gb, const std::vector<LightInView<float>>& lights,
                   const Candidates& candidates);

    int mWidth = 0;
    int mHeight = 0;
    LightIndexLists mLists;
    std::vector<uint32_t> mCounts;                // scratch: per pixel
    std::vector<std::vector<uint32_t>> mRowLists; // scratch: one row's lists, concatenated
};

} // namespace lighting
