// compareImages against hand-checkable pairs (issue 32, class 3): every figure agrees with the
// others and with the pixels. Non-finite samples in either image are counted and make every
// figure "unmeasurable" (inf / -inf) instead of a perfect score; a tiny but real difference keeps
// a finite PSNR and a non-zero relative RMSE; a difference from an all-black reference has
// infinite relative figures, not 0.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "experiments/compare/ImageMetrics.h"

namespace {

using experiments::compareImages;
using experiments::ErrorMetrics;

constexpr double kInf = std::numeric_limits<double>::infinity();

// A 4x2 image, every channel of every pixel `value`.
lighting::StageResult constant(float value) {
    lighting::StageResult image;
    image.width = 4;
    image.height = 2;
    for (auto& channel : image.radiance)
        channel.assign(8, value);
    return image;
}

TEST(ImageMetrics, IdenticalFiniteImagesArePerfect) {
    const ErrorMetrics m = compareImages(constant(0.5f), constant(0.5f));
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.relativeRmse, 0.0);
    EXPECT_EQ(m.relativeMean, 0.0);
    EXPECT_EQ(m.maxAbs, 0.0);
    EXPECT_EQ(m.psnr, kInf);
    EXPECT_EQ(m.nonFinitePixels, 0u);
    EXPECT_EQ(experiments::nonFiniteNote(m), "");
    // Two black images are identical too: no 0/0.
    EXPECT_EQ(compareImages(constant(0.0f), constant(0.0f)).relativeRmse, 0.0);
}

TEST(ImageMetrics, ClosedFormDifference) {
    lighting::StageResult image = constant(1.0f);
    image.radiance[0][3] = 3.0f; // one sample of 24 is off by 2
    const ErrorMetrics m = compareImages(image, constant(1.0f));
    EXPECT_DOUBLE_EQ(m.rmse, std::sqrt(4.0 / 24.0));
    EXPECT_DOUBLE_EQ(m.relativeRmse, std::sqrt(4.0 / 24.0));
    EXPECT_DOUBLE_EQ(m.relativeMean, 2.0 / 24.0);
    EXPECT_EQ(m.maxAbs, 2.0);
    EXPECT_EQ(m.p99Abs, 2.0);
    EXPECT_DOUBLE_EQ(m.psnr, 20.0 * std::log10(1.0 / std::sqrt(4.0 / 24.0)));
}

TEST(ImageMetrics, NonFinitePixelsAreCountedAndNeverScorePerfect) {
    lighting::StageResult image = constant(0.5f);
    image.radiance[1][2] = std::numeric_limits<float>::quiet_NaN();
    image.radiance[0][2] = std::numeric_limits<float>::infinity(); // same pixel: counted once
    image.radiance[2][5] = -std::numeric_limits<float>::infinity();
    const ErrorMetrics m = compareImages(image, image); // "identical", but not measurable
    EXPECT_EQ(m.nonFinitePixels, 2u);
    EXPECT_EQ(m.referenceNonFinitePixels, 2u);
    EXPECT_EQ(m.rmse, kInf);
    EXPECT_EQ(m.relativeRmse, kInf);
    EXPECT_EQ(m.maxAbs, kInf);
    EXPECT_EQ(m.p99Abs, kInf);
    EXPECT_EQ(m.psnr, -kInf);
    EXPECT_NE(experiments::nonFiniteNote(m).find("the image has 2 pixels with NaN or Inf and the "
                                                 "reference has 2 pixels"),
              std::string::npos)
        << experiments::nonFiniteNote(m);

    lighting::StageResult reference = constant(0.5f);
    reference.radiance[0][0] = std::numeric_limits<float>::quiet_NaN();
    const ErrorMetrics onlyReference = compareImages(constant(0.5f), reference);
    EXPECT_EQ(onlyReference.nonFinitePixels, 0u);
    EXPECT_EQ(onlyReference.referenceNonFinitePixels, 1u);
    EXPECT_EQ(onlyReference.rmse, kInf);
}

TEST(ImageMetrics, TinyDifferencesAndBlackReferencesStayConsistent) {
    // The smallest float difference: rmse > 0, so psnr is finite and relative rmse is not 0.
    lighting::StageResult image = constant(1.0f);
    image.radiance[2][7] = std::nextafter(1.0f, 2.0f);
    const ErrorMetrics tiny = compareImages(image, constant(1.0f));
    EXPECT_GT(tiny.rmse, 0.0);
    EXPECT_GT(tiny.relativeRmse, 0.0);
    EXPECT_TRUE(std::isfinite(tiny.psnr)) << tiny.psnr;
    EXPECT_GT(tiny.psnr, 100.0);

    // Subnormal values whose float squares would underflow to 0.
    const ErrorMetrics subnormal = compareImages(constant(1e-44f), constant(0.0f));
    EXPECT_GT(subnormal.rmse, 0.0);
    EXPECT_EQ(subnormal.relativeRmse, kInf); // against an all-black reference
    EXPECT_EQ(subnormal.relativeMean, kInf);
    EXPECT_EQ(subnormal.psnr, -kInf); // no positive peak to compare with

    // Values near float's maximum: the sums are in double and do not overflow.
    const ErrorMetrics huge = compareImages(constant(3e38f), constant(-3e38f));
    EXPECT_DOUBLE_EQ(huge.rmse, 2.0 * double(3e38f));
    EXPECT_DOUBLE_EQ(huge.relativeRmse, 2.0);
}

} // namespace
