// `clustered` vs `brute` on `atrium` at 1280x720 (the setting of Örtegren's Table 1/2: 10 and
// 1000 lights, grids 24x12x{16,32,64}). Times the whole shade() (assignment + shading) with
// manual time; counters report the stage's passes, the (cluster, light) pairs and the culling
// efficiency (oracle light-samples / evaluated light-samples). Ratios between rows of one run are
// what to quote: the machine is shared and absolute figures drift.
//   testbed_bench --benchmark_filter=clustered --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <map>
#include <memory>
#include <string>

#include <tbb/parallel_for.h>

#include "gbuffer/GBufferPass.h"
#include "gbuffer/SceneGeometry.h"
#include "lighting/LightList.h"
#include "lighting/LightListShading.h"
#include "lighting/Oracle.h"
#include "lighting/StageRegistry.h"
#include "tests/bench/BenchScenes.h"

namespace {

// One prepared frame per light count: scene, G-buffer, lights and the oracle, built once.
struct ClusteredBenchScene : bench::BenchScene {
    uint64_t oracleSamples = 0;

    explicit ClusteredBenchScene(int lightCount) : bench::BenchScene("atrium", lightCount) {
        for (uint32_t n : lighting::countContributingLights(inputs))
            oracleSamples += n;
    }
};

const ClusteredBenchScene& benchScene(int lightCount) {
    static std::map<int, std::unique_ptr<ClusteredBenchScene>> frames;
    auto& slot = frames[lightCount];
    if (!slot)
        slot = std::make_unique<ClusteredBenchScene>(lightCount);
    return *slot;
}

// Process CPU time (all threads), seconds: the work done, which other jobs on a shared machine
// disturb far less than wall time does.
double processCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
           1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

void runStage(benchmark::State& state, const std::string& spec, int lightCount) {
    const ClusteredBenchScene& f = benchScene(lightCount);
    auto stage = lighting::makeStage(spec);
    lighting::StageResult result;
    std::map<std::string, double> passMs;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        stage->shade(f.inputs, result);
        state.SetIterationTime(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        for (const auto& [pass, ms] : result.timingsMs)
            passMs[pass] += ms;
    }
    uint64_t evaluated = 0;
    for (uint32_t n : result.lightsEvaluated)
        evaluated += n;
    for (const auto& [pass, ms] : passMs)
        state.counters[pass + "_ms"] = ms / double(state.iterations());
    state.counters["lights"] = lightCount;
    state.counters["efficiency"] =
        double(f.oracleSamples) / double(std::max<uint64_t>(evaluated, 1));
    const auto pairs = result.parameters.find("cluster_light_pairs");
    if (pairs != result.parameters.end())
        state.counters["pairs"] = std::stod(pairs->second);
}

void clusteredBrute(benchmark::State& state) {
    runStage(state, "brute", int(state.range(0)));
}
BENCHMARK(clusteredBrute)
    ->Arg(10)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

void clusteredDefault(benchmark::State& state) {
    runStage(state, "clustered", int(state.range(0)));
}
BENCHMARK(clusteredDefault)
    ->Arg(10)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// Örtegren's grids: 24x12 tiles with 16, 32, 64 depth slices.
void clusteredSlices(benchmark::State& state) {
    runStage(state, "clustered:grid=24x12x" + std::to_string(state.range(1)), int(state.range(0)));
}
BENCHMARK(clusteredSlices)
    ->ArgsProduct({{10, 1000}, {16, 32, 64}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

void clusteredVariants(benchmark::State& state) {
    static const char* const kSpecs[] = {"clustered:assign=binary", "clustered:slices=uniform",
                                         "clustered:test=frustum"};
    state.SetLabel(kSpecs[state.range(0)]);
    runStage(state, kSpecs[state.range(0)], 1000);
}
BENCHMARK(clusteredVariants)
    ->DenseRange(0, 2)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// Paired: each iteration runs `brute` then the clustered spec on the same frame, so the ratio is
// measured under the same machine load (manual time = the clustered stage).
void clusteredVsBrute(benchmark::State& state) {
    static const char* const kSpecs[] = {"clustered", "clustered:grid=48x27x64",
                                         "clustered:grid=80x45x64",
                                         "clustered:grid=24x12x64,test=frustum"};
    const char* spec = kSpecs[state.range(1)];
    state.SetLabel(spec);
    const ClusteredBenchScene& f = benchScene(int(state.range(0)));
    auto brute = lighting::makeStage("brute");
    auto clustered = lighting::makeStage(spec);
    lighting::StageResult bruteResult, result;
    double bruteSeconds = 0.0, clusteredSeconds = 0.0, bruteCpu = 0.0, clusteredCpu = 0.0;
    for (auto _ : state) {
        double cpu = processCpuSeconds();
        auto start = std::chrono::steady_clock::now();
        brute->shade(f.inputs, bruteResult);
        bruteSeconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        bruteCpu += processCpuSeconds() - cpu;
        cpu = processCpuSeconds();
        start = std::chrono::steady_clock::now();
        clustered->shade(f.inputs, result);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        clusteredCpu += processCpuSeconds() - cpu;
        clusteredSeconds += seconds;
        state.SetIterationTime(seconds);
    }
    state.counters["cpu_ratio"] = bruteCpu / std::max(clusteredCpu, 1e-9);
    state.counters["cpu_ms"] = 1e3 * clusteredCpu / double(state.iterations());
    state.counters["brute_cpu_ms"] = 1e3 * bruteCpu / double(state.iterations());
    uint64_t evaluated = 0;
    for (uint32_t n : result.lightsEvaluated)
        evaluated += n;
    state.counters["brute_ms"] = 1e3 * bruteSeconds / double(state.iterations());
    state.counters["ratio"] = bruteSeconds / clusteredSeconds;
    state.counters["efficiency"] =
        double(f.oracleSamples) / double(std::max<uint64_t>(evaluated, 1));
}
BENCHMARK(clusteredVsBrute)
    ->ArgsProduct({{10, 1000}, {0, 1, 2, 3}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// The ceiling of any exact culling with this BRDF: each pixel shaded with exactly the lights
// that contribute there (lists precomputed outside the timer, so culling is free and perfect,
// efficiency 1). brute / this = the largest speed-up an exact stage could reach on this frame.
void clusteredPerfectCullingCeiling(benchmark::State& state) {
    const ClusteredBenchScene& f = benchScene(int(state.range(0)));
    const gbuffer::GBuffer& gb = *f.gbuffer;
    const auto& lights = f.lights.lights;
    const size_t pixelCount = gb.pixelCount();
    std::vector<std::vector<uint32_t>> perRow(gb.height());
    std::vector<std::vector<uint32_t>> rowOffsets(gb.height());
    tbb::parallel_for(0, gb.height(), [&](int y) {
        rowOffsets[y].push_back(0);
        for (int x = 0; x < gb.width(); ++x) {
            gbuffer::Surface point;
            if (gb.surfaceAt(x, y, point)) {
                const glm::vec3 toViewer = glm::normalize(-point.positionView);
                for (uint32_t i = 0; i < lights.size(); ++i)
                    if (lighting::contributes(lighting::evaluateLight(point, toViewer, lights[i])))
                        perRow[y].push_back(i);
            }
            rowOffsets[y].push_back(uint32_t(perRow[y].size()));
        }
    });
    lighting::StageResult result;
    double bruteCpu = 0.0, idealCpu = 0.0;
    auto brute = lighting::makeStage("brute");
    lighting::StageResult bruteResult;
    for (auto _ : state) {
        double cpu = processCpuSeconds();
        brute->shade(f.inputs, bruteResult);
        bruteCpu += processCpuSeconds() - cpu;
        cpu = processCpuSeconds();
        const auto start = std::chrono::steady_clock::now();
        result.resize(gb.width(), gb.height(), false);
        tbb::parallel_for(0, gb.height(), [&](int y) {
            for (int x = 0; x < gb.width(); ++x) {
                if (!gb.covered(size_t(y) * gb.width() + x))
                    continue;
                const std::span<const uint32_t> list(perRow[y].data() + rowOffsets[y][x],
                                                     perRow[y].data() + rowOffsets[y][x + 1]);
                lighting::shadeWithLightList(gb, x, y, lights, list, result);
            }
        });
        state.SetIterationTime(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        idealCpu += processCpuSeconds() - cpu;
    }
    (void)pixelCount;
    state.counters["cpu_ms"] = 1e3 * idealCpu / double(state.iterations());
    state.counters["brute_cpu_ms"] = 1e3 * bruteCpu / double(state.iterations());
    state.counters["cpu_ratio"] = bruteCpu / std::max(idealCpu, 1e-9);
}
BENCHMARK(clusteredPerfectCullingCeiling)
    ->Arg(10)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

} // namespace
