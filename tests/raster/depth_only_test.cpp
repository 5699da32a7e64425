// The depth-only path (raster::DepthOnly, Rasterizer.h) against the generic per-pixel path: on
// random clip-space triangles (large and tiny, slivers, triangles crossing the near and far
// planes and the guard band, shared edges of fans), with every depth test, depth writes on and
// off, every cull mode, the depth buffer must be bitwise the same and the coverage counters
// equal, for 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/task_arena.h>

#include "raster/Rasterizer.h"

namespace {

using raster::CullMode;
using raster::DepthTest;

struct Mesh {
    std::vector<glm::vec4> positions;
    std::vector<uint32_t> indices;
};

// Random triangles in clip space: mostly on screen, some huge or crossing z = 0 / z = w, some
// sub-pixel, and a fan whose triangles share edges.
Mesh randomMesh(uint32_t seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    Mesh mesh;
    auto vertex = [&](float spread, float w) {
        const float x = (unit(rng) * 2.0f - 1.0f) * spread, y = (unit(rng) * 2.0f - 1.0f) * spread;
        const float z = unit(rng) * 1.2f - 0.1f; // some in front of the near, beyond the far plane
        return glm::vec4(x * w, y * w, z * w, w);
    };
    for (int i = 0; i < count; ++i) {
        const int kind = i % 4;
        const float spread = kind == 0 ? 3.0f : kind == 1 ? 0.02f : 1.0f;
        const glm::vec4 a = vertex(spread, 0.5f + 2.0f * unit(rng));
        glm::vec4 b = vertex(spread, 0.5f + 2.0f * unit(rng));
        glm::vec4 c = vertex(spread, 0.5f + 2.0f * unit(rng));
        if (kind == 1) { // tiny: near a
            b = a + 0.01f * (b - a);
            c = a + 0.01f * (c - a);
        }
        const uint32_t base = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {a, b, c});
        mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    }
    // A fan of 64 triangles around a point: shared edges, each pixel covered once.
    const uint32_t centre = uint32_t(mesh.positions.size());
    mesh.positions.emplace_back(0.1f, -0.05f, 0.4f, 1.0f);
    for (int k = 0; k <= 64; ++k) {
        const float angle = float(k) / 64.0f * 6.2831853f;
        mesh.positions.emplace_back(0.7f * std::cos(angle), 0.7f * std::sin(angle),
                                    0.3f + 0.2f * unit(rng), 1.0f);
    }
    for (uint32_t k = 0; k < 64; ++k)
        mesh.indices.insert(mesh.indices.end(), {centre, centre + 1 + k, centre + 2 + k});
    return mesh;
}

struct Drawn {
    std::vector<float> depth;
    raster::RasterStats stats;
};

template <class FragmentFn>
Drawn draw(const Mesh& mesh, const raster::RasterState& state, float clear, int threads,
           FragmentFn fn) {
    const int width = 301, height = 203; // several tiles, partial ones at the edges
    Drawn drawn;
    drawn.depth.assign(size_t(width) * height, clear);
    tbb::task_arena(threads).execute([&] {
        raster::Rasterizer rasterizer(width, height);
        rasterizer.draw(raster::TriangleList{mesh.positions, mesh.indices}, state,
                        drawn.depth.data(), fn);
        drawn.stats = rasterizer.lastStats();
    });
    return drawn;
}

TEST(DepthOnlyPath, BitwiseTheGenericPathForEveryStateAndThreadCount) {
    const Mesh mesh = randomMesh(5, 3000);
    int cases = 0;
    for (DepthTest test : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                           DepthTest::Greater, DepthTest::GreaterEqual})
        for (bool write : {true, false})
            for (CullMode cull : {CullMode::None, CullMode::Back, CullMode::Front}) {
                raster::RasterState state;
                state.depthTest = test;
                state.depthWrite = write;
                state.cullMode = cull;
                state.barycentrics = false;
                const bool nearer = test == DepthTest::Greater || test == DepthTest::GreaterEqual;
                const float clear = nearer ? 0.0f : 1.0f;
                const Drawn generic = draw(mesh, state, clear, 1, [](const raster::Fragment&) {});
                const std::string name = "test " + std::to_string(int(test)) + " write " +
                                         std::to_string(write) + " cull " +
                                         std::to_string(int(cull));
                for (int threads : {1, 2}) {
                    const Drawn fast = draw(mesh, state, clear, threads, raster::DepthOnly{});
                    ASSERT_EQ(0, std::memcmp(fast.depth.data(), generic.depth.data(),
                                             fast.depth.size() * sizeof(float)))
                        << name << ", " << threads << " threads";
                    EXPECT_EQ(fast.stats.samplesCovered, generic.stats.samplesCovered) << name;
                    EXPECT_EQ(fast.stats.samplesPassed, generic.stats.samplesPassed) << name;
                    EXPECT_EQ(fast.stats.fragments, generic.stats.fragments) << name;
                }
                EXPECT_GT(generic.stats.samplesCovered, 100000u) << name;
                ++cases;
            }
    EXPECT_EQ(cases, 30);
}

TEST(DepthOnlyPath, DrawsWithoutADepthBufferCountLikeTheGenericPath) {
    const Mesh mesh = randomMesh(9, 500);
    raster::RasterState state;
    state.depthTest = DepthTest::Always;
    state.barycentrics = false;
    raster::Rasterizer a(160, 90), b(160, 90);
    a.draw(raster::TriangleList{mesh.positions, mesh.indices}, state, nullptr,
           [](const raster::Fragment&) {});
    b.draw(raster::TriangleList{mesh.positions, mesh.indices}, state, nullptr, raster::DepthOnly{});
    EXPECT_EQ(a.lastStats().samplesCovered, b.lastStats().samplesCovered);
    EXPECT_EQ(a.lastStats().samplesPassed, b.lastStats().samplesPassed);
}

} // namespace
