// DepthSpan: the inner loop of the depth-only path (Rasterizer.h, DepthOnly): one row's span of
// covered pixels, each pixel's depth from the triangle's plane, tested against the depth buffer
// and written where it passes. Shadow maps spend nearly all their fill time here (a 512^2 cube
// face is covered several times over by the walls near its light), so the loop runs on SIMD
// lanes through Google Highway with run-time dispatch (DepthSpan.cpp, one copy per instruction
// set), and the scalar loop stays as its oracle.
//
// Exactness: both compute, per pixel px, z = float(clamp(zRow + zStep * double(px), 0, 1)) with
// the same IEEE double operations in the same order (no FMA: -ffp-contract=off; px is an exact
// double), round to float the same way and compare with the same ordered comparison, so the
// vector loop writes bitwise the depths and counts the samples the scalar loop does, NaN
// included (a NaN depth passes no test but Always).
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace raster {

enum class DepthTest { Always, Less, LessEqual, Greater, GreaterEqual };

// One row's covered pixels [lo, hi] of `row` (row[px] is pixel px), a depth plane along the row
// z(px) = zRow + zStep * px, and whether passing pixels are written.
struct DepthSpanArgs {
    float* row = nullptr;
    int lo = 0;
    int hi = -1;
    double zRow = 0.0;
    double zStep = 0.0;
    bool write = true;
    // When set (the visibility draw, Rasterizer.h's TriangleIds): `values[px] = value` at every
    // pixel that passes, whether or not depth is written; `values` is indexed as `row`.
    uint32_t* values = nullptr;
    uint32_t value = 0;
};

namespace detail {
template <DepthTest test> inline bool depthPasses(float fragmentDepth, float storedDepth) {
    switch (test) {
    case DepthTest::Always:
        return true;
    case DepthTest::Less:
        return fragmentDepth < storedDepth;
    case DepthTest::LessEqual:
        return fragmentDepth <= storedDepth;
    case DepthTest::Greater:
        return fragmentDepth > storedDepth;
    case DepthTest::GreaterEqual:
        return fragmentDepth >= storedDepth;
    }
    return false;
}

// One row's covered pixels: pixel first + k, 0 <= k <= kMax, is covered when
// value[e] + k * step[e] >= 0 for the three edges (value: the edge function at the row's first
// pixel plus the fill bias, step: its change per pixel). The half-planes are convex, so the
// covered k form one interval [kLo, kHi], found with at most one integer division per edge and
// none for an edge that does not bound the interval inside [0, kMax] (most edges of a small
// triangle's rows). Exact: the same integer tests as pixel by pixel. Empty when kLo > kHi.
struct RowSpan {
    int64_t kLo, kHi;
};
[[gnu::always_inline]] inline RowSpan coveredSpan(const int64_t value[3], const int64_t step[3],
                                                  int64_t kMax) {
    RowSpan span{0, kMax};
    for (int e = 0; e < 3; ++e) {
        const int64_t v = value[e], s = step[e];
        if (s >= 0) {
            if (v < 0) {
                // Covered from ceil(-v / s) on; never when s == 0.
                if (s == 0 || v + s * span.kHi < 0)
                    return RowSpan{0, -1};
                if (v + s * span.kLo < 0)
                    span.kLo = (-v + s - 1) / s;
            }
        } else if (v < 0) {
            return RowSpan{0, -1};
        } else if (v + s * span.kHi < 0) {
            // Covered up to floor(v / -s).
            span.kHi = v / -s;
        }
    }
    return span;
}
// The scalar span loop (depthSpanScalar, and the vector loop's tail).
template <DepthTest test> inline uint64_t depthSpanScalarLoop(const DepthSpanArgs& span) {
    uint64_t passed = 0;
    for (int px = span.lo; px <= span.hi; ++px) {
        const float z = float(std::clamp(span.zRow + span.zStep * double(px), 0.0, 1.0));
        const bool pass = depthPasses<test>(z, span.row[px]);
        passed += pass;
        span.row[px] = pass && span.write ? z : span.row[px];
        if (span.values && pass)
            span.values[px] = span.value;
    }
    return passed;
}
} // namespace detail

// The multisampled form (Rasterizer.h, rasterizeTileMultisample): a row's pixels [lo, hi] of one
// triangle, each sample covered when the triangle's three edge functions accept it, each covered
// sample's depth z = float(clamp((zRow + zStep * double(px)) + sampleOffsets[s], 0, 1)) tested
// against depth[px * samples + s] and written where it passes; `values` (optional, TriangleIds)
// gets `value` at every passing sample, and `centreDepths` (optional, indexed like depth) the
// pixel centre's float(clamp(zRow + zStep * double(px), 0, 1)) there: the visibility draw's
// record. Sample s of pixel px is covered when, for every edge e,
// edgeAtLo[e] + edgeStep[e] * (px - lo) + edgeOffsets[e][s] >= 0 (integers, as the rasterizer's
// per-sample test: the edge at the pixel centre plus its exact change to the sample, fill bias
// included).
inline constexpr int kMaxSamples = 8; // Rasterizer.h's limit (Fragment::coverage is a byte)
struct MultisampleSpanArgs {
    float* depth = nullptr; // the row's samples: pixel px's sample s at depth[px * samples + s]
    int lo = 0;
    int hi = -1;
    int samples = 4;   // 2, 4 or 8
    double zRow = 0.0; // the centre's plane along the row, as DepthSpanArgs
    double zStep = 0.0;
    // The plane's change from the centre to sample s; kMaxSamples entries readable (the vector
    // loop loads them whole), as each row of edgeOffsets.
    const double* sampleOffsets = nullptr;
    int64_t edgeAtLo[3] = {0, 0, 0};
    int64_t edgeStep[3] = {0, 0, 0};
    const int64_t (*edgeOffsets)[kMaxSamples] = nullptr; // [3][kMaxSamples]
    bool write = true;
    uint32_t* values = nullptr;
    uint32_t value = 0;
    float* centreDepths = nullptr;
};

// What a multisampled span covered and passed: samples, and pixels with a passing sample
// (fragments).
struct MultisampleSpanCounts {
    uint64_t samplesCovered = 0;
    uint64_t samplesPassed = 0;
    uint64_t fragments = 0;
};

namespace detail {
// The scalar loop: the rasterizer's per-sample path, the oracle.
template <DepthTest test>
inline MultisampleSpanCounts multisampleSpanScalarLoop(const MultisampleSpanArgs& span) {
    MultisampleSpanCounts counts;
    const size_t samples = size_t(span.samples);
    for (int px = span.lo; px <= span.hi; ++px) {
        const int64_t k = px - span.lo;
        const int64_t w0 = span.edgeAtLo[0] + span.edgeStep[0] * k;
        const int64_t w1 = span.edgeAtLo[1] + span.edgeStep[1] * k;
        const int64_t w2 = span.edgeAtLo[2] + span.edgeStep[2] * k;
        const double zCentre = span.zRow + span.zStep * double(px);
        const float centre = float(std::clamp(zCentre, 0.0, 1.0));
        unsigned passed = 0;
        for (size_t s = 0; s < samples; ++s) {
            if (((w0 + span.edgeOffsets[0][s]) | (w1 + span.edgeOffsets[1][s]) |
                 (w2 + span.edgeOffsets[2][s])) < 0)
                continue;
            ++counts.samplesCovered;
            const size_t i = size_t(px) * samples + s;
            const float z = float(std::clamp(zCentre + span.sampleOffsets[s], 0.0, 1.0));
            if (!depthPasses<test>(z, span.depth[i]))
                continue;
            passed |= 1u << s;
            if (span.write)
                span.depth[i] = z;
            if (span.values)
                span.values[i] = span.value;
            if (span.centreDepths)
                span.centreDepths[i] = centre;
        }
        counts.samplesPassed += unsigned(std::popcount(passed));
        counts.fragments += passed != 0;
    }
    return counts;
}
} // namespace detail

// One triangle's rows in a tile for the multisampled loop (Rasterizer.h,
// rasterizeTileMultisample calls it once per triangle): each row's pixels with a sample inside
// (every edge's most favourable sample accepted) become one MultisampleSpanArgs, run as the span
// loop runs it. One call per triangle rather than per row, so that what is fixed over a triangle
// (the lanes' samples, their depth and edge offsets) is made once: on dense scenes a triangle
// covers about five pixels over three rows, and the per-row set-up and call were half the
// multisampled traversal (measured 2026-12-07: 22.7% of it outside the loop, 29.7% inside).
struct MultisampleTriangleArgs {
    float* depth = nullptr; // row py's samples start at depth + py * rowStride (as values, centres)
    size_t rowStride = 0;   // floats per row: the target's width times samples
    int minX = 0, maxX = -1, minY = 0, maxY = -1; // the triangle's bounding box in the tile
    int samples = 4;                              // 2, 4 or 8
    // The plane: row py's zRow = zOrigin + zStepY * py, then as MultisampleSpanArgs (zStep =
    // zStepX), so every sample's depth is bitwise the per-row caller's.
    double zOrigin = 0.0;
    double zStepX = 0.0;
    double zStepY = 0.0;
    const double* sampleOffsets = nullptr; // as MultisampleSpanArgs
    int64_t edgeAtMin[3] = {0, 0, 0};      // each edge at pixel (minX, minY)'s centre
    int64_t edgeStepX[3] = {0, 0, 0};
    int64_t edgeStepY[3] = {0, 0, 0};
    const int64_t (*edgeOffsets)[kMaxSamples] = nullptr; // as MultisampleSpanArgs, bias included
    bool write = true;
    uint32_t* values = nullptr; // the whole target's rows, or null
    uint32_t value = 0;
    float* centreDepths = nullptr; // the whole target's rows, or null
};

namespace detail {
// The rows of `t` as spans: calls rowFn(span) for every row with a sample inside. A row shorter
// than kShortRow pixels (most rows of small triangles) is given whole, unless an edge rejects
// both its ends: the span loop tests every sample anyway, and two int64 divisions per edge cost
// more than the lanes they save. Longer rows are cut by coveredSpan on each edge's most
// favourable sample.
template <class RowFn>
[[gnu::always_inline]] inline void forEachMultisampleRow(const MultisampleTriangleArgs& t,
                                                         RowFn&& rowFn) {
    constexpr int kShortRow = 16; // pixels
    int64_t maxOffset[3];
    for (int e = 0; e < 3; ++e) {
        maxOffset[e] = t.edgeOffsets[e][0];
        for (int s = 1; s < t.samples; ++s)
            maxOffset[e] = std::max(maxOffset[e], t.edgeOffsets[e][s]);
    }
    const int64_t kMax = t.maxX - t.minX;
    int64_t row[3] = {t.edgeAtMin[0], t.edgeAtMin[1], t.edgeAtMin[2]};
    for (int py = t.minY; py <= t.maxY; ++py) {
        const int64_t anyInside[3] = {row[0] + maxOffset[0], row[1] + maxOffset[1],
                                      row[2] + maxOffset[2]};
        RowSpan outer{0, kMax};
        if (kMax < kShortRow) {
            for (int e = 0; e < 3; ++e)
                if (anyInside[e] < 0 && anyInside[e] + t.edgeStepX[e] * outer.kHi < 0)
                    outer = {0, -1};
        } else {
            outer = coveredSpan(anyInside, t.edgeStepX, kMax);
        }
        if (outer.kLo <= outer.kHi) {
            const size_t rowStart = size_t(py) * t.rowStride;
            MultisampleSpanArgs span;
            span.depth = t.depth + rowStart;
            span.lo = t.minX + int(outer.kLo);
            span.hi = t.minX + int(outer.kHi);
            span.samples = t.samples;
            span.zRow = t.zOrigin + t.zStepY * py;
            span.zStep = t.zStepX;
            span.sampleOffsets = t.sampleOffsets;
            for (int e = 0; e < 3; ++e) {
                span.edgeAtLo[e] = row[e] + t.edgeStepX[e] * outer.kLo;
                span.edgeStep[e] = t.edgeStepX[e];
            }
            span.edgeOffsets = t.edgeOffsets;
            span.write = t.write;
            span.values = t.values ? t.values + rowStart : nullptr;
            span.value = t.value;
            span.centreDepths = t.centreDepths ? t.centreDepths + rowStart : nullptr;
            rowFn(span);
        }
        for (int e = 0; e < 3; ++e)
            row[e] += t.edgeStepY[e];
    }
}

inline void addCounts(MultisampleSpanCounts& sum, const MultisampleSpanCounts& counts) {
    sum.samplesCovered += counts.samplesCovered;
    sum.samplesPassed += counts.samplesPassed;
    sum.fragments += counts.fragments;
}
} // namespace detail

using MultisampleSpanLoop = MultisampleSpanCounts (*)(const MultisampleSpanArgs&);
// The widest instruction set this CPU runs, chosen once per test (as depthSpanLoop).
MultisampleSpanLoop multisampleSpanLoop(DepthTest test);
// The same, one sample at a time: the oracle.
MultisampleSpanCounts multisampleSpanScalar(DepthTest test, const MultisampleSpanArgs& span);
// The triangle form, chosen once per test (as multisampleSpanLoop): bitwise what
// multisampleTriangleScalar writes and counts.
using MultisampleTriangleLoop = MultisampleSpanCounts (*)(const MultisampleTriangleArgs&);
MultisampleTriangleLoop multisampleTriangleLoop(DepthTest test);
// Its oracle: forEachMultisampleRow's spans through multisampleSpanScalar.
MultisampleSpanCounts multisampleTriangleScalar(DepthTest test, const MultisampleTriangleArgs& t);

// Tests (and writes) the span; returns how many of its pixels passed. The widest instruction set
// this CPU runs (Highway's dispatch). Thread-safe; touches only row[lo..hi].
uint64_t depthSpan(DepthTest test, const DepthSpanArgs& span);
// The same loop for one test, chosen once: a draw calls it per span through this pointer and
// does not pay the dispatch for every span (most shadow-map spans are a few pixels long).
// `values`: whether the spans it will be given carry DepthSpanArgs::values (a loop chosen without
// them ignores them).
using DepthSpanLoop = uint64_t (*)(const DepthSpanArgs&);
DepthSpanLoop depthSpanLoop(DepthTest test, bool values = false);
// The same, one pixel at a time: the oracle.
uint64_t depthSpanScalar(DepthTest test, const DepthSpanArgs& span);

} // namespace raster
