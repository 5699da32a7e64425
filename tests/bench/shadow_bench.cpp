// Shadow-map rendering on `atrium` (issue 29's target: 16 casting point lights, cube maps of
// 512^2, 96 faces, <= 15 ms on 2 threads), at 1 and 2 threads, with the faces in parallel (one
// Rasterizer per thread) or in sequence (the rasterizer's own tile parallelism). Reports ms per
// render (manual time: mean; minimum and median beside it, as a shared machine inflates the
// mean), faces, triangles drawn and bytes.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/ShadowMaps.h"
#include "tests/bench/BenchScenes.h"

namespace {

struct ShadowFrame {
    scenes::Scene scene;
    gbuffer::SceneGeometry geometry;
    gbuffer::CameraView view;
};

// Atrium with 256 generated lights (seed 1), the first 16 point lights casting.
const ShadowFrame& atrium() {
    static const ShadowFrame frame = [] {
        ShadowFrame f;
        f.scene = bench::proceduralScene("atrium", 256);
        int casting = 0;
        for (scenes::Light& light : f.scene.lights)
            if (light.type == scenes::LightType::Point && casting < 16) {
                light.castsShadows = true;
                ++casting;
            }
        f.geometry = gbuffer::SceneGeometry::build(f.scene);
        f.view = gbuffer::CameraView::fromCamera(f.scene.cameras[0], bench::kWidth, bench::kHeight);
        return f;
    }();
    return frame;
}

// range(0): threads; range(1): 0 = faces in parallel, 1 = faces in sequence; range(2): 1 = each
// frame takes over the last frame's depth buffers (what the runner does), 0 = fresh buffers.
void shadowMapRender(benchmark::State& state) {
    const ShadowFrame& f = atrium();
    tbb::task_arena arena(int(state.range(0)));
    lighting::ShadowSettings settings;
    settings.mapSize = 512;
    settings.schedule = state.range(1) == 0 ? lighting::ShadowSchedule::FacesInParallel
                                            : lighting::ShadowSchedule::FacesInSequence;
    state.SetLabel(std::string(state.range(1) == 0 ? "faces in parallel" : "faces in sequence") +
                   (state.range(2) == 1 ? ", buffers recycled" : ", fresh buffers"));
    std::vector<double> renderMs;
    const bool recycleBuffers = state.range(2) == 1;
    lighting::ShadowStats stats;
    lighting::ShadowMaps previous; // the last frame's, whose buffers a frame may take over
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] {
            previous = lighting::ShadowMaps::render(f.scene, f.geometry, f.view, settings,
                                                    recycleBuffers ? &previous : nullptr);
            stats = previous.stats();
        });
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        state.SetIterationTime(seconds);
        renderMs.push_back(seconds * 1e3);
    }
    std::sort(renderMs.begin(), renderMs.end());
    uint64_t triangles = 0;
    for (const lighting::ShadowLightStats& light : stats.lights)
        triangles += light.trianglesDrawn;
    state.counters["render_ms_min"] = renderMs.front();
    state.counters["render_ms_median"] = renderMs[renderMs.size() / 2];
    state.counters["faces"] = double(stats.faceCount);
    state.counters["triangles_drawn"] = double(triangles);
    state.counters["scene_triangles"] = double(f.geometry.triangleCount());
    state.counters["MB"] = double(stats.totalBytes) / (1024.0 * 1024.0);
}
BENCHMARK(shadowMapRender)
    ->ArgsProduct({{1, 2}, {0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

} // namespace
