// Tests for experiments/FlipMetric: ꟻLIP comes from NVIDIA's package flip-evaluator, never from
// code of ours. Without the package every output says why it is unavailable (tested here by
// pointing TESTBED_FLIP_PYTHON at Pythons that cannot have it); with the package (./run.sh
// installs it into .venv/ when the Python package index is reachable) the real metric is run on
// known images. That test is SKIPPED, saying why, when the package is not installed.
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "experiments/compare/FlipMetric.h"
#include "experiments/output/PlotScript.h"

namespace experiments {
namespace {

// Sets TESTBED_FLIP_PYTHON for the test's scope and restores what was there.
class FlipPythonOverride {
public:
    explicit FlipPythonOverride(const std::string& python) {
        if (const char* old = std::getenv(kFlipPythonVariable))
            mOld = old;
        setenv(kFlipPythonVariable, python.c_str(), 1);
    }
    ~FlipPythonOverride() {
        if (mOld)
            setenv(kFlipPythonVariable, mOld->c_str(), 1);
        else
            unsetenv(kFlipPythonVariable);
    }

private:
    std::optional<std::string> mOld;
};

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

TEST(FlipMetric, WithoutAPythonEveryResultSaysWhy) {
    const FlipPythonOverride missing("/nonexistent/testbed-python3");
    EXPECT_EQ(flipPython(), "/nonexistent/testbed-python3");
    const std::string reason = flipUnavailableReason();
    EXPECT_NE(reason.find("/nonexistent/testbed-python3"), std::string::npos) << reason;
    EXPECT_NE(reason.find("run.sh"), std::string::npos) << reason;
    const lighting::StageResult image = ramp(16, 8);
    const FlipResult result = computeFlip(image, image);
    EXPECT_FALSE(result.mean.has_value());
    EXPECT_EQ(result.unavailableReason, reason);
    EXPECT_TRUE(result.errorMap.empty());
}

// Debian's own Python has numpy but not flip-evaluator (pip installs go into .venv/): the check
// names the missing package.
TEST(FlipMetric, APythonWithoutThePackageIsNamed) {
    if (runProcess({"/usr/bin/python3", "-c", "import flip_evaluator"}, true) == 0)
        GTEST_SKIP() << "/usr/bin/python3 has flip_evaluator installed system-wide: no Python "
                        "without the package to test with";
    const FlipPythonOverride system("/usr/bin/python3");
    const std::string reason = flipUnavailableReason();
    EXPECT_NE(reason.find("flip-evaluator is not installed in /usr/bin/python3"), std::string::npos)
        << reason;
}

TEST(FlipMetric, NonFiniteImagesAreRefusedWithAReason) {
    lighting::StageResult image = ramp(16, 8);
    image.radiance[1][5] = std::nanf("");
    const FlipResult result = computeFlip(image, ramp(16, 8));
    EXPECT_FALSE(result.mean.has_value());
    EXPECT_FALSE(result.unavailableReason.empty());
}

// The real package on known images: identical images have no error, visible spots have some,
// bigger spots more; the mean is the map's mean; the parameters are the package's defaults.
TEST(FlipMetric, TheRealPackageMeasuresKnownDifferences) {
    const std::string reason = flipUnavailableReason();
    if (!reason.empty())
        GTEST_SKIP() << "flip-evaluator is not installed, so the real ꟻLIP cannot be run: "
                     << reason;
    const int width = 64, height = 48;
    const lighting::StageResult reference = ramp(width, height);
    const FlipResult same = computeFlip(reference, reference);
    ASSERT_TRUE(same.mean.has_value()) << same.unavailableReason;
    EXPECT_NEAR(*same.mean, 0.0, 1e-6);

    const FlipResult small = computeFlip(withSpots(reference, 7, 0.25f), reference);
    const FlipResult large = computeFlip(withSpots(reference, 7, 2.0f), reference);
    ASSERT_TRUE(small.mean && large.mean) << small.unavailableReason << large.unavailableReason;
    EXPECT_GT(*small.mean, 0.0);
    EXPECT_GT(*large.mean, *small.mean);
    EXPECT_LE(*large.mean, 1.0);
    ASSERT_EQ(large.errorMap.size(), size_t(width) * height);
    double sum = 0.0;
    for (float v : large.errorMap) {
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
        sum += v;
    }
    EXPECT_NEAR(sum / double(large.errorMap.size()), *large.mean, 1e-4);
    // The package's defaults, recorded with the result.
    EXPECT_EQ(large.parameters.value("mode", ""), "HDR");
    EXPECT_NEAR(large.parameters.value("ppd", 0.0), 67.0, 1.0) << large.parameters.dump();
    EXPECT_TRUE(large.parameters.contains("tonemapper")) << large.parameters.dump();
    EXPECT_TRUE(large.parameters.contains("version")) << large.parameters.dump();
}

} // namespace
} // namespace experiments
