// Tests for experiments/compare/Flip: the contract first (NVIDIA's FLIP v1.6 on the validation
// pairs of ../shared/flip: every mean to 1e-4, the exposures to 1e-4, every pixel to 1e-3; the
// data missing is a FAILURE, never a skip), then each stage on inputs whose answers follow by
// hand, then the hard cases (zero median, NaN/Inf, tiny and constant images, negative values,
// bad arguments) and the thread-count independence.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tbb/task_arena.h>

#include "experiments/compare/Flip.h"
#include "experiments/compare/FlipInternal.h"
#include "experiments/output/ImageOutput.h"

namespace experiments::compare {
namespace {

namespace fs = std::filesystem;
using namespace flip;

// A planar RGB image owned by the test.
struct Rgb {
    int width = 0, height = 0;
    std::vector<float> r, g, b;

    Rgb() = default;
    Rgb(int w, int h, float red, float green, float blue)
        : width(w), height(h), r(std::size_t(w) * h, red), g(std::size_t(w) * h, green),
          b(std::size_t(w) * h, blue) {}
    void set(int x, int y, float red, float green, float blue) {
        const std::size_t i = std::size_t(y) * width + x;
        r[i] = red;
        g[i] = green;
        b[i] = blue;
    }
    FlipImage view() const { return {width, height, r.data(), g.data(), b.data()}; }
};

// A smooth image with texture and a range of a few stops, noise from `seed`.
Rgb texturedImage(int width, int height, unsigned seed, float noise = 0.0f) {
    Rgb image(width, height, 0.0f, 0.0f, 0.0f);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> jitter(-1.0f, 1.0f);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float base =
                0.6f + 0.5f * std::sin(0.21f * x) * std::cos(0.13f * y) + 0.02f * (x % 7);
            image.set(x, y, 2.0f * base * base + noise * jitter(rng),
                      base * (0.2f + float(x) / float(width)), 0.3f * base + noise * jitter(rng));
        }
    for (auto* plane : {&image.r, &image.g, &image.b})
        for (float& v : *plane)
            v = std::max(v, 0.0f);
    return image;
}

bool allFinite(const FlipResult& result) {
    for (float v : result.errorMap)
        if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
            return false;
    return std::isfinite(result.mean) && std::isfinite(result.weightedMedian) &&
           std::isfinite(result.p95) && std::isfinite(result.p99) &&
           std::isfinite(result.startExposure) && std::isfinite(result.stopExposure);
}

bool hasWarning(const FlipResult& result, const std::string& part) {
    return std::any_of(result.warnings.begin(), result.warnings.end(),
                       [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

// ---- The contract: NVIDIA's FLIP v1.6 on ../shared/flip ----

const fs::path kFlipData = TESTBED_FLIP_DATA_DIR;

// The EXR's channels as planes (one channel: in r only).
Rgb readExr(const fs::path& path) {
    runImageLibraryOnTheCallingThread();
    Rgb image;
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) {
        ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
        return image;
    }
    const OIIO::ImageSpec spec = input->spec();
    std::vector<float> pixels(spec.image_pixels() * spec.nchannels);
    EXPECT_TRUE(input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
        << input->geterror();
    image = Rgb(spec.width, spec.height, 0.0f, 0.0f, 0.0f);
    for (std::size_t i = 0; i < image.r.size(); ++i) {
        image.r[i] = pixels[i * spec.nchannels];
        if (spec.nchannels >= 3) {
            image.g[i] = pixels[i * spec.nchannels + 1];
            image.b[i] = pixels[i * spec.nchannels + 2];
        }
    }
    return image;
}

TEST(FlipContract, ReproducesNvidiaFlipOnTheValidationPairs) {
    // Missing data fails: CI must not pass by not looking.
    ASSERT_TRUE(fs::is_regular_file(kFlipData / "expected.json"))
        << "the ꟻLIP validation data is missing: " << kFlipData
        << " (TESTBED_SHARED_DIR/flip, ../shared/flip beside the project)";
    nlohmann::json expected;
    std::ifstream(kFlipData / "expected.json") >> expected;
    const Rgb reference = readExr(kFlipData / expected.at("reference").get<std::string>());
    ASSERT_EQ(reference.width, 320);
    ASSERT_EQ(reference.height, 180);
    ASSERT_EQ(expected.at("pairs").size(), 3u);
    for (const auto& [name, figures] : expected.at("pairs").items()) {
        SCOPED_TRACE(name);
        const Rgb test = readExr(kFlipData / name);
        const fs::path mapName = fs::path(name).replace_extension(".flip.exr");
        const Rgb nvidiaMap = readExr(kFlipData / mapName);
        ASSERT_EQ(nvidiaMap.r.size(), reference.r.size());
        const FlipResult result = computeFlip(test.view(), reference.view());
        ASSERT_EQ(result.errorMap.size(), nvidiaMap.r.size());
        double maxDifference = 0.0;
        std::size_t worst = 0;
        for (std::size_t i = 0; i < result.errorMap.size(); ++i) {
            const double d = std::fabs(double(result.errorMap[i]) - nvidiaMap.r[i]);
            if (d > maxDifference) {
                maxDifference = d;
                worst = i;
            }
        }
        const double mean = figures.at("mean").get<double>();
        std::printf("%s: mean %.9f (NVIDIA %.9f, difference %.2e), max per-pixel difference "
                    "%.2e at (%zu, %zu), exposures %.8f to %.8f (NVIDIA %.8f to %.8f), %d\n",
                    name.c_str(), result.mean, mean, result.mean - mean, maxDifference,
                    worst % reference.width, worst / reference.width, result.startExposure,
                    result.stopExposure, figures.at("start").get<double>(),
                    figures.at("stop").get<double>(), result.exposureCount);
        EXPECT_NEAR(result.mean, mean, 1e-4);
        EXPECT_LE(maxDifference, 1e-3);
        EXPECT_NEAR(result.startExposure, figures.at("start").get<double>(), 1e-4);
        EXPECT_NEAR(result.stopExposure, figures.at("stop").get<double>(), 1e-4);
        EXPECT_EQ(result.exposureCount, figures.at("n").get<int>());
        EXPECT_NEAR(result.pixelsPerDegree, figures.at("ppd").get<double>(), 1e-6);
        EXPECT_TRUE(result.warnings.empty());
        EXPECT_TRUE(allFinite(result));
    }
}

// ---- Stages, with answers derived by hand ----

TEST(FlipColour, ConversionsRoundTripAndKeepWhite) {
    // The two matrices are inverses, and white is (1, 1, 1) -> Y = 100, Cx = Cz = 0.
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            float sum = 0.0f;
            for (int k = 0; k < 3; ++k)
                sum += kRgbToXyz.m[i][k] * kXyzToRgb.m[k][j];
            EXPECT_NEAR(sum, i == j ? 1.0f : 0.0f, 1e-6f);
        }
    float yy, cx, cz;
    linearRgbToYCxCz(1.0f, 1.0f, 1.0f, yy, cx, cz);
    EXPECT_NEAR(yy, 100.0f, 1e-4f);
    EXPECT_NEAR(cx, 0.0f, 1e-4f);
    EXPECT_NEAR(cz, 0.0f, 1e-4f);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int n = 0; n < 10000; ++n) {
        const float r = unit(rng), g = unit(rng), b = unit(rng);
        float r2, g2, b2;
        linearRgbToYCxCz(r, g, b, yy, cx, cz);
        yCxCzToLinearRgb(yy, cx, cz, r2, g2, b2);
        ASSERT_NEAR(r2, r, 2e-5f);
        ASSERT_NEAR(g2, g, 2e-5f);
        ASSERT_NEAR(b2, b, 2e-5f);
    }
    // CIELAB: white is L = 100 with no chroma, black L = 0; grey has no chroma either.
    float l, a, b;
    linearRgbToHuntLab(1.0f, 1.0f, 1.0f, l, a, b);
    EXPECT_NEAR(l, 100.0f, 1e-3f);
    EXPECT_NEAR(a, 0.0f, 1e-3f);
    EXPECT_NEAR(b, 0.0f, 1e-3f);
    linearRgbToHuntLab(0.0f, 0.0f, 0.0f, l, a, b);
    EXPECT_NEAR(l, 0.0f, 1e-5f);
    // 18% grey: L = 116 * 0.18^(1/3) - 16 = 49.496.
    linearRgbToHuntLab(0.18f, 0.18f, 0.18f, l, a, b);
    EXPECT_NEAR(l, 116.0 * std::cbrt(0.18) - 16.0, 1e-3);
    EXPECT_NEAR(a, 0.0f, 1e-3f);
    // The Hunt adjustment scales chroma by L / 100: HyAB of two colours is |dL| + |d(ab)|.
    EXPECT_FLOAT_EQ(hyab(50.0f, 3.0f, 0.0f, 40.0f, 0.0f, 4.0f), 10.0f + 5.0f);
}

TEST(FlipColour, FastFunctionsMatchTheLibrary) {
    double worstCube = 0.0, worstPow = 0.0;
    for (int i = 0; i <= 100000; ++i) {
        const double t = 0.008856 + (1.1 - 0.008856) * i / 100000.0;
        worstCube = std::max(worstCube, std::fabs(cubeRoot(float(t)) / std::cbrt(t) - 1.0));
    }
    for (int i = 1; i <= 3000; ++i)
        for (double y : {0.0, 0.05, 0.3, 0.5, 0.7, 0.95, 1.0}) {
            const double x = 300.0 * std::pow(i / 3000.0, 4.0); // dense near 0
            const double exact = std::pow(double(float(x)), y);
            if (exact > 1e-30)
                worstPow =
                    std::max(worstPow, std::fabs(powNonNegative(float(x), float(y)) / exact - 1.0));
        }
    std::printf("fast functions: cube root worst relative error %.2e, pow %.2e\n", worstCube,
                worstPow);
    EXPECT_LT(worstCube, 1e-6);
    EXPECT_LT(worstPow, 2e-6);
    EXPECT_EQ(powNonNegative(0.0f, 0.7f), 0.0f);
    EXPECT_EQ(powNonNegative(0.0f, 0.0f), 1.0f); // std::pow's value
    EXPECT_EQ(powNonNegative(1.0f, 0.3f), 1.0f);
}

TEST(FlipColour, RedistributionIsContinuousAndMapsCmaxToOne) {
    const float cmax = maxColourDistance();
    // cmax = HyAB(green, blue)^0.7 with the Hunt adjustment, about 40 for sRGB primaries.
    EXPECT_GT(cmax, 20.0f);
    EXPECT_LT(cmax, 60.0f);
    const float cut = kCutoffFraction * cmax;
    EXPECT_EQ(redistributeColourError(0.0f, cmax), 0.0f);
    EXPECT_NEAR(redistributeColourError(cmax, cmax), 1.0f, 1e-6f);
    const float below = redistributeColourError(std::nextafter(cut, 0.0f), cmax);
    const float at = redistributeColourError(cut, cmax);
    EXPECT_NEAR(below, kCutoffError, 1e-5f);
    EXPECT_NEAR(at, kCutoffError, 1e-6f);
    float previous = -1.0f;
    for (int i = 0; i <= 1000; ++i) {
        const float v = redistributeColourError(cmax * i / 1000.0f, cmax);
        EXPECT_GE(v, previous);
        previous = v;
    }
}

TEST(FlipFilters, KernelsAreNormalisedAndSized) {
    const float ppd = float(kDefaultPixelsPerDegree);
    // Radius: ceil(3 sqrt(0.04 / (2 pi^2)) ppd) = ceil(9.05) = 10; features ceil(3 * 0.041 ppd) =
    // ceil(8.24) = 9.
    const CsfKernels csf = makeCsfKernels(ppd);
    EXPECT_EQ(csf.achromatic.radius, 10);
    EXPECT_EQ(csf.achromatic.taps.size(), 21u);
    auto sum = [](const Kernel1d& k) {
        double s = 0.0;
        for (float w : k.taps)
            s += w;
        return s;
    };
    // 2D sums: the outer products' sums, sum^2 (the blue-yellow filter: two of them).
    EXPECT_NEAR(sum(csf.achromatic) * sum(csf.achromatic), 1.0, 1e-6);
    EXPECT_NEAR(sum(csf.redGreen) * sum(csf.redGreen), 1.0, 1e-6);
    EXPECT_NEAR(sum(csf.blueYellow1) * sum(csf.blueYellow1) +
                    sum(csf.blueYellow2) * sum(csf.blueYellow2),
                1.0, 1e-6);
    const FeatureKernels features = makeFeatureKernels(ppd);
    EXPECT_EQ(features.gaussian.radius, 9);
    EXPECT_NEAR(sum(features.gaussian), 1.0, 1e-6);
    for (const Kernel1d* k : {&features.firstDerivative, &features.secondDerivative}) {
        double positive = 0.0, negative = 0.0;
        for (float w : k->taps)
            (w > 0.0f ? positive : negative) += w;
        EXPECT_NEAR(positive, 1.0, 1e-6);
        EXPECT_NEAR(negative, -1.0, 1e-6);
    }
    for (int i = 0; i < 19; ++i) {
        EXPECT_EQ(features.gaussian.taps[i], features.gaussian.taps[18 - i]);
        EXPECT_EQ(features.firstDerivative.taps[i], -features.firstDerivative.taps[18 - i]);
    }
}

TEST(FlipFilters, EdgeDetectorRespondsAtAStepAndNotFarFromIt) {
    // A vertical step from 0.2 to 0.8 at x = 40: the 2D edge response in x is the 1D first
    // derivative along the row (the Gaussian across it sums to 1). Centred on the edge the
    // positive weights (left, sum 1) see 0.2 and the negative ones (right, sum -1) see 0.8 or
    // the centre tap's 0: the response is -0.6 there; past the radius it is 0.
    const FeatureKernels f = makeFeatureKernels(float(kDefaultPixelsPerDegree));
    const int radius = f.firstDerivative.radius;
    std::vector<float> row(80);
    for (int x = 0; x < 80; ++x)
        row[x] = x < 40 ? 0.2f : 0.8f;
    auto response = [&](int x) {
        double s = 0.0;
        for (int k = -radius; k <= radius; ++k)
            s += f.firstDerivative.taps[k + radius] * row[std::clamp(x + k, 0, 79)];
        return s;
    };
    int strongest = 0;
    for (int x = 0; x < 80; ++x)
        if (std::fabs(response(x)) > std::fabs(response(strongest)))
            strongest = x;
    EXPECT_GE(strongest, 39);
    EXPECT_LE(strongest, 40);
    EXPECT_NEAR(std::fabs(response(strongest)), 0.6, 1e-5);
    for (int x : {0, 10, 40 - radius - 1, 40 + radius, 70, 79})
        EXPECT_NEAR(response(x), 0.0, 1e-6) << x;
}

// ---- End to end, with answers derived by hand ----

TEST(FlipEndToEnd, IdenticalImagesGiveZeroEverywhere) {
    const Rgb image = texturedImage(97, 61, 1);
    for (FlipMode mode : {FlipMode::Hdr, FlipMode::Ldr}) {
        FlipOptions options;
        options.mode = mode;
        const FlipResult result = computeFlip(image.view(), image.view(), options);
        EXPECT_EQ(result.mean, 0.0);
        EXPECT_EQ(result.max, 0.0);
        EXPECT_EQ(result.weightedMedian, 0.0);
        for (float v : result.errorMap)
            ASSERT_EQ(v, 0.0f);
    }
}

TEST(FlipEndToEnd, SinglePixelImpulseIsLocalSymmetricAndBounded) {
    // Grey everywhere (tone mapped to 0.85); the test has one black pixel in the middle (a bright
    // one would saturate the tone mapper and show little). Beyond the filters' reach (10 pixels)
    // both images filter to the same values: the error is exactly 0 there.
    const int size = 41, centre = 20;
    const Rgb reference(size, size, 0.5f, 0.5f, 0.5f);
    Rgb test = reference;
    test.set(centre, centre, 0.0f, 0.0f, 0.0f);
    const FlipResult result = computeFlip(test.view(), reference.view());
    EXPECT_TRUE(allFinite(result));
    auto at = [&](int x, int y) { return result.errorMap[std::size_t(y) * size + x]; };
    EXPECT_GT(at(centre, centre), 0.1f); // 0.27: the CSF spreads one pixel over its neighbours
    EXPECT_EQ(result.max, at(centre, centre));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            if (std::max(std::abs(x - centre), std::abs(y - centre)) > 10) {
                ASSERT_EQ(at(x, y), 0.0f) << x << ", " << y;
            }
            // Mirror and transpose symmetry (up to float rounding of sums taken in other orders).
            ASSERT_NEAR(at(x, y), at(2 * centre - x, y), 1e-3f);
            ASSERT_NEAR(at(x, y), at(x, 2 * centre - y), 1e-3f);
            ASSERT_NEAR(at(x, y), at(y, x), 1e-3f);
        }
    EXPECT_GT(at(centre + 3, centre), 0.0f);
}

TEST(FlipEndToEnd, PureChromaChangeHasNoFeatureTermButAColourError) {
    // Two colours of equal luminance Y: the feature detectors (on Y) see the same image, so the
    // error is the colour error alone; in the middle of a large patch the filters (which sum to
    // 1) return the patch's own colours, so the error is the colour formula applied by hand.
    const float grey = 0.5f, dRed = 0.1f;
    const float blue = grey - dRed * (kRgbToXyz.m[1][0] / kRgbToXyz.m[1][2]); // same Y
    const int size = 64;
    const Rgb reference(size, size, grey, grey, grey);
    const Rgb test(size, size, grey + dRed, grey, blue);
    FlipOptions options;
    options.mode = FlipMode::Ldr;
    const FlipResult result = computeFlip(test.view(), reference.view(), options);
    float l0, a0, b0, l1, a1, b1;
    linearRgbToHuntLab(grey, grey, grey, l0, a0, b0);
    linearRgbToHuntLab(grey + dRed, grey, blue, l1, a1, b1);
    const float cmax = maxColourDistance();
    const float byHand =
        redistributeColourError(std::pow(hyab(l0, a0, b0, l1, a1, b1), kColourExponent), cmax);
    EXPECT_GT(byHand, 0.1f);
    for (float v : result.errorMap)
        ASSERT_NEAR(v, byHand, 2e-4f);
}

// ---- Hard cases ----

TEST(FlipHardCases, ZeroMedianLuminanceFallsBackToTheLitPixels) {
    // A black frame with five emissive pixels: over half the pixels are black, the published stop
    // exposure log2(x / 0) is infinite. The lit pixels' median (50) is used, with a warning.
    Rgb reference(64, 48, 0.0f, 0.0f, 0.0f);
    for (int i = 0; i < 5; ++i)
        reference.set(5 + 11 * i, 10 + 7 * i, 50.0f, 50.0f, 50.0f);
    Rgb test = reference;
    test.set(5, 10, 25.0f, 25.0f, 25.0f); // one emissive pixel at half its radiance
    const FlipResult result = computeFlip(test.view(), reference.view());
    EXPECT_TRUE(allFinite(result));
    EXPECT_TRUE(hasWarning(result, "median luminance is 0"))
        << ::testing::PrintToString(result.warnings);
    const float expected = std::log2(toneMapperInputForTarget() / 50.0f);
    EXPECT_NEAR(result.startExposure, expected, 1e-5);
    EXPECT_NEAR(result.stopExposure, expected, 1e-5);
    EXPECT_EQ(result.exposureCount, 2);
    EXPECT_GT(result.mean, 0.0);
    EXPECT_GT(result.errorMap[10 * 64 + 5], 0.1f);

    // A difference only in the black region is small at that exposure, but not a perfect score.
    Rgb dim = reference;
    for (int y = 30; y < 40; ++y)
        for (int x = 30; x < 40; ++x)
            dim.set(x, y, 0.05f, 0.05f, 0.05f);
    const FlipResult dark = computeFlip(dim.view(), reference.view());
    EXPECT_TRUE(allFinite(dark));
    EXPECT_GT(dark.mean, 0.0);
}

TEST(FlipHardCases, BlackReferenceTakesTheTestImagesExposures) {
    const Rgb reference(16, 16, 0.0f, 0.0f, 0.0f);
    const Rgb test(16, 16, 0.5f, 0.5f, 0.5f);
    const FlipResult result = computeFlip(test.view(), reference.view());
    EXPECT_TRUE(allFinite(result));
    EXPECT_TRUE(hasWarning(result, "test image's luminance"));
    EXPECT_GT(result.mean, 0.5);
    // Both black: exposures 0 to 0 and a zero map, which is right (the images are equal).
    const FlipResult black = computeFlip(reference.view(), reference.view());
    EXPECT_TRUE(allFinite(black));
    EXPECT_EQ(black.mean, 0.0);
    EXPECT_EQ(black.startExposure, 0.0f);
    EXPECT_TRUE(hasWarning(black, "neither image"));
}

TEST(FlipHardCases, NonFinitePixelsAreCountedMaximalAndContained) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const Rgb image = texturedImage(48, 40, 7);
    Rgb test = image, reference = image;
    test.set(10, 10, nan, 0.5f, 0.5f);
    test.set(30, 20, 0.1f, inf, 0.1f);
    reference.set(40, 35, 0.1f, 0.1f, -inf);
    reference.set(5, 30, inf, inf, inf); // would be the reference's maximum if it counted
    reference.set(6, 30, nan, nan, nan);
    test.set(6, 30, nan, 1.0f, 1.0f); // neither finite: black for the neighbours
    const FlipResult result = computeFlip(test.view(), reference.view());
    EXPECT_TRUE(allFinite(result));
    EXPECT_EQ(result.nonFiniteTest, 3u);
    EXPECT_EQ(result.nonFiniteReference, 3u);
    EXPECT_TRUE(hasWarning(result, "NaN or infinite"));
    for (auto [x, y] : {std::pair{10, 10}, {30, 20}, {40, 35}, {5, 30}, {6, 30}})
        EXPECT_EQ(result.errorMap[std::size_t(y) * 48 + x], 1.0f) << x << ", " << y;
    // Where one image is not finite its neighbours see the other image's pixel, where neither
    // is they see black in both: no difference reaches them, the map is 0 everywhere else.
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 48; ++x) {
            const bool bad = (x == 10 && y == 10) || (x == 30 && y == 20) || (x == 40 && y == 35) ||
                             (x == 5 && y == 30) || (x == 6 && y == 30);
            if (!bad) {
                ASSERT_EQ(result.errorMap[std::size_t(y) * 48 + x], 0.0f) << x << ", " << y;
            }
        }
    // The exposures ignore the non-finite reference pixels: the maximum is a finite pixel's.
    float maxLuminance = 0.0f;
    for (std::size_t i = 0; i < image.r.size(); ++i)
        if (i != 35 * 48 + 40 && i != 30 * 48 + 5 && i != 30 * 48 + 6)
            maxLuminance = std::max(maxLuminance, kLuminanceWeights[0] * reference.r[i] +
                                                      kLuminanceWeights[1] * reference.g[i] +
                                                      kLuminanceWeights[2] * reference.b[i]);
    EXPECT_NEAR(result.startExposure, std::log2(toneMapperInputForTarget() / maxLuminance), 1e-5);
    // A reference with no finite pixel: every pixel is an error of 1, the exposures come from the
    // test image.
    const Rgb allNan(16, 8, nan, nan, nan);
    const Rgb grey(16, 8, 0.5f, 0.5f, 0.5f);
    const FlipResult none = computeFlip(grey.view(), allNan.view());
    EXPECT_TRUE(allFinite(none));
    EXPECT_EQ(none.mean, 1.0);
    EXPECT_EQ(none.nonFiniteReference, 128u);
    EXPECT_TRUE(hasWarning(none, "test image's luminance"));
    // LDR mode handles them the same way.
    FlipOptions ldr;
    ldr.mode = FlipMode::Ldr;
    const FlipResult ldrResult = computeFlip(test.view(), reference.view(), ldr);
    EXPECT_TRUE(allFinite(ldrResult));
    EXPECT_EQ(ldrResult.errorMap[10 * 48 + 10], 1.0f);
}

TEST(FlipHardCases, TinyAndConstantImages) {
    for (auto [w, h] : {std::pair{1, 1}, {1, 7}, {7, 1}, {2, 2}, {1, 300}, {300, 1}}) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
        const Rgb reference(w, h, 0.3f, 0.4f, 0.5f);
        Rgb test = reference;
        test.set(0, 0, 0.9f, 0.1f, 0.1f);
        for (FlipMode mode : {FlipMode::Hdr, FlipMode::Ldr}) {
            FlipOptions options;
            options.mode = mode;
            const FlipResult same = computeFlip(reference.view(), reference.view(), options);
            EXPECT_TRUE(allFinite(same));
            EXPECT_EQ(same.mean, 0.0);
            const FlipResult different = computeFlip(test.view(), reference.view(), options);
            EXPECT_TRUE(allFinite(different));
            EXPECT_GT(different.errorMap[0], 0.1f);
            EXPECT_GT(different.mean, 0.0);
        }
    }
    // Different constants: a uniform map (every pixel sees the same neighbourhood).
    const Rgb grey(20, 12, 0.5f, 0.5f, 0.5f), red(20, 12, 0.6f, 0.3f, 0.3f);
    const FlipResult uniform = computeFlip(red.view(), grey.view());
    EXPECT_TRUE(allFinite(uniform));
    EXPECT_GT(uniform.mean, 0.05);
    for (float v : uniform.errorMap)
        ASSERT_FLOAT_EQ(v, uniform.errorMap[0]);
    // One reference luminance: start == stop; the two equal exposures give what one gives.
    EXPECT_EQ(uniform.startExposure, uniform.stopExposure);
    EXPECT_EQ(uniform.exposureCount, 2);
}

TEST(FlipHardCases, NegativeValuesAreClampedToZero) {
    const Rgb reference = texturedImage(40, 30, 11);
    Rgb negative = reference, zero = reference;
    for (int x = 5; x < 15; ++x) {
        negative.set(x, 12, -0.5f, 0.2f, -3.0f);
        zero.set(x, 12, 0.0f, 0.2f, 0.0f);
    }
    const FlipResult a = computeFlip(negative.view(), reference.view());
    const FlipResult b = computeFlip(zero.view(), reference.view());
    EXPECT_EQ(a.errorMap, b.errorMap);
    EXPECT_TRUE(hasWarning(a, "negative values"));
    EXPECT_TRUE(b.warnings.empty());
}

TEST(FlipHardCases, HugeFiniteValuesStayBounded) {
    Rgb reference = texturedImage(30, 30, 5);
    Rgb test = reference;
    test.set(3, 3, 1e30f, std::numeric_limits<float>::max(), 1e20f);
    reference.set(20, 20, std::numeric_limits<float>::max(), 0.0f, 0.0f);
    const FlipResult result = computeFlip(test.view(), reference.view());
    EXPECT_TRUE(allFinite(result));
    EXPECT_GT(result.exposureCount, 32); // the reference spans over 2^100 in luminance
    EXPECT_TRUE(hasWarning(result, "exposures"));
}

TEST(FlipHardCases, BadArgumentsThrow) {
    const Rgb a(8, 8, 0.5f, 0.5f, 0.5f), b(8, 9, 0.5f, 0.5f, 0.5f);
    EXPECT_THROW(computeFlip(a.view(), b.view()), std::invalid_argument);
    EXPECT_THROW(computeFlip(FlipImage{}, FlipImage{}), std::invalid_argument);
    FlipImage nullPlane = a.view();
    nullPlane.g = nullptr;
    EXPECT_THROW(computeFlip(nullPlane, a.view()), std::invalid_argument);
    for (double ppd : {0.0, -1.0, std::nan(""), 1e9}) {
        FlipOptions options;
        options.pixelsPerDegree = ppd;
        EXPECT_THROW(computeFlip(a.view(), a.view(), options), std::invalid_argument) << ppd;
    }
    FlipOptions reversed;
    reversed.startExposure = 2.0f;
    reversed.stopExposure = 1.0f;
    EXPECT_THROW(computeFlip(a.view(), a.view(), reversed), std::invalid_argument);
    FlipOptions noExposures;
    noExposures.exposureCount = 0;
    EXPECT_THROW(computeFlip(a.view(), a.view(), noExposures), std::invalid_argument);
    FlipOptions tooWide;
    tooWide.startExposure = -1e30f;
    tooWide.stopExposure = 1e30f;
    EXPECT_THROW(computeFlip(a.view(), a.view(), tooWide), std::invalid_argument);
    try {
        computeFlip(a.view(), b.view());
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("8x8"), std::string::npos) << error.what();
    }
}

TEST(FlipOptionsTest, GivenExposuresAndLdrModeAreReported) {
    const Rgb reference = texturedImage(40, 30, 2), test = texturedImage(40, 30, 2, 0.05f);
    FlipOptions options;
    options.startExposure = -1.0f;
    options.stopExposure = 2.0f;
    options.exposureCount = 4;
    const FlipResult given = computeFlip(test.view(), reference.view(), options);
    EXPECT_EQ(given.startExposure, -1.0f);
    EXPECT_EQ(given.stopExposure, 2.0f);
    EXPECT_EQ(given.exposureCount, 4);
    EXPECT_GT(given.mean, 0.0);
    options.mode = FlipMode::Ldr;
    const FlipResult ldr = computeFlip(test.view(), reference.view(), options);
    EXPECT_EQ(ldr.exposureCount, 0);
    EXPECT_TRUE(hasWarning(ldr, "HDR mode only"));
    EXPECT_TRUE(hasWarning(ldr, "clamped to 1")); // the textured image reaches 2.7
    // More exposures can only raise the per-pixel maximum.
    FlipOptions more = FlipOptions{};
    more.startExposure = -1.0f;
    more.stopExposure = 2.0f;
    more.exposureCount = 7; // includes the four above
    const FlipResult dense = computeFlip(test.view(), reference.view(), more);
    for (std::size_t i = 0; i < dense.errorMap.size(); ++i)
        ASSERT_GE(dense.errorMap[i], given.errorMap[i]);
}

TEST(FlipPooling, StatisticsAsNvidiaDefinesThem) {
    // Weighted median: sorted 0.1 0.2 0.3 0.4 (total 1.0); running sums 0.1, 0.3, 0.6 > 0.5.
    PooledValues p = poolValues({0.4f, 0.1f, 0.3f, 0.2f}, 2);
    EXPECT_NEAR(p.mean, 0.25, 1e-7);
    EXPECT_FLOAT_EQ(p.weightedMedian, 0.3f);
    EXPECT_FLOAT_EQ(p.p95, 0.4f); // index ceil(3.8) = 4, at most n - 1 = 3
    EXPECT_FLOAT_EQ(p.max, 0.4f);
    // 0.01 ... 1.00: p95 at index 95 (0.96), p99 at index 99 (1.00).
    std::vector<float> values;
    for (int i = 100; i >= 1; --i)
        values.push_back(i / 100.0f);
    p = poolValues(values, 10);
    EXPECT_FLOAT_EQ(p.p95, 0.96f);
    EXPECT_FLOAT_EQ(p.p99, 1.0f);
    EXPECT_NEAR(p.mean, 0.505, 1e-7);
    // Weighted: total 50.5, half 25.25; sum of 0.01..0.70 = 24.85, + 0.71 = 25.56 > 25.25.
    EXPECT_FLOAT_EQ(p.weightedMedian, 0.71f);
    p = poolValues(std::vector<float>(12, 0.0f), 3);
    EXPECT_EQ(p.weightedMedian, 0.0);
    EXPECT_EQ(p.p99, 0.0);
}

// ---- Determinism ----

TEST(FlipDeterminism, ResultsDoNotDependOnTheThreadCount) {
    const Rgb reference = texturedImage(333, 257, 21);
    const Rgb test = texturedImage(333, 257, 22, 0.08f);
    for (FlipMode mode : {FlipMode::Hdr, FlipMode::Ldr}) {
        FlipOptions options;
        options.mode = mode;
        FlipResult one, two;
        tbb::task_arena(1).execute(
            [&] { one = computeFlip(test.view(), reference.view(), options); });
        tbb::task_arena(2).execute(
            [&] { two = computeFlip(test.view(), reference.view(), options); });
        EXPECT_EQ(one.errorMap, two.errorMap); // bitwise
        EXPECT_EQ(one.mean, two.mean);
        EXPECT_EQ(one.weightedMedian, two.weightedMedian);
        EXPECT_EQ(one.p99, two.p99);
        EXPECT_GT(one.mean, 0.0);
    }
    // Two calls at once (the function keeps no state) agree with one alone.
    FlipResult first, second;
    std::thread a([&] { first = computeFlip(test.view(), reference.view()); });
    std::thread b([&] { second = computeFlip(test.view(), reference.view()); });
    a.join();
    b.join();
    EXPECT_EQ(first.errorMap, second.errorMap);
}

} // namespace
} // namespace experiments::compare
