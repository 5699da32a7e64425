// Light-volume stages against brute force at 1280x720, 2 threads (the machine's cores):
//   wall, 2500 lights of which 1000 behind the wall: `deferred` (and variants) vs `brute`
//   atrium, 1000 lights: `light-indexed` vs `deferred` vs `brute`
// Manual time covers shade() only; the G-buffer is rendered once per fixture. Counters: light
// samples evaluated and ns per light-sample. Compare ratios from one run; absolute figures
// depend on the (shared, noisy) machine.
//   testbed_bench --benchmark_filter='volume' --benchmark_repetitions=3
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferPass.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightList.h"
#include "tests/bench/BenchScenes.h"

namespace {

using VolumeFixture = bench::BenchScene;

const VolumeFixture& wallFixture() {
    static const VolumeFixture fixture("wall", 2500, {{"behind", "1000"}});
    return fixture;
}
const VolumeFixture& atriumFixture() {
    static const VolumeFixture fixture("atrium", 1000, {});
    return fixture;
}

void shadeStage(benchmark::State& state, const VolumeFixture& f, const std::string& stageSpec) {
    tbb::task_arena arena(2);
    auto stage = lighting::makeStage(stageSpec);
    lighting::StageResult result;
    uint64_t samples = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] { stage->shade(f.inputs, result); });
        state.SetIterationTime(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        samples = 0;
        for (uint32_t n : result.lightsEvaluated)
            samples += n;
    }
    state.counters["light_samples"] = double(samples);
    state.counters["ns/light-sample"] =
        benchmark::Counter(double(samples) * 1e-9, benchmark::Counter::kIsIterationInvariantRate |
                                                       benchmark::Counter::kInvert);
    for (const auto& [pass, ms] : result.timingsMs)
        state.counters[pass + "_ms"] = ms;
    for (const char* key : {"overflow_pixels", "volume_fragments"}) {
        const auto found = result.parameters.find(key);
        if (found != result.parameters.end())
            state.counters[key] = std::stod(found->second);
    }
}

void volumeWall(benchmark::State& state, const std::string& stageSpec) {
    shadeStage(state, wallFixture(), stageSpec);
}
void volumeAtrium(benchmark::State& state, const std::string& stageSpec) {
    shadeStage(state, atriumFixture(), stageSpec);
}

BENCHMARK_CAPTURE(volumeWall, brute, std::string("brute"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(volumeWall, deferred, std::string("deferred"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(volumeWall, deferred_stencil, std::string("deferred:stencil=1"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(volumeWall, deferred_rect, std::string("deferred:volume=rect"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(volumeWall, light_indexed, std::string("light-indexed"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

BENCHMARK_CAPTURE(volumeAtrium, brute, std::string("brute"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(volumeAtrium, deferred, std::string("deferred"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK_CAPTURE(volumeAtrium, light_indexed, std::string("light-indexed"))
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

} // namespace
