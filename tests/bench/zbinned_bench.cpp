// `zbinned` (Drobot's z-binning, lighting/culling/ZBins.h) beside `clustered` on atrium at
// 1280x720 with the constant-overlap light generator (scenes/procedural/LightGenerator.h: radii
// shrink with the count, so the lights reaching a pixel stay about constant) at 10^3 .. 10^6
// lights: the scaling of light assignment. Each iteration shades the same frame with `zbinned`
// and then `clustered` (paired, so both see the same machine load); the counters give each stage's
// "assign" and "shading" passes (min and median over the iterations, ms), zbinned's memory (mask,
// bin and sorted-order bytes, stage parameters) and the process's peak resident set so far (the
// frames are built one light count at a time, smallest first, and freed after their run).
// Manual time = zbinned's whole shade().
//   testbed_bench --benchmark_filter=zbinned --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/bench/BenchScenes.h"

namespace {

std::unique_ptr<lighting::PreparedScene> constantOverlapAtrium(int lightCount) {
    scenes::SceneRequest request;
    request.lightCount = lightCount;
    request.seed = 1;
    request.lightDensity = scenes::LightDensity::ConstantOverlap;
    return std::make_unique<lighting::PreparedScene>(
        scenes::buildProceduralScene("atrium", request), bench::kWidth, bench::kHeight);
}

double passMs(const lighting::StageResult& result, const char* pass) {
    for (const auto& [name, ms] : result.timingsMs)
        if (name == pass)
            return ms;
    return 0.0;
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n == 0 ? 0.0 : n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double peakResidentMegabytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0; // kilobytes on Linux
}

void zbinnedVsClustered(benchmark::State& state) {
    const int lightCount = int(state.range(0));
    const std::unique_ptr<lighting::PreparedScene> frame = constantOverlapAtrium(lightCount);
    auto zbinned = lighting::makeStage("zbinned");
    auto clustered = lighting::makeStage("clustered");
    lighting::StageResult zbinnedResult, clusteredResult;
    std::map<std::string, std::vector<double>> ms;
    for (auto _ : state) {
        zbinned->shade(frame->inputs, zbinnedResult);
        clustered->shade(frame->inputs, clusteredResult);
        const double zbinnedAssign = passMs(zbinnedResult, "assign");
        const double zbinnedShading = passMs(zbinnedResult, "shading");
        ms["zbinned_assign"].push_back(zbinnedAssign);
        ms["zbinned_shading"].push_back(zbinnedShading);
        ms["clustered_assign"].push_back(passMs(clusteredResult, "assign"));
        ms["clustered_shading"].push_back(passMs(clusteredResult, "shading"));
        state.SetIterationTime(1e-3 * (zbinnedAssign + zbinnedShading));
    }
    for (const auto& [key, values] : ms) {
        state.counters[key + "_min_ms"] = *std::min_element(values.begin(), values.end());
        state.counters[key + "_med_ms"] = median(values);
    }
    const auto parameter = [&](const char* key) {
        return std::stod(zbinnedResult.parameters.at(key));
    };
    state.counters["lights"] = lightCount;
    state.counters["after_vfc"] = parameter("lights_after_vfc");
    state.counters["mask_MB"] = parameter("mask_bytes") / 1e6;
    state.counters["bin_KB"] = parameter("bin_bytes") / 1e3;
    state.counters["sorted_MB"] = parameter("sorted_bytes") / 1e6;
    state.counters["mask_pairs"] = parameter("tile_light_pairs");
    state.counters["cluster_pairs"] =
        std::stod(clusteredResult.parameters.at("cluster_light_pairs"));
    uint64_t zbinnedEvaluated = 0, clusteredEvaluated = 0;
    for (uint32_t n : zbinnedResult.lightsEvaluated)
        zbinnedEvaluated += n;
    for (uint32_t n : clusteredResult.lightsEvaluated)
        clusteredEvaluated += n;
    state.counters["zbinned_evals_M"] = 1e-6 * double(zbinnedEvaluated);
    state.counters["clustered_evals_M"] = 1e-6 * double(clusteredEvaluated);
    state.counters["peak_rss_MB"] = peakResidentMegabytes();
}
BENCHMARK(zbinnedVsClustered)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

} // namespace
