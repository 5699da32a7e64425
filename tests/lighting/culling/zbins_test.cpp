// ZBins and ZBinTileMasks (lighting/culling/ZBins.h), without a G-buffer: the depth sort, the bin
// ranges on hand-made cases (a light spanning many bins, lights at one depth, lights behind the
// camera, empty bins, unbounded lights), the range-hull table against a loop over the bins, bins
// against a brute-force oracle on random lights (every light whose extent holds a depth is in the
// range of that depth's bin, and each range's ends overlap their bin), the tile masks and their
// bit walk against the tile test itself, and thread-count independence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "gbuffer/visibility/CameraView.h"
#include "lighting/culling/ZBins.h"

namespace {

using lighting::CandidateLight;
using lighting::ZBins;
using lighting::ZBinSpacing;

// A bounded light at view depth `depth` on the view axis.
CandidateLight lightAt(uint32_t index, float depth, float radius) {
    CandidateLight c;
    c.index = index;
    c.centreView = glm::vec3(0.0f, 0.0f, -depth);
    c.positionView = c.centreView;
    c.radius = radius;
    return c;
}

std::vector<uint32_t> sorted(const ZBins& bins) {
    return {bins.sortedLights().begin(), bins.sortedLights().end()};
}

// The sorted position of light `index`.
uint32_t positionOf(const ZBins& bins, uint32_t index) {
    const auto lights = bins.sortedLights();
    return uint32_t(std::find(lights.begin(), lights.end(), index) - lights.begin());
}

bool inRange(ZBins::Range r, uint32_t position) {
    return r.first <= position && position <= r.last;
}

TEST(ZBins, SortsByCentreDepthTiesByLightIndex) {
    const std::vector<CandidateLight> lights = {lightAt(0, 5.0f, 1.0f), lightAt(1, 2.0f, 1.0f),
                                                lightAt(2, 5.0f, 0.5f), lightAt(3, 1.0f, 0.2f),
                                                lightAt(4, 5.0f, 2.0f)};
    ZBins bins;
    bins.build(lights, 0.5f, 10.0f, 16, ZBinSpacing::Uniform);
    EXPECT_EQ(sorted(bins), (std::vector<uint32_t>{3, 1, 0, 2, 4}));
    for (size_t i = 0; i < bins.sortedCount(); ++i)
        EXPECT_EQ(lights[bins.candidateOf(i)].index, bins.sortedLight(i));
}

TEST(ZBins, ALightSpanningManyBinsIsInEveryBinItOverlaps) {
    // Ten uniform bins of 1 m over [0, 10]; light 0 spans [0.5, 9.5], light 1 sits in bins 1-2.
    const std::vector<CandidateLight> lights = {lightAt(0, 5.0f, 4.5f), lightAt(1, 2.0f, 0.25f)};
    ZBins bins;
    bins.build(lights, 0.0f, 10.0f, 10, ZBinSpacing::Uniform);
    const uint32_t wide = positionOf(bins, 0), narrow = positionOf(bins, 1);
    for (int b = 0; b < 10; ++b) {
        EXPECT_TRUE(inRange(bins.range(b), wide)) << "bin " << b;
        EXPECT_EQ(inRange(bins.range(b), narrow), b == 1 || b == 2) << "bin " << b;
    }
    EXPECT_EQ(bins.binnedCount(), 2u);
}

TEST(ZBins, LightsAtTheSameDepthShareTheirBins) {
    std::vector<CandidateLight> lights;
    for (uint32_t i = 0; i < 40; ++i)
        lights.push_back(lightAt(i, 3.3f, 0.1f + 0.01f * float(i % 7)));
    lights.push_back(lightAt(40, 8.0f, 0.1f));
    ZBins bins;
    bins.build(lights, 1.0f, 9.0f, 32, ZBinSpacing::Exponential);
    // Ties keep the light order, and the bin of depth 3.3 holds all forty.
    for (uint32_t i = 0; i < 40; ++i)
        EXPECT_EQ(bins.sortedLight(i), i);
    const ZBins::Range r = bins.range(bins.binOfDepth(3.3f));
    EXPECT_EQ(r.first, 0u);
    EXPECT_EQ(r.last, 39u);
}

TEST(ZBins, LightsBehindTheCamera) {
    // Near 1 m, far 20 m: light 0 wholly behind the eye (extent [-4, -2]), light 1 around the
    // eye reaching 1.5 m in front, light 2 beyond the far depth, light 3 reaching back over it.
    const std::vector<CandidateLight> lights = {lightAt(0, -3.0f, 1.0f), lightAt(1, -0.5f, 2.0f),
                                                lightAt(2, 25.0f, 2.0f), lightAt(3, 22.0f, 2.5f)};
    ZBins bins;
    bins.build(lights, 1.0f, 20.0f, 19, ZBinSpacing::Uniform);
    EXPECT_EQ(bins.sortedCount(), 4u); // sorted, binned or not
    EXPECT_EQ(bins.binnedCount(), 2u);
    const uint32_t behind = positionOf(bins, 0), around = positionOf(bins, 1),
                   beyond = positionOf(bins, 2), reaching = positionOf(bins, 3);
    for (int b = 0; b < bins.binCount(); ++b) {
        EXPECT_FALSE(inRange(bins.range(b), behind)) << "bin " << b;
        EXPECT_FALSE(inRange(bins.range(b), beyond)) << "bin " << b;
        EXPECT_EQ(inRange(bins.range(b), around), b == 0) << "bin " << b;
        EXPECT_EQ(inRange(bins.range(b), reaching), b == bins.binCount() - 1) << "bin " << b;
    }
}

TEST(ZBins, EmptyBinsHaveEmptyRanges) {
    const std::vector<CandidateLight> lights = {lightAt(0, 1.2f, 0.1f), lightAt(1, 8.7f, 0.1f)};
    ZBins bins;
    bins.build(lights, 0.0f, 10.0f, 10, ZBinSpacing::Uniform);
    for (int b = 2; b <= 7; ++b)
        EXPECT_TRUE(bins.range(b).empty()) << "bin " << b;
    EXPECT_TRUE(bins.rangeOfBins(2, 7).empty());
    EXPECT_FALSE(bins.range(1).empty());
    EXPECT_FALSE(bins.range(8).empty());
    const ZBins::Range all = bins.rangeOfBins(0, 9);
    EXPECT_EQ(all.first, 0u);
    EXPECT_EQ(all.last, 1u);
    // No lights at all: every bin empty.
    ZBins none;
    none.build({}, 0.0f, 0.0f, 4, ZBinSpacing::Exponential);
    for (int b = 0; b < 4; ++b)
        EXPECT_TRUE(none.range(b).empty());
    EXPECT_EQ(none.sortedCount(), 0u);
}

TEST(ZBins, UnboundedLightsAreInNoBin) {
    std::vector<CandidateLight> lights = {lightAt(0, 3.0f, 1.0f), lightAt(1, 0.0f, 0.0f),
                                          lightAt(2, 4.0f, 1.0f)};
    lights[1].unbounded = true;
    ZBins bins;
    bins.build(lights, 1.0f, 6.0f, 8, ZBinSpacing::Uniform);
    EXPECT_EQ(sorted(bins), (std::vector<uint32_t>{0, 2}));
    EXPECT_EQ(std::vector<uint32_t>(bins.unboundedLights().begin(), bins.unboundedLights().end()),
              std::vector<uint32_t>{1});
}

TEST(ZBins, RejectsBadBinCountsAndDepthRanges) {
    ZBins bins;
    EXPECT_THROW(bins.build({}, 1.0f, 2.0f, 0, ZBinSpacing::Uniform), std::invalid_argument);
    EXPECT_THROW(bins.build({}, 1.0f, 2.0f, lighting::kMaxZBinCount + 1, ZBinSpacing::Uniform),
                 std::invalid_argument);
    EXPECT_THROW(bins.build({}, 2.0f, 1.0f, 4, ZBinSpacing::Uniform), std::invalid_argument);
    EXPECT_THROW(bins.build({}, NAN, 1.0f, 4, ZBinSpacing::Uniform), std::invalid_argument);
}

// Random lights of every size, some behind the camera or beyond the far depth.
std::vector<CandidateLight> randomLights(std::mt19937& random, int count, float farDepth) {
    std::uniform_real_distribution<float> depth(-2.0f, farDepth * 1.2f), small(0.01f, 0.5f),
        large(0.5f, farDepth);
    std::bernoulli_distribution isLarge(0.05);
    std::vector<CandidateLight> lights;
    for (int i = 0; i < count; ++i)
        lights.push_back(
            lightAt(uint32_t(i), depth(random), isLarge(random) ? large(random) : small(random)));
    return lights;
}

TEST(ZBins, EveryLightWhoseExtentHoldsADepthIsInItsBinsRange) {
    for (const ZBinSpacing spacing : {ZBinSpacing::Uniform, ZBinSpacing::Exponential})
        for (const int binCount : {1, 7, 64, 1000}) {
            std::mt19937 random(11 + binCount);
            const float nearDepth = 0.7f, farDepth = 30.0f;
            const std::vector<CandidateLight> lights = randomLights(random, 600, farDepth);
            ZBins bins;
            bins.build(lights, nearDepth, farDepth, binCount, spacing);
            // Depths inside [near, far], the boundaries themselves and their float neighbours.
            std::vector<float> depths;
            std::uniform_real_distribution<float> anywhere(nearDepth, farDepth);
            for (int i = 0; i < 400; ++i)
                depths.push_back(anywhere(random));
            for (int k = 0; k <= binCount; ++k)
                for (float d : {bins.boundary(k), std::nextafter(bins.boundary(k), 0.0f),
                                std::nextafter(bins.boundary(k), INFINITY)})
                    if (d >= nearDepth && d <= farDepth)
                        depths.push_back(d);
            int misses = 0;
            for (float d : depths) {
                const ZBins::Range r = bins.range(bins.binOfDepth(d));
                for (size_t i = 0; i < bins.sortedCount(); ++i) {
                    const CandidateLight& c = lights[bins.candidateOf(i)];
                    const float centreDepth = -c.centreView.z;
                    // The tile depth test's own expressions.
                    if (centreDepth - c.radius <= d && d <= centreDepth + c.radius &&
                        !inRange(r, uint32_t(i)) && misses++ < 5)
                        ADD_FAILURE()
                            << "light " << c.index << " holds depth " << d << " but is outside bin "
                            << bins.binOfDepth(d) << "'s range (" << binCount << " bins)";
                }
            }
            EXPECT_EQ(misses, 0);
            // Tight ends: each non-empty range begins and ends with a light overlapping the bin.
            for (int b = 0; b < binCount; ++b) {
                const ZBins::Range r = bins.range(b);
                if (r.empty())
                    continue;
                for (uint32_t end : {r.first, r.last}) {
                    const CandidateLight& c = lights[bins.candidateOf(end)];
                    const float centreDepth = -c.centreView.z;
                    EXPECT_LE(bins.binOfDepth(centreDepth - c.radius), b);
                    EXPECT_GE(bins.binOfDepth(centreDepth + c.radius), b);
                }
            }
        }
}

TEST(ZBins, BinOfDepthIsMonotoneAndFollowsTheBoundaries) {
    for (const ZBinSpacing spacing : {ZBinSpacing::Uniform, ZBinSpacing::Exponential}) {
        ZBins bins;
        bins.build({}, 0.25f, 80.0f, 37, spacing);
        EXPECT_EQ(bins.boundary(0), 0.25f);
        EXPECT_EQ(bins.boundary(37), 80.0f);
        for (int k = 0; k < 37; ++k) {
            EXPECT_LE(bins.boundary(k), bins.boundary(k + 1));
            EXPECT_EQ(bins.binOfDepth(bins.boundary(k)), k);
            if (k > 0)
                EXPECT_EQ(bins.binOfDepth(std::nextafter(bins.boundary(k), 0.0f)), k - 1);
        }
        // Geometric bins: equal ratios.
        if (spacing == ZBinSpacing::Exponential) {
            EXPECT_NEAR(bins.boundary(1) / bins.boundary(0), bins.boundary(37) / bins.boundary(36),
                        1e-4);
        } else {
            EXPECT_NEAR(bins.boundary(1) - bins.boundary(0), bins.boundary(37) - bins.boundary(36),
                        1e-4);
        }
        EXPECT_EQ(bins.binOfDepth(-5.0f), 0);
        EXPECT_EQ(bins.binOfDepth(1e6f), 36);
        int previous = 0;
        for (float d = -1.0f; d < 90.0f; d += 0.01f) {
            const int bin = bins.binOfDepth(d);
            EXPECT_GE(bin, previous);
            previous = bin;
        }
    }
}

TEST(ZBins, RangeOfBinsIsTheHullOfTheRanges) {
    std::mt19937 random(7);
    for (const int binCount : {1, 2, 5, 37, 64, 100}) {
        ZBins bins;
        bins.build(randomLights(random, 200, 20.0f), 0.5f, 20.0f, binCount, ZBinSpacing::Uniform);
        for (int a = 0; a < binCount; ++a)
            for (int b = a; b < binCount; ++b) {
                ZBins::Range expected;
                for (int k = a; k <= b; ++k) {
                    expected.first = std::min(expected.first, bins.range(k).first);
                    expected.last = std::max(expected.last, bins.range(k).last);
                }
                const ZBins::Range got = bins.rangeOfBins(a, b);
                ASSERT_EQ(got.first, expected.first) << binCount << " bins, " << a << ".." << b;
                ASSERT_EQ(got.last, expected.last) << binCount << " bins, " << a << ".." << b;
            }
    }
}

// A small frame for the masks: a camera at the origin, 200x120 pixels, tiles of 16 (a partial
// last column and row), random depth bounds per tile (some tiles uncovered).
struct MaskFrame {
    gbuffer::CameraView view;
    lighting::TileGrid grid;
    lighting::TileEdgePlanes edges;
    std::vector<lighting::TileSurfaceBounds> bounds;
    std::vector<lighting::CandidateLight> candidates;
    float nearDepth = INFINITY, farDepth = -INFINITY;

    explicit MaskFrame(int lightCount, uint32_t seed) {
        scenes::Camera camera;
        camera.verticalFovRadians = 1.0f;
        camera.nearMetres = 0.1f;
        camera.farMetres = 50.0f;
        view = gbuffer::CameraView::fromCamera(camera, 200, 120);
        grid = lighting::TileGrid::make(200, 120, 16);
        edges = lighting::TileEdgePlanes::make(view, grid);
        std::mt19937 random(seed);
        std::uniform_real_distribution<float> depth(1.0f, 30.0f), span(0.0f, 6.0f);
        std::bernoulli_distribution covered(0.85);
        bounds.resize(size_t(grid.tileCount()));
        for (lighting::TileSurfaceBounds& b : bounds) {
            if (!covered(random))
                continue;
            b.covered = true;
            b.minDepthMetres = depth(random);
            b.maxDepthMetres = b.minDepthMetres + span(random);
            nearDepth = std::min(nearDepth, b.minDepthMetres);
            farDepth = std::max(farDepth, b.maxDepthMetres);
        }
        // Lights in and around the view frustum, of every size, one unbounded.
        std::vector<lighting::LightSphere> spheres;
        std::uniform_real_distribution<float> lateral(-1.0f, 1.0f), lightDepth(-1.0f, 40.0f),
            radius(0.05f, 3.0f);
        for (int i = 0; i < lightCount; ++i) {
            lighting::LightSphere s;
            const float d = lightDepth(random);
            s.centreView = glm::vec3(lateral(random) * (std::abs(d) + 1.0f),
                                     0.6f * lateral(random) * (std::abs(d) + 1.0f), -d);
            s.positionView = s.centreView;
            s.radius = i % 50 == 0 ? 10.0f * radius(random) : radius(random);
            s.unbounded = i == 3;
            spheres.push_back(s);
        }
        candidates = lighting::candidateLights(view, grid, edges, spheres, true);
    }
};

TEST(ZBinTileMasks, BitsAreTheTileTestAndTheWalkVisitsExactlyThem) {
    for (const int binCount : {1, 16, 512}) {
        const MaskFrame f(700, 21u + uint32_t(binCount));
        ZBins bins;
        bins.build(f.candidates, f.nearDepth, f.farDepth, binCount, ZBinSpacing::Uniform);
        lighting::ZBinTileMasks masks;
        masks.build(f.grid, f.edges, f.bounds, f.candidates, bins);
        ASSERT_EQ(masks.tileCount(), size_t(f.grid.tileCount()));
        uint64_t expectedBits = 0;
        int failures = 0;
        for (int tile = 0; tile < f.grid.tileCount(); ++tile) {
            const lighting::TileSurfaceBounds& b = f.bounds[size_t(tile)];
            const int tx = tile % f.grid.tileCountX, ty = tile / f.grid.tileCountX;
            // The tile test for every sorted light (the brute-force masks).
            std::vector<bool> expected(bins.sortedCount(), false);
            if (b.covered) {
                const lighting::TileBox box =
                    lighting::tileBox(f.edges, f.grid, tx, ty, b.minDepthMetres, b.maxDepthMetres);
                for (size_t i = 0; i < bins.sortedCount(); ++i)
                    expected[i] = lighting::boundedCandidateTouchesTile(
                        f.candidates[bins.candidateOf(i)], tx, ty, b, box);
            } else {
                EXPECT_TRUE(masks.words(size_t(tile)).empty()) << "uncovered tile " << tile;
            }
            expectedBits += uint64_t(std::count(expected.begin(), expected.end(), true));
            // The walk over every bin's range and over ranges cut at arbitrary positions (word
            // edges inside, first and last words partial): exactly the expected bits inside.
            std::vector<std::pair<uint32_t, uint32_t>> ranges;
            for (int k = 0; k < binCount; ++k)
                if (!bins.range(k).empty())
                    ranges.emplace_back(bins.range(k).first, bins.range(k).last);
            const uint32_t n = uint32_t(bins.sortedCount());
            for (uint32_t a : {0u, 1u, 31u, 32u, 33u, 63u, 95u, n / 3})
                for (uint32_t z : {a, a + 1, a + 31, a + 32, a + 64, a + 100, n - 1})
                    if (a <= z && z < n)
                        ranges.emplace_back(a, z);
            for (const auto& [first, last] : ranges) {
                std::vector<uint32_t> visited;
                masks.forEachSetBit(size_t(tile), first, last,
                                    [&](uint32_t position) { visited.push_back(position); });
                std::vector<uint32_t> want;
                for (uint32_t i = first; i <= last; ++i)
                    if (expected[i])
                        want.push_back(i);
                if (visited != want && failures++ < 5)
                    ADD_FAILURE() << "tile " << tile << " range [" << first << ", " << last
                                  << "]: walked " << visited.size() << " lights, expected "
                                  << want.size() << " (" << binCount << " bins)";
            }
        }
        EXPECT_EQ(failures, 0);
        EXPECT_EQ(masks.bitCount(), expectedBits);
        EXPECT_GT(expectedBits, 100u) << "the frame tests nothing";
        // Windows: never more words than the whole sorted order per covered tile.
        EXPECT_LE(masks.wordCount(), size_t(f.grid.tileCount()) * ((bins.sortedCount() + 31) / 32));
    }
}

TEST(ZBinTileMasks, ABitOutsideItsTilesWindowIsAnError) {
    // Bins that end before a tile's depth range: a light that passes the tile's depth test is in
    // no bin of the tile, so its bit would fall outside the window.
    const MaskFrame f(300, 5u);
    ZBins bins;
    bins.build(f.candidates, f.nearDepth, 0.5f * (f.nearDepth + f.farDepth), 64,
               ZBinSpacing::Uniform);
    lighting::ZBinTileMasks masks;
    EXPECT_THROW(masks.build(f.grid, f.edges, f.bounds, f.candidates, bins), std::logic_error);
}

TEST(ZBins, IndependentOfTheThreadCount) {
    const MaskFrame f(20000, 9u);
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 7);
    ZBins bins[2];
    lighting::ZBinTileMasks masks[2];
    const int threads[2] = {1, 7};
    for (int k = 0; k < 2; ++k)
        tbb::task_arena(threads[k]).execute([&] {
            bins[k].build(f.candidates, f.nearDepth, f.farDepth, 300, ZBinSpacing::Exponential);
            masks[k].build(f.grid, f.edges, f.bounds, f.candidates, bins[k]);
        });
    EXPECT_EQ(sorted(bins[0]), sorted(bins[1]));
    for (int b = 0; b < 300; ++b) {
        EXPECT_EQ(bins[0].range(b).first, bins[1].range(b).first);
        EXPECT_EQ(bins[0].range(b).last, bins[1].range(b).last);
    }
    EXPECT_EQ(masks[0].bitCount(), masks[1].bitCount());
    for (size_t tile = 0; tile < masks[0].tileCount(); ++tile) {
        EXPECT_EQ(masks[0].firstWord(tile), masks[1].firstWord(tile));
        const auto a = masks[0].words(tile), b = masks[1].words(tile);
        EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "tile " << tile;
    }
}

} // namespace
