// What anti-aliasing costs each stage (issue 28's targets): atrium at 1280x720, 256 lights,
// 2 threads, the stage's derived G-buffer layout. One benchmark per (stage, samples, detection)
// renders the 1-sample frame and the multisampled one ALTERNATELY in the same minutes and reports
// their ratios (frame, G-buffer pass, G-buffer bytes as the fragment layers store them), the
// complex fraction and the surfaces shaded per covered pixel, with minimum and median times, and
// the G-buffer pass's phases (rasterization, fragment layers, resolve; minimum, 1x beside) and the
// stage's runs (layer 0, then the other fragments: the packed run or the layers above;
// MultisampleShading::runMs).
// Targets at 4x: frame <= 2.0x (tiled, clustered), G-buffer pass <= 2.5x, bytes <= 2.5x.
//   build/bin/testbed_bench --benchmark_filter=msaaCost --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/MultisampleShading.h"
#include "lighting/StageRegistry.h"
#include "tests/bench/BenchScenes.h"

namespace {

const char* const kStages[] = {"brute", "deferred",       "light-indexed", "clustered",
                               "tiled", "tiled-backface", "light-prepass", "inferred"};

struct Sampled {
    std::vector<double> frameMs, gbufferMs;
    std::vector<double> rasterMs, layersMs, resolveMs; // the G-buffer pass's phases
    std::vector<double> shadeMainMs, shadeUpperMs;     // the stage on layer 0, on the others
    void add(double frame, const gbuffer::GBufferPassTimings& t) {
        frameMs.push_back(frame);
        gbufferMs.push_back(t.transformMs + t.rasterMs + t.layersMs + t.resolveMs);
        rasterMs.push_back(t.rasterMs);
        layersMs.push_back(t.layersMs);
        resolveMs.push_back(t.resolveMs);
    }
    static double median(std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    }
    static double min(const std::vector<double>& v) {
        return *std::min_element(v.begin(), v.end());
    }
};

void msaaCost(benchmark::State& state) {
    const std::string stageName = kStages[state.range(0)];
    const int samples = int(state.range(1));
    const auto detection = state.range(2) == 0 ? gbuffer::ComplexDetection::Primitive
                                               : gbuffer::ComplexDetection::Discontinuity;
    state.SetLabel(stageName + " " + std::to_string(samples) + "x " +
                   gbuffer::complexDetectionName(detection));
    tbb::task_arena arena(2);
    const auto stage = lighting::makeStage(stageName);
    std::unique_ptr<lighting::PreparedScene> frames[2];
    arena.execute([&] {
        for (int i = 0; i < 2; ++i) {
            scenes::Scene scene = bench::proceduralScene("atrium", 256);
            const gbuffer::GBufferLayout layout =
                gbuffer::deriveLayout(scene, stage->requirements().channels);
            lighting::Multisampling multisampling;
            multisampling.samples = i == 0 ? 1 : samples;
            multisampling.layers.detection = detection;
            frames[i] = std::make_unique<lighting::PreparedScene>(
                std::move(scene), bench::kWidth, bench::kHeight, false, layout, multisampling);
        }
    });
    lighting::MultisampleShading shading[2];
    lighting::StageResult results[2];
    Sampled measured[2];
    for (auto _ : state) {
        double iteration = 0.0;
        for (int i = 0; i < 2; ++i) {
            const auto start = std::chrono::steady_clock::now();
            arena.execute([&] {
                frames[i]->renderGBuffer();
                shading[i].shade(*stage, *frames[i], results[i]);
            });
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
            measured[i].add(ms, frames[i]->gbufferTimings);
            const std::vector<double>& runs = shading[i].runMs();
            measured[i].shadeMainMs.push_back(runs.front());
            measured[i].shadeUpperMs.push_back(std::accumulate(runs.begin() + 1, runs.end(), 0.0));
            if (i == 1)
                iteration = ms;
        }
        state.SetIterationTime(iteration / 1e3);
    }
    const gbuffer::FragmentLayers& layers = frames[1]->multisample->layers;
    const double bytesPerPixel = frames[0]->gbuffer->layout().bytesPerPixel();
    const double oneSampleBytes = bytesPerPixel * double(layers.pixelCount());
    state.counters["frame_1x_ms_med"] = Sampled::median(measured[0].frameMs);
    state.counters["frame_ms_med"] = Sampled::median(measured[1].frameMs);
    state.counters["frame_ms_min"] = Sampled::min(measured[1].frameMs);
    state.counters["frame_ratio_med"] =
        Sampled::median(measured[1].frameMs) / Sampled::median(measured[0].frameMs);
    state.counters["frame_ratio_min"] =
        Sampled::min(measured[1].frameMs) / Sampled::min(measured[0].frameMs);
    state.counters["gbuffer_ratio_min"] =
        Sampled::min(measured[1].gbufferMs) / Sampled::min(measured[0].gbufferMs);
    // The G-buffer pass's phases (minimum over the iterations): rasterization, the fragment
    // layers' build, the resolve of every layer; 1x beside.
    state.counters["raster_1x_ms_min"] = Sampled::min(measured[0].rasterMs);
    state.counters["resolve_1x_ms_min"] = Sampled::min(measured[0].resolveMs);
    state.counters["raster_ms_min"] = Sampled::min(measured[1].rasterMs);
    state.counters["layers_ms_min"] = Sampled::min(measured[1].layersMs);
    state.counters["resolve_ms_min"] = Sampled::min(measured[1].resolveMs);
    // The stage's runs (minimum): on layer 0 (1x: the whole shading) and on the other fragments
    // (the packed run of tiled and clustered, else the layers above; with the background run).
    state.counters["shade_1x_ms_min"] = Sampled::min(measured[0].shadeMainMs);
    state.counters["shade_main_ms_min"] = Sampled::min(measured[1].shadeMainMs);
    state.counters["shade_upper_ms_min"] = Sampled::min(measured[1].shadeUpperMs);
    state.counters["bytes_ratio"] = layers.storedBytes(bytesPerPixel) / oneSampleBytes;
    state.counters["alloc_ratio"] = layers.allocatedBytes(bytesPerPixel) / oneSampleBytes;
    state.counters["complex_frac"] = layers.complexFraction();
    state.counters["surfaces/px"] =
        double(layers.counts().fragments) / double(layers.counts().coveredPixels);
}

void allStages(benchmark::internal::Benchmark* b) {
    for (int stage = 0; stage < int(std::size(kStages)); ++stage)
        for (int detection : {0, 1})
            b->Args({stage, 4, detection});
    for (int samples : {2, 8})
        b->Args({4, samples, 1}); // tiled at 2x and 8x
}
BENCHMARK(msaaCost)
    ->Apply(allStages)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

} // namespace
