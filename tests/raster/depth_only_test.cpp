// The depth-only path (raster::DepthOnly, Rasterizer.h) against the generic per-pixel path: on
// random clip-space triangles (large and tiny, slivers, triangles crossing the near and far
// planes and the guard band, shared edges of fans), with every depth test, depth writes on and
// off, every cull mode, the depth buffer must be bitwise the same and the coverage counters
// equal, for 1 and 2 threads; the same for raster::TriangleIds (the visibility draw's spans, which
// also write each pixel's triangle id), one-sample and multisampled. The span loops' SIMD forms
// (DepthSpan.h, the multisampled one per row and per triangle) against their scalar oracles, and
// the in-draw clear (RasterState::clearDepth) against a clear before the draw, with and without
// the record of clear tiles (RasterState::tilesNotClear), and the caller's planes cleared with it
// (RasterState::alsoClearTile).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <hwy/targets.h>
#include <tbb/task_arena.h>

#include "raster/DepthSpan.h"
#include "raster/Rasterizer.h"
#include "tests/raster/SanitizerBuild.h"
#include "tests/raster/TestMeshes.h"

namespace {

using raster::CullMode;
using raster::DepthTest;

using raster_test::Mesh;

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
    raster_test::appendFan(mesh, rng);
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
    drawn.depth.assign(size_t(width) * height * size_t(state.samples), clear);
    tbb::task_arena(threads).execute([&] {
        raster::Rasterizer rasterizer(width, height);
        rasterizer.draw(raster::TriangleList{mesh.positions, mesh.indices}, state,
                        drawn.depth.data(), fn);
        drawn.stats = rasterizer.lastStats();
    });
    return drawn;
}

// The 30 states of forEveryDrawState, and the stride of its sample under the sanitizers (7:
// every depth test, write mode and cull mode stays in the sample; SanitizerBuild.h).
constexpr int kDrawStates = 30, kDrawStateStride = 7;

// Calls fn(state, clear, name) for every depth test, depth writes on and off and every cull mode
// (kDrawStates states, no barycentrics; a sample of them in the sanitizer build), with the clear
// value the test starts from and a name for the failure messages; returns how many states it ran.
template <class Fn> int forEveryDrawState(Fn&& fn) {
    int cases = 0, index = 0;
    for (DepthTest test : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                           DepthTest::Greater, DepthTest::GreaterEqual})
        for (bool write : {true, false})
            for (CullMode cull : {CullMode::None, CullMode::Back, CullMode::Front}) {
                if (!raster_test::sweepRunsCase(index++, kDrawStateStride))
                    continue;
                raster::RasterState state;
                state.depthTest = test;
                state.depthWrite = write;
                state.cullMode = cull;
                state.barycentrics = false;
                const bool nearer = test == DepthTest::Greater || test == DepthTest::GreaterEqual;
                const float clear = nearer ? 0.0f : 1.0f;
                fn(state, clear,
                   "test " + std::to_string(int(test)) + " write " + std::to_string(write) +
                       " cull " + std::to_string(int(cull)));
                ++cases;
            }
    return cases;
}

TEST(DepthOnlyPath, BitwiseTheGenericPathForEveryStateAndThreadCount) {
    const Mesh mesh = randomMesh(5, 3000);
    const int cases = forEveryDrawState(
        [&](const raster::RasterState& state, float clear, const std::string& name) {
            const Drawn generic = draw(mesh, state, clear, 1, [](const raster::Fragment&) {});
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
        });
    EXPECT_EQ(cases, raster_test::sweptCaseCount(kDrawStates, kDrawStateStride));
}

// raster::TriangleIds (the visibility draw) takes the same spans and writes each passing pixel's
// id in the vector loop: the ids and the depth buffer bitwise what a per-fragment function
// writing the same ids gives, every depth test, depth writes on and off, every cull mode (back
// faces carry the bit), 1 and 2 threads; and without a depth buffer (per fragment).
TEST(TriangleIdsPath, BitwiseTheGenericPathForEveryStateAndThreadCount) {
    const Mesh mesh = randomMesh(6, 3000);
    const int width = 301, height = 203; // draw()'s size
    constexpr uint32_t kNone = 0xdeadbeefu, kBackFaceBit = 1u << 31;
    int backFacesSeen = 0, statesShowingBackFaces = 0;
    const int cases = forEveryDrawState([&](const raster::RasterState& state, float clear,
                                            const std::string& name) {
        std::vector<uint32_t> genericIds(size_t(width) * height, kNone);
        const raster::TriangleIds genericWriter{genericIds.data(), size_t(width), kBackFaceBit};
        const Drawn generic = draw(mesh, state, clear, 1, [&](const raster::Fragment& fragment) {
            genericWriter(fragment);
        });
        for (int threads : {1, 2}) {
            std::vector<uint32_t> ids(genericIds.size(), kNone);
            const Drawn fast = draw(mesh, state, clear, threads,
                                    raster::TriangleIds{ids.data(), size_t(width), kBackFaceBit});
            ASSERT_EQ(0, std::memcmp(fast.depth.data(), generic.depth.data(),
                                     fast.depth.size() * sizeof(float)))
                << name << ", " << threads << " threads";
            ASSERT_EQ(ids, genericIds) << name << ", " << threads << " threads";
            EXPECT_EQ(fast.stats.samplesCovered, generic.stats.samplesCovered) << name;
            EXPECT_EQ(fast.stats.samplesPassed, generic.stats.samplesPassed) << name;
            EXPECT_EQ(fast.stats.fragments, generic.stats.fragments) << name;
        }
        const bool backFaceSeen =
            std::any_of(genericIds.begin(), genericIds.end(),
                        [&](uint32_t id) { return id != kNone && (id & kBackFaceBit); });
        backFacesSeen += int(backFaceSeen);
        statesShowingBackFaces += int(state.cullMode != CullMode::Back);
        EXPECT_GT(generic.stats.samplesPassed, 10000u) << name;
    });
    EXPECT_EQ(cases, raster_test::sweptCaseCount(kDrawStates, kDrawStateStride));
    EXPECT_EQ(backFacesSeen, statesShowingBackFaces); // every state but the back-face cull
    EXPECT_GT(statesShowingBackFaces, 0);

    // Without a depth buffer the ids are written per fragment: every covered pixel's last one.
    raster::RasterState state;
    state.depthTest = DepthTest::Always;
    state.barycentrics = false;
    std::vector<uint32_t> genericIds(size_t(width) * height, kNone), ids = genericIds;
    const raster::TriangleIds genericWriter{genericIds.data(), size_t(width), kBackFaceBit};
    raster::Rasterizer a(width, height), b(width, height);
    a.draw(raster::TriangleList{mesh.positions, mesh.indices}, state, nullptr,
           [&](const raster::Fragment& fragment) { genericWriter(fragment); });
    b.draw(raster::TriangleList{mesh.positions, mesh.indices}, state, nullptr,
           raster::TriangleIds{ids.data(), size_t(width), kBackFaceBit});
    EXPECT_EQ(ids, genericIds);
}

// Multisampled (2, 4 and 8 samples): pixels whose every sample is covered take DepthSpan.h's
// multisampled loop; the per-sample depths, the ids and centre depths of the visibility draw
// (TriangleIds with centreDepths) and the counters are bitwise what a per-fragment function
// writing the same gives, every depth test, depth writes on and off, every cull mode, 1 and 2
// threads; and DepthOnly the same against an empty fragment function.
TEST(TriangleIdsPath, MultisampledBitwiseTheGenericPathForEveryStateAndThreadCount) {
    const Mesh mesh = randomMesh(8, 400);
    const size_t pixels = 301 * 203; // draw()'s size
    constexpr uint32_t kNone = 0xdeadbeefu, kBackFaceBit = 1u << 31;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    int cases = 0;
    for (int samples : {2, 4, 8})
        cases += forEveryDrawState([&](raster::RasterState state, float clear,
                                       const std::string& stateName) {
            state.samples = samples;
            const std::string name = stateName + ", " + std::to_string(samples) + " samples";
            const size_t count = pixels * size_t(samples);
            std::vector<uint32_t> genericIds(count, kNone);
            std::vector<float> genericCentres(count, nan);
            const raster::TriangleIds genericWriter{genericIds.data(), 301, kBackFaceBit, samples,
                                                    genericCentres.data()};
            const Drawn generic =
                draw(mesh, state, clear, 1, [&](const raster::Fragment& f) { genericWriter(f); });
            const Drawn genericDepthOnly =
                draw(mesh, state, clear, 1, [](const raster::Fragment&) {});
            for (int threads : {1, 2}) {
                std::vector<uint32_t> ids(count, kNone);
                std::vector<float> centres(count, nan);
                const Drawn fast = draw(
                    mesh, state, clear, threads,
                    raster::TriangleIds{ids.data(), 301, kBackFaceBit, samples, centres.data()});
                ASSERT_EQ(
                    0, std::memcmp(fast.depth.data(), generic.depth.data(), count * sizeof(float)))
                    << name << ", " << threads << " threads";
                ASSERT_EQ(ids, genericIds) << name << ", " << threads << " threads";
                ASSERT_EQ(0,
                          std::memcmp(centres.data(), genericCentres.data(), count * sizeof(float)))
                    << name << ", " << threads << " threads";
                EXPECT_EQ(fast.stats.samplesCovered, generic.stats.samplesCovered) << name;
                EXPECT_EQ(fast.stats.samplesPassed, generic.stats.samplesPassed) << name;
                EXPECT_EQ(fast.stats.fragments, generic.stats.fragments) << name;

                const Drawn depthOnly = draw(mesh, state, clear, threads, raster::DepthOnly{});
                ASSERT_EQ(0, std::memcmp(depthOnly.depth.data(), genericDepthOnly.depth.data(),
                                         count * sizeof(float)))
                    << name << ", " << threads << " threads, depth only";
                EXPECT_EQ(depthOnly.stats.samplesPassed, genericDepthOnly.stats.samplesPassed)
                    << name;
                EXPECT_EQ(depthOnly.stats.fragments, genericDepthOnly.stats.fragments) << name;
            }
            EXPECT_GT(generic.stats.samplesPassed, 10000u) << name;
        });
    EXPECT_EQ(cases, 3 * raster_test::sweptCaseCount(kDrawStates, kDrawStateStride));

    // A TriangleIds of another sample count than the draw's is refused.
    raster::RasterState state;
    state.samples = 4;
    std::vector<float> depth(pixels * 4, 1.0f);
    std::vector<uint32_t> ids(pixels * 4);
    raster::Rasterizer rasterizer(301, 203);
    EXPECT_THROW(rasterizer.draw(raster::TriangleList{mesh.positions, mesh.indices}, state,
                                 depth.data(), raster::TriangleIds{ids.data(), 301, 0, 2}),
                 std::invalid_argument);
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

// Random spans of 0 to 69 pixels at random offsets (the vector body and every tail length), planes
// crossing 0 and 1 (the clamp), steep and flat, and NaN; stored depths random, equal to the
// incoming ones, and NaN: the vector loop writes and counts bitwise what the scalar loop does.
void checkVectorSpansAgainstScalar() {
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    int spans = 0, passedSomewhere = 0, failedSomewhere = 0, valuesWritten = 0;
    for (DepthTest test : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                           DepthTest::Greater, DepthTest::GreaterEqual})
        for (bool write : {true, false})
            for (int trial = 0; trial < 400; ++trial) {
                raster::DepthSpanArgs span;
                span.lo = int(rng() % 40);
                span.hi = span.lo + int(rng() % 70) - 1;
                span.zStep = (unit(rng) - 0.5) * (trial % 3 == 0 ? 0.1 : 1e-4);
                span.zRow = unit(rng) * 1.4 - 0.2 - span.zStep * span.lo;
                if (trial % 50 == 7)
                    span.zStep = std::numeric_limits<double>::quiet_NaN();
                span.write = write;
                std::vector<float> stored(128);
                for (size_t i = 0; i < stored.size(); ++i) {
                    const double z = span.zRow + span.zStep * double(i);
                    stored[i] = i % 11 == 3  ? nan
                                : i % 5 == 1 ? float(std::clamp(z, 0.0, 1.0)) // equal depths
                                             : float(unit(rng));
                }
                std::vector<float> scalarRow = stored, vectorRow = stored;
                // Every other span also writes a value where it passes (TriangleIds).
                std::vector<uint32_t> scalarValues(stored.size()), vectorValues;
                std::iota(scalarValues.begin(), scalarValues.end(), 1000u);
                vectorValues = scalarValues;
                span.value = uint32_t(rng());
                span.row = scalarRow.data();
                span.values = trial % 2 ? scalarValues.data() : nullptr;
                const uint64_t scalarPassed = raster::depthSpanScalar(test, span);
                span.row = vectorRow.data();
                span.values = trial % 2 ? vectorValues.data() : nullptr;
                const uint64_t vectorPassed = raster::depthSpan(test, span);
                ASSERT_EQ(vectorValues, scalarValues) << "test " << int(test) << " trial " << trial;
                valuesWritten += trial % 2 && scalarPassed > 0;
                ASSERT_EQ(vectorPassed, scalarPassed) << "test " << int(test) << " trial " << trial;
                ASSERT_EQ(0, std::memcmp(vectorRow.data(), scalarRow.data(),
                                         scalarRow.size() * sizeof(float)))
                    << "test " << int(test) << " trial " << trial;
                passedSomewhere += scalarPassed > 0;
                failedSomewhere += scalarPassed < uint64_t(std::max(0, span.hi - span.lo + 1));
                ++spans;
            }
    EXPECT_EQ(spans, 4000);
    EXPECT_GT(passedSomewhere, 1000);
    EXPECT_GT(failedSomewhere, 1000);
    EXPECT_GT(valuesWritten, 500);
}

// The multisampled loop the same way: 2, 4 and 8 samples (more and fewer samples than a vector
// has lanes), runs of 0 to 24 pixels (every tail), edges that cover every sample, none or some
// (and change along the run), sample offsets that push samples across 0 and 1, NaN planes, stored
// depths random, equal and NaN; ids and centre depths on and off.
void checkMultisampledSpansAgainstScalar() {
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<int64_t> edgeValue(-3000, 3000), edgeStep(-900, 900),
        edgeOffset(-400, 400);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    int spans = 0, passedSomewhere = 0, failedSomewhere = 0, partlyPassed = 0, partlyCovered = 0;
    for (int samples : {2, 4, 8})
        for (DepthTest test : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                               DepthTest::Greater, DepthTest::GreaterEqual})
            for (bool write : {true, false})
                for (int trial = 0; trial < 120; ++trial) {
                    raster::MultisampleSpanArgs span;
                    span.samples = samples;
                    span.lo = int(rng() % 20);
                    span.hi = span.lo + int(rng() % 25) - 1;
                    span.zStep = (unit(rng) - 0.5) * (trial % 3 == 0 ? 0.1 : 1e-4);
                    span.zRow = unit(rng) * 1.4 - 0.2 - span.zStep * span.lo;
                    if (trial % 40 == 7)
                        span.zStep = std::numeric_limits<double>::quiet_NaN();
                    double offsets[raster::kMaxSamples];
                    for (double& o : offsets)
                        o = (unit(rng) - 0.5) * (trial % 4 == 1 ? 0.2 : 1e-4);
                    span.sampleOffsets = offsets;
                    int64_t edgeOffsets[3][raster::kMaxSamples];
                    const bool whole = trial % 5 == 0; // every sample covered
                    for (int e = 0; e < 3; ++e) {
                        span.edgeAtLo[e] = whole ? 100000 : edgeValue(rng);
                        span.edgeStep[e] = whole ? 0 : edgeStep(rng);
                        for (int64_t& o : edgeOffsets[e])
                            o = edgeOffset(rng) - int64_t(rng() % 2); // with a fill bias
                    }
                    span.edgeOffsets = edgeOffsets;
                    span.write = write;
                    const size_t count = 48 * size_t(samples);
                    std::vector<float> stored(count);
                    for (size_t i = 0; i < count; ++i) {
                        const double z = span.zRow + span.zStep * double(i / size_t(samples)) +
                                         offsets[i % size_t(samples)];
                        stored[i] = i % 11 == 3  ? nan
                                    : i % 5 == 1 ? float(std::clamp(z, 0.0, 1.0)) // equal
                                                 : float(unit(rng));
                    }
                    std::vector<float> scalarDepth = stored, vectorDepth = stored;
                    std::vector<uint32_t> scalarValues(count), vectorValues;
                    std::iota(scalarValues.begin(), scalarValues.end(), 1000u);
                    vectorValues = scalarValues;
                    std::vector<float> scalarCentres(count, -1.0f), vectorCentres = scalarCentres;
                    span.value = uint32_t(rng());
                    const bool values = trial % 2 == 1, centres = trial % 3 != 2;
                    span.depth = scalarDepth.data();
                    span.values = values ? scalarValues.data() : nullptr;
                    span.centreDepths = centres ? scalarCentres.data() : nullptr;
                    const raster::MultisampleSpanCounts scalar =
                        raster::multisampleSpanScalar(test, span);
                    span.depth = vectorDepth.data();
                    span.values = values ? vectorValues.data() : nullptr;
                    span.centreDepths = centres ? vectorCentres.data() : nullptr;
                    const raster::MultisampleSpanCounts vector =
                        raster::multisampleSpanLoop(test)(span);
                    const std::string name = std::to_string(samples) + " samples, test " +
                                             std::to_string(int(test)) + " trial " +
                                             std::to_string(trial);
                    ASSERT_EQ(vector.samplesCovered, scalar.samplesCovered) << name;
                    ASSERT_EQ(vector.samplesPassed, scalar.samplesPassed) << name;
                    ASSERT_EQ(vector.fragments, scalar.fragments) << name;
                    ASSERT_EQ(0, std::memcmp(vectorDepth.data(), scalarDepth.data(),
                                             count * sizeof(float)))
                        << name;
                    ASSERT_EQ(vectorValues, scalarValues) << name;
                    ASSERT_EQ(0, std::memcmp(vectorCentres.data(), scalarCentres.data(),
                                             count * sizeof(float)))
                        << name;
                    const uint64_t spanSamples =
                        uint64_t(std::max(0, span.hi - span.lo + 1)) * uint64_t(samples);
                    passedSomewhere += scalar.samplesPassed > 0;
                    failedSomewhere += scalar.samplesPassed < scalar.samplesCovered;
                    partlyCovered +=
                        scalar.samplesCovered > 0 && scalar.samplesCovered < spanSamples;
                    // Pixels with some samples passing and others not.
                    partlyPassed += scalar.fragments * uint64_t(samples) > scalar.samplesPassed;
                    ++spans;
                }
    EXPECT_EQ(spans, 3600);
    EXPECT_GT(passedSomewhere, 1000);
    EXPECT_GT(failedSomewhere, 1000);
    EXPECT_GT(partlyCovered, 600);
    EXPECT_GT(partlyPassed, 300);
}

// The triangle form (raster::MultisampleTriangleArgs, one call per triangle): random bounding
// boxes of 1 to 40 pixels by 1 to 6 rows (rows shorter than forEachMultisampleRow's 16 pixels go
// whole, longer ones are cut by coveredSpan), edges that change along rows and down columns, 2, 4
// and 8 samples, every depth test. Two oracles: the vector loop against
// multisampleTriangleScalar (bitwise: depth, ids, centre depths, counters), and that against
// every row's whole bounding box through the scalar span loop, which tests every sample, so the
// rows' cutting drops no sample an edge accepts.
void checkMultisampledTrianglesAgainstScalar() {
    std::mt19937 rng(29);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<int64_t> edgeValue(-3000, 9000), edgeStep(-900, 900),
        edgeOffset(-400, 400);
    constexpr int kWidth = 64, kRows = 8;
    int triangles = 0, covering = 0, cutRows = 0;
    for (int samples : {2, 4, 8})
        for (DepthTest test : {DepthTest::Always, DepthTest::Less, DepthTest::LessEqual,
                               DepthTest::Greater, DepthTest::GreaterEqual})
            for (int trial = 0; trial < 60; ++trial) {
                raster::MultisampleTriangleArgs t;
                t.samples = samples;
                t.rowStride = size_t(kWidth) * size_t(samples);
                t.minX = int(rng() % 20);
                t.maxX = t.minX + int(rng() % 40);
                t.minY = int(rng() % 2);
                t.maxY = t.minY + int(rng() % 6);
                t.zStepX = (unit(rng) - 0.5) * 0.01;
                t.zStepY = (unit(rng) - 0.5) * 0.01;
                t.zOrigin = unit(rng) * 1.2 - 0.1;
                double offsets[raster::kMaxSamples];
                for (double& o : offsets)
                    o = (unit(rng) - 0.5) * 1e-3;
                t.sampleOffsets = offsets;
                int64_t edgeOffsets[3][raster::kMaxSamples];
                for (int e = 0; e < 3; ++e) {
                    t.edgeAtMin[e] = edgeValue(rng);
                    t.edgeStepX[e] = edgeStep(rng);
                    t.edgeStepY[e] = edgeStep(rng);
                    for (int64_t& o : edgeOffsets[e])
                        o = edgeOffset(rng) - int64_t(rng() % 2);
                }
                t.edgeOffsets = edgeOffsets;
                t.write = trial % 3 != 0;
                t.value = uint32_t(rng());
                const size_t count = size_t(kRows) * t.rowStride;
                std::vector<float> stored(count);
                for (float& z : stored)
                    z = float(unit(rng));
                struct Target {
                    std::vector<float> depth, centres;
                    std::vector<uint32_t> values;
                };
                auto fresh = [&] {
                    Target target{stored, std::vector<float>(count, -1.0f), {}};
                    target.values.resize(count);
                    std::iota(target.values.begin(), target.values.end(), 7u);
                    return target;
                };
                auto aim = [&](raster::MultisampleTriangleArgs& args, Target& target) {
                    args.depth = target.depth.data();
                    args.values = target.values.data();
                    args.centreDepths = trial % 2 ? target.centres.data() : nullptr;
                };
                Target vector = fresh(), scalar = fresh(), whole = fresh();
                aim(t, vector);
                const raster::MultisampleSpanCounts vectorCounts =
                    raster::multisampleTriangleLoop(test)(t);
                aim(t, scalar);
                const raster::MultisampleSpanCounts scalarCounts =
                    raster::multisampleTriangleScalar(test, t);
                // Every row's whole bounding box, one span per row.
                raster::MultisampleSpanCounts wholeCounts;
                int64_t row[3] = {t.edgeAtMin[0], t.edgeAtMin[1], t.edgeAtMin[2]};
                for (int py = t.minY; py <= t.maxY; ++py) {
                    raster::MultisampleSpanArgs span;
                    const size_t rowStart = size_t(py) * t.rowStride;
                    span.depth = whole.depth.data() + rowStart;
                    span.values = whole.values.data() + rowStart;
                    span.centreDepths = trial % 2 ? whole.centres.data() + rowStart : nullptr;
                    span.value = t.value;
                    span.lo = t.minX;
                    span.hi = t.maxX;
                    span.samples = samples;
                    span.zRow = t.zOrigin + t.zStepY * py;
                    span.zStep = t.zStepX;
                    span.sampleOffsets = offsets;
                    for (int e = 0; e < 3; ++e) {
                        span.edgeAtLo[e] = row[e];
                        span.edgeStep[e] = t.edgeStepX[e];
                        row[e] += t.edgeStepY[e];
                    }
                    span.edgeOffsets = edgeOffsets;
                    span.write = t.write;
                    const raster::MultisampleSpanCounts counts =
                        raster::multisampleSpanScalar(test, span);
                    wholeCounts.samplesCovered += counts.samplesCovered;
                    wholeCounts.samplesPassed += counts.samplesPassed;
                    wholeCounts.fragments += counts.fragments;
                }
                const std::string name = std::to_string(samples) + " samples, test " +
                                         std::to_string(int(test)) + " trial " +
                                         std::to_string(trial);
                const raster::MultisampleSpanCounts* otherCounts[] = {&vectorCounts, &wholeCounts};
                for (const raster::MultisampleSpanCounts* other : otherCounts) {
                    ASSERT_EQ(other->samplesCovered, scalarCounts.samplesCovered) << name;
                    ASSERT_EQ(other->samplesPassed, scalarCounts.samplesPassed) << name;
                    ASSERT_EQ(other->fragments, scalarCounts.fragments) << name;
                }
                for (const Target* other : {&vector, &whole}) {
                    ASSERT_EQ(0, std::memcmp(other->depth.data(), scalar.depth.data(),
                                             count * sizeof(float)))
                        << name;
                    ASSERT_EQ(other->values, scalar.values) << name;
                    ASSERT_EQ(0, std::memcmp(other->centres.data(), scalar.centres.data(),
                                             count * sizeof(float)))
                        << name;
                }
                ++triangles;
                covering += scalarCounts.samplesCovered > 0;
                cutRows += t.maxX - t.minX >= 16 && scalarCounts.samplesCovered > 0;
            }
    EXPECT_EQ(triangles, 900);
    EXPECT_GT(covering, 500);
    EXPECT_GT(cutRows, 300);
}

// Runs `check` on every target this build has and this CPU runs: the masked tail exists only
// where masked memory operations cannot fault (AVX-512), the others keep the scalar tail.
template <class Check> void onEveryTarget(Check check) {
    const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
    ASSERT_FALSE(targets.empty());
    for (int64_t target : targets) {
        hwy::SetSupportedTargetsForTest(target); // lifted after the loop
        SCOPED_TRACE(hwy::TargetName(target));
        check();
    }
    hwy::SetSupportedTargetsForTest(0);
}

TEST(DepthSpan, VectorLoopIsBitwiseTheScalarLoop) {
    onEveryTarget(checkVectorSpansAgainstScalar);
}

TEST(DepthSpan, MultisampledVectorLoopIsBitwiseTheScalarLoop) {
    onEveryTarget(checkMultisampledSpansAgainstScalar);
}

TEST(DepthSpan, MultisampledTriangleLoopIsBitwiseTheScalarLoopAndDropsNoSample) {
    onEveryTarget(checkMultisampledTrianglesAgainstScalar);
}

// RasterState::clearDepth: each tile clears its own pixels (all samples) inside the draw; the
// buffer, filled with garbage before, ends bitwise as with a clear before the draw, for 1 and 4
// samples and 1 and 2 threads, including pixels no triangle covers.
// The in-draw clear tests' state: reversed depth (Greater), no cull, no barycentrics.
raster::RasterState clearTestState(int samples) {
    raster::RasterState state;
    state.depthTest = DepthTest::Greater;
    state.cullMode = CullMode::None;
    state.barycentrics = false;
    state.samples = samples;
    return state;
}

TEST(DepthOnlyPath, ClearInsideTheDrawEqualsAClearBefore) {
    const Mesh mesh = randomMesh(23, 0); // the fan alone: the corners stay uncovered
    for (int samples : {1, 4})
        for (int threads : {1, 2}) {
            raster::RasterState state = clearTestState(samples);
            const int width = 301, height = 203;
            const size_t size = size_t(width) * height * size_t(samples);
            std::vector<float> before(size, 0.0f), inside(size, 0.75f);
            for (size_t i = 0; i < size; i += 7)
                inside[i] = std::numeric_limits<float>::quiet_NaN();
            tbb::task_arena(threads).execute([&] {
                raster::Rasterizer rasterizer(width, height);
                const raster::TriangleList triangles{mesh.positions, mesh.indices};
                rasterizer.draw(triangles, state, before.data(), raster::DepthOnly{});
                state.clearDepth = 0.0f;
                rasterizer.draw(triangles, state, inside.data(), raster::DepthOnly{});
            });
            EXPECT_EQ(0, std::memcmp(inside.data(), before.data(), size * sizeof(float)))
                << samples << " samples, " << threads << " threads";
            EXPECT_GT(std::count(before.begin(), before.end(), 0.0f), 1000) << "uncovered pixels";
        }
}

// RasterState::tilesNotClear: frame after frame into one buffer, with casters moving between
// tiles (and a frame with none), the buffer is bitwise a full clear's after every draw, for 1
// and 2 threads; a tile recorded clear that no triangle reaches is not written at all (its
// sentinel survives: the clear really is skipped), and the record is rewritten to the tiles
// triangles were binned to.
// RasterState::alsoClearTile: called once per tile, with the tile's pixels, before the tile's
// triangles: ids cleared inside the draw end as with a clear before it (the visibility draw's
// codes), for 1 and 4 samples and 1 and 2 threads, and every pixel's samples are handed over
// exactly once.
TEST(DepthOnlyPath, AlsoClearTileClearsEachPixelOnceBeforeItsTriangles) {
    const Mesh mesh = randomMesh(29, 0); // the fan alone: the corners stay uncovered
    constexpr uint32_t kNone = 0xffffffffu;
    for (int samples : {1, 4})
        for (int threads : {1, 2}) {
            raster::RasterState state = clearTestState(samples);
            const int width = 301, height = 203;
            const size_t pixels = size_t(width) * height, size = pixels * size_t(samples);
            std::vector<float> depthBefore(size, 0.0f), depthInside(size, 0.5f);
            std::vector<uint32_t> idsBefore(size, kNone), idsInside(size, 12345u);
            std::vector<int> handedOver(pixels, 0);
            // Per sample for the multisampled draw (no span path there), as the visibility
            // draw records its codes.
            auto writer = [samples](std::vector<uint32_t>& ids, int width) {
                return [&ids, samples, width](const raster::Fragment& f) {
                    for (int s = 0; s < samples; ++s)
                        if (samples == 1 || (f.coverage >> s & 1u))
                            ids[(size_t(f.y) * size_t(width) + size_t(f.x)) * size_t(samples) +
                                size_t(s)] = f.triangle;
                };
            };
            tbb::task_arena(threads).execute([&] {
                raster::Rasterizer rasterizer(width, height);
                const raster::TriangleList triangles{mesh.positions, mesh.indices};
                rasterizer.draw(triangles, state, depthBefore.data(), writer(idsBefore, width));
                state.clearDepth = 0.0f;
                state.alsoClearTile = [&](int x0, int y0, int x1, int y1) {
                    for (int y = y0; y < y1; ++y)
                        for (int x = x0; x < x1; ++x) {
                            const size_t pixel = size_t(y) * size_t(width) + size_t(x);
                            ++handedOver[pixel];
                            std::fill_n(idsInside.begin() + std::ptrdiff_t(pixel * samples),
                                        samples, kNone);
                        }
                };
                rasterizer.draw(triangles, state, depthInside.data(), writer(idsInside, width));
            });
            const std::string name =
                std::to_string(samples) + " samples, " + std::to_string(threads) + " threads";
            EXPECT_EQ(0, std::memcmp(depthInside.data(), depthBefore.data(), size * sizeof(float)))
                << name;
            EXPECT_EQ(idsInside, idsBefore) << name;
            EXPECT_TRUE(std::all_of(handedOver.begin(), handedOver.end(), [](int calls) {
                return calls == 1;
            })) << name;
            EXPECT_GT(std::count(idsBefore.begin(), idsBefore.end(), kNone), 1000) << name;
            EXPECT_GT(std::count_if(idsBefore.begin(), idsBefore.end(),
                                    [](uint32_t id) { return id != kNone; }),
                      10000)
                << name;
        }
}

TEST(DepthOnlyPath, ClearOnlyTilesNotClearEqualsAFullClear) {
    const int width = 301, height = 203; // 3 x 2 tiles of 128, partial ones at the edges
    // Small triangles around NDC centres: each lies within one tile.
    auto trianglesAt = [](std::initializer_list<glm::vec2> centres) {
        Mesh mesh;
        for (const glm::vec2& c : centres) {
            const uint32_t base = uint32_t(mesh.positions.size());
            mesh.positions.insert(mesh.positions.end(), {glm::vec4(c.x - 0.1f, c.y - 0.1f, 0.3f, 1),
                                                         glm::vec4(c.x + 0.1f, c.y - 0.1f, 0.5f, 1),
                                                         glm::vec4(c.x, c.y + 0.1f, 0.4f, 1)});
            mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
        }
        return mesh;
    };
    // NDC y up, row 0 at the top: (-0.6, 0.5) is in tile 0, (0.1, -0.5) in tile 4, (0.8, 0.5)
    // in tile 2.
    const std::vector<Mesh> frames = {
        trianglesAt({{-0.6f, 0.5f}}), trianglesAt({{0.1f, -0.5f}, {0.8f, 0.5f}}), Mesh{},
        trianglesAt({{-0.6f, 0.5f}, {0.1f, -0.5f}}), randomMesh(29, 40)};
    for (int threads : {1, 2}) {
        raster::RasterState state;
        state.depthTest = DepthTest::Greater;
        state.cullMode = CullMode::None;
        state.barycentrics = false;
        state.clearDepth = 0.0f;
        std::vector<float> kept(size_t(width) * height, 0.0f);
        std::vector<uint8_t> record(6, 0);
        tbb::task_arena(threads).execute([&] {
            raster::Rasterizer rasterizer(width, height);
            ASSERT_EQ(rasterizer.tileCountX() * rasterizer.tileCountY(), 6);
            for (size_t frame = 0; frame < frames.size(); ++frame) {
                const raster::TriangleList triangles{frames[frame].positions,
                                                     frames[frame].indices};
                std::vector<float> full(kept.size(), 0.5f);
                raster::RasterState fullState = state;
                rasterizer.draw(triangles, fullState, full.data(), raster::DepthOnly{});
                const std::vector<uint8_t> before = record;
                // A sentinel in the last pixel of every tile recorded clear: it must survive
                // exactly where no triangle is binned.
                std::vector<size_t> sentinels;
                for (int tile = 0; tile < 6; ++tile)
                    if (!record[size_t(tile)]) {
                        const int x = std::min((tile % 3) * 128 + 127, width - 1);
                        const int y = std::min((tile / 3) * 128 + 127, height - 1);
                        sentinels.push_back(size_t(y) * width + size_t(x));
                    }
                for (size_t i : sentinels)
                    kept[i] = -1.0f;
                raster::RasterState keptState = state;
                keptState.tilesNotClear = record;
                rasterizer.draw(triangles, keptState, kept.data(), raster::DepthOnly{});
                for (int tile = 0; tile < 6; ++tile) {
                    const int x0 = (tile % 3) * 128, y0 = (tile / 3) * 128;
                    const size_t sentinel = size_t(std::min(y0 + 127, height - 1)) * width +
                                            size_t(std::min(x0 + 127, width - 1));
                    if (!before[size_t(tile)] && !record[size_t(tile)]) {
                        EXPECT_EQ(kept[sentinel], -1.0f)
                            << "frame " << frame << ", tile " << tile << " was cleared again";
                        kept[sentinel] = 0.0f; // what the tile holds apart from the sentinel
                    }
                }
                EXPECT_EQ(0, std::memcmp(kept.data(), full.data(), kept.size() * sizeof(float)))
                    << "frame " << frame << ", " << threads << " threads";
            }
        });
        // The last frame (random triangles over the whole screen) reaches every tile, the
        // empty frame none.
        EXPECT_EQ(record, std::vector<uint8_t>(6, 1));
    }
    // A record of the wrong size is refused.
    raster::RasterState state;
    state.clearDepth = 0.0f;
    std::vector<uint8_t> record(5, 0);
    state.tilesNotClear = record;
    std::vector<float> depth(size_t(width) * height, 0.0f);
    raster::Rasterizer rasterizer(width, height);
    const Mesh mesh = trianglesAt({{0.0f, 0.0f}});
    EXPECT_THROW(rasterizer.draw(raster::TriangleList{mesh.positions, mesh.indices}, state,
                                 depth.data(), raster::DepthOnly{}),
                 std::invalid_argument);
}

} // namespace
