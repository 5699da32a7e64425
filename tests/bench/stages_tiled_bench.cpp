// `tiled` and `tiled-backface` against each other and against `brute`, at 1280x720:
//   wall, 2500 lights, behind=1000 and behind=0: tiled vs tiled-backface (issue targets:
//     backface >= 1.4x faster with 1000 behind, not slower with none; tiledVsBackface measures
//     the ratio paired, in process CPU time)
//   atrium, 1000 lights: brute vs tiled (target: tiled >= 5x faster)
// Manual time over the stage's shade() only (cull + shading); the G-buffer is rasterized once
// per scene in a static fixture. Counters: the stage's own cull/shading ms of the last
// iteration, light samples evaluated, and for tiled-backface the rejected (tile, light) pairs.
// Compare ratios from one run; the machine's absolute figures vary.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "gbuffer/GBufferPass.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightList.h"
#include "tests/bench/BenchScenes.h"

namespace {

// wall takes its lights-behind count as a scene option; other scenes take none.
struct TiledBenchScene : bench::BenchScene {
    TiledBenchScene(const std::string& sceneName, int lightCount, int behind)
        : bench::BenchScene(
              sceneName, lightCount,
              sceneName == "wall"
                  ? std::map<std::string, std::string>{{"behind", std::to_string(behind)}}
                  : std::map<std::string, std::string>{}) {}
};

const TiledBenchScene& prepared(const std::string& sceneName, int lightCount, int behind) {
    static std::map<std::string, std::unique_ptr<TiledBenchScene>> cache;
    auto& slot = cache[sceneName + "/" + std::to_string(lightCount) + "/" + std::to_string(behind)];
    if (!slot)
        slot = std::make_unique<TiledBenchScene>(sceneName, lightCount, behind);
    return *slot;
}

double timing(const lighting::StageResult& result, const char* pass) {
    for (const auto& [name, ms] : result.timingsMs)
        if (name == pass)
            return ms;
    return 0.0;
}

void shadeStage(benchmark::State& state, const char* sceneName, int lightCount, int behind,
                const char* spec) {
    const TiledBenchScene& f = prepared(sceneName, lightCount, behind);
    auto stage = lighting::makeStage(spec);
    lighting::StageResult result;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        stage->shade(f.inputs, result);
        state.SetIterationTime(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    uint64_t samples = 0;
    for (uint32_t n : result.lightsEvaluated)
        samples += n;
    state.counters["light_samples"] = double(samples);
    state.counters["cull_ms"] = timing(result, "cull");
    state.counters["shading_ms"] = timing(result, "shading");
    const auto rejected = result.parameters.find("backface_rejected");
    if (rejected != result.parameters.end())
        state.counters["backface_rejected"] = std::stod(rejected->second);
}

BENCHMARK_CAPTURE(shadeStage, wall2500_behind1000_tiled, "wall", 2500, 1000, "tiled")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_CAPTURE(shadeStage, wall2500_behind1000_tiled_backface, "wall", 2500, 1000,
                  "tiled-backface")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_CAPTURE(shadeStage, wall2500_behind0_tiled, "wall", 2500, 0, "tiled")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_CAPTURE(shadeStage, wall2500_behind0_tiled_backface, "wall", 2500, 0, "tiled-backface")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
// Process CPU time (all threads), seconds: other jobs on a shared machine disturb it far less
// than wall time.
double processCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
           1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// The issue-14 target "tiled-backface at least 1.4x faster than tiled with 1000 of 2500 lights
// behind the wall, no slower with none", paired: each iteration runs `tiled` then
// `tiled-backface` on the same frame and counts the process CPU time of each, so the ratio
// (cpu_ratio = tiled / tiled-backface) is measured under the same machine load. Manual time =
// tiled-backface's wall time; min_ratio is the same ratio from each stage's fastest wall time.
// Counters also give the light samples each stage evaluates.
//   testbed_bench --benchmark_filter=tiledVsBackface --benchmark_counters_tabular=true
void tiledVsBackface(benchmark::State& state) {
    const TiledBenchScene& f = prepared("wall", 2500, int(state.range(0)));
    auto tiled = lighting::makeStage("tiled");
    auto backface = lighting::makeStage("tiled-backface");
    lighting::StageResult tiledResult, backfaceResult;
    double tiledCpu = 0.0, backfaceCpu = 0.0, tiledMin = 1e30, backfaceMin = 1e30;
    for (auto _ : state) {
        double cpu = processCpuSeconds();
        auto start = std::chrono::steady_clock::now();
        tiled->shade(f.inputs, tiledResult);
        tiledMin = std::min(
            tiledMin,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        tiledCpu += processCpuSeconds() - cpu;
        cpu = processCpuSeconds();
        start = std::chrono::steady_clock::now();
        backface->shade(f.inputs, backfaceResult);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        backfaceCpu += processCpuSeconds() - cpu;
        backfaceMin = std::min(backfaceMin, seconds);
        state.SetIterationTime(seconds);
    }
    const auto samples = [](const lighting::StageResult& r) {
        uint64_t n = 0;
        for (uint32_t e : r.lightsEvaluated)
            n += e;
        return double(n);
    };
    const double n = double(state.iterations());
    state.counters["tiled_cpu_ms"] = 1e3 * tiledCpu / n;
    state.counters["backface_cpu_ms"] = 1e3 * backfaceCpu / n;
    state.counters["cpu_ratio"] = tiledCpu / std::max(backfaceCpu, 1e-12);
    state.counters["min_ratio"] = tiledMin / backfaceMin;
    state.counters["tiled_samples"] = samples(tiledResult);
    state.counters["backface_samples"] = samples(backfaceResult);
}
BENCHMARK(tiledVsBackface)
    ->Arg(1000)
    ->Arg(0)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(10);

BENCHMARK_CAPTURE(shadeStage, atrium1000_brute, "atrium", 1000, 0, "brute")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);
BENCHMARK_CAPTURE(shadeStage, atrium1000_tiled, "atrium", 1000, 0, "tiled")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

} // namespace
