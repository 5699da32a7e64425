// The `zbinned` stage (lighting/stages/ZBinnedStage.cpp, lighting/culling/ZBins.h) at 10^2 and
// 10^4 lights on atrium and on wall (with lights behind it), with the fixed-radius and the
// constant-overlap generator: bitwise `brute`'s image on the same ISA, every contributing light
// among each pixel's evaluated lights (light identity, tests/lighting/LightIdentity.h), and each
// pixel's evaluated lights exactly its candidates by definition (its tile's mask bits inside its
// bin's range, or with the default lists=packet the hull of its packet's bins in its tile, plus
// the unbounded lights, ascending), from bins and masks rebuilt here; option
// variants (tile sizes that split packets, one bin, many bins, geometric bins); bitwise the same
// on 1, 2 and 7 threads at 10^4 lights; passes and parameters.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/culling/ZBins.h"
#include "lighting/lists/ContributingLights.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 96;

struct Case {
    std::string scene;
    int lights;
    scenes::LightDensity density;
};

std::string label(const Case& c) {
    return c.scene + "_" + std::to_string(c.lights) +
           (c.density == scenes::LightDensity::FixedRadius ? "_fixed" : "_overlap");
}

// A prepared frame, brute's image and the contributing lights of every pixel.
struct Frame {
    std::unique_ptr<lighting::PreparedScene> prepared;
    lighting::StageResult brute;
    lighting::ContributingLights contributing;
};

const Frame& frame(const Case& c) {
    static std::map<std::string, std::unique_ptr<Frame>> cache;
    auto& slot = cache[label(c)];
    if (slot)
        return *slot;
    slot = std::make_unique<Frame>();
    scenes::SceneRequest request;
    request.lightCount = c.lights;
    request.seed = 7;
    request.lightDensity = c.density;
    if (c.scene == "wall")
        request.options = {{"behind", std::to_string(c.lights / 2)}};
    slot->prepared = std::make_unique<lighting::PreparedScene>(
        scenes::buildProceduralScene(c.scene, request), kWidth, kHeight);
    lighting::makeStage("brute")->shade(slot->prepared->inputs, slot->brute);
    slot->contributing.build(*slot->prepared->inputs.gbuffer,
                             slot->prepared->inputs.lights->lights);
    return *slot;
}

// Each pixel's candidates by the definition (the stage's assignment rebuilt here with its
// defaults or the given ones), ascending, plus the unbounded lights: with perPixel its tile's mask
// bits inside its own bin's range; otherwise, per 4x4 packet and tile, the bits inside the hull of
// the ranges of the bins from the nearest to the farthest of the packet's pixels in that tile.
std::vector<std::vector<uint32_t>> candidatesByDefinition(const lighting::StageInputs& inputs,
                                                          int tileSize, int binCount,
                                                          lighting::ZBinSpacing spacing,
                                                          bool perPixel) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    const lighting::TileGrid grid = lighting::TileGrid::make(gb.width(), gb.height(), tileSize);
    const std::vector<lighting::LightSphere> spheres =
        lighting::boundingSpheresView(*inputs.lights);
    const std::vector<lighting::TileSurfaceBounds> bounds =
        lighting::computeTileSurfaceBounds(gb, grid, {});
    const lighting::TileEdgePlanes edges = lighting::TileEdgePlanes::make(gb.view(), grid);
    const std::vector<lighting::CandidateLight> candidates =
        lighting::candidateLights(gb.view(), grid, edges, spheres, true);
    float nearDepth = INFINITY, farDepth = -INFINITY;
    for (const lighting::TileSurfaceBounds& b : bounds)
        if (b.covered) {
            nearDepth = std::min(nearDepth, b.minDepthMetres);
            farDepth = std::max(farDepth, b.maxDepthMetres);
        }
    lighting::ZBins bins;
    bins.build(candidates, nearDepth, farDepth, binCount, spacing);
    lighting::ZBinTileMasks masks;
    masks.build(grid, edges, bounds, candidates, bins);
    const int width = gb.width(), height = gb.height();
    auto tileOf = [&](int x, int y) {
        return size_t(y / tileSize) * size_t(grid.tileCountX) + size_t(x / tileSize);
    };
    auto binOf = [&](int x, int y) { return bins.binOfDepth(-gb.decode(x, y).positionView.z); };
    std::vector<std::vector<uint32_t>> lists(size_t(width) * size_t(height));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * size_t(width) + size_t(x);
            if (!gb.covered(pixel))
                continue;
            int lowBin = binOf(x, y), highBin = lowBin;
            if (!perPixel) // the packet's pixels in the same tile
                for (int py = y / 4 * 4; py < std::min(y / 4 * 4 + 4, height); ++py)
                    for (int px = x / 4 * 4; px < std::min(x / 4 * 4 + 4, width); ++px)
                        if (gb.covered(size_t(py) * size_t(width) + size_t(px)) &&
                            tileOf(px, py) == tileOf(x, y)) {
                            lowBin = std::min(lowBin, binOf(px, py));
                            highBin = std::max(highBin, binOf(px, py));
                        }
            const lighting::ZBins::Range r = bins.rangeOfBins(lowBin, highBin);
            std::vector<uint32_t>& list = lists[pixel];
            masks.forEachSetBit(tileOf(x, y), r.first, r.last, [&](uint32_t position) {
                list.push_back(bins.sortedLight(position));
            });
            list.insert(list.end(), bins.unboundedLights().begin(), bins.unboundedLights().end());
            std::sort(list.begin(), list.end());
        }
    return lists;
}

class ZBinnedExact : public ::testing::TestWithParam<Case> {};

TEST_P(ZBinnedExact, BitwiseBruteEveryContributingLightAndExactlyItsCandidates) {
    const Case& c = GetParam();
    const Frame& f = frame(c);
    for (const bool perPixel : {false, true}) {
        const std::string spec = perPixel ? "zbinned:lists=pixel" : "zbinned";
        const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(spec);
        const lighting::StageResult result = stagecheck::shadeTraced(*stage, f.prepared->inputs);
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(result, f.brute)) << label(c) << " " << spec;
        EXPECT_TRUE(stagecheck::everyContributingLightEvaluated(result, f.contributing, true))
            << label(c) << " " << spec;
        const std::vector<std::vector<uint32_t>> expected = candidatesByDefinition(
            f.prepared->inputs, 32, 1024, lighting::ZBinSpacing::Uniform, perPixel);
        int failures = 0;
        uint64_t evaluated = 0, contributing = 0;
        for (size_t pixel = 0; pixel < expected.size(); ++pixel) {
            evaluated += result.lightsEvaluated[pixel];
            contributing += f.contributing.lightsOf(pixel).size();
            if ((result.lightTrace[pixel] != expected[pixel] ||
                 result.lightsEvaluated[pixel] != expected[pixel].size()) &&
                failures++ < 5)
                ADD_FAILURE() << label(c) << " " << spec << ": pixel (" << pixel % kWidth << ", "
                              << pixel / kWidth << ") evaluated " << result.lightsEvaluated[pixel]
                              << " lights, " << expected[pixel].size()
                              << " candidates by definition";
        }
        EXPECT_EQ(failures, 0);
        EXPECT_GT(contributing, 0u) << label(c) << ": no light reaches the frame";
        RecordProperty(
            perPixel ? "culling_efficiency_pixel" : "culling_efficiency_packet",
            std::to_string(double(contributing) / double(std::max<uint64_t>(evaluated, 1))));
    }
}

INSTANTIATE_TEST_SUITE_P(
    AtriumAndWall, ZBinnedExact,
    ::testing::Values(Case{"atrium", 100, scenes::LightDensity::FixedRadius},
                      Case{"atrium", 10000, scenes::LightDensity::FixedRadius},
                      Case{"atrium", 100, scenes::LightDensity::ConstantOverlap},
                      Case{"atrium", 10000, scenes::LightDensity::ConstantOverlap},
                      Case{"wall", 100, scenes::LightDensity::FixedRadius},
                      Case{"wall", 10000, scenes::LightDensity::FixedRadius},
                      Case{"wall", 100, scenes::LightDensity::ConstantOverlap},
                      Case{"wall", 10000, scenes::LightDensity::ConstantOverlap}),
    [](const auto& info) { return label(info.param); });

// Tiles that are no multiple of 4 (packets across tiles), tiny and huge tiles, one bin (the
// ranges are the tiles' whole windows), many bins (packets across bins), both list modes,
// geometric bins: the same image, every contributing light, exactly the candidates.
TEST(ZBinnedStage, EveryOptionVariantIsExact) {
    const Case c{"atrium", 2000, scenes::LightDensity::FixedRadius};
    const Frame& f = frame(c);
    struct Variant {
        const char* spec;
        int tile, bins;
        lighting::ZBinSpacing spacing;
        bool perPixel;
    };
    const Variant variants[] = {
        {"zbinned:tile=13,bins=300", 13, 300, lighting::ZBinSpacing::Uniform, false},
        {"zbinned:tile=13,bins=300,lists=pixel", 13, 300, lighting::ZBinSpacing::Uniform, true},
        {"zbinned:tile=4,bins=1", 4, 1, lighting::ZBinSpacing::Uniform, false},
        {"zbinned:tile=6,bins=1,lists=pixel", 6, 1, lighting::ZBinSpacing::Uniform, true},
        {"zbinned:tile=128,bins=65536,spacing=exp", 128, 65536, lighting::ZBinSpacing::Exponential,
         false},
        {"zbinned:tile=16,bins=64,spacing=exp,lists=pixel", 16, 64,
         lighting::ZBinSpacing::Exponential, true},
    };
    for (const Variant& v : variants) {
        const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(v.spec);
        const lighting::StageResult result = stagecheck::shadeTraced(*stage, f.prepared->inputs);
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(result, f.brute)) << v.spec;
        EXPECT_TRUE(stagecheck::everyContributingLightEvaluated(result, f.contributing, true))
            << v.spec;
        const auto expected =
            candidatesByDefinition(f.prepared->inputs, v.tile, v.bins, v.spacing, v.perPixel);
        int failures = 0;
        for (size_t pixel = 0; pixel < expected.size(); ++pixel)
            if (result.lightTrace[pixel] != expected[pixel] && failures++ < 3)
                ADD_FAILURE() << v.spec << ": pixel " << pixel << " evaluated "
                              << result.lightTrace[pixel].size() << " lights, "
                              << expected[pixel].size() << " by definition";
        EXPECT_EQ(failures, 0) << v.spec;
        EXPECT_EQ(result.parameters.at("tile"), std::to_string(v.tile));
        EXPECT_EQ(result.parameters.at("bins"), std::to_string(v.bins));
        EXPECT_EQ(result.parameters.at("spacing"),
                  v.spacing == lighting::ZBinSpacing::Uniform ? "uniform" : "exp");
        EXPECT_EQ(result.parameters.at("lists"), v.perPixel ? "pixel" : "packet");
    }
}

TEST(ZBinnedStage, BitwiseTheSameOn1And2And7Threads) {
    const Frame& f = frame({"atrium", 10000, scenes::LightDensity::ConstantOverlap});
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 7);
    const int threadCounts[] = {1, 2, 7};
    lighting::StageResult results[3];
    for (int i = 0; i < 3; ++i)
        tbb::task_arena(threadCounts[i]).execute([&] {
            lighting::makeStage("zbinned:tile=16")->shade(f.prepared->inputs, results[i]);
        });
    for (int i = 1; i < 3; ++i) {
        const std::string what = "1 vs " + std::to_string(threadCounts[i]) + " threads";
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(results[i], results[0])) << what;
        EXPECT_EQ(results[i].lightsEvaluated, results[0].lightsEvaluated) << what;
        for (const auto& [key, value] : results[0].parameters)
            EXPECT_EQ(results[i].parameters.at(key), value) << what << ", " << key;
    }
}

TEST(ZBinnedStage, RecordsItsPassesAndItsMemory) {
    const Frame& f = frame({"atrium", 10000, scenes::LightDensity::ConstantOverlap});
    const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage("zbinned");
    lighting::StageResult result;
    stage->shade(f.prepared->inputs, result);
    ASSERT_EQ(result.timingsMs.size(), 2u);
    EXPECT_EQ(result.timingsMs[0].first, "assign");
    EXPECT_EQ(result.timingsMs[1].first, "shading");
    const auto number = [&](const char* key) { return std::stod(result.parameters.at(key)); };
    const double afterVfc = number("lights_after_vfc");
    EXPECT_GT(afterVfc, 0.0);
    const lighting::LightList& lights = *f.prepared->inputs.lights;
    EXPECT_EQ(afterVfc + number("vfc_culled"), double(lights.size()));
    // The scene's directional and ambient lights: unbounded, never culled, in no bin.
    double unbounded = 0.0;
    for (const lighting::LightSphere& s : lighting::boundingSpheresView(lights))
        unbounded += s.unbounded ? 1.0 : 0.0;
    EXPECT_GT(unbounded, 0.0) << "atrium's own lights are no longer unbounded: test it elsewhere";
    EXPECT_LE(number("binned_lights"), afterVfc);
    EXPECT_GE(number("mask_bytes"), 4.0 * number("mask_words"));
    // The windows: at most the whole sorted order per tile (5 x 3 tiles of 32 at 160x96).
    EXPECT_LE(number("mask_words"), 15.0 * std::ceil(afterVfc / 32.0));
    EXPECT_GE(number("bin_bytes"), 8.0 * 1024);
    EXPECT_EQ(number("sorted_bytes"), 8.0 * (afterVfc - unbounded) + 4.0 * unbounded);
    EXPECT_GT(number("tile_light_pairs"), 0.0);
    EXPECT_LT(number("zbin_near_m"), number("zbin_far_m"));
    // Reused across frames: the same result again.
    lighting::StageResult again;
    stage->shade(f.prepared->inputs, again);
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(again, result));
    EXPECT_EQ(again.lightsEvaluated, result.lightsEvaluated);
}

} // namespace
