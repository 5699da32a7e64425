#include "lighting/culling/ZBins.h"

#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace lighting {

namespace {

// Sorted lights per bin-range task: large enough to amortise a task and its local bins, small
// enough to balance 10^3 lights over a few cores. Fixed, so the merge never depends on the thread
// count.
constexpr size_t kLightsPerBinChunk = 4096;
// Mask words per bit-setting task (64 words = 2048 sorted lights); each task owns its words.
constexpr size_t kWordsPerMaskChunk = 64;

// A float's order as an unsigned integer (negative values reversed), for one integer sort key.
uint32_t orderedBits(float value) {
    const uint32_t bits = std::bit_cast<uint32_t>(value);
    return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
}

ZBins::Range hull(ZBins::Range a, ZBins::Range b) {
    return {std::min(a.first, b.first), std::max(a.last, b.last)};
}

} // namespace

void ZBins::build(std::span<const CandidateLight> candidates, float nearDepthMetres,
                  float farDepthMetres, int binCount, ZBinSpacing spacing) {
    if (binCount < 1 || binCount > kMaxZBinCount)
        throw std::invalid_argument("ZBins: bin count " + std::to_string(binCount) +
                                    " outside 1.." + std::to_string(kMaxZBinCount));
    if (!(nearDepthMetres <= farDepthMetres))
        throw std::invalid_argument("ZBins: need near depth <= far depth");
    mBinCount = binCount;
    mSearchStep = 0;
    while (mSearchStep * 2 <= binCount - 1)
        mSearchStep = std::max(1, mSearchStep * 2);

    // Boundaries in double so that rounding cannot reorder them; ends exact, then made
    // non-decreasing (all binOfDepth needs for monotonicity).
    mBoundary.resize(size_t(binCount) + 1);
    const double nearD = nearDepthMetres, farD = farDepthMetres;
    const bool geometric = spacing == ZBinSpacing::Exponential && nearD > 0.0;
    for (int k = 0; k <= binCount; ++k) {
        const double t = double(k) / binCount;
        mBoundary[size_t(k)] =
            float(geometric ? nearD * std::pow(farD / nearD, t) : nearD + (farD - nearD) * t);
    }
    mBoundary.front() = nearDepthMetres;
    mBoundary.back() = farDepthMetres;
    for (size_t k = 1; k < mBoundary.size(); ++k)
        mBoundary[k] = std::max(mBoundary[k], mBoundary[k - 1]);

    // Sort the bounded candidates by centre depth; ties by candidate position, i.e. by light
    // index. Keys are unique, so any sort gives the one order.
    mUnbounded.clear();
    mKeys.clear();
    for (size_t k = 0; k < candidates.size(); ++k) {
        if (candidates[k].unbounded)
            mUnbounded.push_back(candidates[k].index);
        else
            mKeys.push_back(uint64_t(orderedBits(-candidates[k].centreView.z)) << 32 | k);
    }
    tbb::parallel_sort(mKeys.begin(), mKeys.end());
    const size_t n = mKeys.size();
    mSortedLights.resize(n);
    mCandidateOf.resize(n);
    // Each sorted light's bins (first > last: in none), read from its candidate once (in sorted
    // order the candidates are visited at random; the chunks below then read these in order).
    mBinsOf.resize(n);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const uint32_t position = uint32_t(mKeys[i] & 0xFFFFFFFFu);
        mCandidateOf[i] = position;
        const CandidateLight& c = candidates[position];
        mSortedLights[i] = c.index;
        const float centreDepth = -c.centreView.z;
        const float low = centreDepth - c.radius, high = centreDepth + c.radius;
        // Wholly outside [near, far]: the comparisons of the tile depth test.
        mBinsOf[i] = high < nearDepthMetres || low > farDepthMetres
                         ? std::pair<int, int>(1, 0)
                         : std::pair<int, int>(binOfDepth(low), binOfDepth(high));
    });

    // Bin ranges: per chunk of sorted lights the ranges of the bins it touches, then merged in
    // chunk order (min of firsts, max of lasts: the same for any split).
    const size_t chunkCount = (n + kLightsPerBinChunk - 1) / kLightsPerBinChunk;
    mChunkRanges.resize(chunkCount);
    mChunkFirstBin.assign(chunkCount, 0);
    std::vector<size_t> chunkBinned(chunkCount, 0);
    tbb::parallel_for(size_t(0), chunkCount, [&](size_t chunk) {
        const size_t begin = chunk * kLightsPerBinChunk,
                     end = std::min(n, begin + kLightsPerBinChunk);
        int lowest = binCount, highest = -1;
        for (size_t i = begin; i < end; ++i) {
            const auto [firstBin, lastBin] = mBinsOf[i];
            if (firstBin <= lastBin) {
                lowest = std::min(lowest, firstBin);
                highest = std::max(highest, lastBin);
                ++chunkBinned[chunk];
            }
        }
        std::vector<Range>& local = mChunkRanges[chunk];
        local.assign(size_t(std::max(0, highest - lowest + 1)), Range{});
        mChunkFirstBin[chunk] = lowest;
        for (size_t i = begin; i < end; ++i) {
            const auto [firstBin, lastBin] = mBinsOf[i];
            for (int b = firstBin; b <= lastBin; ++b) {
                Range& r = local[size_t(b - lowest)];
                r = hull(r, {uint32_t(i), uint32_t(i)});
            }
        }
    });
    mRanges.assign(size_t(binCount), Range{});
    mBinnedCount = 0;
    for (size_t chunk = 0; chunk < chunkCount; ++chunk) {
        mBinnedCount += chunkBinned[chunk];
        const std::vector<Range>& local = mChunkRanges[chunk];
        for (size_t k = 0; k < local.size(); ++k) {
            Range& r = mRanges[size_t(mChunkFirstBin[chunk]) + k];
            r = hull(r, local[k]);
        }
    }

    // The range-hull table: level l holds the hull of 2^l consecutive bins.
    const int levels = std::bit_width(unsigned(binCount));
    mHullTable.resize(size_t(levels) * size_t(binCount));
    std::copy(mRanges.begin(), mRanges.end(), mHullTable.begin());
    for (int level = 1; level < levels; ++level) {
        const size_t half = size_t(1) << (level - 1);
        const Range* below = mHullTable.data() + size_t(level - 1) * size_t(binCount);
        Range* row = mHullTable.data() + size_t(level) * size_t(binCount);
        for (size_t b = 0; b + 2 * half <= size_t(binCount); ++b)
            row[b] = hull(below[b], below[b + half]);
    }
}

ZBins::Range ZBins::rangeOfBins(int firstBin, int lastBin) const {
    const unsigned length = unsigned(lastBin - firstBin + 1);
    const int level = std::bit_width(length) - 1;
    const Range* row = mHullTable.data() + size_t(level) * size_t(mBinCount);
    return hull(row[firstBin], row[lastBin - (1 << level) + 1]);
}

size_t ZBins::binBytes() const {
    return (mRanges.size() + mHullTable.size()) * sizeof(Range) + mBoundary.size() * sizeof(float);
}

size_t ZBins::sortedBytes() const {
    return (mSortedLights.size() + mCandidateOf.size() + mUnbounded.size()) * sizeof(uint32_t);
}

void ZBinTileMasks::build(const TileGrid& grid, const TileEdgePlanes& edges,
                          std::span<const TileSurfaceBounds> bounds,
                          std::span<const CandidateLight> candidates, const ZBins& bins) {
    const size_t tileCount = size_t(grid.tileCount());
    if (bounds.size() != tileCount)
        throw std::invalid_argument("ZBinTileMasks: one bound per tile expected");

    // Windows: the hull of the ranges of the bins each covered tile's depth range spans.
    mFirstWord.assign(tileCount, 0);
    mOffsets.resize(tileCount + 1);
    mOffsets[0] = 0;
    for (size_t tile = 0; tile < tileCount; ++tile) {
        const TileSurfaceBounds& b = bounds[tile];
        size_t count = 0;
        if (b.covered) {
            const ZBins::Range window = bins.rangeOfBins(bins.binOfDepth(b.minDepthMetres),
                                                         bins.binOfDepth(b.maxDepthMetres));
            if (!window.empty()) {
                mFirstWord[tile] = window.first >> 5;
                count = size_t(window.last >> 5) - mFirstWord[tile] + 1;
            }
        }
        mOffsets[tile + 1] = mOffsets[tile] + count;
    }
    mWords.resize(mOffsets[tileCount]);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mWords.size(), size_t(1) << 16),
                      [&](const tbb::blocked_range<size_t>& r) {
                          std::fill(mWords.begin() + r.begin(), mWords.begin() + r.end(), 0u);
                      });
    mBoxes.resize(tileCount);
    tbb::parallel_for(size_t(0), tileCount, [&](size_t tile) {
        const TileSurfaceBounds& b = bounds[tile];
        if (b.covered)
            mBoxes[tile] =
                tileBox(edges, grid, int(tile % size_t(grid.tileCountX)),
                        int(tile / size_t(grid.tileCountX)), b.minDepthMetres, b.maxDepthMetres);
    });

    // Bits: each task owns whole words (32 consecutive sorted lights each) in every tile.
    const size_t n = bins.sortedCount();
    const size_t wordColumns = (n + 31) / 32;
    const size_t chunkCount = (wordColumns + kWordsPerMaskChunk - 1) / kWordsPerMaskChunk;
    std::vector<uint64_t> chunkBits(chunkCount, 0);
    tbb::parallel_for(size_t(0), chunkCount, [&](size_t chunk) {
        const size_t begin = chunk * kWordsPerMaskChunk * 32;
        const size_t end = std::min(n, begin + kWordsPerMaskChunk * 32);
        uint64_t bitCount = 0;
        for (size_t i = begin; i < end; ++i) {
            const CandidateLight& c = candidates[bins.candidateOf(i)];
            const uint32_t word = uint32_t(i >> 5), bit = 1u << (i & 31);
            for (int ty = c.rowMin; ty <= c.rowMax; ++ty)
                for (int tx = c.columnMin; tx <= c.columnMax; ++tx) {
                    const size_t tile = size_t(ty) * size_t(grid.tileCountX) + size_t(tx);
                    const TileSurfaceBounds& b = bounds[tile];
                    if (!b.covered || !boundedCandidateTouchesTile(c, tx, ty, b, mBoxes[tile]))
                        continue;
                    const size_t local = size_t(word) - mFirstWord[tile];
                    if (word < mFirstWord[tile] || local >= mOffsets[tile + 1] - mOffsets[tile])
                        throw std::logic_error("ZBinTileMasks: light " + std::to_string(c.index) +
                                               " touches tile " + std::to_string(tile) +
                                               " outside the tile's window of bins");
                    mWords[mOffsets[tile] + local] |= bit;
                    ++bitCount;
                }
        }
        chunkBits[chunk] = bitCount;
    });
    mBitCount = 0;
    for (uint64_t bits : chunkBits)
        mBitCount += bits;
}

size_t ZBinTileMasks::byteCount() const {
    return mWords.size() * sizeof(uint32_t) + mOffsets.size() * sizeof(size_t) +
           mFirstWord.size() * sizeof(uint32_t);
}

} // namespace lighting
