// FlipFeatures: ꟻLIP's edge and point detectors (HPG 2020, section 4.3): a Gaussian of standard
// deviation sigma = 0.5 w ppd pixels (w = 0.082 degrees, the human edge detector's peak-to-trough
// width) and its first and second derivatives, over 3 sigma either side. The 2D edge detector in
// x is G'(x) G(y), the point detector G''(x) G(y) (the same transposed for y), so both are
// separable; each 1D kernel's positive weights are scaled to sum to 1 and its negative weights to
// -1, which makes the 2D kernels' positive and negative parts sum to 1 and -1 too (the Gaussian
// factor sums to 1).
#include <cmath>

#include "experiments/compare/FlipInternal.h"

namespace experiments::compare::flip {

FeatureKernels makeFeatureKernels(float ppd) {
    // In float, as the reference implementation, so that the radius agrees at every ppd.
    const float sigma = 0.5f * kFeatureWidthDegrees * ppd;
    const int radius = static_cast<int>(std::ceil(3.0f * sigma));
    const int width = 2 * radius + 1;
    std::vector<double> g(width), dg(width), ddg(width);
    double gSum = 0.0, dgPositive = 0.0, dgNegative = 0.0, ddgPositive = 0.0, ddgNegative = 0.0;
    const double s = sigma;
    for (int i = 0; i < width; ++i) {
        const double x = i - radius;
        g[i] = std::exp(-x * x / (2.0 * s * s));
        dg[i] = -x * g[i];
        ddg[i] = (x * x / (s * s) - 1.0) * g[i];
        gSum += g[i];
        (dg[i] > 0.0 ? dgPositive : dgNegative) += std::fabs(dg[i]);
        (ddg[i] > 0.0 ? ddgPositive : ddgNegative) += std::fabs(ddg[i]);
    }
    // At a tiny ppd (sigma well below a pixel) the off-centre weights underflow: a part whose
    // weights sum to 0 stays 0 (that detector sees nothing) rather than dividing 0 by 0.
    auto scaled = [](double v, double positive, double negative) {
        const double sum = v > 0.0 ? positive : negative;
        return sum > 0.0 ? static_cast<float>(v / sum) : 0.0f;
    };
    FeatureKernels kernels;
    for (Kernel1d* k : {&kernels.gaussian, &kernels.firstDerivative, &kernels.secondDerivative}) {
        k->radius = radius;
        k->taps.resize(width);
    }
    for (int i = 0; i < width; ++i) {
        kernels.gaussian.taps[i] = static_cast<float>(g[i] / gSum);
        kernels.firstDerivative.taps[i] = scaled(dg[i], dgPositive, dgNegative);
        kernels.secondDerivative.taps[i] = scaled(ddg[i], ddgPositive, ddgNegative);
    }
    return kernels;
}

} // namespace experiments::compare::flip
