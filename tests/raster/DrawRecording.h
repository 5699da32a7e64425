// Recording a draw for the rasterizer's exactness tests against an oracle (row_span_test.cpp,
// triangle_setup_test.cpp): every fragment with its position, triangle, facing, coverage, depth
// and barycentrics bitwise, kept per screen tile in the order the draw calls the fragment
// function (the order determinism promises), and a comparison that also checks the depth buffer
// bitwise and every statistic (also on its own, for tests that record draws their own way).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "raster/Rasterizer.h"

namespace raster_test {

template <class T> uint32_t floatBits(T value) {
    static_assert(sizeof(T) == sizeof(uint32_t));
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    return bits;
}

struct RecordedFragment {
    int x, y;
    uint32_t triangle;
    uint32_t depthBits;
    uint32_t barycentricBits[3];
    uint8_t coverage;
    bool frontFacing;
    bool operator==(const RecordedFragment&) const = default;

    static RecordedFragment of(const raster::Fragment& f) {
        return {
            f.x,
            f.y,
            f.triangle,
            floatBits(f.depth),
            {floatBits(f.barycentric.x), floatBits(f.barycentric.y), floatBits(f.barycentric.z)},
            f.coverage,
            f.frontFacing};
    }
};

struct RecordedDraw {
    std::vector<float> depth;
    std::vector<std::vector<RecordedFragment>> fragmentsPerTile;
    raster::RasterStats stats;
};

// Every statistic of two draws equal.
inline void expectSameStats(const raster::RasterStats& got, const raster::RasterStats& reference,
                            const std::string& name) {
    EXPECT_EQ(got.trianglesIn, reference.trianglesIn) << name;
    EXPECT_EQ(got.trianglesCulled, reference.trianglesCulled) << name;
    EXPECT_EQ(got.trianglesClipped, reference.trianglesClipped) << name;
    EXPECT_EQ(got.trianglesSetUp, reference.trianglesSetUp) << name;
    EXPECT_EQ(got.samplesCovered, reference.samplesCovered) << name;
    EXPECT_EQ(got.samplesPassed, reference.samplesPassed) << name;
    EXPECT_EQ(got.fragments, reference.fragments) << name;
}

// The same fragments in the same order per tile, the depth buffers bitwise, every statistic.
inline void expectSameDraw(const RecordedDraw& got, const RecordedDraw& reference,
                           const std::string& name) {
    ASSERT_EQ(got.fragmentsPerTile.size(), reference.fragmentsPerTile.size()) << name;
    for (size_t tile = 0; tile < got.fragmentsPerTile.size(); ++tile) {
        const auto& a = got.fragmentsPerTile[tile];
        const auto& b = reference.fragmentsPerTile[tile];
        ASSERT_EQ(a.size(), b.size()) << name << ", tile " << tile;
        for (size_t i = 0; i < a.size(); ++i)
            ASSERT_TRUE(a[i] == b[i])
                << name << ", tile " << tile << ", fragment " << i << ": (" << a[i].x << ", "
                << a[i].y << ") of triangle " << a[i].triangle << " against (" << b[i].x << ", "
                << b[i].y << ") of triangle " << b[i].triangle;
    }
    ASSERT_EQ(got.depth.size(), reference.depth.size()) << name;
    ASSERT_EQ(
        0, std::memcmp(got.depth.data(), reference.depth.data(), got.depth.size() * sizeof(float)))
        << name << ": depth buffers differ";
    expectSameStats(got.stats, reference.stats, name);
}

} // namespace raster_test
