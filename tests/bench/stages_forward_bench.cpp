// Forward shading vs `brute` on `atrium` at 1280x720 with 64 and 1000 lights, at the caller's
// thread count. Manual time = shade() only: the scene, geometry, G-buffer (which brute reads)
// and light list are prepared once per light count in a static fixture. Forward's shade()
// includes its own vertex transform and rasterization; brute's excludes the G-buffer pass, so
// compare forward with brute + the G-buffer pass of gbuffer_bench. Quote ratios from one run.
//   testbed_bench --benchmark_filter='forward|Forward' --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>

#include "gbuffer/GBufferPass.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightList.h"
#include "tests/bench/BenchScenes.h"

namespace {

struct ForwardBenchScene : bench::BenchScene {
    explicit ForwardBenchScene(int lightCount) : bench::BenchScene("atrium", lightCount) {}
};

const ForwardBenchScene& forwardBenchFrame(int lightCount) {
    static std::map<int, std::unique_ptr<ForwardBenchScene>> frames;
    auto& slot = frames[lightCount];
    if (!slot)
        slot = std::make_unique<ForwardBenchScene>(lightCount);
    return *slot;
}

void runStage(benchmark::State& state, const char* stageName) {
    const ForwardBenchScene& f = forwardBenchFrame(int(state.range(0)));
    auto stage = lighting::makeStage(stageName);
    lighting::StageResult result;
    stage->shade(f.inputs, result); // warm-up: scratch buffers allocated outside the timing
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
    for (const auto& [pass, ms] : result.timingsMs)
        state.counters[pass + "_ms"] = ms;
}

void forwardBrute(benchmark::State& state) {
    runStage(state, "brute");
}
void forwardSinglePass(benchmark::State& state) {
    runStage(state, "forward");
}
void forwardSinglePassPrepass(benchmark::State& state) {
    runStage(state, "forward:prepass=1");
}
void forwardMultipass(benchmark::State& state) {
    runStage(state, "forward-multipass");
}

BENCHMARK(forwardBrute)
    ->Arg(64)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK(forwardSinglePass)
    ->Arg(64)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK(forwardSinglePassPrepass)
    ->Arg(64)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
// One pass per light re-sets-up the light's objects: seconds per frame at 1000 lights.
BENCHMARK(forwardMultipass)
    ->Arg(64)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

} // namespace
