// Tests for experiments/CpuLoad (issue 16: timings must not lie): the verdict on CPU time against
// wall time is forced both ways with chosen figures (no clock, no timed test), and a render
// records the measured figures in stats.json.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "experiments/render/CpuLoad.h"
#include "experiments/render/RenderCommand.h"
#include "experiments/render/RenderJob.h"

namespace experiments {
namespace {

TEST(CpuLoad, ThreadsStarvedOfCpuAreALoadedMachine) {
    // 2 threads on 2 cores that got 0.3 CPU seconds per second: the development machine under a
    // load of 16 looks like this.
    const CpuLoad load = judgeCpuLoad(0.6, 2.0, 2, 2);
    EXPECT_TRUE(load.loaded);
    EXPECT_DOUBLE_EQ(load.cpuWallRatio, 0.3);
    EXPECT_EQ(load.usableThreads, 2);
    EXPECT_NE(load.warning.find("0.60 s of CPU time in 2.00 s"), std::string::npos) << load.warning;
    EXPECT_NE(load.warning.find("0.30 CPU seconds per second with 2 worker threads"),
              std::string::npos)
        << load.warning;
    EXPECT_NE(load.warning.find("loaded"), std::string::npos) << load.warning;
}

TEST(CpuLoad, BusyThreadsAreNotALoadedMachine) {
    EXPECT_FALSE(judgeCpuLoad(1.9, 1.0, 2, 2).loaded);
    EXPECT_TRUE(judgeCpuLoad(1.9, 1.0, 2, 2).warning.empty());
    EXPECT_FALSE(judgeCpuLoad(0.95, 1.0, 1, 8).loaded); // one thread, busy all the time
    EXPECT_TRUE(judgeCpuLoad(0.4, 1.0, 1, 8).loaded);   // one thread, waiting most of it
}

TEST(CpuLoad, TheThresholdIsAFractionOfTheUsableThreads) {
    // 8 threads asked on a 2-core machine: at most 2 CPU seconds per second are possible.
    const CpuLoad oversubscribed = judgeCpuLoad(1.8, 1.0, 8, 2);
    EXPECT_EQ(oversubscribed.usableThreads, 2);
    EXPECT_FALSE(oversubscribed.loaded);
    // Just under and just over half of 2 threads, and a stricter fraction.
    EXPECT_TRUE(judgeCpuLoad(0.99, 1.0, 2, 2).loaded);
    EXPECT_FALSE(judgeCpuLoad(1.01, 1.0, 2, 2).loaded);
    EXPECT_TRUE(judgeCpuLoad(1.5, 1.0, 2, 2, 0.9).loaded);
    EXPECT_DOUBLE_EQ(judgeCpuLoad(1.5, 1.0, 2, 2, 0.9).fraction, 0.9);
    // Unknown hardware concurrency (0): the threads asked for.
    EXPECT_EQ(judgeCpuLoad(1.0, 1.0, 4, 0).usableThreads, 4);
}

TEST(CpuLoad, NoWallTimeIsNoVerdict) {
    const CpuLoad load = judgeCpuLoad(0.0, 0.0, 2, 2);
    EXPECT_FALSE(load.loaded);
    EXPECT_EQ(load.cpuWallRatio, 0.0);
}

TEST(CpuLoad, ARenderRecordsItsFiguresInStatsJson) {
    RenderOptions options;
    options.scene = "spheres";
    options.lights = 8;
    options.width = 64;
    options.height = 36;
    options.threads = 1;
    options.repetitions = 2;
    const RenderRun run = runRender(planRender(options));
    const nlohmann::json stats = statsJson(run);
    ASSERT_TRUE(stats.contains("cpu_load")) << stats.dump(2);
    const nlohmann::json& load = stats["cpu_load"];
    EXPECT_GT(load["wall_seconds"].get<double>(), 0.0);
    EXPECT_GE(load["cpu_seconds"].get<double>(), 0.0);
    EXPECT_EQ(load["threads"], 1);
    EXPECT_DOUBLE_EQ(load["cpu_wall_ratio"].get<double>(),
                     load["cpu_seconds"].get<double>() / load["wall_seconds"].get<double>());
    EXPECT_TRUE(load["loaded_machine_warning"].is_boolean());
    EXPECT_EQ(load["loaded_machine_warning"].get<bool>(),
              !load["warning"].get<std::string>().empty());
}

} // namespace
} // namespace experiments
