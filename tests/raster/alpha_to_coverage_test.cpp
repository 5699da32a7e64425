// Tests for alpha-to-coverage (raster/AlphaToCoverage.h) and the rasterizer's SampleMask fragment
// functions (raster/Rasterizer.h): the mask keeps round(alpha * N) samples at every pixel for a
// sweep of alphas at each sample count, alpha >= 1 keeps every sample and alpha <= 0 (and NaN)
// none, masks grow with alpha, the 2x2 dither visits each sample once per quad at one sample of
// four; a draw whose fragment function returns a SampleMask writes depth and counts only at the
// kept samples; and such a draw is bitwise the same for 1, 2 and 4 threads.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "raster/AlphaToCoverage.h"
#include "raster/Rasterizer.h"

namespace raster {
namespace {

constexpr int kSampleCounts[] = {2, 4, 8};

TEST(AlphaToCoverage, KeepsRoundAlphaTimesNSamplesAtEveryPixel) {
    for (int samples : kSampleCounts)
        for (int i = 0; i <= 1000; ++i) {
            const float alpha = float(i) / 1000.0f;
            const int expected = int(std::round(double(alpha) * samples));
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x) {
                    const uint8_t mask = alphaToCoverageMask(alpha, samples, x, y);
                    ASSERT_EQ(std::popcount(unsigned(mask)), expected)
                        << "alpha " << alpha << ", " << samples << " samples, pixel " << x << ","
                        << y;
                    ASSERT_EQ(mask >> samples, 0) << "a sample beyond the pixel's " << samples;
                }
        }
}

TEST(AlphaToCoverage, OneKeepsEverySampleAndZeroNone) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (int samples : kSampleCounts)
        for (int x = 0; x < 2; ++x)
            for (int y = 0; y < 2; ++y) {
                const uint8_t all = uint8_t((1u << samples) - 1u);
                for (float alpha : {1.0f, 1.5f, inf})
                    EXPECT_EQ(alphaToCoverageMask(alpha, samples, x, y), all) << alpha;
                for (float alpha : {0.0f, -0.0f, -2.0f, -inf, nan})
                    EXPECT_EQ(alphaToCoverageMask(alpha, samples, x, y), 0) << alpha;
                // Just below a half sample: nothing; at it (ties up): one sample.
                EXPECT_EQ(alphaToCoverageMask(0.49f / float(samples), samples, x, y), 0);
                EXPECT_EQ(std::popcount(
                              unsigned(alphaToCoverageMask(0.5f / float(samples), samples, x, y))),
                          1);
            }
}

TEST(AlphaToCoverage, MasksGrowWithAlphaAndTheQuadVisitsEverySample) {
    for (int samples : kSampleCounts) {
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) {
                uint8_t previous = 0;
                for (int k = 0; k <= samples; ++k) {
                    const uint8_t mask = alphaToCoverageMask(float(k) / samples, samples, x, y);
                    EXPECT_EQ(mask & previous, previous) << "a sample turned off as alpha grew";
                    previous = mask;
                }
            }
        // At one sample in four (4x: one sample; 8x: two), the quad's four pixels together
        // use four different subsets; at 4x they are the four samples, once each.
        const float quarter = 0.25f;
        unsigned unionOfQuad = 0;
        int total = 0;
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) {
                const uint8_t mask = alphaToCoverageMask(quarter, samples, x, y);
                total += std::popcount(unsigned(mask));
                unionOfQuad |= mask;
            }
        if (samples == 4)
            EXPECT_EQ(unionOfQuad, 0xFu);
        if (samples == 8)
            EXPECT_EQ(unionOfQuad, 0xFFu) << "the 8x pairs rotate through all samples";
        EXPECT_EQ(total, 4 * int(std::round(quarter * samples)));
        // The pattern repeats every 2 pixels (a fixed function of the pixel's parity).
        for (float alpha : {0.3f, 0.5f, 0.7f})
            EXPECT_EQ(alphaToCoverageMask(alpha, samples, 5, 3),
                      alphaToCoverageMask(alpha, samples, 1, 1));
    }
}

TEST(AlphaToCoverage, FillOrdersArePermutations) {
    for (int samples : kSampleCounts) {
        const uint8_t* order = alphaToCoverageOrder(samples);
        unsigned seen = 0;
        for (int i = 0; i < samples; ++i)
            seen |= 1u << order[i];
        EXPECT_EQ(seen, (1u << samples) - 1u) << samples;
    }
}

// A quad over the whole viewport at depth 0.5, w = 1.
struct Quad {
    std::vector<glm::vec4> clip = {
        {-1, -1, 0.5f, 1}, {1, -1, 0.5f, 1}, {1, 1, 0.5f, 1}, {-1, 1, 0.5f, 1}};
    std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
    TriangleList list() const { return {clip, indices}; }
};

TEST(AlphaToCoverageDraw, OnlyTheKeptSamplesAreWrittenAndCounted) {
    const int width = 37, height = 23;
    const Quad quad;
    for (int samples : kSampleCounts) {
        Rasterizer rasterizer(width, height);
        RasterState state;
        state.cullMode = CullMode::None;
        state.depthTest = DepthTest::Less;
        state.samples = samples;
        std::vector<float> depth(size_t(width) * height * samples, 1.0f);
        // Alpha varies over the screen; every pixel's kept samples are its mask.
        auto alphaAt = [&](int x, int y) { return float((x * 7 + y * 3) % 11) / 10.0f; };
        // Fragments kept per pixel (the quad's diagonal gives its pixels two partial ones).
        std::vector<uint32_t> keptFragments(size_t(width) * height, 0);
        rasterizer.draw(quad.list(), state, depth.data(), [&](const Fragment& f) {
            const uint8_t mask = alphaToCoverageMask(alphaAt(f.x, f.y), samples, f.x, f.y);
            keptFragments[size_t(f.y) * width + f.x] += (mask & f.coverage) != 0;
            return SampleMask{mask};
        });
        uint64_t kept = 0, fragments = 0;
        for (uint32_t count : keptFragments)
            fragments += count;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const uint8_t mask = alphaToCoverageMask(alphaAt(x, y), samples, x, y);
                kept += unsigned(std::popcount(unsigned(mask)));
                for (int s = 0; s < samples; ++s)
                    ASSERT_EQ(depth[(size_t(y) * width + x) * samples + s],
                              (mask >> s & 1u) ? 0.5f : 1.0f)
                        << samples << " samples, pixel " << x << "," << y << " sample " << s;
            }
        EXPECT_EQ(rasterizer.lastStats().samplesPassed, kept);
        EXPECT_EQ(rasterizer.lastStats().fragments, fragments);
        EXPECT_EQ(rasterizer.lastStats().samplesCovered, uint64_t(width) * height * samples);
    }
    // One sample per pixel: bit 0 keeps the fragment.
    Rasterizer rasterizer(width, height);
    RasterState state;
    state.cullMode = CullMode::None;
    std::vector<float> depth(size_t(width) * height, 1.0f);
    rasterizer.draw(quad.list(), state, depth.data(),
                    [&](const Fragment& f) { return SampleMask{uint8_t(f.x % 2 == 0 ? 1 : 2)}; });
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            ASSERT_EQ(depth[size_t(y) * width + x], x % 2 == 0 ? 0.5f : 1.0f) << x << "," << y;
}

TEST(AlphaToCoverageDraw, SameSamplesForOneTwoAndFourThreads) {
    const int width = 300, height = 200;
    std::vector<glm::vec4> clip;
    std::vector<uint32_t> indices;
    uint64_t state = 77;
    auto uniform = [&](float lo, float hi) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return lo + (hi - lo) * float(state >> 40) / float(1u << 24);
    };
    for (int t = 0; t < 3000; ++t) {
        const float cx = uniform(-1.1f, 1.1f), cy = uniform(-1.1f, 1.1f),
                    size = uniform(0.01f, 0.3f);
        for (int v = 0; v < 3; ++v) {
            indices.push_back(uint32_t(clip.size()));
            clip.emplace_back(cx + uniform(-size, size), cy + uniform(-size, size),
                              uniform(0.0f, 1.0f), 1.0f);
        }
    }
    const TriangleList list{clip, indices};
    for (int samples : kSampleCounts) {
        auto run = [&](int threads) {
            std::vector<float> depth(size_t(width) * height * samples, 1.0f);
            std::vector<uint32_t> owner(depth.size(), UINT32_MAX);
            Rasterizer rasterizer(width, height);
            RasterState rs;
            rs.cullMode = CullMode::None;
            rs.samples = samples;
            tbb::task_arena(threads).execute([&] {
                rasterizer.draw(list, rs, depth.data(), [&](const Fragment& f) {
                    const float alpha = float(f.triangle % 13) / 12.0f;
                    const uint8_t kept = f.coverage & alphaToCoverageMask(alpha, samples, f.x, f.y);
                    for (int s = 0; s < samples; ++s)
                        if (kept >> s & 1u)
                            owner[(size_t(f.y) * width + f.x) * samples + s] = f.triangle;
                    return SampleMask{kept};
                });
            });
            return std::make_pair(depth, owner);
        };
        const auto one = run(1), two = run(2), four = run(4);
        EXPECT_EQ(one.first, two.first) << samples;
        EXPECT_EQ(one.first, four.first) << samples;
        EXPECT_EQ(one.second, two.second) << samples;
        EXPECT_EQ(one.second, four.second) << samples;
    }
}

} // namespace
} // namespace raster
