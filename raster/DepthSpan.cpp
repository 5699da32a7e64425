// The depth-only span loop per instruction set: hwy/foreach_target.h compiles this file once per
// target Highway builds (the same policy as lighting/kernel/VectorTargets.cpp), and
// HWY_DYNAMIC_DISPATCH calls the best one this CPU runs. See DepthSpan.h for the contract.
#include "raster/DepthSpan.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/DepthSpan.cpp"
#include <hwy/foreach_target.h> // must come before highway.h

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace raster::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// Depth in double lanes (the plane is double), tested and stored as float lanes of the same
// count. No load or store ever leaves [lo, hi]: the tail (fewer pixels than a vector) is one
// masked vector where masked memory operations cannot fault (AVX-512), the scalar loop elsewhere.
template <DepthTest kTest, bool kValues> HWY_INLINE uint64_t spanLoop(const DepthSpanArgs& span) {
    const hn::ScalableTag<double> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<uint32_t, decltype(dd)> du;
    const auto value = hn::Set(du, span.value);
    const int lanes = int(hn::Lanes(dd));
    const auto zero = hn::Zero(dd);
    const auto one = hn::Set(dd, 1.0);
    const auto zRow = hn::Set(dd, span.zRow);
    const auto zStep = hn::Set(dd, span.zStep);
    const auto advance = hn::Set(dd, double(lanes));
    auto px = hn::Iota(dd, double(span.lo));
    float* row = span.row;
    uint64_t passed = 0;
    int x = span.lo;
    for (; x + lanes - 1 <= span.hi; x += lanes, px = hn::Add(px, advance)) {
        auto z = hn::Add(zRow, hn::Mul(zStep, px));
        // std::clamp(z, 0, 1): z < 0 ? 0 : (1 < z ? 1 : z), NaN kept.
        z = hn::IfThenElse(hn::Lt(z, zero), zero, hn::IfThenElse(hn::Lt(one, z), one, z));
        const auto depth = hn::DemoteTo(df, z);
        const auto stored = hn::LoadU(df, row + x);
        hn::Mask<decltype(df)> pass;
        if constexpr (kTest == DepthTest::Always)
            pass = hn::FirstN(df, size_t(lanes));
        else if constexpr (kTest == DepthTest::Less)
            pass = hn::Lt(depth, stored);
        else if constexpr (kTest == DepthTest::LessEqual)
            pass = hn::Le(depth, stored);
        else if constexpr (kTest == DepthTest::Greater)
            pass = hn::Gt(depth, stored);
        else
            pass = hn::Ge(depth, stored);
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
    auto z = hn::Add(zRow, hn::Mul(zStep, px));
    z = hn::IfThenElse(hn::Lt(z, zero), zero, hn::IfThenElse(hn::Lt(one, z), one, z));
    const auto depth = hn::DemoteTo(df, z);
    const auto stored = hn::MaskedLoad(inside, df, row + x);
    hn::Mask<decltype(df)> pass;
    if constexpr (kTest == DepthTest::Always)
        pass = inside;
    else if constexpr (kTest == DepthTest::Less)
        pass = hn::And(inside, hn::Lt(depth, stored));
    else if constexpr (kTest == DepthTest::LessEqual)
        pass = hn::And(inside, hn::Le(depth, stored));
    else if constexpr (kTest == DepthTest::Greater)
        pass = hn::And(inside, hn::Gt(depth, stored));
    else
        pass = hn::And(inside, hn::Ge(depth, stored));
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

} // namespace raster::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace raster {

HWY_EXPORT(depthSpanLoopFor);

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
