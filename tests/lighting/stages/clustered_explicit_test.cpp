// The `clustered-explicit` stage (lighting/stages/ClusteredExplicitStage.cpp): exact by light
// identity against brute force (every contributing light among the lights each pixel evaluated,
// tests/lighting/LightIdentity.h) and bitwise brute's image, at 10^2 and 10^4 lights on atrium
// and on wall with lights behind it (where back-face culling must reject, and must not drop),
// with and without normal clustering; the same result on 1, 2 and 7 threads, bitwise, with the
// same clusters and lists; the stage parameters stats.json records.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <tuple>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/lists/ContributingLights.h"
#include "lighting/passes/PassNames.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

namespace {

constexpr int kWidth = 192;
constexpr int kHeight = 108;

struct Frame {
    std::unique_ptr<lighting::PreparedScene> prepared;
    lighting::ContributingLights contributing;
    lighting::StageResult brute;
};

const Frame& frame(const std::string& scene, int lightCount) {
    static std::map<std::string, std::unique_ptr<Frame>> cache;
    auto& slot = cache[scene + std::to_string(lightCount)];
    if (slot)
        return *slot;
    slot = std::make_unique<Frame>();
    scenes::SceneRequest request;
    request.lightCount = lightCount;
    request.seed = 7;
    if (scene == "wall") // half the lights behind the wall: what back-face culling rejects
        request.options = {{"behind", std::to_string(lightCount / 2)}};
    slot->prepared = std::make_unique<lighting::PreparedScene>(
        scenes::buildProceduralScene(scene, request), kWidth, kHeight);
    slot->contributing.build(*slot->prepared->inputs.gbuffer,
                             slot->prepared->inputs.lights->lights);
    lighting::makeStage("brute")->shade(slot->prepared->inputs, slot->brute);
    return *slot;
}

class ClusteredExplicitExact
    : public ::testing::TestWithParam<std::tuple<const char*, int, const char*>> {};

TEST_P(ClusteredExplicitExact, EveryContributingLightEvaluatedAndBruteImage) {
    const auto& [scene, lightCount, spec] = GetParam();
    const Frame& f = frame(scene, lightCount);
    const auto stage = lighting::makeStage(spec);
    const lighting::StageResult result = stagecheck::shadeTraced(*stage, f.prepared->inputs);
    EXPECT_TRUE(stagecheck::everyContributingLightEvaluated(result, f.contributing, true))
        << spec << " on " << scene << " with " << lightCount << " lights";
    EXPECT_TRUE(stagecheck::bitwiseEqualImages(result, f.brute)) << spec << " on " << scene;
    // Culling happened: fewer evaluations than brute's.
    uint64_t evaluated = 0, bruteEvaluated = 0;
    for (size_t pixel = 0; pixel < result.lightsEvaluated.size(); ++pixel) {
        evaluated += result.lightsEvaluated[pixel];
        bruteEvaluated += f.brute.lightsEvaluated[pixel];
    }
    EXPECT_LT(evaluated, bruteEvaluated / 2) << spec << " on " << scene;
    // With the lights behind the wall, the cones rejected some.
    if (std::string(scene) == "wall")
        EXPECT_GT(std::stoull(result.parameters.at("backface_rejected")), 0u) << spec;
}

INSTANTIATE_TEST_SUITE_P(
    AtriumAndWall, ClusteredExplicitExact,
    ::testing::Combine(::testing::Values("atrium", "wall"), ::testing::Values(100, 10000),
                       ::testing::Values("clustered-explicit", "clustered-explicit:normals=3",
                                         "clustered-explicit:normals=1,tile=8")),
    [](const auto& info) {
        std::string name = std::string(std::get<0>(info.param)) + "_" +
                           std::to_string(std::get<1>(info.param)) + "_" + std::get<2>(info.param);
        for (char& c : name)
            if (!std::isalnum(static_cast<unsigned char>(c)))
                c = '_';
        return name;
    });

// 1, 2 and 7 threads (global_control lifts TBB's cap at the core count, so 7 really splits the
// tiles seven ways), each against 1 thread: images, counts, traces and the clusters' figures.
TEST(ClusteredExplicit, SameResultOnOneTwoAndSevenThreads) {
    const Frame& f = frame("atrium", 1000);
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 7);
    for (const char* spec : {"clustered-explicit", "clustered-explicit:normals=3"}) {
        const int threads[] = {1, 2, 7};
        lighting::StageResult results[3];
        for (int i = 0; i < 3; ++i) {
            tbb::task_arena arena(threads[i]);
            arena.execute([&] {
                results[i].traceLights = true;
                lighting::makeStage(spec)->shade(f.prepared->inputs, results[i]);
            });
        }
        for (int i = 1; i < 3; ++i) {
            EXPECT_TRUE(stagecheck::bitwiseEqualImages(results[0], results[i]))
                << spec << " on " << threads[i] << " threads";
            EXPECT_EQ(results[0].lightsEvaluated, results[i].lightsEvaluated) << spec;
            EXPECT_EQ(results[0].lightTrace, results[i].lightTrace) << spec;
            for (const char* key : {"unique_clusters", "cluster_light_pairs", "backface_rejected",
                                    "cluster_bytes", "simt_lane_slots"})
                EXPECT_EQ(results[0].parameters.at(key), results[i].parameters.at(key))
                    << spec << " " << key << " on " << threads[i] << " threads";
        }
    }
}

TEST(ClusteredExplicit, RecordsItsParametersAndPasses) {
    const Frame& f = frame("atrium", 100);
    lighting::StageResult plain, normals;
    lighting::makeStage("clustered-explicit")->shade(f.prepared->inputs, plain);
    lighting::makeStage("clustered-explicit:normals=3,tile=16,backface=0")
        ->shade(f.prepared->inputs, normals);
    EXPECT_EQ(plain.parameters.at("tile"), "32");
    EXPECT_EQ(plain.parameters.at("normals"), "0");
    EXPECT_EQ(plain.parameters.at("backface"), "1");
    EXPECT_EQ(normals.parameters.at("tile"), "16");
    EXPECT_EQ(normals.parameters.at("backface"), "0");
    EXPECT_EQ(normals.parameters.at("backface_rejected"), "0");
    const auto count = [](const lighting::StageResult& r, const char* key) {
        return std::stod(r.parameters.at(key));
    };
    // 192x108 in 32-pixel tiles: 6x4 tiles, at least one cluster per covered tile; more with
    // normals and smaller tiles.
    EXPECT_GE(count(plain, "unique_clusters"), 24.0);
    EXPECT_GT(count(normals, "unique_clusters"), count(plain, "unique_clusters"));
    EXPECT_NEAR(count(plain, "mean_lights_per_cluster"),
                count(plain, "cluster_light_pairs") / count(plain, "unique_clusters"), 1e-3);
    // At least the per-pixel cluster indices and the lists.
    EXPECT_GE(count(plain, "cluster_bytes"),
              4.0 * (kWidth * kHeight + count(plain, "cluster_light_pairs")));
    ASSERT_EQ(plain.timingsMs.size(), 3u);
    EXPECT_EQ(plain.timingsMs[0].first, lighting::pass::kClusters);
    EXPECT_EQ(plain.timingsMs[1].first, lighting::pass::kAssign);
    EXPECT_EQ(plain.timingsMs[2].first, lighting::pass::kShading);
}

} // namespace
