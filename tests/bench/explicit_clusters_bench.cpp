// Explicit (unique) clusters vs the implicit grid (issue 30, item 3): `clustered` (24x12x32 grid),
// `clustered-explicit` (32x32 tiles, exponential slices, back-face cones) and
// `clustered-explicit:normals=3` (plus the paper's 3x3 normal cells per cube face) on atrium
// 1280x720 with constant-overlap lights (scenes/procedural/LightGenerator.h), 10^3, 10^4 and
// 10^5 lights. Paired: each iteration shades the same frame with the three stages one after the
// other, so their ratios are measured under the same machine load. Reported per stage (prefix
// imp_, exp_, expn_): clusters (implicit: the grid's; explicit: unique clusters), (cluster,
// light) pairs, light evaluations per covered pixel, culling efficiency (oracle / evaluated),
// and the min and median over the iterations of the cluster finding, assignment and shading
// passes and of the whole shade() (ms). A summary table goes to stderr.
//   testbed_bench --benchmark_filter=explicitClusters --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lighting/Oracle.h"
#include "lighting/StageRegistry.h"
#include "lighting/passes/PassNames.h"
#include "tests/bench/BenchScenes.h"

namespace {

struct OverlapScene : lighting::PreparedScene {
    uint64_t oracleSamples = 0;
    uint64_t coveredPixels = 0;

    static scenes::Scene build(int lightCount) {
        scenes::SceneRequest request;
        request.lightCount = lightCount;
        request.seed = 1;
        request.lightDensity = scenes::LightDensity::ConstantOverlap;
        return scenes::buildProceduralScene("atrium", request);
    }
    explicit OverlapScene(int lightCount)
        : lighting::PreparedScene(build(lightCount), bench::kWidth, bench::kHeight) {
        for (uint32_t n : lighting::countContributingLights(inputs))
            oracleSamples += n;
        for (size_t p = 0; p < size_t(bench::kWidth) * bench::kHeight; ++p)
            coveredPixels += gbuffer->covered(p) ? 1 : 0;
    }
};

const OverlapScene& overlapScene(int lightCount) {
    static std::map<int, std::unique_ptr<OverlapScene>> frames;
    auto& slot = frames[lightCount];
    if (!slot)
        slot = std::make_unique<OverlapScene>(lightCount);
    return *slot;
}

struct Variant {
    const char* prefix;
    const char* spec;
};
constexpr Variant kVariants[] = {
    {"imp", "clustered"}, {"exp", "clustered-explicit"}, {"expn", "clustered-explicit:normals=3"}};

double passMs(const lighting::StageResult& result, const char* pass) {
    double ms = 0.0;
    for (const auto& [name, value] : result.timingsMs)
        if (name == pass)
            ms += value;
    return ms;
}

double minOf(std::vector<double> v) {
    return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
}
double medianOf(std::vector<double> v) {
    if (v.empty())
        return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

void explicitClustersVsImplicit(benchmark::State& state) {
    const int lightCount = int(state.range(0));
    const OverlapScene& f = overlapScene(lightCount);
    constexpr size_t kCount = std::size(kVariants);
    std::unique_ptr<lighting::ShadingStage> stages[kCount];
    lighting::StageResult results[kCount];
    // Per variant: clusters, assign, shading, whole shade() per iteration.
    std::vector<double> times[kCount][4];
    for (size_t v = 0; v < kCount; ++v)
        stages[v] = lighting::makeStage(kVariants[v].spec);
    for (auto _ : state) {
        double total = 0.0;
        for (size_t v = 0; v < kCount; ++v) {
            const auto start = std::chrono::steady_clock::now();
            stages[v]->shade(f.inputs, results[v]);
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
            total += ms;
            times[v][0].push_back(passMs(results[v], lighting::pass::kClusters));
            times[v][1].push_back(passMs(results[v], lighting::pass::kAssign));
            times[v][2].push_back(passMs(results[v], lighting::pass::kShading));
            times[v][3].push_back(ms);
        }
        state.SetIterationTime(1e-3 * total);
    }
    std::fprintf(stderr,
                 "\n%d constant-overlap lights, atrium %dx%d, %llu covered pixels, oracle %.2f "
                 "lights/pixel, %d iterations (ms: min / median)\n",
                 lightCount, bench::kWidth, bench::kHeight,
                 static_cast<unsigned long long>(f.coveredPixels),
                 double(f.oracleSamples) / double(f.coveredPixels), int(state.iterations()));
    std::fprintf(stderr, "%-30s %9s %11s %9s %8s %15s %15s %15s %15s\n", "stage", "clusters",
                 "pairs", "evals/px", "eff", "find", "assign", "shading", "shade()");
    for (size_t v = 0; v < kCount; ++v) {
        const lighting::StageResult& r = results[v];
        uint64_t evaluated = 0;
        for (uint32_t n : r.lightsEvaluated)
            evaluated += n;
        const auto parameter = [&](const char* key) {
            const auto it = r.parameters.find(key);
            return it == r.parameters.end() ? 0.0 : std::stod(it->second);
        };
        // The implicit grid's clusters are its grid cells (24x12x32 by default).
        double clusters = parameter("unique_clusters");
        if (clusters == 0.0) {
            int x = 0, y = 0, z = 0;
            std::sscanf(r.parameters.at("grid").c_str(), "%dx%dx%d", &x, &y, &z);
            clusters = double(x) * y * z;
        }
        const double pairs = parameter("cluster_light_pairs");
        const double perPixel = double(evaluated) / double(std::max<uint64_t>(f.coveredPixels, 1));
        const double efficiency =
            double(f.oracleSamples) / double(std::max<uint64_t>(evaluated, 1));
        const std::string p = kVariants[v].prefix;
        state.counters[p + "_clusters"] = clusters;
        state.counters[p + "_pairs"] = pairs;
        state.counters[p + "_evals_px"] = perPixel;
        state.counters[p + "_eff"] = efficiency;
        state.counters[p + "_find_ms"] = minOf(times[v][0]);
        state.counters[p + "_assign_ms"] = minOf(times[v][1]);
        state.counters[p + "_shading_ms"] = minOf(times[v][2]);
        state.counters[p + "_shade_ms"] = minOf(times[v][3]);
        if (parameter("cluster_bytes") > 0.0)
            state.counters[p + "_bytes"] = parameter("cluster_bytes");
        std::fprintf(stderr,
                     "%-30s %9.0f %11.0f %9.2f %8.3f %7.1f/%7.1f %7.1f/%7.1f %7.1f/%7.1f "
                     "%7.1f/%7.1f\n",
                     kVariants[v].spec, clusters, pairs, perPixel, efficiency, minOf(times[v][0]),
                     medianOf(times[v][0]), minOf(times[v][1]), medianOf(times[v][1]),
                     minOf(times[v][2]), medianOf(times[v][2]), minOf(times[v][3]),
                     medianOf(times[v][3]));
    }
    state.counters["lights"] = lightCount;
    state.counters["oracle_px"] = double(f.oracleSamples) / double(f.coveredPixels);
}
BENCHMARK(explicitClustersVsImplicit)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(7);

} // namespace
