// Depth-only rasterization (issue 31's target: >= 15 Mtri/s per core; the shadow maps' path,
// raster::DepthOnly): the camera view of `atrium` at 1280x720, default and dense (detail=8,
// ~300k triangles, the shape of the 308,696-triangle scene), with back faces culled and a
// closer test, drawn by the depth-only span path and by the generic per-pixel path (a no-op
// fragment function) ALTERNATELY in the same minutes, so their ratio is measured under the same
// load. Reports the minimum and median ms per draw of each path, Mtri/s of the span path per
// thread (input triangles / median time / threads) and the ratio.
//   build/bin/testbed_bench --benchmark_filter=depthOnlyDraw --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/visibility/VisibilityPass.h"
#include "raster/Rasterizer.h"
#include "tests/bench/BenchScenes.h"

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// range(0): threads; range(1): atrium detail.
void depthOnlyDraw(benchmark::State& state) {
    const int threads = int(state.range(0));
    const int detail = int(state.range(1));
    tbb::task_arena arena(threads);
    const bench::BenchScene frame("atrium", 0, {{"detail", std::to_string(detail)}});
    gbuffer::VisibilityPass visibility;
    arena.execute([&] { visibility.transform(frame.scene, frame.geometry, frame.view); });
    const raster::TriangleList triangles{visibility.clipPositions(), frame.geometry.indices};
    raster::RasterState rasterState = visibility.drawState();
    rasterState.barycentrics = false;
    raster::Rasterizer rasterizer(bench::kWidth, bench::kHeight);
    std::vector<float> depth(size_t(bench::kWidth) * bench::kHeight);
    std::vector<double> spanMs, genericMs;
    uint64_t covered[2] = {0, 0};
    auto timeDraw = [&](bool span) {
        std::fill(depth.begin(), depth.end(), frame.view.clearDepth());
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] {
            if (span)
                rasterizer.draw(triangles, rasterState, depth.data(), raster::DepthOnly{});
            else
                rasterizer.draw(triangles, rasterState, depth.data(),
                                [](const raster::Fragment&) {});
        });
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        covered[span ? 0 : 1] = rasterizer.lastStats().samplesCovered;
        return ms;
    };
    for (auto _ : state) {
        const double span = timeDraw(true);
        genericMs.push_back(timeDraw(false));
        spanMs.push_back(span);
        state.SetIterationTime(span / 1e3);
    }
    const double triangleCount = double(triangles.triangleCount());
    state.counters["triangles"] = triangleCount;
    state.counters["span_ms_min"] = *std::min_element(spanMs.begin(), spanMs.end());
    state.counters["span_ms_med"] = median(spanMs);
    state.counters["generic_ms_min"] = *std::min_element(genericMs.begin(), genericMs.end());
    state.counters["generic_ms_med"] = median(genericMs);
    state.counters["speedup_med"] = median(genericMs) / median(spanMs);
    state.counters["Mtri/s/thread"] = triangleCount / (median(spanMs) * 1e3) / double(threads);
    state.counters["same_coverage"] = covered[0] == covered[1] ? 1.0 : 0.0;
}

BENCHMARK(depthOnlyDraw)
    ->ArgsProduct({{1, 2}, {1, 8}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(15);

// The visibility draw (gbuffer::VisibilityPass::draw, the G-buffer pass's traversal) at 1, 2, 4
// and 8 samples on the atrium default, 2 threads: what multisampling costs the traversal (issue
// 28's G-buffer ratio). Reports the minimum and median draw (clears included: they run inside
// the draw), the traversal phase alone, samples covered and fragments.
//   build/bin/testbed_bench --benchmark_filter=visibilityDraw --benchmark_counters_tabular=true
void visibilityDraw(benchmark::State& state) {
    const int samples = int(state.range(0));
    tbb::task_arena arena(2);
    const bench::BenchScene frame("atrium", 0);
    gbuffer::VisibilityPass visibility;
    arena.execute([&] { visibility.transform(frame.scene, frame.geometry, frame.view); });
    raster::Rasterizer rasterizer(bench::kWidth, bench::kHeight);
    std::vector<float> depth(size_t(bench::kWidth) * bench::kHeight * size_t(samples));
    std::vector<double> drawMs, traversalMs;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] { visibility.draw(rasterizer, depth, samples); });
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        drawMs.push_back(ms);
        traversalMs.push_back(rasterizer.lastPhaseTimes().traversalMs);
        state.SetIterationTime(ms / 1e3);
    }
    const raster::RasterStats& stats = rasterizer.lastStats();
    state.counters["draw_ms_min"] = *std::min_element(drawMs.begin(), drawMs.end());
    state.counters["draw_ms_med"] = median(drawMs);
    state.counters["traversal_ms_min"] = *std::min_element(traversalMs.begin(), traversalMs.end());
    state.counters["samples_covered_M"] = 1e-6 * double(stats.samplesCovered);
    state.counters["fragments_M"] = 1e-6 * double(stats.fragments);
}

BENCHMARK(visibilityDraw)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(15);

} // namespace
