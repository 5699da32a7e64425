// ZBins and ZBinTileMasks: Drobot's z-binning (M. Drobot, "Improved Culling for Tiled and
// Clustered Rendering", SIGGRAPH 2017 Advances in Real-Time Rendering, Call of Duty: Infinite
// Warfare), the light assignment of the `zbinned` stage (lighting/stages/ZBinnedStage.cpp),
// usable and testable without a G-buffer.
//
// Data (rebuilt every frame):
// - ZBins: the bounded candidate lights (TileFrusta.h candidateLights, i.e. those view-frustum
//   culling keeps) sorted by the view depth of their sphere's centre, ties by light index:
//   sorted position i holds light sortedLight(i). Per z-bin (binCount bins of view depth between
//   the nearest and farthest sample, uniform or geometric), the inclusive range [first, last] of
//   the sorted positions whose depth extent [centre - radius, centre + radius] overlaps the bin:
//   every light overlapping the bin lies inside; lights in between that do not overlap it lie
//   inside too (the price of one range per bin, O(bins) memory).
// - ZBinTileMasks: per screen tile a bit mask over the sorted positions, bit i set when light
//   sortedLight(i)'s sphere passes the tile test of tiled culling (boundedCandidateTouchesTile,
//   TileFrusta.h: the tile's column/row slabs, its depth range, its depth-bounded frustum box).
// A sample at view depth d in tile t may be reached only by the lights whose bits are set in t's
// mask within the range of bin binOfDepth(d), and by the unbounded lights (directional, ambient:
// unboundedLights()), which are in no bin and no mask and reach every sample.
//
// Conservative with no tolerance of its own (the one slack policy, culling/README.md): the spheres
// carry the emitter slack (rule 1), the tile bounds are the samples' own (rule 2), and bins are
// only compared, never tested geometrically: binOfDepth is one monotone function (comparisons
// against fixed, non-decreasing boundaries) applied alike to a sample's decoded depth and to the
// ends of a light's extent, computed by the same float expressions as the tile depth test. So a
// sample whose depth lies in a light's extent lands in one of the light's bins whatever the
// boundaries are: they need no slack, and their rounding moves work, never drops a light.
//
// Memory (the `zbinned` stage reports each figure in its parameters):
// - bins: 8 bytes per bin (first, last), plus the range-hull table over them (rangeOfBins: 8 bytes
//   x bins x (log2(bins) + 1)); O(bins log bins), independent of the light count.
// - sorted order: 8 bytes per bounded candidate (light index, candidate position).
// - masks: each covered tile stores only the words of its WINDOW: the hull of the ranges of the
//   bins its depth range [min, max] spans. A light that passes the tile's depth test overlaps one
//   of those bins, so its bit lies in the window (build() checks it). At most candidates / 32 + 1
//   words per tile: O(tiles x lights / 32) in the worst case, much less when tiles span a small
//   part of the frame's depth range. Tiles without a covered sample store none.
//
// Conventions: view space right-handed, camera looking down -Z, depth = -z in metres (positive in
// front). Threads: the builds run in parallel with TBB (the sort on unique keys; bins in fixed
// chunks of sorted lights merged in chunk order; masks in fixed chunks of whole 32-light words,
// each word written by one task), so their results never depend on the thread count. Not
// reentrant; the const queries are thread-safe.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "lighting/culling/TileFrusta.h"

namespace lighting {

enum class ZBinSpacing { Uniform, Exponential };

// Beyond 2^16 bins the bins cost more to build and to search than they tighten (a bin far thinner
// than any light's depth extent gives the same range as its neighbours). 65536 bins: 512 KiB of
// ranges and 8.5 MiB of range-hull table.
inline constexpr int kMaxZBinCount = 1 << 16;

class ZBins {
public:
    // Inclusive range of sorted positions; empty when first > last.
    struct Range {
        uint32_t first = UINT32_MAX;
        uint32_t last = 0;
        bool empty() const { return first > last; }
    };

    // Sorts the bounded lights of `candidates` (ascending light index, as candidateLights returns
    // them) by centre depth and fills binCount bins between nearDepthMetres and farDepthMetres
    // (geometric spacing needs near > 0 and falls back to uniform otherwise); the unbounded ones go
    // to unboundedLights(). A light whose extent lies wholly outside [near, far] (high < near or
    // low > far: the comparisons of the tile depth test) is in the sorted order but in no bin.
    // Throws std::invalid_argument for binCount outside 1..kMaxZBinCount or !(near <= far).
    // Cost: O(n log n) sort + O(n + bins spanned) ranges + O(bins log bins) table; parallel.
    void build(std::span<const CandidateLight> candidates, float nearDepthMetres,
               float farDepthMetres, int binCount, ZBinSpacing spacing);

    int binCount() const { return mBinCount; }
    // Boundary k (0..binCount) in metres: bin k holds depths in [boundary(k), boundary(k + 1)).
    float boundary(int k) const { return mBoundary[size_t(k)]; }
    // The bin of a view depth: the largest k < binCount with boundary(k) <= depth, 0 when none (a
    // depth below the first boundary, or NaN) -- depths beyond the last boundary land in the last
    // bin. Monotone in depth. Branch-free binary lifting: called once per shaded sample.
    int binOfDepth(float depthMetres) const {
        const float* boundary = mBoundary.data();
        int bin = 0;
        for (int step = mSearchStep; step > 0; step >>= 1) {
            const int candidate = bin + step;
            bin = candidate < mBinCount && boundary[candidate] <= depthMetres ? candidate : bin;
        }
        return bin;
    }
    Range range(int bin) const { return mRanges[size_t(bin)]; }
    // The hull of the ranges of bins firstBin..lastBin (inclusive, firstBin <= lastBin): the
    // smallest first and the largest last. O(1) (a sparse table over the bins).
    Range rangeOfBins(int firstBin, int lastBin) const;

    size_t sortedCount() const { return mSortedLights.size(); }
    // The light at sorted position i, and its position in build()'s candidates.
    uint32_t sortedLight(size_t position) const { return mSortedLights[position]; }
    uint32_t candidateOf(size_t position) const { return mCandidateOf[position]; }
    std::span<const uint32_t> sortedLights() const { return mSortedLights; }
    // Lights without a bound (ascending light index): in every list, never in a bin or a mask.
    std::span<const uint32_t> unboundedLights() const { return mUnbounded; }
    // Bounded lights whose extent overlaps [near, far] (in some bin).
    size_t binnedCount() const { return mBinnedCount; }

    size_t binBytes() const;    // ranges + range-hull table + boundaries
    size_t sortedBytes() const; // sorted light indices and candidate positions

private:
    int mBinCount = 0;
    int mSearchStep = 0;           // largest power of two < binCount (0 for one bin)
    std::vector<float> mBoundary;  // binCount + 1, non-decreasing
    std::vector<Range> mRanges;    // binCount
    std::vector<Range> mHullTable; // level l, bin b: hull of bins b .. b + 2^l - 1
    std::vector<uint32_t> mSortedLights;
    std::vector<uint32_t> mCandidateOf;
    std::vector<uint32_t> mUnbounded;
    size_t mBinnedCount = 0;
    std::vector<uint64_t> mKeys;                  // build() scratch: depth key, position
    std::vector<std::pair<int, int>> mBinsOf;     // build() scratch: bins of each sorted light
    std::vector<std::vector<Range>> mChunkRanges; // build() scratch: per chunk of lights
    std::vector<int> mChunkFirstBin;
};

class ZBinTileMasks {
public:
    // The masks of the tiles of `grid` (row-major; `bounds` from computeTileSurfaceBounds or
    // computeTileDepthBounds on that grid, `edges` TileEdgePlanes::make of it) over `bins`, which
    // build() made from the same `candidates`; every covered tile's depth range must lie inside
    // the bins' [near, far] (the stage bins the span of its tiles' ranges). Throws
    // std::logic_error if a light would set a bit outside its tile's window (the header's argument
    // says it cannot when that holds). Cost: O(tiles + window
    // words + sum over lights of the tiles of their column/row rectangle); parallel.
    void build(const TileGrid& grid, const TileEdgePlanes& edges,
               std::span<const TileSurfaceBounds> bounds,
               std::span<const CandidateLight> candidates, const ZBins& bins);

    size_t tileCount() const { return mFirstWord.size(); }
    // The tile's window: mask words firstWord .. firstWord + words.size() - 1, word w holding the
    // bits of sorted positions 32 w .. 32 w + 31 (bit i % 32). Empty for uncovered tiles.
    uint32_t firstWord(size_t tile) const { return mFirstWord[tile]; }
    std::span<const uint32_t> words(size_t tile) const {
        return {mWords.data() + mOffsets[tile], mWords.data() + mOffsets[tile + 1]};
    }
    // Calls visit(position) for every sorted position in [first, last] (inclusive; nothing when
    // first > last) whose bit is set in the tile's mask, ascending. Positions outside the tile's
    // window are skipped: their bits are zero by construction.
    template <class Visit>
    void forEachSetBit(size_t tile, uint32_t first, uint32_t last, Visit&& visit) const {
        const size_t begin = mOffsets[tile], count = mOffsets[tile + 1] - begin;
        if (first > last || count == 0)
            return;
        const uint32_t windowFirst = mFirstWord[tile];
        const uint32_t w0 = std::max(first >> 5, windowFirst);
        const uint32_t w1 = std::min(last >> 5, windowFirst + uint32_t(count) - 1);
        for (uint32_t w = w0; w <= w1; ++w) {
            uint32_t bits = mWords[begin + (w - windowFirst)];
            if (w == first >> 5)
                bits &= ~0u << (first & 31u);
            if (w == last >> 5)
                bits &= ~0u >> (31u - (last & 31u));
            for (; bits != 0; bits &= bits - 1)
                visit(w * 32u + uint32_t(__builtin_ctz(bits)));
        }
    }
    uint64_t bitCount() const { return mBitCount; }    // (tile, light) pairs set
    size_t wordCount() const { return mWords.size(); } // mask words over all windows
    size_t byteCount() const;                          // words + per-tile offsets and windows

private:
    std::vector<uint32_t> mWords;     // the windows, tile after tile
    std::vector<size_t> mOffsets;     // tileCount + 1: tile t's words begin at mOffsets[t]
    std::vector<uint32_t> mFirstWord; // per tile
    std::vector<TileBox> mBoxes;      // build() scratch: per covered tile
    uint64_t mBitCount = 0;
};

} // namespace lighting
