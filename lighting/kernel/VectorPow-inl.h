// powNonNegative: x^y for the specular lobe, per lane, as exp(y log x) through Highway's
// contrib/math (Highway 1.0.3 has Exp and Log but no Pow). Per-target code: included by
// VectorTargets.cpp once for every compiled instruction set (foreach_target.h).
//
// Domain: y >= 0 (a specular power); x any float, taken as 0 unless x > 0 (so n.h needs no clamp
// and NaN counts as 0). Where x is 0 the result is what std::pow gives, 0 for y > 0 and 1 for
// y == 0, not exp(y log 0) (Log(0) is not -inf in Highway's implementation, and 0 * -inf would be
// NaN); the logarithm is then taken of 1 instead, so no lane computes a NaN or an infinity. Exp
// returns 0 below an argument of -104, where the float result would be subnormal or zero anyway
// (exp(-104) = 6.8e-46 < the smallest subnormal 1.4e-45). Accuracy against double std::pow:
// measured in tests/kernel/vector_pow_test.cpp (README.md).
//
// Highway's Exp and Log use MulAdd, which is a fused multiply-add on AVX2 and AVX-512 and a
// multiply then an add on SSE4: the last bits of pow differ between those two groups of targets
// (and from the scalar path's std::pow); AVX2 and AVX-512 run the same operations lane by lane and
// agree bitwise.
#include <cstddef>

#if defined(LIGHTING_KERNEL_VECTOR_POW_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef LIGHTING_KERNEL_VECTOR_POW_INL_H_
#undef LIGHTING_KERNEL_VECTOR_POW_INL_H_
#else
#define LIGHTING_KERNEL_VECTOR_POW_INL_H_
#endif

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace lighting::kernel::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <class D, class V> HWY_INLINE V powNonNegative(D d, V x, V y) {
    const V zero = hn::Zero(d);
    const V one = hn::Set(d, 1.0f);
    const auto positive = hn::Gt(x, zero);
    const V logX = hn::Log(d, hn::IfThenElse(positive, x, one));
    const V power = hn::Exp(d, hn::Mul(y, logX));
    return hn::IfThenElse(positive, power, hn::IfThenElseZero(hn::Eq(y, zero), one));
}

// out[i] = powNonNegative(x[i], y[i]) for i < count: the accuracy study's entry point
// (VectorFunctions::pow), not used by the shading loop.
void powArrayVector(const float* x, const float* y, float* out, size_t count) {
    const hn::ScalableTag<float> d;
    const size_t lanes = hn::Lanes(d);
    size_t i = 0;
    for (; i + lanes <= count; i += lanes)
        hn::StoreU(powNonNegative(d, hn::LoadU(d, x + i), hn::LoadU(d, y + i)), d, out + i);
    if (i < count) {
        HWY_ALIGN float xs[hn::MaxLanes(d)] = {}, ys[hn::MaxLanes(d)] = {},
                        results[hn::MaxLanes(d)];
        for (size_t j = i; j < count; ++j) {
            xs[j - i] = x[j];
            ys[j - i] = y[j];
        }
        hn::Store(powNonNegative(d, hn::Load(d, xs), hn::Load(d, ys)), d, results);
        for (size_t j = i; j < count; ++j)
            out[j] = results[j - i];
    }
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // include guard toggle
