// Tests for the rasterizer's multisampling (raster/Rasterizer.h, RasterState::samples): the
// standard sample patterns, per-sample coverage against an oracle that does not reuse the
// rasterizer's arithmetic, watertightness per sample, one fragment per pixel and triangle, depth
// per sample, and determinism for any thread count.
//
// Oracle: point-in-triangle in double at each sample position (pixel centre + offset / 16), with
// the top-left tie rule as a symbolic perturbation of the sample by (e, e^2), e -> 0+, screen
// space y down (as tests/raster/rasterizer_test.cpp). Exact for vertices on the 1/256-pixel grid:
// snapping is then the identity and sample positions lie on the 1/16 grid.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "raster/Rasterizer.h"

namespace raster {
namespace {

using Tri2 = std::array<glm::dvec2, 3>;

class Random {
public:
    explicit Random(uint64_t seed) : mState(seed) {}
    uint64_t next() { // splitmix64
        uint64_t z = (mState += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform(double lo, double hi) {
        return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53;
    }
    double onGrid(double lo, double hi) { return std::round(uniform(lo, hi) * 256.0) / 256.0; }

private:
    uint64_t mState;
};

double cross(glm::dvec2 a, glm::dvec2 b) {
    return a.x * b.y - a.y * b.x;
}

bool oracleCovers(const Tri2& v, glm::dvec2 p) {
    if (cross(v[1] - v[0], v[2] - v[0]) == 0.0)
        return false;
    for (int i = 0; i < 3; ++i) {
        const glm::dvec2 a = v[i], d = v[(i + 1) % 3] - v[i], opposite = v[(i + 2) % 3];
        const double interiorSide = cross(d, opposite - a);
        double side = cross(d, p - a);
        if (side == 0.0)
            side = d.y != 0.0 ? -d.y : d.x;
        if ((side > 0.0) != (interiorSide > 0.0))
            return false;
    }
    return true;
}

// Screen-space triangles (pixels, y down) with one NDC depth per vertex, w = 1.
struct Mesh {
    std::vector<glm::dvec2> screen;
    std::vector<glm::vec4> clip;
    std::vector<uint32_t> indices;
    int width, height;

    Mesh(int w, int h) : width(w), height(h) {}
    void add(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, float za = 0.5f, float zb = 0.5f,
             float zc = 0.5f) {
        const glm::dvec2 p[3] = {a, b, c};
        const float z[3] = {za, zb, zc};
        for (int i = 0; i < 3; ++i) {
            indices.push_back(uint32_t(screen.size()));
            screen.push_back(p[i]);
            clip.emplace_back(float(2.0 * p[i].x / width - 1.0), float(1.0 - 2.0 * p[i].y / height),
                              z[i], 1.0f);
        }
    }
    TriangleList list() const { return {clip, indices}; }
    Tri2 triangle(size_t t) const {
        return {screen[indices[3 * t]], screen[indices[3 * t + 1]], screen[indices[3 * t + 2]]};
    }
};

glm::dvec2 samplePosition(int x, int y, SampleOffset o) {
    return {x + 0.5 + o.x / 16.0, y + 0.5 + o.y / 16.0};
}

// Per sample (pixel-major), how many fragments covered it; and fragment calls per pixel/triangle.
struct SampleCounts {
    std::vector<uint32_t> perSample;
    std::set<std::pair<size_t, uint32_t>> pixelTriangles;
    bool repeatedPixelTriangle = false;
    bool emptyCoverage = false;
};

SampleCounts rasterizeSamples(const Mesh& mesh, int samples, CullMode cull = CullMode::None) {
    Rasterizer rasterizer(mesh.width, mesh.height);
    RasterState state;
    state.cullMode = cull;
    state.depthTest = DepthTest::Always;
    state.depthWrite = false;
    state.samples = samples;
    SampleCounts counts;
    counts.perSample.assign(size_t(mesh.width) * mesh.height * samples, 0);
    std::vector<std::vector<uint32_t>> seen(size_t(mesh.width) * mesh.height);
    tbb::task_arena(1).execute([&] {
        rasterizer.draw(mesh.list(), state, nullptr, [&](const Fragment& f) {
            const size_t pixel = size_t(f.y) * mesh.width + f.x;
            if (f.coverage == 0 || f.coverage >> samples)
                counts.emptyCoverage = true;
            for (uint32_t t : seen[pixel])
                if (t == f.triangle)
                    counts.repeatedPixelTriangle = true;
            seen[pixel].push_back(f.triangle);
            for (int s = 0; s < samples; ++s)
                if (f.coverage >> s & 1)
                    ++counts.perSample[pixel * samples + s];
        });
    });
    return counts;
}

std::vector<uint32_t> oracleSamples(const Mesh& mesh, int samples) {
    const auto pattern = standardSamplePattern(samples);
    std::vector<uint32_t> counts(size_t(mesh.width) * mesh.height * samples, 0);
    for (size_t t = 0; t < mesh.indices.size() / 3; ++t) {
        const Tri2 v = mesh.triangle(t);
        for (int y = 0; y < mesh.height; ++y)
            for (int x = 0; x < mesh.width; ++x)
                for (int s = 0; s < samples; ++s)
                    counts[(size_t(y) * mesh.width + x) * samples + s] +=
                        oracleCovers(v, samplePosition(x, y, pattern[s]));
    }
    return counts;
}

TEST(MultisamplePattern, StandardDirect3DPositions) {
    const auto four = standardSamplePattern(4);
    const SampleOffset expected[] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
    ASSERT_EQ(four.size(), 4u);
    for (int s = 0; s < 4; ++s) {
        EXPECT_EQ(four[s].x, expected[s].x);
        EXPECT_EQ(four[s].y, expected[s].y);
    }
    EXPECT_EQ(standardSamplePattern(1)[0].x, 0);
    for (int n : {1, 2, 4, 8, 16}) {
        const auto pattern = standardSamplePattern(n);
        ASSERT_EQ(int(pattern.size()), n);
        std::set<std::pair<int, int>> distinct;
        for (const SampleOffset& o : pattern) {
            // Inside the pixel [-8, 8) / 16 around the centre.
            EXPECT_GE(o.x, -8);
            EXPECT_LT(o.x, 8);
            EXPECT_GE(o.y, -8);
            EXPECT_LT(o.y, 8);
            distinct.insert({o.x, o.y});
        }
        EXPECT_EQ(int(distinct.size()), n) << n << " samples";
    }
    EXPECT_THROW(standardSamplePattern(3), std::invalid_argument);
}

TEST(MultisampleCoverage, UnsupportedSampleCountsAreRefused) {
    Mesh mesh(8, 8);
    mesh.add({0, 0}, {8, 0}, {0, 8});
    for (int samples : {0, 3, 16}) {
        Rasterizer rasterizer(8, 8);
        RasterState state;
        state.samples = samples;
        EXPECT_THROW(rasterizer.draw(mesh.list(), state, nullptr, [](const Fragment&) {}),
                     std::invalid_argument)
            << samples;
    }
}

TEST(MultisampleCoverage, RandomTrianglesMatchTheOraclePerSample) {
    for (int samples : {2, 4, 8}) {
        Mesh mesh(48, 40);
        Random random(uint64_t(samples) * 7919);
        for (int i = 0; i < 60; ++i) {
            // Small, thin and large triangles, some reaching past the borders.
            const double size = i % 3 == 0 ? 2.0 : (i % 3 == 1 ? 9.0 : 40.0);
            const glm::dvec2 c(random.onGrid(-4, 52), random.onGrid(-4, 44));
            mesh.add(c, c + glm::dvec2(random.onGrid(-size, size), random.onGrid(-size, size)),
                     c + glm::dvec2(random.onGrid(-size, size), random.onGrid(-size, size)));
        }
        const SampleCounts got = rasterizeSamples(mesh, samples);
        EXPECT_FALSE(got.repeatedPixelTriangle) << "one fragment per pixel and triangle";
        EXPECT_FALSE(got.emptyCoverage);
        const std::vector<uint32_t> expected = oracleSamples(mesh, samples);
        size_t mismatches = 0;
        for (size_t i = 0; i < expected.size(); ++i)
            mismatches += got.perSample[i] != expected[i];
        EXPECT_EQ(mismatches, 0u) << samples << " samples";
    }
}

TEST(MultisampleCoverage, SixtyFourTrianglesMeetingInAPixelCoverEverySampleOnce) {
    // A closed fan of 64 triangles around a point inside pixel (10, 10): every sample inside the
    // rim (a square far outside the pixel) is covered exactly once, at every sample count.
    for (int samples : {1, 2, 4, 8}) {
        Mesh mesh(21, 21);
        const glm::dvec2 centre(10.5 + 3.0 / 256, 10.5 - 5.0 / 256);
        std::vector<glm::dvec2> rim;
        for (int i = 0; i < 64; ++i) {
            const double angle = 2.0 * 3.14159265358979 * i / 64;
            rim.emplace_back(std::round((10.5 + 9.0 * std::cos(angle)) * 256) / 256,
                             std::round((10.5 + 9.0 * std::sin(angle)) * 256) / 256);
        }
        for (int i = 0; i < 64; ++i)
            mesh.add(centre, rim[size_t(i)], rim[size_t(i + 1) % 64]);
        const SampleCounts got = rasterizeSamples(mesh, samples);
        const auto pattern = standardSamplePattern(samples);
        for (int y = 5; y <= 15; ++y)
            for (int x = 5; x <= 15; ++x)
                for (int s = 0; s < samples; ++s)
                    ASSERT_EQ(got.perSample[(size_t(y) * 21 + x) * samples + s], 1u)
                        << "pixel " << x << "," << y << " sample " << s << " of " << samples;
        // At the pixel where the triangles meet, several triangles share the pixel and each sample
        // belongs to exactly one of them.
        uint32_t inCentre = 0;
        for (int s = 0; s < samples; ++s)
            inCentre += got.perSample[(size_t(10) * 21 + 10) * samples + s];
        EXPECT_EQ(inCentre, uint32_t(samples));
        (void)pattern;
    }
}

TEST(MultisampleCoverage, SubPixelTrianglesCoverOnlyTheSamplesInside) {
    // Triangles far smaller than a pixel: with one sample most cover nothing; with 8 some cover a
    // sample that is not the centre. Every covered sample must be inside (oracle), none missed.
    Mesh mesh(16, 16);
    Random random(99);
    for (int i = 0; i < 400; ++i) {
        const glm::dvec2 c(random.onGrid(0, 16), random.onGrid(0, 16));
        mesh.add(c, c + glm::dvec2(random.onGrid(-0.4, 0.4), random.onGrid(-0.4, 0.4)),
                 c + glm::dvec2(random.onGrid(-0.4, 0.4), random.onGrid(-0.4, 0.4)));
    }
    for (int samples : {1, 8}) {
        const SampleCounts got = rasterizeSamples(mesh, samples);
        EXPECT_EQ(got.perSample, oracleSamples(mesh, samples)) << samples;
    }
}

TEST(MultisampleDepth, PerSampleDepthIsThePlaneAtTheSample) {
    // A sloped plane: depth(x, y) = 0.1 + 0.01 x + 0.02 y (screen pixels), affine in screen space
    // because w = 1. The depth buffer holds the plane at each sample; the fragment's depth is the
    // centre's.
    const int width = 24, height = 20;
    auto plane = [](double x, double y) { return 0.1 + 0.01 * x + 0.02 * y; };
    Mesh mesh(width, height);
    const glm::dvec2 a(-2, -2), b(30, -2), c(-2, 30);
    mesh.add(a, b, c, float(plane(a.x, a.y)), float(plane(b.x, b.y)), float(plane(c.x, c.y)));
    for (int samples : {2, 4, 8}) {
        Rasterizer rasterizer(width, height);
        RasterState state;
        state.cullMode = CullMode::None;
        state.depthTest = DepthTest::Less;
        state.samples = samples;
        std::vector<float> depth(size_t(width) * height * samples, 1.0f);
        double worstCentre = 0.0;
        rasterizer.draw(mesh.list(), state, depth.data(), [&](const Fragment& f) {
            worstCentre = std::max(worstCentre, std::abs(f.depth - plane(f.x + 0.5, f.y + 0.5)));
        });
        EXPECT_LT(worstCentre, 1e-6);
        const auto pattern = standardSamplePattern(samples);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int s = 0; s < samples; ++s) {
                    const glm::dvec2 p = samplePosition(x, y, pattern[s]);
                    if (!oracleCovers(mesh.triangle(0), p))
                        continue;
                    EXPECT_NEAR(depth[(size_t(y) * width + x) * samples + s], plane(p.x, p.y), 1e-6)
                        << x << "," << y << " sample " << s;
                }
    }
}

TEST(MultisampleDepth, AnEdgeBetweenTwoDepthsSplitsThePixelsSamples) {
    // A near triangle over a far one: pixels along the near triangle's edge keep far samples where
    // the near one does not reach, so their samples come from two triangles.
    const int width = 16, height = 16;
    Mesh mesh(width, height);
    mesh.add({0, 0}, {16, 0}, {0, 16}, 0.8f, 0.8f, 0.8f);             // far
    mesh.add({0, 0}, {10, 0}, {0, 10.0 + 1.0 / 3}, 0.2f, 0.2f, 0.2f); // near, inside the far one
    Rasterizer rasterizer(width, height);
    RasterState state;
    state.cullMode = CullMode::None;
    state.depthTest = DepthTest::Less;
    state.samples = 4;
    std::vector<float> depth(size_t(width) * height * 4, 1.0f);
    std::vector<uint32_t> owner(size_t(width) * height * 4, UINT32_MAX);
    rasterizer.draw(mesh.list(), state, depth.data(), [&](const Fragment& f) {
        for (int s = 0; s < 4; ++s)
            if (f.coverage >> s & 1)
                owner[(size_t(f.y) * width + f.x) * 4 + s] = f.triangle;
    });
    int mixed = 0;
    for (size_t pixel = 0; pixel < size_t(width) * height; ++pixel) {
        std::set<uint32_t> owners(owner.begin() + pixel * 4, owner.begin() + pixel * 4 + 4);
        owners.erase(UINT32_MAX);
        mixed += owners.size() == 2;
        for (int s = 0; s < 4; ++s) { // each sample holds its owner's depth
            if (owner[pixel * 4 + s] == 0)
                EXPECT_FLOAT_EQ(depth[pixel * 4 + s], 0.8f);
            if (owner[pixel * 4 + s] == 1)
                EXPECT_FLOAT_EQ(depth[pixel * 4 + s], 0.2f);
        }
    }
    EXPECT_GT(mixed, 8);
}

TEST(MultisampleDeterminism, SameSamplesAndFragmentsForAnyThreadCount) {
    const int width = 300, height = 260;
    Mesh mesh(width, height);
    Random random(4242);
    for (int i = 0; i < 6000; ++i) {
        const glm::dvec2 c(random.uniform(-10, 310), random.uniform(-10, 270));
        const double size = random.uniform(0.3, 60.0);
        mesh.add(c, c + glm::dvec2(random.uniform(-size, size), random.uniform(-size, size)),
                 c + glm::dvec2(random.uniform(-size, size), random.uniform(-size, size)),
                 float(random.uniform(0, 1)), float(random.uniform(0, 1)),
                 float(random.uniform(0, 1)));
    }
    for (int samples : {2, 4, 8}) {
        struct Output {
            std::vector<float> depth;
            std::vector<std::vector<std::pair<uint32_t, uint8_t>>> fragments; // per pixel
            RasterStats stats;
        };
        auto run = [&](int threads) {
            Output out;
            out.depth.assign(size_t(width) * height * samples, 1.0f);
            out.fragments.resize(size_t(width) * height);
            Rasterizer rasterizer(width, height);
            RasterState state;
            state.cullMode = CullMode::None;
            state.samples = samples;
            tbb::task_arena(threads).execute([&] {
                rasterizer.draw(mesh.list(), state, out.depth.data(), [&](const Fragment& f) {
                    out.fragments[size_t(f.y) * width + f.x].emplace_back(f.triangle, f.coverage);
                });
            });
            out.stats = rasterizer.lastStats();
            return out;
        };
        const Output one = run(1), two = run(2);
        EXPECT_EQ(one.depth, two.depth) << samples;
        EXPECT_EQ(one.fragments, two.fragments) << samples;
        EXPECT_EQ(one.stats.samplesPassed, two.stats.samplesPassed);
        EXPECT_EQ(one.stats.fragments, two.stats.fragments);
        EXPECT_GT(one.stats.samplesPassed, one.stats.fragments) << "several samples per fragment";
    }
}

} // namespace
} // namespace raster
