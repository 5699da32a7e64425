// The one-sample traversal's row spans (detail::coveredSpan in raster/Rasterizer.h: each row's
// covered pixels found by one division per edge) against the plain per-pixel traversal
// (RasterState::referenceTraversal, the oracle): on thousands of seeded random triangles (large,
// huge beyond the guard band, sub-pixel, degenerate, grazing planes nearly parallel to the view
// direction, shared edges), with every depth test, depth writes on and off, a fragment function
// that keeps every fragment, one that discards some (an alpha test), and the depth-only path, the
// fragments must be the same in the same order per tile (position, triangle, facing, depth
// bitwise), the depth buffer bitwise the same and the statistics equal, for 1 and 2 threads. The
// depth buffer starts from a clear, from random stored depths with NaNs, and from the mesh's own
// depths (a redraw with LessEqual or GreaterEqual, where every visible pixel passes only by
// equality). (A hierarchical depth was tried against this oracle and removed as slower: see
// raster/README.md.)
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/task_arena.h>

#include "raster/Rasterizer.h"
#include "tests/raster/DrawRecording.h"
#include "tests/raster/SanitizerBuild.h"
#include "tests/raster/TestMeshes.h"

namespace {

using raster::CullMode;
using raster::DepthTest;

constexpr int kWidth = 301, kHeight = 203; // several tiles, partial ones at the edges

using raster_test::Mesh;

using raster_test::randomMesh;

using raster_test::RecordedDraw;
using raster_test::RecordedFragment;

enum class Shading { Keep, Discard, DepthOnly };

// The alpha test of the discarding fragment function: a fixed pseudo-random third of fragments.
bool discards(const raster::Fragment& f) {
    return (uint32_t(f.x) * 7u + uint32_t(f.y) * 13u + f.triangle * 5u) % 3u == 0u;
}

RecordedDraw draw(const Mesh& mesh, raster::RasterState state, const std::vector<float>& startDepth,
                  Shading shading, int threads) {
    RecordedDraw drawn;
    drawn.depth = startDepth;
    tbb::task_arena(threads).execute([&] {
        raster::Rasterizer rasterizer(kWidth, kHeight);
        drawn.fragmentsPerTile.resize(size_t(rasterizer.tileCountX() * rasterizer.tileCountY()));
        auto record = [&](const raster::Fragment& f) {
            drawn.fragmentsPerTile[size_t(rasterizer.tileOf(f.x, f.y))].push_back(
                RecordedFragment::of(f));
        };
        const raster::TriangleList triangles{mesh.positions, mesh.indices};
        switch (shading) {
        case Shading::Keep:
            rasterizer.draw(triangles, state, drawn.depth.data(), record);
            break;
        case Shading::Discard:
            rasterizer.draw(triangles, state, drawn.depth.data(), [&](const raster::Fragment& f) {
                if (discards(f))
                    return false;
                record(f);
                return true;
            });
            break;
        case Shading::DepthOnly:
            rasterizer.draw(triangles, state, drawn.depth.data(), raster::DepthOnly{});
            break;
        }
        drawn.stats = rasterizer.lastStats();
    });
    return drawn;
}

bool nearIsLarge(DepthTest test) {
    return test == DepthTest::Greater || test == DepthTest::GreaterEqual;
}

// The three starting depth buffers of a test: cleared to the far value; random depths with NaNs
// (NaN passes no test but Always); and the mesh's
// own visible depths, drawn before with the strict test, so that a redraw passes only by equality.
std::vector<std::vector<float>> startDepths(const Mesh& mesh, DepthTest test) {
    const float far = nearIsLarge(test) ? 0.0f : 1.0f;
    std::vector<std::vector<float>> starts;
    starts.emplace_back(size_t(kWidth) * kHeight, far);
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> noisy(size_t(kWidth) * kHeight);
    for (size_t i = 0; i < noisy.size(); ++i)
        noisy[i] = i % 97 == 5 ? std::numeric_limits<float>::quiet_NaN()
                               : (i / kWidth / 40 % 2 ? unit(rng) : 0.3f + 0.1f * unit(rng));
    starts.push_back(noisy);
    raster::RasterState strict;
    strict.cullMode = CullMode::None;
    strict.barycentrics = false;
    strict.depthTest = nearIsLarge(test) ? DepthTest::Greater : DepthTest::Less;
    starts.push_back(draw(mesh, strict, starts.front(), Shading::DepthOnly, 1).depth);
    return starts;
}

TEST(RowSpanTraversal, BitwiseTheReferenceForEveryStateShadingAndThreadCount) {
    const Mesh mesh = randomMesh(31, 1200);
    // 5 x 3 x 2 x 3 cases; under the sanitizers every 7th (SanitizerBuild.h: every value of
    // every axis stays in the sample).
    constexpr int kCases = 5 * 3 * 2 * 3, kStride = 7;
    int cases = 0, index = 0;
    for (DepthTest test : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                           DepthTest::Greater, DepthTest::GreaterEqual}) {
        const std::vector<std::vector<float>> starts = startDepths(mesh, test);
        for (size_t start = 0; start < starts.size(); ++start)
            for (bool write : {true, false})
                for (Shading shading : {Shading::Keep, Shading::Discard, Shading::DepthOnly}) {
                    if (!raster_test::sweepRunsCase(index++, kStride))
                        continue;
                    raster::RasterState state;
                    state.depthTest = test;
                    state.depthWrite = write;
                    state.cullMode = CullMode::None;
                    state.barycentrics = false;
                    state.referenceTraversal = true;
                    const RecordedDraw reference = draw(mesh, state, starts[start], shading, 1);
                    state.referenceTraversal = false;
                    const std::string name = "test " + std::to_string(int(test)) + ", start " +
                                             std::to_string(start) + ", write " +
                                             std::to_string(write) + ", shading " +
                                             std::to_string(int(shading));
                    for (int threads : {1, 2}) {
                        const RecordedDraw got = draw(mesh, state, starts[start], shading, threads);
                        raster_test::expectSameDraw(
                            got, reference, name + ", " + std::to_string(threads) + " threads");
                    }
                    EXPECT_GT(reference.stats.samplesCovered, 30000u) << name;
                    ++cases;
                }
    }
    EXPECT_EQ(cases, raster_test::sweptCaseCount(kCases, kStride));
}

} // namespace
