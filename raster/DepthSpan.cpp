// The depth-only span loop per instruction set: hwy/foreach_target.h compiles this file once per
// target Highway builds (the same policy as lighting/kernel/VectorTargets.cpp), and
// HWY_DYNAMIC_DISPATCH calls the best one this CPU runs. See DepthSpan.h for the contract.
#include "raster/DepthSpan.h"

#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/DepthSpan.cpp"
#include <hwy/foreach_target.h> // must come before highway.h

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace raster::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// std::clamp(z, 0, 1): z < 0 ? 0 : (1 < z ? 1 : z), NaN kept.
template <class DD, class V> HWY_INLINE V clampToUnit(DD dd, V z) {
    const auto zero = hn::Zero(dd);
    const auto one = hn::Set(dd, 1.0);
    return hn::IfThenElse(hn::Lt(z, zero), zero, hn::IfThenElse(hn::Lt(one, z), one, z));
}

// detail::depthPasses on lanes.
template <DepthTest kTest, class DF, class V>
HWY_INLINE hn::Mask<DF> depthPassesLanes(DF df, V depth, V stored) {
    if constexpr (kTest == DepthTest::Always)
        return hn::FirstN(df, hn::Lanes(df));
    else if constexpr (kTest == DepthTest::Less)
        return hn::Lt(depth, stored);
    else if constexpr (kTest == DepthTest::LessEqual)
        return hn::Le(depth, stored);
    else if constexpr (kTest == DepthTest::Greater)
        return hn::Gt(depth, stored);
    else
        return hn::Ge(depth, stored);
}

// Depth in double lanes (the plane is double), tested and stored as float lanes of the same
// count. No load or store ever leaves [lo, hi]: the tail (fewer pixels than a vector) is one
// masked vector where masked memory operations cannot fault (AVX-512), the scalar loop elsewhere.
template <DepthTest kTest, bool kValues> HWY_INLINE uint64_t spanLoop(const DepthSpanArgs& span) {
    const hn::ScalableTag<double> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<uint32_t, decltype(dd)> du;
    const auto value = hn::Set(du, span.value);
    const int lanes = int(hn::Lanes(dd));
    const auto zRow = hn::Set(dd, span.zRow);
    const auto zStep = hn::Set(dd, span.zStep);
    const auto advance = hn::Set(dd, double(lanes));
    auto px = hn::Iota(dd, double(span.lo));
    float* row = span.row;
    uint64_t passed = 0;
    int x = span.lo;
    for (; x + lanes - 1 <= span.hi; x += lanes, px = hn::Add(px, advance)) {
        const auto depth = hn::DemoteTo(df, clampToUnit(dd, hn::Add(zRow, hn::Mul(zStep, px))));
        const auto stored = hn::LoadU(df, row + x);
        const auto pass = depthPassesLanes<kTest>(df, depth, stored);
        passed += hn::CountTrue(df, pass);
        if (span.write)
            hn::StoreU(hn::IfThenElse(pass, depth, stored), df, row + x);
        if constexpr (kValues)
            hn::BlendedStore(value, hn::RebindMask(du, pass), du, span.values + x);
    }
#if HWY_MEM_OPS_MIGHT_FAULT
    DepthSpanArgs tail = span;
    tail.lo = x;
    if constexpr (!kValues)
        tail.values = nullptr;
    return passed + detail::depthSpanScalarLoop<kTest>(tail);
#else
    // The tail (and a whole short span) as one masked vector: lanes past hi are neither loaded
    // nor stored (masked memory operations do not fault on this target), and the lanes inside
    // compute exactly what the full vectors do.
    if (x > span.hi)
        return passed;
    const auto inside = hn::FirstN(df, size_t(span.hi - x + 1));
    const auto depth = hn::DemoteTo(df, clampToUnit(dd, hn::Add(zRow, hn::Mul(zStep, px))));
    const auto stored = hn::MaskedLoad(inside, df, row + x);
    const auto pass = hn::And(inside, depthPassesLanes<kTest>(df, depth, stored));
    passed += hn::CountTrue(df, pass);
    if (span.write)
        hn::BlendedStore(depth, pass, df, row + x);
    if constexpr (kValues)
        hn::BlendedStore(value, hn::RebindMask(du, pass), du, span.values + x);
    return passed;
#endif
}

// The loop for one test as a plain function, so that a draw can take its address once.
template <DepthTest kTest, bool kValues> uint64_t spanLoopFunction(const DepthSpanArgs& span) {
    return spanLoop<kTest, kValues>(span);
}

template <bool kValues> DepthSpanLoop spanLoopFor(DepthTest test) {
    switch (test) {
    case DepthTest::Always:
        return &spanLoopFunction<DepthTest::Always, kValues>;
    case DepthTest::Less:
        return &spanLoopFunction<DepthTest::Less, kValues>;
    case DepthTest::LessEqual:
        return &spanLoopFunction<DepthTest::LessEqual, kValues>;
    case DepthTest::Greater:
        return &spanLoopFunction<DepthTest::Greater, kValues>;
    case DepthTest::GreaterEqual:
        return &spanLoopFunction<DepthTest::GreaterEqual, kValues>;
    }
    return nullptr;
}

DepthSpanLoop depthSpanLoopFor(DepthTest test, bool values) {
    return values ? spanLoopFor<true>(test) : spanLoopFor<false>(test);
}

// One vector of a multisampled span: `lanes` consecutive samples from flat index i (whole pixels,
// or a whole pixel's part when a pixel has more samples than a vector has lanes), the centre's
// plane value zCentre and the samples' offsets per lane, the covered lanes `covered` (none
// outside the span). Returns the passing lanes and adds to the counts.
template <DepthTest kTest, class DD, class VD>
HWY_INLINE hn::Mask<hn::Rebind<float, DD>>
multisampleVector(DD dd, const MultisampleSpanArgs& span, size_t i, VD zCentre, VD offsets,
                  hn::Mask<hn::Rebind<float, DD>> covered, bool full) {
    const hn::Rebind<float, DD> df;
    const hn::Rebind<uint32_t, DD> du;
    const auto depth = hn::DemoteTo(df, clampToUnit(dd, hn::Add(zCentre, offsets)));
    const auto stored =
        full ? hn::LoadU(df, span.depth + i) : hn::MaskedLoad(covered, df, span.depth + i);
    const auto pass = hn::And(covered, depthPassesLanes<kTest>(df, depth, stored));
    if (span.write) {
        if (full)
            hn::StoreU(hn::IfThenElse(pass, depth, stored), df, span.depth + i);
        else
            hn::BlendedStore(depth, pass, df, span.depth + i);
    }
    if (span.values)
        hn::BlendedStore(hn::Set(du, span.value), hn::RebindMask(du, pass), du, span.values + i);
    if (span.centreDepths)
        hn::BlendedStore(hn::DemoteTo(df, clampToUnit(dd, zCentre)), pass, df,
                         span.centreDepths + i);
    return pass;
}

// The covered lanes: every edge value (the sample's, fill bias included) >= 0. The int64 lanes'
// mask becomes the float lanes' through its bits (no mask conversion across lane sizes here).
template <class DF, class VI> HWY_INLINE hn::Mask<DF> coveredLanes(DF df, const VI* edge) {
    const hn::RebindToSigned<hn::Rebind<double, DF>> di;
    const auto outside = hn::Lt(hn::Or(hn::Or(edge[0], edge[1]), edge[2]), hn::Zero(di));
    uint8_t bits[8] = {}; // at most 64 lanes
    hn::StoreMaskBits(di, hn::Not(outside), bits);
    return hn::LoadMaskBits(df, bits);
}

// Of `pixels` pixels of `samples` lanes each, those with a passing lane.
template <class DF>
HWY_INLINE uint64_t pixelsWithAPass(DF df, hn::Mask<DF> pass, size_t pixels, size_t samples) {
    uint8_t bytes[8] = {}; // at most 64 lanes
    hn::StoreMaskBits(df, pass, bytes);
    uint64_t bits = 0;
    std::memcpy(&bits, bytes, sizeof(bytes));
    const uint64_t pixelMask = (1ull << samples) - 1ull; // samples <= 8
    uint64_t count = 0;
    for (size_t p = 0; p < pixels; ++p)
        count += (bits >> (p * samples) & pixelMask) != 0;
    return count;
}

// What the vectors of a multisampled span share when a vector holds whole pixels (lanes >=
// samples; lane l is pixel l / samples, sample l % samples): the lanes' depth offsets, their
// pixel (as double), and per edge the lanes' offsets from the span's first pixel centre (the
// sample's offset plus the edge's step times the lane's pixel) and the step of a whole vector.
// Fixed over a triangle: made once per MultisampleTriangleArgs, or per span by the span form.
// Made in registers: patterns written to memory and loaded back as a vector stalled on store
// forwarding.
template <class DD> struct LanePatterns {
    hn::Vec<DD> offsets;
    hn::Vec<DD> pixelOfLane;
    hn::Vec<hn::RebindToSigned<DD>> edgeOfLane[3];
    hn::Vec<hn::RebindToSigned<DD>> edgeAdvance[3];
    size_t pixelsPerVector;

    // From the samples' offsets (kMaxSamples readable), the edges' offsets and steps.
    HWY_INLINE static LanePatterns make(DD dd, size_t samples, const double* sampleOffsets,
                                        const int64_t (*edgeOffsets)[kMaxSamples],
                                        const int64_t edgeStep[3]) {
        const hn::RebindToSigned<DD> di;
        LanePatterns p;
        p.pixelsPerVector = hn::Lanes(dd) / samples;
        const auto sampleOfLane = hn::And(hn::Iota(di, 0), hn::Set(di, int64_t(samples) - 1));
        const auto pixelOfLane = hn::ShiftRightSame(hn::Iota(di, 0), std::countr_zero(samples));
        p.offsets = hn::TableLookupLanes(hn::LoadU(dd, sampleOffsets),
                                         hn::IndicesFromVec(dd, sampleOfLane));
        p.pixelOfLane = hn::ConvertTo(dd, pixelOfLane);
        for (int e = 0; e < 3; ++e) {
            // The offset of the lane's sample plus step * pixel, by adds (no int64 multiply on
            // every target).
            const auto step = hn::Set(di, edgeStep[e]);
            auto value = hn::TableLookupLanes(hn::LoadU(di, edgeOffsets[e]),
                                              hn::IndicesFromVec(di, sampleOfLane));
            for (int64_t q = 1; q < int64_t(p.pixelsPerVector); ++q)
                value = hn::Add(value,
                                hn::IfThenElseZero(hn::Gt(pixelOfLane, hn::Set(di, q - 1)), step));
            p.edgeOfLane[e] = value;
            p.edgeAdvance[e] = hn::Set(di, edgeStep[e] * int64_t(p.pixelsPerVector));
        }
        return p;
    }
};

// A span of whole-pixel vectors with its triangle's patterns: a flat walk over the span's samples
// (contiguous: depth[px * samples + s]). Edge values are int64 lanes of the vector's count,
// advanced by adds.
template <DepthTest kTest, class DD>
HWY_INLINE MultisampleSpanCounts wholePixelSpan(DD dd, const MultisampleSpanArgs& span,
                                                const LanePatterns<DD>& patterns) {
    const hn::Rebind<float, DD> df;
    const hn::RebindToSigned<DD> di;
    const size_t samples = size_t(span.samples);
    const size_t pixelsPerVector = patterns.pixelsPerVector;
    MultisampleSpanCounts counts;
    const auto zRow = hn::Set(dd, span.zRow);
    const auto zStep = hn::Set(dd, span.zStep);
    hn::Vec<decltype(di)> edge[3];
    for (int e = 0; e < 3; ++e)
        edge[e] = hn::Add(hn::Set(di, span.edgeAtLo[e]), patterns.edgeOfLane[e]);
    const auto advance = hn::Set(dd, double(pixelsPerVector));
    auto px = hn::Add(hn::Set(dd, double(span.lo)), patterns.pixelOfLane);
    int x = span.lo;
    for (; x + int(pixelsPerVector) - 1 <= span.hi; x += int(pixelsPerVector)) {
        const auto covered = coveredLanes(df, edge);
        counts.samplesCovered += hn::CountTrue(df, covered);
        const auto zCentre = hn::Add(zRow, hn::Mul(zStep, px));
        const auto pass = multisampleVector<kTest>(dd, span, size_t(x) * samples, zCentre,
                                                   patterns.offsets, covered, true);
        counts.samplesPassed += hn::CountTrue(df, pass);
        counts.fragments += pixelsWithAPass(df, pass, pixelsPerVector, samples);
        px = hn::Add(px, advance);
        for (int e = 0; e < 3; ++e)
            edge[e] = hn::Add(edge[e], patterns.edgeAdvance[e]);
    }
    if (x > span.hi)
        return counts;
#if HWY_MEM_OPS_MIGHT_FAULT
    MultisampleSpanArgs tail = span;
    tail.lo = x;
    for (int e = 0; e < 3; ++e)
        tail.edgeAtLo[e] = span.edgeAtLo[e] + span.edgeStep[e] * int64_t(x - span.lo);
    detail::addCounts(counts, detail::multisampleSpanScalarLoop<kTest>(tail));
#else
    // The last pixels (fewer than a vector holds) as one masked vector, as spanLoop's tail.
    const size_t pixels = size_t(span.hi - x + 1);
    const auto covered = hn::And(hn::FirstN(df, pixels * samples), coveredLanes(df, edge));
    counts.samplesCovered += hn::CountTrue(df, covered);
    const auto zCentre = hn::Add(zRow, hn::Mul(zStep, px));
    const auto pass = multisampleVector<kTest>(dd, span, size_t(x) * samples, zCentre,
                                               patterns.offsets, covered, false);
    counts.samplesPassed += hn::CountTrue(df, pass);
    counts.fragments += pixelsWithAPass(df, pass, pixels, samples);
#endif
    return counts;
}

// A pixel takes samples / lanes vectors (more samples than a vector has lanes).
template <DepthTest kTest, class DD>
HWY_INLINE MultisampleSpanCounts splitPixelSpan(DD dd, const MultisampleSpanArgs& span) {
    const hn::Rebind<float, DD> df;
    const hn::RebindToSigned<DD> di;
    const size_t lanes = hn::Lanes(dd);
    const size_t samples = size_t(span.samples);
    MultisampleSpanCounts counts;
    const auto zRow = hn::Set(dd, span.zRow);
    const auto zStep = hn::Set(dd, span.zStep);
    for (int px = span.lo; px <= span.hi; ++px) {
        const int64_t k = px - span.lo;
        const auto zCentre = hn::Add(zRow, hn::Mul(zStep, hn::Set(dd, double(px))));
        bool any = false;
        for (size_t c = 0; c < samples; c += lanes) {
            hn::Vec<decltype(di)> edge[3];
            for (int e = 0; e < 3; ++e)
                edge[e] = hn::Add(hn::Set(di, span.edgeAtLo[e] + span.edgeStep[e] * k),
                                  hn::LoadU(di, span.edgeOffsets[e] + c));
            const auto covered = coveredLanes(df, edge);
            counts.samplesCovered += hn::CountTrue(df, covered);
            const auto offsets = hn::LoadU(dd, span.sampleOffsets + c);
            const auto pass = multisampleVector<kTest>(dd, span, size_t(px) * samples + c, zCentre,
                                                       offsets, covered, true);
            counts.samplesPassed += hn::CountTrue(df, pass);
            any |= !hn::AllFalse(df, pass);
        }
        counts.fragments += any;
    }
    return counts;
}

// The span form: with at least as many lanes as samples a vector holds whole pixels, otherwise a
// pixel takes samples / lanes vectors.
template <DepthTest kTest>
MultisampleSpanCounts multisampleSpanLoopFunction(const MultisampleSpanArgs& span) {
    const hn::ScalableTag<double> dd;
    const size_t lanes = hn::Lanes(dd);
    const size_t samples = size_t(span.samples);
    // sampleOffsets and edgeOffsets hold kMaxSamples values: one vector's load (the lane
    // patterns' source).
    if (lanes > size_t(kMaxSamples))
        return detail::multisampleSpanScalarLoop<kTest>(span);
    if (span.lo > span.hi)
        return {};
    if (lanes < samples)
        return splitPixelSpan<kTest>(dd, span);
    return wholePixelSpan<kTest>(
        dd, span,
        LanePatterns<hn::ScalableTag<double>>::make(dd, samples, span.sampleOffsets,
                                                    span.edgeOffsets, span.edgeStep));
}

// The triangle form: the patterns once, then every row's span.
template <DepthTest kTest>
MultisampleSpanCounts multisampleTriangleFunction(const MultisampleTriangleArgs& t) {
    const hn::ScalableTag<double> dd;
    const size_t lanes = hn::Lanes(dd);
    const size_t samples = size_t(t.samples);
    MultisampleSpanCounts counts;
    if (lanes > size_t(kMaxSamples)) {
        detail::forEachMultisampleRow(t, [&](const MultisampleSpanArgs& span) {
            detail::addCounts(counts, detail::multisampleSpanScalarLoop<kTest>(span));
        });
    } else if (lanes < samples) {
        detail::forEachMultisampleRow(t, [&](const MultisampleSpanArgs& span) {
            detail::addCounts(counts, splitPixelSpan<kTest>(dd, span));
        });
    } else {
        const auto patterns = LanePatterns<hn::ScalableTag<double>>::make(
            dd, samples, t.sampleOffsets, t.edgeOffsets, t.edgeStepX);
        detail::forEachMultisampleRow(t, [&](const MultisampleSpanArgs& span) {
            detail::addCounts(counts, wholePixelSpan<kTest>(dd, span, patterns));
        });
    }
    return counts;
}

MultisampleTriangleLoop multisampleTriangleLoopFor(DepthTest test) {
    switch (test) {
    case DepthTest::Always:
        return &multisampleTriangleFunction<DepthTest::Always>;
    case DepthTest::Less:
        return &multisampleTriangleFunction<DepthTest::Less>;
    case DepthTest::LessEqual:
        return &multisampleTriangleFunction<DepthTest::LessEqual>;
    case DepthTest::Greater:
        return &multisampleTriangleFunction<DepthTest::Greater>;
    case DepthTest::GreaterEqual:
        return &multisampleTriangleFunction<DepthTest::GreaterEqual>;
    }
    return nullptr;
}

MultisampleSpanLoop multisampleSpanLoopFor(DepthTest test) {
    switch (test) {
    case DepthTest::Always:
        return &multisampleSpanLoopFunction<DepthTest::Always>;
    case DepthTest::Less:
        return &multisampleSpanLoopFunction<DepthTest::Less>;
    case DepthTest::LessEqual:
        return &multisampleSpanLoopFunction<DepthTest::LessEqual>;
    case DepthTest::Greater:
        return &multisampleSpanLoopFunction<DepthTest::Greater>;
    case DepthTest::GreaterEqual:
        return &multisampleSpanLoopFunction<DepthTest::GreaterEqual>;
    }
    return nullptr;
}

} // namespace raster::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace raster {

HWY_EXPORT(depthSpanLoopFor);
HWY_EXPORT(multisampleSpanLoopFor);
HWY_EXPORT(multisampleTriangleLoopFor);

MultisampleSpanLoop multisampleSpanLoop(DepthTest test) {
    return HWY_DYNAMIC_DISPATCH(multisampleSpanLoopFor)(test);
}

MultisampleTriangleLoop multisampleTriangleLoop(DepthTest test) {
    return HWY_DYNAMIC_DISPATCH(multisampleTriangleLoopFor)(test);
}

MultisampleSpanCounts multisampleTriangleScalar(DepthTest test, const MultisampleTriangleArgs& t) {
    MultisampleSpanCounts counts;
    detail::forEachMultisampleRow(t, [&](const MultisampleSpanArgs& span) {
        detail::addCounts(counts, multisampleSpanScalar(test, span));
    });
    return counts;
}

MultisampleSpanCounts multisampleSpanScalar(DepthTest test, const MultisampleSpanArgs& span) {
    switch (test) {
    case DepthTest::Always:
        return detail::multisampleSpanScalarLoop<DepthTest::Always>(span);
    case DepthTest::Less:
        return detail::multisampleSpanScalarLoop<DepthTest::Less>(span);
    case DepthTest::LessEqual:
        return detail::multisampleSpanScalarLoop<DepthTest::LessEqual>(span);
    case DepthTest::Greater:
        return detail::multisampleSpanScalarLoop<DepthTest::Greater>(span);
    case DepthTest::GreaterEqual:
        return detail::multisampleSpanScalarLoop<DepthTest::GreaterEqual>(span);
    }
    return {};
}

DepthSpanLoop depthSpanLoop(DepthTest test, bool values) {
    return HWY_DYNAMIC_DISPATCH(depthSpanLoopFor)(test, values);
}

uint64_t depthSpan(DepthTest test, const DepthSpanArgs& span) {
    return depthSpanLoop(test, span.values != nullptr)(span);
}

uint64_t depthSpanScalar(DepthTest test, const DepthSpanArgs& span) {
    switch (test) {
    case DepthTest::Always:
        return detail::depthSpanScalarLoop<DepthTest::Always>(span);
    case DepthTest::Less:
        return detail::depthSpanScalarLoop<DepthTest::Less>(span);
    case DepthTest::LessEqual:
        return detail::depthSpanScalarLoop<DepthTest::LessEqual>(span);
    case DepthTest::Greater:
        return detail::depthSpanScalarLoop<DepthTest::Greater>(span);
    case DepthTest::GreaterEqual:
        return detail::depthSpanScalarLoop<DepthTest::GreaterEqual>(span);
    }
    return 0;
}

} // namespace raster
#endif // HWY_ONCE
