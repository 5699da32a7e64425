// FlipColour: ꟻLIP's colour pipeline constants: the contrast sensitivity filters (HPG 2020,
// section 4.1) and the largest colour distance cmax (section 4.2). The per-pixel colour
// functions are inline in FlipInternal.h so that the row loops vectorise.
#include <algorithm>
#include <cmath>

#include "experiments/compare/FlipInternal.h"

namespace experiments::compare::flip {

namespace {

// The widest Gaussian's scale parameter b sets the filters' common radius.
float widestCsfScale() {
    return std::max({kCsfAchromatic.b1, kCsfAchromatic.b2, kCsfRedGreen.b1, kCsfRedGreen.b2,
                     kCsfBlueYellow.b1, kCsfBlueYellow.b2});
}

// One Gaussian of the CSF, a sqrt(pi / b) exp(-pi^2 x^2 / b), with x in degrees.
double csfGaussian(double x, double a, double b) {
    return a * std::sqrt(kPi / b) * std::exp(-double(kPi) * kPi * x * x / b);
}

} // namespace

int csfRadius(float ppd) {
    // Three standard deviations of the widest Gaussian: exp(-pi^2 x^2 / b) has sigma =
    // sqrt(b / (2 pi^2)) degrees. In float, as the reference implementation, so that the radius
    // (an integer) agrees with it at every ppd.
    const float sigmaDegrees = std::sqrt(widestCsfScale() / (2.0f * kPi * kPi));
    return static_cast<int>(std::ceil(3.0f * sigmaDegrees * ppd));
}

CsfKernels makeCsfKernels(float ppd) {
    const int radius = csfRadius(ppd);
    const int width = 2 * radius + 1;
    std::vector<double> achromatic(width), redGreen(width), blueYellow1(width), blueYellow2(width);
    double sumA = 0.0, sumRg = 0.0, sumBy1 = 0.0, sumBy2 = 0.0;
    for (int i = 0; i < width; ++i) {
        const double x = (i - radius) / double(ppd);
        // The achromatic and red-green CSFs are single Gaussians (a2 = 0): each 2D filter is the
        // outer product of its 1D kernel with itself, normalised by the 1D sum.
        achromatic[i] = csfGaussian(x, kCsfAchromatic.a1, kCsfAchromatic.b1);
        redGreen[i] = csfGaussian(x, kCsfRedGreen.a1, kCsfRedGreen.b1);
        // The blue-yellow CSF is a sum of two: a sqrt(pi / b) exp(-pi^2 (x^2 + y^2) / b) is the
        // product of sqrt(a sqrt(pi / b)) exp(-pi^2 x^2 / b) with the same in y, so it is filtered
        // as two separable passes whose results are added.
        blueYellow1[i] = std::sqrt(kCsfBlueYellow.a1 * std::sqrt(kPi / kCsfBlueYellow.b1)) *
                         std::exp(-double(kPi) * kPi * x * x / kCsfBlueYellow.b1);
        blueYellow2[i] = std::sqrt(kCsfBlueYellow.a2 * std::sqrt(kPi / kCsfBlueYellow.b2)) *
                         std::exp(-double(kPi) * kPi * x * x / kCsfBlueYellow.b2);
        sumA += achromatic[i];
        sumRg += redGreen[i];
        sumBy1 += blueYellow1[i];
        sumBy2 += blueYellow2[i];
    }
    // The 2D blue-yellow filter sums to sumBy1^2 + sumBy2^2: each 1D kernel is divided by its
    // square root so that the 2D filter sums to 1, as the others do.
    const double normBy = std::sqrt(sumBy1 * sumBy1 + sumBy2 * sumBy2);
    CsfKernels kernels;
    for (Kernel1d* k :
         {&kernels.achromatic, &kernels.redGreen, &kernels.blueYellow1, &kernels.blueYellow2}) {
        k->radius = radius;
        k->taps.resize(width);
    }
    for (int i = 0; i < width; ++i) {
        kernels.achromatic.taps[i] = static_cast<float>(achromatic[i] / sumA);
        kernels.redGreen.taps[i] = static_cast<float>(redGreen[i] / sumRg);
        kernels.blueYellow1.taps[i] = static_cast<float>(blueYellow1[i] / normBy);
        kernels.blueYellow2.taps[i] = static_cast<float>(blueYellow2[i] / normBy);
    }
    return kernels;
}

float maxColourDistance() {
    float lg, ag, bg, lb, ab, bb;
    linearRgbToHuntLab(0.0f, 1.0f, 0.0f, lg, ag, bg);
    linearRgbToHuntLab(0.0f, 0.0f, 1.0f, lb, ab, bb);
    return std::pow(hyab(lg, ag, bg, lb, ab, bb), kColourExponent);
}

} // namespace experiments::compare::flip
