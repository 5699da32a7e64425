// Light assignment with and without the light BVH (lighting/culling/LightBvh.h), on atrium at
// 1280x720 with constant-overlap lights (scenes::LightDensity::ConstantOverlap: the expected number
// of lights reaching a point stays that of 10^3 lights, so the curve measures scaling, not
// overlap), 10^3 .. 10^6 lights, with 1 and 2 threads (tbb::task_arena). Rows:
//   build                  LightBvh::build over the frame's light spheres alone
//   clusters walk | bvh    ClusterGrid::assign on the default grid 24x12x32 (bvh: build included)
//   tiles loop | bvh [hier]  buildTileLightLists, 16-pixel tiles, vfc on (tile bounds from the
//                          G-buffer computed outside: they do not depend on the lights)
//   clustered:assign=walk | bvh  the stage's whole "assign" pass (depth range, grid, spheres,
//                          lists), the figure of the 2 ms target; shading_ms beside it
// One iteration per repetition after an untimed warm-up call (storage is then reused, as it is
// from frame to frame in a stage), three repetitions: the aggregates report the median and the
// minimum. Manual time = that pass (or the build); counters: the shading pass, the list pairs
// (equal between the rows of one stage: the lists are the same) and the light count. Frames are
// prepared once per light count (only one kept, they are large at 10^6). The log-log slope of
// assignment time against the light count is fitted from the JSON output
// (lighting/culling/README.md has the command). Ratios between rows of one run are what to quote:
// the machine is shared.
//   testbed_bench --benchmark_filter=lightBvh --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include <tbb/task_arena.h>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/ClusterGrid.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightBvh.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/passes/PassNames.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/bench/BenchScenes.h"

namespace {

struct BvhBenchScene {
    int lightCount = 0;
    std::unique_ptr<lighting::PreparedScene> prepared;
    std::vector<lighting::LightSphere> spheres;
    lighting::TileGrid tiles;
    std::vector<lighting::TileSurfaceBounds> tileBounds;
    float nearDepthMetres = 0.0f, farDepthMetres = 0.0f; // of the covered samples
};

const BvhBenchScene& benchScene(int lightCount) {
    static BvhBenchScene scene;
    if (scene.lightCount != lightCount) {
        scene.prepared.reset();
        scenes::SceneRequest request;
        request.lightCount = lightCount;
        request.seed = 1;
        request.lightDensity = scenes::LightDensity::ConstantOverlap;
        scene.prepared = std::make_unique<lighting::PreparedScene>(
            scenes::buildProceduralScene("atrium", request), bench::kWidth, bench::kHeight);
        scene.spheres = lighting::boundingSpheresView(scene.prepared->lights);
        const gbuffer::GBuffer& gb = *scene.prepared->gbuffer;
        scene.tiles = lighting::TileGrid::make(gb.width(), gb.height(), 16);
        scene.tileBounds = lighting::computeTileSurfaceBounds(gb, scene.tiles, {});
        scene.nearDepthMetres = INFINITY;
        scene.farDepthMetres = 0.0f;
        for (int y = 0; y < gb.height(); ++y)
            for (int x = 0; x < gb.width(); ++x)
                if (gb.covered(size_t(y) * size_t(gb.width()) + size_t(x))) {
                    const float depth = -gb.decode(x, y).positionView.z;
                    scene.nearDepthMetres = std::min(scene.nearDepthMetres, depth);
                    scene.farDepthMetres = std::max(scene.farDepthMetres, depth);
                }
        scene.lightCount = lightCount;
    }
    return scene;
}

const char* const kRows[] = {"build",
                             "clusters walk",
                             "clusters bvh",
                             "tiles loop",
                             "tiles bvh",
                             "tiles loop hier",
                             "tiles bvh hier",
                             "clustered:assign=walk",
                             "clustered:assign=bvh"};

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void lightBvh(benchmark::State& state) {
    const int lightCount = int(state.range(0));
    const int row = int(state.range(1));
    const int threads = int(state.range(2));
    state.SetLabel(std::string(kRows[row]) + " threads=" + std::to_string(threads));
    const BvhBenchScene& f = benchScene(lightCount);
    const gbuffer::CameraView& view = f.prepared->gbuffer->view();
    tbb::task_arena arena(threads);
    lighting::LightBvh bvh;
    if (row == 0) {
        arena.execute([&] { bvh.build(f.spheres); }); // warm-up: storage reused, as per frame
        for (auto _ : state) {
            const auto start = std::chrono::steady_clock::now();
            arena.execute([&] { bvh.build(f.spheres); });
            state.SetIterationTime(secondsSince(start));
        }
        state.counters["nodes"] = double(bvh.nodes().size());
    } else if (row <= 2) {
        // ClusterGrid::assign alone on the stage's default grid (grid geometry built outside).
        lighting::ClusterGridOptions options;
        options.assign = row == 2 ? lighting::AssignMethod::Bvh : lighting::AssignMethod::Walk;
        lighting::ClusterGrid grid(options, view, f.nearDepthMetres, f.farDepthMetres);
        arena.execute([&] { grid.assign(f.spheres); }); // warm-up
        for (auto _ : state) {
            const auto start = std::chrono::steady_clock::now();
            arena.execute([&] { grid.assign(f.spheres); });
            state.SetIterationTime(secondsSince(start));
        }
        state.counters["pairs"] = double(grid.pairCount());
    } else if (row <= 6) {
        // buildTileLightLists alone (tile 16, vfc on; tile bounds computed outside).
        lighting::TileCullOptions options{true, false, false};
        options.assign =
            row == 4 || row == 6 ? lighting::TileAssign::Bvh : lighting::TileAssign::Loop;
        options.hierarchical = row >= 5;
        lighting::LightIndexLists lists;
        arena.execute([&] { // warm-up
            lighting::buildTileLightLists(view, f.tiles, f.tileBounds, f.spheres, options, lists,
                                          &bvh);
        });
        for (auto _ : state) {
            const auto start = std::chrono::steady_clock::now();
            arena.execute([&] {
                lighting::buildTileLightLists(view, f.tiles, f.tileBounds, f.spheres, options,
                                              lists, &bvh);
            });
            state.SetIterationTime(secondsSince(start));
        }
        state.counters["pairs"] = double(lists.pairCount());
    } else {
        // The clustered stage's "assign" pass (depth range, grid, spheres, lists).
        const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(kRows[row]);
        lighting::StageResult result;
        double shadingMs = 0.0;
        arena.execute([&] { stage->shade(f.prepared->inputs, result); }); // warm-up
        for (auto _ : state) {
            arena.execute([&] { stage->shade(f.prepared->inputs, result); });
            double passMs = 0.0;
            for (const auto& [name, ms] : result.timingsMs) {
                if (name == lighting::pass::kAssign)
                    passMs += ms;
                if (name == lighting::pass::kShading)
                    shadingMs += ms;
            }
            state.SetIterationTime(1e-3 * passMs);
        }
        state.counters["shading_ms"] = shadingMs / double(state.iterations());
        state.counters["pairs"] = std::stod(result.parameters.at("cluster_light_pairs"));
    }
    state.counters["lights"] = lightCount;
    state.counters["threads"] = threads;
}
// Light count outermost (one prepared frame at a time), then row, then threads.
BENCHMARK(lightBvh)
    ->Apply([](benchmark::internal::Benchmark* b) {
        for (int lightCount : {1000, 10000, 100000, 1000000})
            for (int row = 0; row < int(std::size(kRows)); ++row)
                for (int threads : {2, 1})
                    b->Args({lightCount, row, threads});
    })
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ComputeStatistics("min",
                        [](const std::vector<double>& v) {
                            return *std::min_element(v.begin(), v.end());
                        })
    ->ReportAggregatesOnly(true);

} // namespace

// Where hierarchical tile culling pays: buildTileLightLists with the loop, flat vs 4x4 groups
// (hier=1), over tile sizes and few lights (same frames, constant overlap; 1 thread).
//   testbed_bench --benchmark_filter=lightBvhHier --benchmark_counters_tabular=true
void lightBvhHier(benchmark::State& state) {
    const int lightCount = int(state.range(0));
    const int tileSize = int(state.range(1));
    const bool hierarchical = state.range(2) != 0;
    state.SetLabel(std::string(hierarchical ? "hier=1" : "hier=0") +
                   " tile=" + std::to_string(tileSize));
    const BvhBenchScene& f = benchScene(lightCount);
    const gbuffer::GBuffer& gb = *f.prepared->gbuffer;
    const lighting::TileGrid tiles = lighting::TileGrid::make(gb.width(), gb.height(), tileSize);
    const std::vector<lighting::TileSurfaceBounds> bounds =
        lighting::computeTileSurfaceBounds(gb, tiles, {});
    lighting::TileCullOptions options{true, false, false};
    options.hierarchical = hierarchical;
    lighting::LightIndexLists lists;
    tbb::task_arena arena(1);
    auto build = [&] {
        lighting::buildTileLightLists(gb.view(), tiles, bounds, f.spheres, options, lists);
    };
    arena.execute(build); // warm-up
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute(build);
        state.SetIterationTime(secondsSince(start));
    }
    state.counters["pairs"] = double(lists.pairCount());
    state.counters["lights"] = lightCount;
}
BENCHMARK(lightBvhHier)
    ->Apply([](benchmark::internal::Benchmark* b) {
        for (int lightCount : {10, 100, 1000})
            for (int tileSize : {8, 16, 32, 64})
                for (int hier : {0, 1})
                    b->Args({lightCount, tileSize, hier});
    })
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(5)
    ->ComputeStatistics("min",
                        [](const std::vector<double>& v) {
                            return *std::min_element(v.begin(), v.end());
                        })
    ->ReportAggregatesOnly(true);
