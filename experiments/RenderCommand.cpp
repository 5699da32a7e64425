#include "experiments/RenderCommand.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <thread>

#include <unistd.h>

#include "experiments/AtomicFile.h"
#include "experiments/ImageOutput.h"
#include "lighting/StageRegistry.h"
#include "scenes/Scene.h"

#ifndef TESTBED_COMMIT
#define TESTBED_COMMIT "unknown"
#endif

namespace experiments {

namespace {

// Z layer: view-space depth in metres (positive, along the view direction), 0 = background.
std::vector<float> viewDepthMetres(const gbuffer::GBuffer& gb) {
    std::vector<float> depth(gb.pixelCount(), 0.0f);
    for (int y = 0; y < gb.height(); ++y)
        for (int x = 0; x < gb.width(); ++x) {
            const size_t pixel = size_t(y) * gb.width() + x;
            if (gb.covered(pixel))
                depth[pixel] = -gb.reconstructPositionView(x, y, gb.depth()[pixel]).z;
        }
    return depth;
}

std::vector<float> toFloat(const std::vector<uint32_t>& counts) {
    return std::vector<float>(counts.begin(), counts.end());
}

void writeOutputs(const RenderRun& run, const RenderCommandOptions& options, const nlohmann::json& stats) {
    const gbuffer::GBuffer& gb = run.gbuffer();
    const int w = gb.width(), h = gb.height();
    const std::vector<float> z = viewDepthMetres(gb);
    const std::vector<float> evaluated = toFloat(run.result.lightsEvaluated);
    const std::vector<float> oracle = toFloat(run.oracle);
    // Evaluations that added nothing: the culling stage's waste at each pixel.
    std::vector<float> wasted(evaluated.size());
    for (size_t pixel = 0; pixel < wasted.size(); ++pixel) wasted[pixel] = evaluated[pixel] - oracle[pixel];
    std::vector<ImagePlane> planes = {
        {"R", run.result.radiance[0].data()},
        {"G", run.result.radiance[1].data()},
        {"B", run.result.radiance[2].data()},
        {"N.X", gb.normalPlane(0).data()},
        {"N.Y", gb.normalPlane(1).data()},
        {"N.Z", gb.normalPlane(2).data()},
        {"Z", z.data()},
        {"albedo.R", gb.albedoPlane(0).data()},
        {"albedo.G", gb.albedoPlane(1).data()},
        {"albedo.B", gb.albedoPlane(2).data()},
        {"lights.evaluated", evaluated.data()},
        {"lights.oracle", oracle.data()},
        {"lights.wasted", wasted.data()},
    };
    std::vector<std::pair<std::string, std::string>> metadata = {
        {"testbed:scene", run.options.scene},
        {"testbed:stage", run.options.stage},
        {"testbed:commit", TESTBED_COMMIT},
        {"testbed:stats", stats.dump()},
        {"testbed:Z", "view-space depth in metres, 0 = background"},
    };
    writeMultiLayerExr(options.out / "render.exr", w, h, planes, metadata);
    writePreviewPng(options.out / "preview.png", w, h, run.result.radiance[0].data(),
                    run.result.radiance[1].data(), run.result.radiance[2].data());
    writeHeatmapPng(options.out / "heatmap.png", w, h, run.result.lightsEvaluated.data(),
                    options.heatmapMax);
    writeTextAtomically(options.out / "stats.json", stats.dump(2) + "\n");
}

}  // namespace

nlohmann::json statsJson(const RenderRun& run) {
    nlohmann::json stats;
    stats["scene"] = run.scene().name;
    stats["scene_source"] = run.options.scene;
    stats["scene_options"] = run.options.sceneOptions;
    stats["stage"] = run.options.stage;
    stats["stage_parameters"] = run.result.parameters;
    stats["width"] = run.options.width;
    stats["height"] = run.options.height;
    stats["threads"] = run.threads;
    stats["hardware_threads"] = std::thread::hardware_concurrency();
    stats["commit"] = TESTBED_COMMIT;
    stats["triangles"] = run.scene().triangleCount();
    stats["lights"] = run.scene().lights.size();
    stats["generated_lights"] = run.options.lights;
    stats["seed"] = run.options.seed;
    const gbuffer::GBufferLayout& layout = run.gbuffer().layout();
    nlohmann::json planes = nlohmann::json::array();
    for (const gbuffer::ChannelDesc& channel : layout.channels)
        for (const gbuffer::PlaneDesc& plane : channel.planes)
            planes.push_back({{"name", plane.name},
                              {"channel", gbuffer::channelName(channel.channel)},
                              {"encoding", channel.encoding},
                              {"format", plane.format},
                              {"bits", plane.bits}});
    stats["layout"] = {{"name", layout.name}, {"planes", planes}, {"bytes_per_pixel", layout.bytesPerPixel()}};
    stats["bytes_per_pixel"] = layout.bytesPerPixel();
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [pass, ms] : run.timingsMs) timings[pass] = ms;
    stats["timings_ms"] = timings;
    stats["gbuffer_steps_ms"] = {{"transform", run.prepared->gbufferTimings.transformMs},
                                 {"raster", run.prepared->gbufferTimings.rasterMs},
                                 {"resolve", run.prepared->gbufferTimings.resolveMs},
                                 {"exact_surface", run.prepared->gbufferTimings.exactMs}};
    stats["measurement_ms"] = {{"oracle", run.oracleMs}, {"reference", run.referenceMs}};
    const uint64_t evaluations = run.lightEvaluations(), oracle = run.oracleLightEvaluations();
    stats["light_evaluations"] = evaluations;
    stats["oracle_light_evaluations"] = oracle;
    stats["culling_efficiency"] = evaluations > 0 ? double(oracle) / double(evaluations) : 1.0;
    stats["raster"] = {{"triangles_in", run.prepared->rasterStats.trianglesIn},
                       {"triangles_culled", run.prepared->rasterStats.trianglesCulled},
                       {"triangles_clipped", run.prepared->rasterStats.trianglesClipped},
                       {"triangles_set_up", run.prepared->rasterStats.trianglesSetUp},
                       {"samples_covered", run.prepared->rasterStats.samplesCovered},
                       {"samples_passed", run.prepared->rasterStats.samplesPassed}};
    if (run.error) {
        stats["error"] = {{"reference", "reference"},
                          {"rmse", run.error->rmse},
                          {"relative_rmse", run.error->relativeRmse},
                          {"max_abs", run.error->maxAbs},
                          {"psnr", std::isfinite(run.error->psnr) ? nlohmann::json(run.error->psnr)
                                                                  : nlohmann::json("inf")}};
    }
    stats["warnings"] = run.scene().warnings;
    return stats;
}

int runRenderCommand(const RenderCommandOptions& options) {
    try {
        validate(options.render);
        ensureWritableDirectory(options.out);
        const bool terminal = isatty(STDERR_FILENO);
        const auto start = std::chrono::steady_clock::now();
        auto progress = [&](const std::string& step) {
            if (!terminal) return;
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            std::cerr << "[" << std::fixed << std::setprecision(1) << seconds << " s] " << step << "\n";
        };
        const RenderRun run = runRender(options.render, progress);
        progress("writing outputs");
        const nlohmann::json stats = statsJson(run);
        writeOutputs(run, options, stats);
        std::cout << "testbed: " << run.options.stage << " on " << run.scene().name << " ("
                  << run.scene().triangleCount() << " triangles, " << run.scene().lights.size()
                  << " lights) at " << run.options.width << "x" << run.options.height << ", "
                  << run.threads << " threads\n";
        for (const auto& [pass, ms] : run.timingsMs)
            std::cout << "  " << pass << ": " << std::fixed << std::setprecision(2) << ms << " ms\n";
        if (run.error)
            std::cout << "  error vs reference: rmse " << std::scientific << run.error->rmse
                      << ", max_abs " << run.error->maxAbs << ", relative rmse "
                      << run.error->relativeRmse << "\n";
        std::cout << "outputs in " << std::filesystem::absolute(options.out).string() << ":\n";
        for (const char* file : {"render.exr", "preview.png", "heatmap.png", "stats.json"})
            std::cout << "  " << (options.out / file).string() << "\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "testbed: error: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace experiments
