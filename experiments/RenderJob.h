// RenderJob: one render of one scene with one stage, end to end, in memory: load the scene,
// rasterize the G-buffer, shade, count the oracle, optionally compare with the reference.
// Writing files is RenderCommand's business; this is what tests and benchmarks drive directly.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/PreparedScene.h"
#include "lighting/ShadingStage.h"
#include "scenes/Scene.h"

namespace experiments {

// Every option of a render, with its default in one place (the CLI's --help shows these).
struct RenderOptions {
    std::string scene = "atrium";
    std::map<std::string, std::string> sceneOptions; // --scene-option key=value
    std::string stage = "brute";
    int lights = 256;
    uint64_t seed = 1;
    int width = 1280;
    int height = 720;
    int threads = 0; // 0 = every hardware thread
    bool compareReference = false;
    // G-buffer: a preset name ("" = derived from the scene and the stage,
    // gbuffer/LayoutDerivation.h), then overrides of its normal encoding ("NAME:BITS"), depth
    // format and position method.
    std::string layout;
    std::string normals;
    std::string depth;
    std::string position;
    std::string normalSpace; // "view" (default) or "world"
    int warmup = 0;      // untimed runs of the G-buffer pass and the stage before the timed ones
    int repetitions = 1; // timed runs; timings are reported as median, min and max over them
};

// Sets one option from text, by the name the CLI and sweep files use: scene, stage, lights,
// seed, width, height, resolution (WxH), threads, layout, normals, normal-space, depth, position,
// and scene-option.KEY. Values are checked later by validate(); a malformed number or an unknown
// key throws UsageError naming it. The sweep runner goes through this, so every stage, encoding
// or scene added later is reachable without touching the runner.
void setRenderOption(RenderOptions& options, const std::string& key, const std::string& value);
// The keys setRenderOption accepts (scene-option.KEY listed once as "scene-option.<key>").
std::vector<std::string> renderOptionKeys();

// Limits checked before any work or allocation (issue: 100000x100000 must be refused up front).
inline constexpr int kMaxImageSide = 16384;
inline constexpr uint64_t kMaxPixels = uint64_t(8192) * 8192;
inline constexpr int kMaxLights = 1'000'000;
inline constexpr int kMaxThreads = 1024;
inline constexpr int kMaxRepetitions = 1000;

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws UsageError with one clear message for the first bad option (unknown stage or scene,
// missing file, sizes, light count, threads). Cheap: loads nothing.
void validate(const RenderOptions& options);

// Over all pixels and the three colour channels.
struct ErrorMetrics {
    double rmse = 0.0;
    double relativeRmse = 0.0; // rmse / rms of the reference
    double maxAbs = 0.0;
    double psnr = 0.0;         // dB, peak = the reference's maximum channel value
    double relativeMean = 0.0; // mean |image - reference| / mean |reference|
    double p99Abs = 0.0;       // 99th percentile of |image - reference|
};

// One pass's times over the timed repetitions, in execution order of the passes.
struct PassTiming {
    std::string pass;
    std::vector<double> samplesMs;
    double medianMs() const;
    double minMs() const;
    double maxMs() const;
};

struct RenderRun {
    RenderOptions options;
    int threads = 0;                                   // effective
    std::unique_ptr<lighting::PreparedScene> prepared; // scene, G-buffer, exact surface, lights
    lighting::StageResult result;
    std::vector<uint32_t> oracle; // per pixel, from the stage or counted by brute force
    std::vector<PassTiming>
        passTimings; // gbuffer, exact_surface (reference only), stage passes, total
    std::vector<std::pair<std::string, double>> timingsMs; // the medians of passTimings
    bool oracleFromLosslessGBuffer = false; // the layout lacked channels the oracle needs
    double oracleMs = 0.0;
    double referenceMs = 0.0;
    std::optional<ErrorMetrics> error;
    lighting::StageResult reference; // filled when compared with the reference

    const scenes::Scene& scene() const { return prepared->scene; }
    const gbuffer::GBuffer& gbuffer() const { return *prepared->gbuffer; }
    uint64_t lightEvaluations() const;
    uint64_t oracleLightEvaluations() const;
};

// Runs under a tbb::task_arena of options.threads. Throws UsageError / scenes::SceneError /
// lighting::StageError on bad input.
// `progress`, when set, is told the name of each step as it starts (for a terminal display).
// When `reference` is given it is the image the error is measured against (compareReference is
// implied) and no reference is rendered: a sweep renders it once per scene, lights and size.
RenderRun runRender(const RenderOptions& options,
                    const std::function<void(const std::string&)>& progress = {},
                    const lighting::StageResult* reference = nullptr);

// The double-precision reference image of (scene, scene options, lights, seed, width, height).
// It does not depend on the stage or the G-buffer layout. Runs under options.threads.
lighting::StageResult renderReference(const RenderOptions& options);

// The G-buffer layout request of the options (throws UsageError for a bad name).
gbuffer::LayoutRequest layoutRequest(const RenderOptions& options);
// The layout a render with these options uses (loads the scene; renders nothing). Throws
// UsageError when the layout lacks a channel the stage reads.
gbuffer::GBufferLayout renderLayout(const RenderOptions& options);

ErrorMetrics compareImages(const lighting::StageResult& image,
                           const lighting::StageResult& reference);

} // namespace experiments
