// UniformPixels (gbuffer/msaa/UniformPixels.h): the lanes write bitwise what the scalar loop
// writes, for every sample count, row lengths that are not a multiple of any vector, rows with
// mixed, uncovered and far-plane pixels and NaN depths; and the scalar loop does what the header
// says on a hand-made row.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "gbuffer/msaa/UniformPixels.h"

namespace gbuffer {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

// A row's inputs and the planes one run writes (filled with a sentinel first, so that an
// unwritten entry shows).
struct Row {
    std::vector<uint32_t> codes;
    std::vector<float> depths;
    std::vector<uint32_t> mainCodes, mixed;
    std::vector<float> mainDepths;
    std::vector<uint8_t> coverage, background, complex;

    Row(int pixels, int samples)
        : codes(size_t(pixels * samples)), depths(size_t(pixels * samples)),
          mainCodes(size_t(pixels), 0xdeadbeefu), mixed(size_t(pixels) + kMixedPixelSlack, 0),
          mainDepths(size_t(pixels), -7.0f), coverage(size_t(pixels), 0xab),
          background(size_t(pixels), 0xab), complex(size_t(pixels), 0xab) {}

    UniformRowArgs args(int samples, float clear, float nearerClear) {
        UniformRowArgs a;
        a.codes = codes.data();
        a.centreDepths = depths.data();
        a.pixels = int(mainCodes.size());
        a.samples = samples;
        a.noTriangle = kNone;
        a.clear = clear;
        a.nearerClear = nearerClear;
        a.mainCodes = mainCodes.data();
        a.mainDepths = mainDepths.data();
        a.mainCoverage = coverage.data();
        a.background = background.data();
        a.complex = complex.data();
        a.mixed = mixed.data();
        return a;
    }
};

std::vector<uint32_t> bitsOf(const std::vector<float>& values) {
    std::vector<uint32_t> bits;
    for (const float v : values)
        bits.push_back(std::bit_cast<uint32_t>(v));
    return bits;
}

TEST(UniformPixels, LanesAreBitwiseTheScalarLoop) {
    std::mt19937 random(20261207);
    const float clear = 0.0f; // reversed Z
    const float nearerClear = std::nextafter(clear, 1.0f);
    for (const int samples : {2, 4, 8})
        for (const int pixels : {1, 3, 15, 16, 17, 31, 33, 64, 100, 1280}) {
            SCOPED_TRACE(::testing::Message() << samples << " samples, " << pixels << " pixels");
            Row lanes(pixels, samples), scalar(pixels, samples);
            std::uniform_int_distribution<int> kind(0, 9);
            std::uniform_int_distribution<uint32_t> triangle(0, 3);
            std::uniform_real_distribution<float> depth(0.0f, 1.0f);
            for (int x = 0; x < pixels; ++x) {
                const int k = kind(random);
                const uint32_t first = k == 0 ? kNone : triangle(random);
                for (int s = 0; s < samples; ++s) {
                    const size_t i = size_t(x * samples + s);
                    // Kinds: 0 background, 1-2 one sample differs (maybe background), the rest
                    // uniform; depths: the clear value, NaN or a random depth.
                    uint32_t code = first;
                    if ((k == 1 || k == 2) && s == x % samples)
                        code = k == 1 ? kNone : first + 1;
                    lanes.codes[i] = code;
                    const int d = kind(random);
                    lanes.depths[i] = d == 0   ? clear
                                      : d == 1 ? std::numeric_limits<float>::quiet_NaN()
                                               : depth(random);
                }
            }
            scalar.codes = lanes.codes;
            scalar.depths = lanes.depths;
            const UniformRowResult fast = writeUniformRow(lanes.args(samples, clear, nearerClear));
            const UniformRowResult slow =
                writeUniformRowScalar(scalar.args(samples, clear, nearerClear));
            EXPECT_EQ(fast.mixedCount, slow.mixedCount);
            EXPECT_EQ(fast.coveredUniformPixels, slow.coveredUniformPixels);
            lanes.mixed.resize(size_t(fast.mixedCount));
            scalar.mixed.resize(size_t(slow.mixedCount));
            EXPECT_EQ(lanes.mixed, scalar.mixed);
            EXPECT_EQ(lanes.mainCodes, scalar.mainCodes);
            EXPECT_EQ(bitsOf(lanes.mainDepths), bitsOf(scalar.mainDepths));
            EXPECT_EQ(lanes.coverage, scalar.coverage);
            EXPECT_EQ(lanes.background, scalar.background);
            EXPECT_EQ(lanes.complex, scalar.complex);
            if (pixels == 1280) { // the random row has all three kinds of pixel
                EXPECT_GT(slow.mixedCount, 100);
                EXPECT_GT(slow.coveredUniformPixels, 500u);
            }
        }
}

TEST(UniformPixels, TheScalarLoopWritesWhatTheHeaderSays) {
    // Four pixels of 4 samples (forward Z, clear 1): uniform covered, uniform covered with its
    // centre depth at the clear value, background, and mixed.
    Row row(4, 4);
    row.codes = {7, 7, 7, 7, 9, 9, 9, 9, kNone, kNone, kNone, kNone, 7, 8, 7, 7};
    row.depths = {0.25f, 0.3f, 0.3f, 0.3f, 1.0f,  1.0f, 1.0f, 1.0f,
                  0.5f,  0.5f, 0.5f, 0.5f, 0.75f, 0.2f, 0.2f, 0.2f};
    const float nearerClear = std::nextafter(1.0f, 0.0f);
    for (const bool lanes : {false, true}) {
        Row run = row;
        const UniformRowArgs args = run.args(4, 1.0f, nearerClear);
        const UniformRowResult result = lanes ? writeUniformRow(args) : writeUniformRowScalar(args);
        EXPECT_EQ(result.coveredUniformPixels, 2u);
        ASSERT_EQ(result.mixedCount, 1);
        EXPECT_EQ(run.mixed[0], 3u);
        EXPECT_EQ(run.mainCodes, (std::vector<uint32_t>{7, 9, kNone, 7}));
        EXPECT_EQ(run.mainDepths, (std::vector<float>{0.25f, nearerClear, 1.0f, 0.75f}));
        EXPECT_EQ(run.coverage, (std::vector<uint8_t>{15, 15, 0, 15}));
        EXPECT_EQ(run.background, (std::vector<uint8_t>{0, 0, 4, 0}));
        EXPECT_EQ(run.complex, (std::vector<uint8_t>{0, 0, 0, 0}));
    }
}

} // namespace
} // namespace gbuffer
