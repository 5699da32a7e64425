// HierarchicalDepth: one screen tile's hierarchical depth (Hi-Z), a bound on the stored depths of
// each 8x8-pixel block, so the traversal can skip a triangle's pixels in a block where its depth
// plane cannot pass the depth test at any of them (they would all fail the per-pixel test).
//
// The bound is the block's farthest stored depth for Less and LessEqual (the largest), its
// nearest for Greater and GreaterEqual (the smallest); NaN stored depths pass no test but Always
// and are left out. It stays valid as the tile is drawn without being touched: a depth is only
// written where it passed the test, so it is never farther than the depth it replaces, and the
// block's farthest depth can only move nearer. Writes are counted per block instead, and after
// kPixelsPerBlock of them the bound is recomputed from the depth buffer at its next use (an exact
// maximum: a tighter bound, never a wrong one). Fragments that were discarded or drawn without a
// depth write change nothing, so they need no care.
//
// Exactness of the rejection: the traversal computes a pixel's depth as
// float(clamp(zRow + z1 px, 0, 1)) with zRow = z0 + z2 py in double (Rasterizer.h). The plane is
// affine, so over a rectangle of pixel centres its exact extreme is at a corner; the computed
// value at any pixel differs from the exact plane by at most 3 roundings of the magnitudes
// involved (|z0| + |z1 px| + |z2 py|, relative 2^-53 each), and so does the corner's. The bound
// takes the corner's computed value moved by 2^-48 of those magnitudes (more than twice that
// error), then clamps and rounds it to float as the pixels are: both are monotonic, so no pixel's
// float depth lies beyond it. A NaN plane gives a NaN bound, which rejects nothing.
//
// Not thread-safe: one object per tile, used by the task that draws the tile (Rasterizer.h).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "raster/DepthSpan.h"

namespace raster {

template <DepthTest kDepthTest> class HierarchicalDepth {
public:
    static constexpr int kBlockSize = 8;
    static constexpr int kPixelsPerBlock = kBlockSize * kBlockSize;
    // Blocks per tile side: tiles up to 128 pixels (a block row's columns fit a 16-bit mask).
    static constexpr int kMaxBlocksPerSide = 16;

    // The tile's pixels [tileMinX, tileMaxX] x [tileMinY, tileMaxY] of `depth` (one float per
    // pixel, `width` per row). Reads nothing yet: each block's bound is computed at its first use.
    HierarchicalDepth(const float* depth, int width, int tileMinX, int tileMinY, int tileMaxX,
                      int tileMaxY)
        : mDepth(depth), mWidth(width), mTileMinX(tileMinX), mTileMinY(tileMinY),
          mTileMaxX(tileMaxX), mTileMaxY(tileMaxY) {
        mWritesSinceBound.fill(kPixelsPerBlock);
    }

    int blockColumnOf(int px) const { return (px - mTileMinX) / kBlockSize; }
    int blockRowOf(int py) const { return (py - mTileMinY) / kBlockSize; }
    // The last pixel row of block row `blockRow` (clamped to the tile).
    int blockRowEnd(int blockRow) const {
        return std::min(mTileMinY + (blockRow + 1) * kBlockSize, mTileMaxY + 1) - 1;
    }
    int blockColumnEnd(int blockColumn) const {
        return std::min(mTileMinX + (blockColumn + 1) * kBlockSize, mTileMaxX + 1) - 1;
    }

    // Bit c set when block column c of block row `blockRow` rejects every pixel of the pixel
    // rectangle [minX, maxX] x [minY, maxY] (inside that block row and the tile) for the depth
    // plane z (Rasterizer.h's SetupTriangle::z). Cost: one plane evaluation per block column.
    uint32_t rejectedColumns(const double z[3], int blockRow, int minX, int maxX, int minY,
                             int maxY) {
        if constexpr (kDepthTest == DepthTest::Always)
            return 0;
        uint32_t rejected = 0;
        const int lastColumn = blockColumnOf(maxX);
        for (int column = blockColumnOf(minX); column <= lastColumn; ++column) {
            const int x0 = std::max(minX, mTileMinX + column * kBlockSize);
            const int x1 = std::min(maxX, blockColumnEnd(column));
            const float extreme = nearestDepth(z, x0, x1, minY, maxY);
            if (rejects(extreme, bound(blockRow * kMaxBlocksPerSide + column)))
                rejected |= 1u << column;
        }
        return rejected;
    }

    // `count` depths were written in block columns [firstColumn, lastColumn] of `blockRow` (when
    // a run spans several blocks, each gets the whole count: an early recomputation is harmless).
    void noteWrites(int blockRow, int firstColumn, int lastColumn, uint64_t count) {
        for (int column = firstColumn; column <= lastColumn; ++column) {
            int32_t& writes = mWritesSinceBound[size_t(blockRow * kMaxBlocksPerSide + column)];
            writes = int32_t(std::min<uint64_t>(uint64_t(writes) + count, kPixelsPerBlock));
        }
    }

    // The depth, rounded as the traversal rounds it, that is at least as near (for the test's
    // direction) as the plane's depth at every pixel centre of [x0, x1] x [y0, y1].
    static float nearestDepth(const double z[3], int x0, int x1, int y0, int y1) {
        constexpr bool kNearIsSmall = kDepthTest == DepthTest::Less ||
                                      kDepthTest == DepthTest::LessEqual ||
                                      kDepthTest == DepthTest::Always;
        // The corner where the plane is nearest (the smallest for Less: the low end of every
        // coordinate along which it grows).
        const bool lowX = (z[1] >= 0.0) == kNearIsSmall, lowY = (z[2] >= 0.0) == kNearIsSmall;
        const double x = lowX ? x0 : x1, y = lowY ? y0 : y1;
        const double corner = z[0] + z[2] * y + z[1] * x;
        // Pixel coordinates are not negative: x1, y1 are the largest magnitudes.
        const double margin =
            (std::abs(z[0]) + std::abs(z[1]) * double(x1) + std::abs(z[2]) * double(y1)) *
            kRoundingMargin;
        const double extreme = kNearIsSmall ? corner - margin : corner + margin;
        return float(std::clamp(extreme, 0.0, 1.0));
    }

    // Whether a fragment depth `nearest`, at least as near as every pixel's, fails the test
    // against a block whose stored depths are all bounded by `farthest`.
    static bool rejects(float nearest, float farthest) {
        switch (kDepthTest) {
        case DepthTest::Always:
            return false;
        case DepthTest::Less:
            return nearest >= farthest;
        case DepthTest::LessEqual:
            return nearest > farthest;
        case DepthTest::Greater:
            return nearest <= farthest;
        case DepthTest::GreaterEqual:
            return nearest < farthest;
        }
        return false;
    }

private:
    // Relative error allowance of the plane's evaluation (see the file comment): 2^-48.
    static constexpr double kRoundingMargin = 0x1p-48;

    float bound(int block) {
        if (mWritesSinceBound[size_t(block)] >= kPixelsPerBlock) {
            mBound[size_t(block)] = farthestStored(block);
            mWritesSinceBound[size_t(block)] = 0;
        }
        return mBound[size_t(block)];
    }

    // The farthest non-NaN stored depth of the block (the nearest with Greater tests); the
    // comparisons are false for NaN, which leaves it out.
    float farthestStored(int block) const {
        const int column = block % kMaxBlocksPerSide, row = block / kMaxBlocksPerSide;
        const int x0 = mTileMinX + column * kBlockSize, x1 = blockColumnEnd(column);
        const int y0 = mTileMinY + row * kBlockSize, y1 = blockRowEnd(row);
        constexpr bool kFarIsLarge =
            kDepthTest == DepthTest::Less || kDepthTest == DepthTest::LessEqual;
        float farthest = kFarIsLarge ? -std::numeric_limits<float>::infinity()
                                     : std::numeric_limits<float>::infinity();
        for (int y = y0; y <= y1; ++y) {
            const float* row = mDepth + size_t(y) * size_t(mWidth);
            for (int x = x0; x <= x1; ++x) {
                const float stored = row[x];
                if (kFarIsLarge ? stored > farthest : stored < farthest)
                    farthest = stored;
            }
        }
        return farthest;
    }

    const float* mDepth;
    int mWidth;
    int mTileMinX, mTileMinY, mTileMaxX, mTileMaxY;
    static constexpr size_t kMaxBlocks = size_t(kMaxBlocksPerSide) * kMaxBlocksPerSide;
    std::array<float, kMaxBlocks> mBound;
    // Writes since the bound was computed; kPixelsPerBlock (the start value) asks for a new one.
    std::array<int32_t, kMaxBlocks> mWritesSinceBound;
};

} // namespace raster
