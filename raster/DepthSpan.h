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
