// Accuracy of the kernel's pow (exp(y log x) through Highway's Exp and Log, VectorPow-inl.h) on
// every compiled target, against std::pow in double: the specular lobe x^y for x = n.h in [0, 1]
// and powers 0..8192. The float std::pow the scalar path uses is measured beside it.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>
#include <vector>

#include "lighting/kernel/VectorTargets.h"
#include "tests/kernel/KernelTestInputs.h"

namespace {

using lighting::kernel::KernelIsa;

class VectorPowTest : public ::testing::TestWithParam<KernelIsa> {};

std::vector<float> vectorPow(const KernelIsa& isa, const std::vector<float>& x,
                             const std::vector<float>& y) {
    std::vector<float> out(x.size());
    isa.vector()->pow(x.data(), y.data(), out.data(), x.size());
    return out;
}

TEST_P(VectorPowTest, SpecialValues) {
    const KernelIsa isa = GetParam();
    const std::vector<float> x = {0.0f, 0.0f, -0.0f, 1.0f, 1.0f, 0.5f, 0.5f, 1e-30f, 0.25f};
    const std::vector<float> y = {0.0f, 3.0f, 3.0f, 8192.0f, 0.0f, 0.0f, 1.0f, 8192.0f, 2.0f};
    const std::vector<float> expected = {1.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f, 0.5f, 0.0f, 0.0625f};
    const std::vector<float> got = vectorPow(isa, x, y);
    for (size_t i = 0; i < x.size(); ++i)
        EXPECT_EQ(got[i], expected[i]) << "pow(" << x[i] << ", " << y[i] << ")";
}

// Relative error against double pow where the result is a normal float; absolute error below.
// Error model: the argument y log x carries about |y log x| float roundings of relative error
// into the result, plus Exp's and Log's own few ulps.
TEST_P(VectorPowTest, AccuracyAgainstDouble) {
    const KernelIsa isa = GetParam();
    std::mt19937 random(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const size_t count = 1 << 20;
    std::vector<float> x(count), y(count);
    for (size_t i = 0; i < count; ++i) {
        // Half near 1 (where specular highlights live), half spread over (0, 1] logarithmically.
        x[i] = i % 2 ? 1.0f - unit(random) * 0.01f : std::exp2(-20.0f * unit(random));
        y[i] = i % 7 == 0 ? std::floor(std::exp2(13.0f * unit(random)))
                          : std::exp2(13.0f * unit(random));
    }
    const std::vector<float> got = vectorPow(isa, x, y);
    double worstRelative = 0, worstStdRelative = 0, worstModelRatio = 0, worstAbsolute = 0;
    for (size_t i = 0; i < count; ++i) {
        const double exact = std::pow(double(x[i]), double(y[i]));
        const double argument = std::abs(double(y[i]) * std::log(double(x[i])));
        if (exact >= FLT_MIN) {
            const double relative = std::abs(got[i] - exact) / exact;
            worstRelative = std::max(worstRelative, relative);
            worstStdRelative =
                std::max(worstStdRelative, std::abs(std::pow(x[i], y[i]) - exact) / exact);
            // In units of float epsilon per unit of |y log x| (+ 4 ulps for Exp and Log).
            worstModelRatio =
                std::max(worstModelRatio, relative / (FLT_EPSILON * (argument + 4.0)));
        } else {
            worstAbsolute = std::max(worstAbsolute, std::abs(got[i] - exact));
        }
    }
    std::printf("[ %s ] pow: worst relative error %.3g (std::pow float: %.3g), worst error / "
                "(eps (|y log x| + 4)) %.3g, worst absolute error below FLT_MIN %.3g\n",
                isa.name().c_str(), worstRelative, worstStdRelative, worstModelRatio,
                worstAbsolute);
    EXPECT_LT(worstModelRatio, 1.0);
    EXPECT_LT(worstAbsolute, double(FLT_MIN));
}

std::string isaName(const ::testing::TestParamInfo<KernelIsa>& info) {
    return info.param.name();
}

INSTANTIATE_TEST_SUITE_P(EveryTarget, VectorPowTest, ::testing::ValuesIn(kerneltest::vectorIsas()),
                         isaName);

} // namespace
