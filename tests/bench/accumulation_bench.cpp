// The stages on accumulateLights (lighting/passes/LightAccumulation.h), with the kernel's scalar
// path and its widest vector target timed alternately in one benchmark (iteration i: scalar, then
// vector, on the same frame), so their ratio comes from the same moments of a shared machine.
// Each iteration runs the stage's whole shade() under a tbb::task_arena of `threads`, wall clock.
// Counters: the median of each ISA's times (ms), their ratio (scalar / vector, median and best),
// and, for brute, the vector path's ns per pixel-light (covered pixels x lights).
//   testbed_bench --benchmark_filter=accumulation --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "lighting/StageRegistry.h"
#include "tests/bench/BenchScenes.h"

namespace {

using lighting::kernel::KernelIsa;

const bench::BenchScene& frame(const std::string& scene, int lights, int behind) {
    static std::map<std::string, std::unique_ptr<bench::BenchScene>> cache;
    auto& slot = cache[scene + "/" + std::to_string(lights) + "/" + std::to_string(behind)];
    if (!slot)
        slot = std::make_unique<bench::BenchScene>(
            scene, lights,
            behind > 0 ? std::map<std::string, std::string>{{"behind", std::to_string(behind)}}
                       : std::map<std::string, std::string>{});
    return *slot;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Times `specA` on isaA and `specB` on isaB alternately; reports the median of each and A / B.
void alternate(benchmark::State& state, const char* scene, int lights, int behind, int threads,
               const char* specA, KernelIsa isaA, const char* specB, KernelIsa isaB) {
    const bench::BenchScene& f = frame(scene, lights, behind);
    auto stageA = lighting::makeStage(specA), stageB = lighting::makeStage(specB);
    lighting::StageInputs inputsA = f.inputs, inputsB = f.inputs;
    inputsA.isa = isaA;
    inputsB.isa = isaB;
    lighting::StageResult result;
    std::vector<double> a, b;
    tbb::task_arena arena(threads);
    for (auto _ : state) {
        double ms[2];
        int k = 0;
        for (auto* run : {&a, &b}) {
            const auto start = std::chrono::steady_clock::now();
            arena.execute(
                [&] { (k == 0 ? stageA : stageB)->shade(k == 0 ? inputsA : inputsB, result); });
            ms[k] =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
            run->push_back(ms[k]);
            ++k;
        }
        state.SetIterationTime((ms[0] + ms[1]) * 1e-3);
    }
    state.counters["a_median_ms"] = median(a);
    state.counters["b_median_ms"] = median(b);
    state.counters["a_best_ms"] = *std::min_element(a.begin(), a.end());
    state.counters["b_best_ms"] = *std::min_element(b.begin(), b.end());
    state.counters["ratio_median"] = median(a) / median(b);
    state.counters["ratio_best"] =
        *std::min_element(a.begin(), a.end()) / *std::min_element(b.begin(), b.end());
    uint64_t covered = 0;
    for (size_t p = 0; p < f.gbuffer->pixelCount(); ++p)
        covered += f.gbuffer->covered(p) ? 1 : 0;
    state.counters["b_ns_per_pixel_light"] =
        median(b) * 1e6 / (double(covered) * double(f.lights.size()));
    state.SetLabel(std::string(specA) + "/" + isaA.name() + " vs " + specB + "/" + isaB.name());
}

// brute, atrium 1280x720, 256 lights, 1 thread: scalar path / widest vector target.
void accumulationBruteAtrium(benchmark::State& state) {
    alternate(state, "atrium", 256, 0, 1, "brute", KernelIsa::scalar(), "brute", KernelIsa::best());
}
BENCHMARK(accumulationBruteAtrium)->UseManualTime()->Iterations(5)->Unit(benchmark::kMillisecond);

// clustered (assignment + shading), atrium 1280x720, 1000 lights, 2 threads: scalar / vector.
void accumulationClusteredAtrium(benchmark::State& state) {
    alternate(state, "atrium", 1000, 0, 2, "clustered", KernelIsa::scalar(), "clustered",
              KernelIsa::best());
}
BENCHMARK(accumulationClusteredAtrium)
    ->UseManualTime()
    ->Iterations(7)
    ->Unit(benchmark::kMillisecond);

// wall, 2500 lights of which 1000 (or none) behind it, vector path, 1 thread: tiled /
// tiled-backface.
void accumulationWallBackface(benchmark::State& state) {
    alternate(state, "wall", 2500, int(state.range(0)), 1, "tiled", KernelIsa::best(),
              "tiled-backface", KernelIsa::best());
}
BENCHMARK(accumulationWallBackface)
    ->Arg(1000)
    ->Arg(0)
    ->UseManualTime()
    ->Iterations(7)
    ->Unit(benchmark::kMillisecond);

} // namespace
