// `clustered` vs `brute` on `atrium` at 1280x720 (the setting of Örtegren's Table 1/2: 10 and
// 1000 lights, grids 24x12x{16,32,64}). Times the whole shade() (assignment + shading) with
// manual time; counters report the stage's passes, the (cluster, light) pairs and the culling
// efficiency (oracle light-samples / evaluated light-samples). Ratios between rows of one run are
// what to quote: the machine is shared and absolute figures drift.
//   testbed_bench --benchmark_filter=clustered --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "gbuffer/GBufferPass.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/Oracle.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightList.h"
#include "lighting/lists/PacketContributingLights.h"
#include "lighting/passes/LightAccumulation.h"
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

// The ceiling of any exact culling with this BRDF and kernel: the `ideal` stage, each pixel
// shaded with exactly the lights that contribute there (lists precomputed outside its timer, so
// culling is free and perfect, efficiency 1; per packet one evaluation per light of its lanes'
// union). Manual time = ideal's shading pass; brute / this = the largest speed-up an exact stage
// could reach on this frame.
void clusteredPerfectCullingCeiling(benchmark::State& state) {
    const ClusteredBenchScene& f = benchScene(int(state.range(0)));
    auto brute = lighting::makeStage("brute");
    auto ideal = lighting::makeStage("ideal");
    lighting::StageResult bruteResult, result;
    double bruteSeconds = 0.0, idealSeconds = 0.0;
    for (auto _ : state) {
        auto start = std::chrono::steady_clock::now();
        brute->shade(f.inputs, bruteResult);
        bruteSeconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ideal->shade(f.inputs, result);
        double shadingMs = 0.0;
        for (const auto& [pass, ms] : result.timingsMs)
            shadingMs += ms;
        idealSeconds += 1e-3 * shadingMs;
        state.SetIterationTime(1e-3 * shadingMs);
    }
    uint64_t evaluated = 0;
    for (uint32_t n : result.lightsEvaluated)
        evaluated += n;
    state.counters["brute_ms"] = 1e3 * bruteSeconds / double(state.iterations());
    state.counters["ratio"] = bruteSeconds / std::max(idealSeconds, 1e-12);
    state.counters["efficiency"] =
        double(f.oracleSamples) / double(std::max<uint64_t>(evaluated, 1));
    state.counters["packet_light_pairs"] = std::stod(result.parameters.at("packet_light_pairs"));
}
BENCHMARK(clusteredPerfectCullingCeiling)
    ->Arg(10)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// The issue-14 target "clustered at least 0.85 of ideal's speed", measured on a shared machine:
// each iteration runs the whole `clustered` shade() (assignment + shading) and then the `ideal`
// stage's shading (accumulateLights over the packet lists `ideal` builds, built once outside the
// loop), and counts both wall time and process CPU time (all threads; other jobs on the machine
// inflate wall time much more than CPU time). speed_fraction = ideal / clustered, from the
// minimum of each (wall) and from the CPU totals. Manual time = clustered's wall time.
//   testbed_bench --benchmark_filter=clusteredVsIdeal --benchmark_counters_tabular=true
void clusteredVsIdeal(benchmark::State& state) {
    const ClusteredBenchScene& f = benchScene(int(state.range(0)));
    static std::map<int, std::unique_ptr<lighting::PacketContributingLights>> idealLists;
    auto& lists = idealLists[int(state.range(0))];
    if (!lists) {
        lighting::ContributingLights pixels;
        pixels.build(*f.gbuffer, f.lights.lights);
        lists = std::make_unique<lighting::PacketContributingLights>();
        lists->build(pixels, f.lights.lights.size());
    }
    auto clustered = lighting::makeStage("clustered");
    lighting::StageResult clusteredResult, idealResult;
    idealResult.resize(f.gbuffer->width(), f.gbuffer->height(), false);
    double clusteredMin = 1e30, idealMin = 1e30, clusteredCpu = 0.0, idealCpu = 0.0;
    for (auto _ : state) {
        double cpu = processCpuSeconds();
        auto start = std::chrono::steady_clock::now();
        clustered->shade(f.inputs, clusteredResult);
        const double clusteredSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        clusteredCpu += processCpuSeconds() - cpu;
        cpu = processCpuSeconds();
        start = std::chrono::steady_clock::now();
        lighting::accumulateLights(f.inputs, *lists, {}, idealResult);
        const double idealSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        idealCpu += processCpuSeconds() - cpu;
        clusteredMin = std::min(clusteredMin, clusteredSeconds);
        idealMin = std::min(idealMin, idealSeconds);
        state.SetIterationTime(clusteredSeconds);
    }
    const double n = double(state.iterations());
    state.counters["clustered_min_ms"] = 1e3 * clusteredMin;
    state.counters["ideal_min_ms"] = 1e3 * idealMin;
    state.counters["clustered_cpu_ms"] = 1e3 * clusteredCpu / n;
    state.counters["ideal_cpu_ms"] = 1e3 * idealCpu / n;
    state.counters["speed_fraction"] = idealMin / clusteredMin;
    state.counters["cpu_speed_fraction"] = idealCpu / std::max(clusteredCpu, 1e-12);
    // The kernel's cost drivers per frame (millions of packet-wide light iterations by outcome,
    // LightAccumulation.h): what the clustered lists cost beyond ideal's.
    const auto millions = [](const lighting::StageResult& r, const char* key) {
        const auto it = r.parameters.find(key);
        return it == r.parameters.end() ? 0.0 : 1e-6 * std::stod(it->second);
    };
    for (const auto& [prefix, r] :
         {std::pair<std::string, const lighting::StageResult*>{"clustered_", &clusteredResult},
          {"ideal_", &idealResult}}) {
        state.counters[prefix + "range_skips_M"] = millions(*r, "packet_lights_skipped_at_range");
        state.counters[prefix + "cone_skips_M"] =
            millions(*r, "packet_lights_skipped_at_cone_or_facing");
        state.counters[prefix + "shaded_M"] = millions(*r, "packet_lights_shaded");
    }
}
BENCHMARK(clusteredVsIdeal)
    ->Arg(1000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(10);

} // namespace
