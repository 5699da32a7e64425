// Every registered stage (reference, exact and approximate alike) gives bitwise the same result
// on 1, 2 and 7 threads: radiance, lights.evaluated and, when the stage fills it, lights.oracle
// (ShadingStage.h: results independent of the thread count). 7 threads is more than the machine
// may have cores: tbb::global_control lifts TBB's default cap (the core count) so the arena really
// splits the work seven ways, and the split differs from the 2-thread one. New stages are
// covered as soon as they are registered; nothing here names them.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/lighting/LightIdentity.h"

namespace {

// atrium: many objects (forward overdraw, per-object lists), depth complexity and lights of
// every size; small enough that every stage runs in well under a second.
constexpr int kWidth = 256;
constexpr int kHeight = 144;
constexpr int kLightCount = 200;
constexpr int kThreadCounts[] = {1, 2, 7};

const lighting::PreparedScene& frame() {
    static const std::unique_ptr<lighting::PreparedScene> prepared = [] {
        scenes::SceneRequest request;
        request.lightCount = kLightCount;
        request.seed = 5;
        return std::make_unique<lighting::PreparedScene>(
            scenes::buildProceduralScene("atrium", request), kWidth, kHeight, true);
    }();
    return *prepared;
}

std::vector<std::string> allStageNames() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        names.push_back(info.name);
    return names;
}

class EveryStage : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryStage, BitwiseTheSameOn1And2And7Threads) {
    const std::string& stageName = GetParam();
    const lighting::PreparedScene& f = frame();
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 7);
    lighting::StageResult results[std::size(kThreadCounts)];
    for (size_t i = 0; i < std::size(kThreadCounts); ++i) {
        // A fresh stage object per run: no scratch state carried from another thread count.
        tbb::task_arena(kThreadCounts[i]).execute([&] {
            lighting::makeStage(stageName)->shade(f.inputs, results[i]);
        });
        ASSERT_EQ(results[i].width, kWidth);
        ASSERT_EQ(results[i].height, kHeight);
    }
    uint64_t evaluated = 0;
    for (uint32_t count : results[0].lightsEvaluated)
        evaluated += count;
    EXPECT_GT(evaluated, 0u) << stageName << " evaluated no light: the scene tests nothing";
    for (size_t i = 1; i < std::size(kThreadCounts); ++i) {
        const std::string label =
            stageName + ": 1 vs " + std::to_string(kThreadCounts[i]) + " threads";
        EXPECT_TRUE(stagecheck::bitwiseEqualImages(results[i], results[0])) << label;
        EXPECT_EQ(results[i].lightsEvaluated, results[0].lightsEvaluated) << label;
        EXPECT_EQ(results[i].lightsOracle, results[0].lightsOracle) << label;
        // Counters (not timings) must not depend on the thread count either.
        for (const auto& [key, value] : results[0].parameters)
            if (!key.ends_with("_ms"))
                EXPECT_EQ(results[i].parameters[key], value) << label << ", parameter " << key;
    }
}

INSTANTIATE_TEST_SUITE_P(AllStages, EveryStage, ::testing::ValuesIn(allStageNames()),
                         [](const auto& info) {
                             std::string name = info.param;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

} // namespace
