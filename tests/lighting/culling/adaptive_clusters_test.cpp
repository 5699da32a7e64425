// AdaptiveClusterGrid (culling/AdaptiveClusterGrid.h) alone: a brute-force assignment oracle
// (dense points of every stored cluster's piece of its tile's frustum, between its slice's and its
// tile's depth bounds; any point inside a sphere forces that light into the cluster's list) on
// random light sets mixing tiny, ordinary and huge lights with hard cases; lists independent of
// the thread count; every sample's slice inside its tile's stored range; the size choice follows
// the lights and the cluster budget holds. The stage (`clustered:grid=adaptive`) against brute and
// the oracle is in tests/lighting/stages/clustered_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferPass.h"
#include "lighting/PreparedScene.h"
#include "lighting/culling/AdaptiveClusterGrid.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using lighting::AdaptiveClusterGrid;
using lighting::LightSphere;

gbuffer::CameraView testView() {
    scenes::Camera camera;
    camera.verticalFovRadians = 0.9f;
    camera.nearMetres = 0.1f;
    camera.farMetres = 50.0f;
    return gbuffer::CameraView::fromCamera(camera, 320, 180);
}

// Tile depth ranges: a floor-like ramp with steps, some empty tiles and some spanning everything.
std::vector<float> tileDepths(int tilePixels, uint32_t seed) {
    const gbuffer::CameraView view = testView();
    const int tilesX = (view.width + tilePixels - 1) / tilePixels;
    const int tilesY = (view.height + tilePixels - 1) / tilePixels;
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> depths;
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            const float u = unit(random);
            float lo = 0.5f + 20.0f * float(tilesY - ty) / tilesY * (0.8f + 0.4f * unit(random));
            float hi = lo * (1.0f + 0.3f * unit(random));
            if (u < 0.1f) { // empty tile (background)
                lo = 1.0f;
                hi = 0.0f;
            } else if (u < 0.15f) { // depth edge: the whole range
                lo = 0.5f;
                hi = 25.0f;
            }
            depths.push_back(std::clamp(lo, 0.5f, 25.0f));
            depths.push_back(u < 0.1f ? 0.0f : std::clamp(hi, lo, 25.0f));
        }
    return depths;
}

std::vector<LightSphere> mixedSpheres(int count, uint32_t seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<LightSphere> spheres;
    for (int i = 0; i < count; ++i) {
        LightSphere s;
        const float d = -2.0f + 30.0f * unit(random);
        s.centreView = glm::vec3((unit(random) - 0.5f) * 1.6f * std::abs(d) + (unit(random) - 0.5f),
                                 (unit(random) - 0.5f) * 0.9f * std::abs(d), -d);
        const int kind = i % 4; // tiny, small, ordinary, huge
        s.radius = kind == 0   ? 1e-3f * unit(random)
                   : kind == 1 ? 0.05f * unit(random)
                   : kind == 2 ? 0.1f + 2.0f * unit(random)
                               : 5.0f + 40.0f * unit(random);
        s.positionView = s.centreView;
        spheres.push_back(s);
    }
    // Hard cases: camera inside, crossing the near plane, behind, covering all, unbounded, radius
    // 0.
    auto add = [&](glm::vec3 c, float r, bool unbounded = false) {
        LightSphere s;
        s.centreView = c;
        s.positionView = c;
        s.radius = r;
        s.unbounded = unbounded;
        spheres.push_back(s);
    };
    add({0.0f, 0.0f, 0.0f}, 1.0f);
    add({0.2f, -0.1f, -0.5f}, 0.3f);
    add({0.0f, 0.0f, 5.0f}, 1.0f);
    add({0.0f, 0.0f, -5.0f}, 1e4f);
    add({0.0f, 0.0f, 0.0f}, 0.0f, true);
    add({1.0f, 0.5f, -10.0f}, 0.0f);
    return spheres;
}

bool listed(const AdaptiveClusterGrid& grid, size_t cluster, uint32_t light) {
    const auto list = grid.lightsOf(cluster);
    return std::binary_search(list.begin(), list.end(), light);
}

// The oracle: dense points of each stored cluster's region (the tile's frustum between
// max(slice near, tile near) and min(slice far, tile far)).
void expectSuperset(const AdaptiveClusterGrid& grid, const std::vector<LightSphere>& spheres,
                    const std::string& what) {
    constexpr int kSamples = 5;
    int failures = 0;
    size_t clustersSeen = 0;
    for (int ty = 0; ty < grid.tilesY(); ++ty)
        for (int tx = 0; tx < grid.tilesX(); ++tx)
            for (int k = grid.tileFirstSlice(tx, ty); k <= grid.tileLastSlice(tx, ty); ++k) {
                ++clustersSeen;
                const size_t cluster = grid.clusterIndex(tx, ty, k);
                const auto list = grid.lightsOf(cluster);
                EXPECT_TRUE(std::is_sorted(list.begin(), list.end())) << what;
                EXPECT_TRUE(std::adjacent_find(list.begin(), list.end()) == list.end()) << what;
                const lighting::ViewBox box = grid.clusterBox(tx, ty, k);
                const float nearD = std::max(grid.sliceDepth(k), grid.tileDepthLo(tx, ty)),
                            farD = std::min(grid.sliceDepth(k + 1), grid.tileDepthHi(tx, ty));
                for (uint32_t light = 0; light < spheres.size(); ++light) {
                    const LightSphere& s = spheres[light];
                    bool touches = s.unbounded;
                    for (int a = 0; a < kSamples && !touches; ++a)
                        for (int b = 0; b < kSamples && !touches; ++b)
                            for (int c = 0; c < kSamples && !touches; ++c) {
                                const float u = float(a) / (kSamples - 1),
                                            v = float(b) / (kSamples - 1),
                                            w = float(c) / (kSamples - 1);
                                const float d = nearD + w * (farD - nearD);
                                const float tanX = grid.edgeTanX(tx) +
                                                   u * (grid.edgeTanX(tx + 1) - grid.edgeTanX(tx));
                                const float tanDown =
                                    grid.edgeTanDownY(ty) +
                                    v * (grid.edgeTanDownY(ty + 1) - grid.edgeTanDownY(ty));
                                const glm::vec3 p(tanX * d, -tanDown * d, -d);
                                touches = glm::length(p - s.centreView) <= s.radius;
                            }
                    if (touches && !listed(grid, cluster, light) && failures++ < 5)
                        ADD_FAILURE()
                            << what << ": light " << light << " (centre " << s.centreView.x << ", "
                            << s.centreView.y << ", " << s.centreView.z << " radius " << s.radius
                            << ") missing from cluster " << tx << "," << ty << "," << k;
                    // Every listed bounded light touches the cluster's box.
                    if (!s.unbounded && listed(grid, cluster, light)) {
                        const glm::vec3 q = glm::clamp(s.centreView, box.lo, box.hi);
                        EXPECT_LE(glm::length(q - s.centreView), s.radius * 1.0001f + 1e-5f)
                            << what;
                    }
                }
            }
    EXPECT_EQ(clustersSeen, grid.clusterCount()) << what;
    EXPECT_EQ(failures, 0) << what;
}

TEST(AdaptiveClusterGrid, AssignmentIsASupersetOfTouchedClusters) {
    const gbuffer::CameraView view = testView();
    for (int tilePixels : {4, 16, 64, 256})
        for (int slices : {1, 7, 64, 1000}) {
            if (tilePixels == 4 && slices == 1000)
                continue; // the oracle's cost, not a different case
            const std::string what =
                "tile " + std::to_string(tilePixels) + " slices " + std::to_string(slices);
            AdaptiveClusterGrid grid;
            grid.buildFixed(view, tilePixels, slices, 0.5f, 25.0f, tileDepths(tilePixels, 3));
            const std::vector<LightSphere> spheres =
                mixedSpheres(tilePixels == 4 ? 24 : 80, uint32_t(tilePixels + slices));
            grid.assign(spheres);
            expectSuperset(grid, spheres, what);
            // The huge light covering everything and the unbounded one are in every cluster; the
            // one wholly behind the camera in none.
            const uint32_t base = uint32_t(spheres.size() - 6);
            for (size_t c = 0; c < grid.clusterCount(); ++c) {
                EXPECT_TRUE(listed(grid, c, base + 3)) << what;
                EXPECT_TRUE(listed(grid, c, base + 4)) << what;
                EXPECT_FALSE(listed(grid, c, base + 2)) << what;
            }
        }
}

TEST(AdaptiveClusterGrid, ListsIndependentOfThreadCount) {
    const gbuffer::CameraView view = testView();
    AdaptiveClusterGrid one, many;
    one.buildFixed(view, 8, 64, 0.5f, 25.0f, tileDepths(8, 5));
    many.buildFixed(view, 8, 64, 0.5f, 25.0f, tileDepths(8, 5));
    const std::vector<LightSphere> spheres = mixedSpheres(3000, 9);
    tbb::task_arena(1).execute([&] { one.assign(spheres); });
    tbb::task_arena(2).execute([&] { many.assign(spheres); });
    ASSERT_EQ(one.clusterCount(), many.clusterCount());
    ASSERT_EQ(one.pairCount(), many.pairCount());
    ASSERT_GT(one.pairCount(), 0u);
    for (size_t c = 0; c <= one.clusterCount(); ++c) {
        const auto a = one.lightsOf(c), b = many.lightsOf(c);
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << c;
    }
}

// On a real G-buffer: every covered pixel's slice (from its decoded position, as shading finds
// it) lies in its tile's stored range, so clusterIndex never clamps a sample; the size follows
// the lights (constant-overlap lights shrink with the count: smaller clusters); the budget holds.
TEST(AdaptiveClusterGrid, SamplesLieInStoredClustersAndSizeFollowsLights) {
    int previousTile = 1 << 20, previousSlices = 0;
    for (int lightCount : {100, 10000}) {
        scenes::SceneRequest request;
        request.lightCount = lightCount;
        request.seed = 5;
        request.lightDensity = scenes::LightDensity::ConstantOverlap;
        const lighting::PreparedScene prepared(scenes::buildProceduralScene("atrium", request), 320,
                                               180);
        const gbuffer::GBuffer& gb = *prepared.inputs.gbuffer;
        const std::vector<LightSphere> spheres =
            lighting::boundingSpheresView(*prepared.inputs.lights);
        AdaptiveClusterGrid grid;
        ASSERT_TRUE(grid.build({}, gb, spheres));
        int failures = 0;
        for (int y = 0; y < gb.height(); ++y)
            for (int x = 0; x < gb.width(); ++x) {
                const float ndc = gb.depth()[size_t(y) * gb.width() + x];
                if (ndc == gb.view().clearDepth())
                    continue;
                const float depth = -gb.depthDecoder().positionView(x, y, ndc).z;
                const int tx = grid.tileXOfPixel(x), ty = grid.tileYOfPixel(y);
                const int k = grid.sliceOfDepth(depth);
                if ((k < grid.tileFirstSlice(tx, ty) || k > grid.tileLastSlice(tx, ty)) &&
                    failures++ < 3)
                    ADD_FAILURE() << "pixel " << x << "," << y << " slice " << k
                                  << " outside its tile's stored slices";
            }
        EXPECT_EQ(failures, 0);
        EXPECT_LE(grid.tilePixels(), previousTile) << lightCount;
        EXPECT_GE(grid.slices(), previousSlices) << lightCount;
        EXPECT_TRUE(grid.tilePixels() < previousTile || grid.slices() > previousSlices)
            << lightCount;
        previousTile = grid.tilePixels();
        previousSlices = grid.slices();

        lighting::AdaptiveClusterOptions small;
        small.maxClusters = 500;
        AdaptiveClusterGrid bounded;
        ASSERT_TRUE(bounded.build(small, gb, spheres));
        EXPECT_LE(bounded.clusterCount(), 500u);
        EXPECT_GT(bounded.clusterCount(), 0u);
    }
}

} // namespace
