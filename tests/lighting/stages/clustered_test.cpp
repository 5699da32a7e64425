// The `clustered` stage and its ClusterGrid. Every option combination against `brute` and the
// oracle; walk and binary assignment give identical lists; a brute-force assignment oracle
// (dense points of every cluster's frustum piece that lie inside a sphere force the light into
// that cluster's list) on random and hard lights; thread-count independence; option parsing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferPass.h"
#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/ClusterGrid.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using lighting::ClusterGrid;
using lighting::ClusterGridOptions;
using lighting::LightSphere;

constexpr int kWidth = 160;
constexpr int kHeight = 96;

// A prepared frame plus its oracle and brute's image.
struct ClusterScene : lighting::PreparedScene {
    std::vector<uint32_t> oracle;
    lighting::StageResult brute;

    explicit ClusterScene(scenes::Scene scene)
        : lighting::PreparedScene(std::move(scene), kWidth, kHeight) {
        oracle = lighting::countContributingLights(inputs);
        lighting::makeStage("brute")->shade(inputs, brute);
    }
};

const ClusterScene& prepared(const std::string& sceneName, int lightCount) {
    static std::map<std::string, std::unique_ptr<ClusterScene>> cache;
    auto& slot = cache[sceneName + std::to_string(lightCount)];
    if (!slot) {
        scenes::SceneRequest request;
        request.lightCount = lightCount;
        request.seed = 5;
        slot = std::make_unique<ClusterScene>(scenes::buildProceduralScene(sceneName, request));
    }
    return *slot;
}

// Image within 1e-5 of peak of brute, and never fewer lights evaluated than contribute.
void expectExact(const ClusterScene& f, const lighting::StageResult& result,
                 const std::string& what) {
    float peak = 0.0f;
    for (int ch = 0; ch < 3; ++ch)
        for (float v : f.brute.radiance[ch])
            peak = std::max(peak, v);
    int failures = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        for (int ch = 0; ch < 3; ++ch)
            if (!(std::abs(result.radiance[ch][pixel] - f.brute.radiance[ch][pixel]) <=
                  1e-5f * peak) &&
                failures++ < 3)
                ADD_FAILURE() << what << ": pixel " << pixel << " differs from brute";
        if (result.lightsEvaluated[pixel] < f.oracle[pixel] && failures++ < 3)
            ADD_FAILURE() << what << ": pixel " << pixel << " evaluated "
                          << result.lightsEvaluated[pixel] << " < oracle " << f.oracle[pixel];
    }
    EXPECT_EQ(failures, 0) << what;
}

TEST(ClusteredStage, EveryOptionCombinationMatchesBrute) {
    for (const char* scene : {"spheres", "atrium"}) {
        const ClusterScene& f = prepared(scene, 120);
        for (const char* grid : {"1x1x1", "24x12x32", "64x32x64", "7x5x3"})
            for (const char* slices : {"exp", "uniform"})
                for (const char* test : {"aabb", "frustum"}) {
                    lighting::StageResult walk, binary;
                    const std::string base = std::string("clustered:grid=") + grid +
                                             ",slices=" + slices + ",test=" + test;
                    lighting::makeStage(base + ",assign=walk")->shade(f.inputs, walk);
                    lighting::makeStage(base + ",assign=binary")->shade(f.inputs, binary);
                    expectExact(f, walk, std::string(scene) + " " + base + ",assign=walk");
                    // Identical lists give bitwise identical images and counts.
                    for (int ch = 0; ch < 3; ++ch)
                        EXPECT_EQ(walk.radiance[ch], binary.radiance[ch]) << base;
                    EXPECT_EQ(walk.lightsEvaluated, binary.lightsEvaluated) << base;
                    EXPECT_EQ(walk.parameters.at("cluster_light_pairs"),
                              binary.parameters.at("cluster_light_pairs"));
                    EXPECT_EQ(walk.parameters.at("grid"), grid);
                    EXPECT_EQ(walk.parameters.at("slices"), slices);
                    EXPECT_EQ(walk.parameters.at("test"), test);
                    EXPECT_EQ(binary.parameters.at("assign"), "binary");
                }
    }
}

TEST(ClusteredStage, IndependentOfThreadCountAndRecordsPasses) {
    const ClusterScene& f = prepared("atrium", 120);
    lighting::StageResult one, many;
    tbb::task_arena(1).execute([&] { lighting::makeStage("clustered")->shade(f.inputs, one); });
    lighting::makeStage("clustered")->shade(f.inputs, many);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_EQ(one.radiance[ch], many.radiance[ch]);
    EXPECT_EQ(one.lightsEvaluated, many.lightsEvaluated);
    ASSERT_EQ(one.timingsMs.size(), 2u);
    EXPECT_EQ(one.timingsMs[0].first, "assign");
    EXPECT_EQ(one.timingsMs[1].first, "shading");
    EXPECT_EQ(one.parameters.at("grid"), "24x12x32");
    EXPECT_EQ(one.parameters.at("slices"), "exp");
    EXPECT_EQ(one.parameters.at("assign"), "walk");
    EXPECT_EQ(one.parameters.at("test"), "aabb");
    EXPECT_GT(std::stoll(one.parameters.at("cluster_light_pairs")), 0);
}

TEST(ClusteredStage, ReusedAcrossFramesEqualsFresh) {
    const ClusterScene& atrium = prepared("atrium", 120);
    const ClusterScene& spheres = prepared("spheres", 120);
    auto reused = lighting::makeStage("clustered:grid=64x32x64");
    lighting::StageResult first, second, third, fresh;
    reused->shade(atrium.inputs, first);
    reused->shade(spheres.inputs, second);
    reused->shade(atrium.inputs, third);
    lighting::makeStage("clustered:grid=64x32x64")->shade(spheres.inputs, fresh);
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_EQ(first.radiance[ch], third.radiance[ch]);
        EXPECT_EQ(second.radiance[ch], fresh.radiance[ch]);
    }
    EXPECT_EQ(first.lightsEvaluated, third.lightsEvaluated);
    EXPECT_EQ(second.lightsEvaluated, fresh.lightsEvaluated);
    expectExact(spheres, second, "reused stage on spheres");
}

// grid=adaptive: exact against brute and the oracle over cluster densities, a budget that forces
// coarsening, and constant-overlap lights (small, many) where the grid is finest.
TEST(ClusteredStage, AdaptiveGridMatchesBrute) {
    for (const char* scene : {"spheres", "atrium"}) {
        const ClusterScene& f = prepared(scene, 120);
        for (const char* options : {"cells=0.5", "cells=2", "cells=8", "cells=4,max_clusters=50"}) {
            lighting::StageResult result;
            const std::string spec = std::string("clustered:grid=adaptive,") + options;
            lighting::makeStage(spec)->shade(f.inputs, result);
            expectExact(f, result, std::string(scene) + " " + spec);
            EXPECT_EQ(result.parameters.at("grid"), "adaptive");
            EXPECT_GT(std::stoll(result.parameters.at("clusters")), 0);
            if (std::string(options).find("max_clusters=50") != std::string::npos)
                EXPECT_LE(std::stoll(result.parameters.at("clusters")), 50);
        }
    }
    scenes::SceneRequest request;
    request.lightCount = 3000;
    request.seed = 7;
    request.lightDensity = scenes::LightDensity::ConstantOverlap;
    const ClusterScene dense(scenes::buildProceduralScene("atrium", request));
    lighting::StageResult result;
    lighting::makeStage("clustered:grid=adaptive")->shade(dense.inputs, result);
    expectExact(dense, result, "atrium, 3000 constant-overlap lights, grid=adaptive");
}

TEST(ClusteredStage, AdaptiveGridIndependentOfThreadCount) {
    const ClusterScene& f = prepared("atrium", 120);
    lighting::StageResult one, two;
    tbb::task_arena(1).execute(
        [&] { lighting::makeStage("clustered:grid=adaptive,cells=4")->shade(f.inputs, one); });
    tbb::task_arena(2).execute(
        [&] { lighting::makeStage("clustered:grid=adaptive,cells=4")->shade(f.inputs, two); });
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_EQ(one.radiance[ch], two.radiance[ch]);
    EXPECT_EQ(one.lightsEvaluated, two.lightsEvaluated);
    EXPECT_EQ(one.parameters.at("cluster_light_pairs"), two.parameters.at("cluster_light_pairs"));
    EXPECT_EQ(one.parameters.at("adaptive_grid"), two.parameters.at("adaptive_grid"));
}

TEST(ClusteredStage, RejectsBadOptions) {
    for (const char* bad : {"clustered:grid=24x12",
                            "clustered:grid=0x12x32",
                            "clustered:grid=24x12x0",
                            "clustered:grid=100000x1x1",
                            "clustered:grid=1024x1024x1024",
                            "clustered:grid=24x12x32x",
                            "clustered:grid=abc",
                            "clustered:grid=",
                            "clustered:grid=-1x2x3",
                            "clustered:grid=24X12X32",
                            "clustered:slices=log",
                            "clustered:assign=octree",
                            "clustered:test=sphere",
                            "clustered:tiles=16",
                            "clustered:grid=adaptive,test=frustum",
                            "clustered:grid=adaptive,assign=bvh",
                            "clustered:grid=adaptive,slices=uniform",
                            "clustered:cells=3",
                            "clustered:grid=24x12x32,max_clusters=100",
                            "clustered:grid=adaptive,cells=0",
                            "clustered:grid=adaptive,max_clusters=0",
                            "clustered:grid=Adaptive"})
        EXPECT_THROW(lighting::makeStage(bad), lighting::StageError) << bad;
    EXPECT_NO_THROW(
        lighting::makeStage("clustered:grid=1x1x1,slices=uniform,assign=binary,test=frustum"));
    EXPECT_NO_THROW(lighting::makeStage("clustered:grid=64x32x64"));
    EXPECT_NO_THROW(lighting::makeStage("clustered:assign=bvh"));
    EXPECT_NO_THROW(lighting::makeStage("clustered:grid=adaptive,cells=3,max_clusters=1000"));
    // An option of the other grid kind at its default value changes nothing: accepted.
    EXPECT_NO_THROW(lighting::makeStage("clustered:grid=adaptive,test=aabb"));
    EXPECT_NO_THROW(lighting::makeStage("clustered:cells=2"));
}

// ---- ClusterGrid alone ------------------------------------------------------------------------

gbuffer::CameraView testView() {
    scenes::Camera camera;
    camera.verticalFovRadians = 0.9f;
    camera.nearMetres = 0.1f;
    camera.farMetres = 50.0f;
    return gbuffer::CameraView::fromCamera(camera, 320, 180);
}

bool listed(const ClusterGrid& grid, size_t cluster, uint32_t light) {
    const auto list = grid.lightsOf(cluster);
    return std::binary_search(list.begin(), list.end(), light);
}

// Dense points of every cluster's frustum piece (corners, edges, faces, interior); any inside a
// sphere forces that light into the cluster's list. Lists must also be ascending.
void expectSuperset(const ClusterGrid& grid, const std::vector<LightSphere>& spheres,
                    const std::string& what) {
    const ClusterGridOptions& o = grid.options();
    constexpr int kSamples = 5;
    int failures = 0;
    for (int k = 0; k < o.slices; ++k)
        for (int ty = 0; ty < o.tilesY; ++ty)
            for (int tx = 0; tx < o.tilesX; ++tx) {
                const size_t cluster = grid.clusterIndex(tx, ty, k);
                const auto list = grid.lightsOf(cluster);
                EXPECT_TRUE(std::is_sorted(list.begin(), list.end()));
                EXPECT_TRUE(std::adjacent_find(list.begin(), list.end()) == list.end());
                for (uint32_t light = 0; light < spheres.size(); ++light) {
                    const LightSphere& s = spheres[light];
                    bool touches = s.unbounded;
                    for (int a = 0; a < kSamples && !touches; ++a)
                        for (int b = 0; b < kSamples && !touches; ++b)
                            for (int c = 0; c < kSamples && !touches; ++c) {
                                const float u = float(a) / (kSamples - 1),
                                            v = float(b) / (kSamples - 1),
                                            w = float(c) / (kSamples - 1);
                                const float d = grid.sliceDepth(k) +
                                                w * (grid.sliceDepth(k + 1) - grid.sliceDepth(k));
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
                    // With test=aabb every listed bounded light touches the cluster's AABB.
                    if (o.test == lighting::ClusterTest::Aabb && !s.unbounded &&
                        listed(grid, cluster, light)) {
                        const auto& box = grid.bounds(cluster);
                        const glm::vec3 q = glm::clamp(s.centreView, box.lo, box.hi);
                        EXPECT_LE(glm::length(q - s.centreView), s.radius * 1.0001f + 1e-5f)
                            << what;
                    }
                }
            }
    EXPECT_EQ(failures, 0) << what;
}

std::vector<LightSphere> randomSpheres(int count, uint32_t seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<LightSphere> spheres;
    for (int i = 0; i < count; ++i) {
        LightSphere s;
        const float d = -2.0f + 30.0f * unit(random);
        s.centreView = glm::vec3((unit(random) - 0.5f) * 1.6f * std::abs(d) + (unit(random) - 0.5f),
                                 (unit(random) - 0.5f) * 0.9f * std::abs(d), -d);
        s.radius = 0.05f + 3.0f * unit(random) * unit(random);
        spheres.push_back(s);
    }
    return spheres;
}

// Hard cases: centres on slice boundaries and tile planes, crossing the near plane, the camera
// inside, radius zero at a cluster corner, covering everything, behind the camera, unbounded.
std::vector<LightSphere> hardSpheres(const ClusterGrid& grid) {
    const ClusterGridOptions& o = grid.options();
    std::vector<LightSphere> s;
    auto add = [&](glm::vec3 c, float r, bool unbounded = false) {
        s.push_back({c, r, unbounded});
    };
    const int k = o.slices / 2, tx = o.tilesX / 2, ty = o.tilesY / 3;
    const float d = grid.sliceDepth(k);
    add({0.3f, 0.1f, -d}, 0.2f); // on a slice boundary
    add({grid.edgeTanX(tx) * 4.0f, -grid.edgeTanDownY(ty) * 4.0f, -4.0f}, 0.3f); // on tile planes
    add({grid.edgeTanX(tx) * d, -grid.edgeTanDownY(ty) * d, -d}, 0.0f); // radius 0 at a corner
    add({grid.edgeTanX(tx) * d, -grid.edgeTanDownY(ty) * d, -d}, 1e-6f);
    add({0.0f, 0.0f, -grid.sliceDepth(0)}, 0.5f);             // crossing the near plane
    add({0.0f, 0.0f, 0.0f}, 1.0f);                            // camera inside
    add({0.0f, 0.0f, -5.0f}, 1e4f);                           // covers everything
    add({0.0f, 0.0f, 5.0f}, 1.0f);                            // behind the camera
    add({2.0f, 1.0f, 3.0f}, 3.5f);                            // behind, reaching in
    add({0.0f, 0.0f, 0.0f}, 0.0f, true);                      // unbounded
    add({grid.edgeTanX(0) * 6.0f - 0.1f, 0.0f, -6.0f}, 0.2f); // on the left frustum side
    add({0.0f, 0.0f, -grid.sliceDepth(o.slices)}, 0.4f);      // on the far boundary
    return s;
}

TEST(ClusterGrid, AssignmentIsASupersetOfTouchedClustersAndMethodsAgree) {
    const gbuffer::CameraView view = testView();
    for (const char* gridText : {"24x12x32", "1x1x1", "7x5x9", "64x32x64"})
        for (auto spacing : {lighting::SliceSpacing::Exponential, lighting::SliceSpacing::Uniform})
            for (auto test : {lighting::ClusterTest::Aabb, lighting::ClusterTest::Frustum}) {
                ClusterGridOptions o;
                ASSERT_TRUE(lighting::parseClusterGrid(gridText, o.tilesX, o.tilesY, o.slices));
                o.spacing = spacing;
                o.test = test;
                const std::string what =
                    std::string(gridText) +
                    (spacing == lighting::SliceSpacing::Exponential ? " exp" : " uniform") +
                    (test == lighting::ClusterTest::Aabb ? " aabb" : " frustum");
                ClusterGridOptions binaryOptions = o;
                binaryOptions.assign = lighting::AssignMethod::Binary;
                ClusterGrid walk(o, view, 0.5f, 25.0f), binary(binaryOptions, view, 0.5f, 25.0f);
                std::vector<LightSphere> spheres = randomSpheres(o.tilesX >= 64 ? 12 : 60, 11);
                for (const LightSphere& hard : hardSpheres(walk))
                    spheres.push_back(hard);
                walk.assign(spheres);
                binary.assign(spheres);
                ASSERT_EQ(walk.pairCount(), binary.pairCount()) << what;
                for (size_t c = 0; c < walk.clusterCount(); ++c) {
                    const auto a = walk.lightsOf(c), b = binary.lightsOf(c);
                    ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()))
                        << what << " cluster " << c;
                }
                if (o.tilesX < 64)
                    expectSuperset(walk, spheres, what);
                // Covering-everything and unbounded lights are in every cluster; behind-only in
                // none.
                const uint32_t base = uint32_t(spheres.size() - hardSpheres(walk).size());
                for (size_t c = 0; c < walk.clusterCount(); ++c) {
                    EXPECT_TRUE(listed(walk, c, base + 6)) << what;
                    EXPECT_TRUE(listed(walk, c, base + 9)) << what;
                    EXPECT_FALSE(listed(walk, c, base + 7)) << what;
                }
            }
}

TEST(ClusterGrid, PixelsFallInClustersThatContainThem) {
    const gbuffer::CameraView view = testView();
    ClusterGridOptions o;
    ClusterGrid grid(o, view, 0.5f, 25.0f);
    // Slices: a depth exactly on a boundary belongs to the slice that starts there.
    for (int k = 0; k < o.slices; ++k) {
        EXPECT_EQ(grid.sliceOfDepth(grid.sliceDepth(k)), k);
        const int s = grid.sliceOfDepth(std::nextafter(grid.sliceDepth(k + 1), 0.0f));
        EXPECT_TRUE(s == k || grid.sliceDepth(k + 1) == grid.sliceDepth(k)) << k;
    }
    EXPECT_EQ(grid.sliceOfDepth(0.01f), 0);
    EXPECT_EQ(grid.sliceOfDepth(1e6f), o.slices - 1);
    // Tiles: every pixel centre's ray lies strictly between its tile's edges.
    for (int x = 0; x < view.width; ++x) {
        const int tx = grid.tileXOfPixel(x);
        const glm::vec4 p =
            view.viewFromClip * glm::vec4(view.ndcOfPixel(x, 0).x, 0.0f, 1.0f, 1.0f);
        const float tanX = (p.x / p.w) / -(p.z / p.w);
        EXPECT_LT(grid.edgeTanX(tx), tanX);
        EXPECT_GT(grid.edgeTanX(tx + 1), tanX);
    }
    for (int y = 0; y < view.height; ++y) {
        const int ty = grid.tileYOfPixel(y);
        const glm::vec4 p =
            view.viewFromClip * glm::vec4(0.0f, view.ndcOfPixel(0, y).y, 1.0f, 1.0f);
        const float tanDown = -(p.y / p.w) / -(p.z / p.w);
        EXPECT_LT(grid.edgeTanDownY(ty), tanDown);
        EXPECT_GT(grid.edgeTanDownY(ty + 1), tanDown);
    }
}

TEST(ClusterGrid, SliceSearchMatchesCountingBoundaries) {
    const gbuffer::CameraView view = testView();
    std::mt19937 random(3);
    std::uniform_real_distribution<float> depth(0.0f, 30.0f);
    for (int slices : {1, 2, 3, 7, 16, 31, 32, 33, 64, 1000}) {
        ClusterGridOptions o;
        o.slices = slices;
        ClusterGrid grid(o, view, 0.5f, 25.0f);
        for (int i = 0; i < 2000; ++i) {
            const float d = i < slices + 1 ? grid.sliceDepth(i) : depth(random);
            int expected = 0;
            for (int k = 1; k < slices; ++k)
                expected += grid.sliceDepth(k) <= d ? 1 : 0;
            ASSERT_EQ(grid.sliceOfDepth(d), expected) << slices << " slices, depth " << d;
        }
    }
}

TEST(ClusterGrid, ListsIndependentOfThreadCount) {
    const gbuffer::CameraView view = testView();
    ClusterGridOptions o;
    ClusterGrid one(o, view, 0.5f, 25.0f), many(o, view, 0.5f, 25.0f);
    const std::vector<LightSphere> spheres = randomSpheres(500, 7);
    tbb::task_arena(1).execute([&] { one.assign(spheres); });
    many.assign(spheres);
    ASSERT_EQ(one.pairCount(), many.pairCount());
    for (size_t c = 0; c < one.clusterCount(); ++c) {
        const auto a = one.lightsOf(c), b = many.lightsOf(c);
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()));
    }
}

TEST(ClusterGrid, ParsesGridText) {
    int x = 0, y = 0, z = 0;
    EXPECT_TRUE(lighting::parseClusterGrid("24x12x32", x, y, z));
    EXPECT_EQ(x, 24);
    EXPECT_EQ(y, 12);
    EXPECT_EQ(z, 32);
    for (const char* bad :
         {"24x12", "0x1x1", "1x1x1025", "1024x1024x2", "x1x1", "1x1x1 ", "+1x1x1", ""})
        EXPECT_FALSE(lighting::parseClusterGrid(bad, x, y, z)) << bad;
}

} // namespace
