// The uniform-pixel row loop per instruction set: hwy/foreach_target.h compiles this file once per
// target Highway supports here, and HWY_DYNAMIC_DISPATCH calls the best one this CPU runs. See
// UniformPixels.h for the contract.
#include "gbuffer/msaa/UniformPixels.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "gbuffer/msaa/UniformPixels.cpp"
#include <hwy/foreach_target.h> // must come before highway.h

#include <hwy/highway.h>

#ifndef GBUFFER_UNIFORM_PIXELS_ONCE
#define GBUFFER_UNIFORM_PIXELS_ONCE
namespace gbuffer::detail {

// Pixels [from, to) of the row, one at a time; `result` accumulates.
inline void uniformRowScalar(const UniformRowArgs& a, int from, int to, UniformRowResult& result) {
    const size_t samples = size_t(a.samples);
    const uint8_t allSamples = uint8_t((1u << a.samples) - 1u);
    for (int x = from; x < to; ++x) {
        const uint32_t* codes = a.codes + size_t(x) * samples;
        bool uniform = true;
        for (size_t s = 1; s < samples; ++s)
            uniform &= codes[s] == codes[0];
        const bool covered = codes[0] != a.noTriangle;
        const float centre = a.centreDepths[size_t(x) * samples];
        a.mainCodes[x] = codes[0];
        a.mainDepths[x] = !covered ? a.clear : centre == a.clear ? a.nearerClear : centre;
        a.mainCoverage[x] = covered ? allSamples : 0;
        a.background[x] = covered ? 0 : uint8_t(samples);
        a.complex[x] = 0;
        if (!uniform)
            a.mixed[result.mixedCount++] = uint32_t(x);
        else
            result.coveredUniformPixels += covered;
    }
}

} // namespace gbuffer::detail
#endif

HWY_BEFORE_NAMESPACE();
namespace gbuffer::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

static_assert(HWY_MAX_BYTES / sizeof(uint32_t) <= kMixedPixelSlack);

template <size_t kSamples> UniformRowResult uniformRowLanes(const UniformRowArgs& a) {
    const hn::ScalableTag<uint32_t> du;
    const hn::Rebind<float, decltype(du)> df;
    const hn::Rebind<uint8_t, decltype(du)> d8;
    using VU = hn::Vec<decltype(du)>;
    using VF = hn::Vec<decltype(df)>;
    const size_t lanes = hn::Lanes(du);
    const VU none = hn::Set(du, a.noTriangle);
    const VF clear = hn::Set(df, a.clear);
    const VF nearerClear = hn::Set(df, a.nearerClear);
    const VU allSamples = hn::Set(du, (1u << kSamples) - 1u);
    const VU sampleCount = hn::Set(du, uint32_t(kSamples));
    const VU iota = hn::Iota(du, 0);
    UniformRowResult result;
    size_t x = 0;
    for (; x + lanes <= size_t(a.pixels); x += lanes) {
        const uint32_t* codes = a.codes + x * kSamples;
        const float* depths = a.centreDepths + x * kSamples;
        VU code0, code1;
        VF depth0, depth1;
        hn::Mask<decltype(du)> uniform;
        if constexpr (kSamples == 4) {
            VU code2, code3;
            VF depth2, depth3;
            hn::LoadInterleaved4(du, codes, code0, code1, code2, code3);
            hn::LoadInterleaved4(df, depths, depth0, depth1, depth2, depth3);
            uniform =
                hn::And(hn::And(hn::Eq(code0, code1), hn::Eq(code0, code2)), hn::Eq(code0, code3));
        } else {
            hn::LoadInterleaved2(du, codes, code0, code1);
            hn::LoadInterleaved2(df, depths, depth0, depth1);
            uniform = hn::Eq(code0, code1);
        }
        const auto covered = hn::Ne(code0, none);
        const auto coveredF = hn::RebindMask(df, covered);
        const VF depth = hn::IfThenElse(
            coveredF, hn::IfThenElse(hn::Eq(depth0, clear), nearerClear, depth0), clear);
        hn::StoreU(code0, du, a.mainCodes + x);
        hn::StoreU(depth, df, a.mainDepths + x);
        hn::StoreU(hn::U8FromU32(hn::IfThenElseZero(covered, allSamples)), d8, a.mainCoverage + x);
        hn::StoreU(hn::U8FromU32(hn::IfThenZeroElse(covered, sampleCount)), d8, a.background + x);
        hn::StoreU(hn::Zero(d8), d8, a.complex + x);
        result.mixedCount +=
            int(hn::CompressStore(hn::Add(iota, hn::Set(du, uint32_t(x))), hn::Not(uniform), du,
                                  a.mixed + result.mixedCount));
        result.coveredUniformPixels += hn::CountTrue(du, hn::And(uniform, covered));
    }
    detail::uniformRowScalar(a, int(x), a.pixels, result);
    return result;
}

UniformRowResult uniformRow(const UniformRowArgs& args) {
    switch (args.samples) {
    case 2:
        return uniformRowLanes<2>(args);
    case 4:
        return uniformRowLanes<4>(args);
    default: { // 8: no 8-way de-interleave; the scalar loop
        UniformRowResult result;
        detail::uniformRowScalar(args, 0, args.pixels, result);
        return result;
    }
    }
}

} // namespace gbuffer::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace gbuffer {

HWY_EXPORT(uniformRow);

UniformRowResult writeUniformRow(const UniformRowArgs& args) {
    return HWY_DYNAMIC_DISPATCH(uniformRow)(args);
}

UniformRowResult writeUniformRowScalar(const UniformRowArgs& args) {
    UniformRowResult result;
    detail::uniformRowScalar(args, 0, args.pixels, result);
    return result;
}

} // namespace gbuffer
#endif // HWY_ONCE
