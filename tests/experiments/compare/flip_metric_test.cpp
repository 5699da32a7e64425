// Tests for experiments/compare/FlipMetric: the render-facing ꟻLIP (the metric itself is tested
// against NVIDIA's figures in flip_test.cpp): what it records, and that images it cannot compare
// say why instead of scoring.
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "experiments/compare/FlipMetric.h"

namespace experiments {
namespace {

// A smooth HDR image: a horizontal ramp from 0.05 to 4 in R, a vertical one in G, constant B.
lighting::StageResult ramp(int width, int height) {
    lighting::StageResult image;
    image.resize(width, height, false);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const size_t i = size_t(y) * width + x;
            image.radiance[0][i] = 0.05f + 3.95f * float(x) / float(width - 1);
            image.radiance[1][i] = 0.05f + 1.95f * float(y) / float(height - 1);
            image.radiance[2][i] = 0.5f;
        }
    return image;
}

// The image with every `period`-th pixel's red multiplied by (1 + amount): a visible, known
// pattern of errors.
lighting::StageResult withSpots(lighting::StageResult image, int period, float amount) {
    for (size_t i = 0; i < image.radiance[0].size(); i += size_t(period))
        image.radiance[0][i] *= 1.0f + amount;
    return image;
}

TEST(FlipMetric, ImagesOfDifferentSizesSayWhy) {
    const FlipComparison result = computeFlip(ramp(16, 8), ramp(8, 16));
    EXPECT_FALSE(result.mean.has_value());
    EXPECT_FALSE(result.unavailableReason.empty());
    EXPECT_TRUE(result.errorMap.empty());
}

// A NaN pixel is counted, reported and never turns into a NaN mean or a perfect score.
TEST(FlipMetric, NonFinitePixelsAreCountedAndReported) {
    lighting::StageResult image = ramp(16, 8);
    image.radiance[1][5] = std::nanf("");
    const FlipComparison result = computeFlip(image, ramp(16, 8));
    ASSERT_TRUE(result.mean.has_value()) << result.unavailableReason;
    EXPECT_TRUE(std::isfinite(*result.mean));
    EXPECT_GT(*result.mean, 0.0);
    EXPECT_EQ(result.parameters.value("non_finite_test_pixels", 0), 1);
    EXPECT_FALSE(result.parameters["warnings"].empty());
}

// Known images: identical images have no error, visible spots have some, bigger spots more; the
// mean is the map's mean; the parameters are ꟻLIP's defaults.
TEST(FlipMetric, MeasuresKnownDifferences) {
    const int width = 64, height = 48;
    const lighting::StageResult reference = ramp(width, height);
    const FlipComparison same = computeFlip(reference, reference);
    ASSERT_TRUE(same.mean.has_value()) << same.unavailableReason;
    EXPECT_EQ(*same.mean, 0.0);

    const FlipComparison small = computeFlip(withSpots(reference, 7, 0.25f), reference);
    const FlipComparison large = computeFlip(withSpots(reference, 7, 2.0f), reference);
    ASSERT_TRUE(small.mean && large.mean) << small.unavailableReason << large.unavailableReason;
    EXPECT_GT(*small.mean, 0.0);
    EXPECT_GT(*large.mean, *small.mean);
    EXPECT_LE(*large.mean, 1.0);
    // The weighted median (half of the error mass lies below it) may exceed p99 when the error
    // is concentrated; both stay within the map's range.
    EXPECT_GT(*large.weightedMedian, 0.0);
    EXPECT_LE(*large.weightedMedian, 1.0);
    EXPECT_LE(*large.p95, *large.p99);
    ASSERT_EQ(large.errorMap.size(), size_t(width) * height);
    double sum = 0.0;
    for (float v : large.errorMap) {
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
        sum += v;
    }
    EXPECT_NEAR(sum / double(large.errorMap.size()), *large.mean, 1e-6);
    EXPECT_EQ(large.parameters.value("mode", ""), "HDR");
    EXPECT_NEAR(large.parameters.value("pixels_per_degree", 0.0), 67.02, 0.01)
        << large.parameters.dump();
    EXPECT_GE(large.parameters.value("exposure_count", 0), 2) << large.parameters.dump();
}

} // namespace
} // namespace experiments
