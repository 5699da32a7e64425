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

#include "lighting/PreparedFrame.h"
#include "lighting/ShadingStage.h"
#include "scenes/Scene.h"

namespace experiments {

// Every option of a render, with its default in one place (the CLI's --help shows these).
struct RenderOptions {
    std::string scene = "atrium";
    std::map<std::string, std::string> sceneOptions;  // --scene-option key=value
    std::string stage = "brute";
    int lights = 256;
    uint64_t seed = 1;
    int width = 1280;
    int height = 720;
    int threads = 0;  // 0 = every hardware thread
    bool compareReference = false;
    // G-buffer: a preset name ("" = derived from the scene and the stage, gbuffer/LayoutDerivation.h),
    // then overrides of its normal encoding ("NAME:BITS"), depth format and position method.
    std::string layout;
    std::string normals;
    std::string depth;
    std::string position;
};

// Sets one option from text, by the name the CLI and sweep files use: scene, stage, lights,
// seed, width, height, resolution (WxH), threads, layout, normals, depth, position, and
// scene-option.KEY. Values are checked later by validate(); a malformed number or an unknown
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

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws UsageError with one clear message for the first bad option (unknown stage or scene,
// missing file, sizes, light count, threads). Cheap: loads nothing.
void validate(const RenderOptions& options);

struct ErrorMetrics {
    double rmse = 0.0;
    double relativeRmse = 0.0;  // rmse / rms of the reference
    double maxAbs = 0.0;
    double psnr = 0.0;          // dB, peak = the reference's maximum channel value
};

struct RenderRun {
    RenderOptions options;
    int threads = 0;  // effective
    std::unique_ptr<lighting::PreparedFrame> prepared;  // scene, G-buffer, exact surface, lights
    lighting::StageResult result;
    std::vector<uint32_t> oracle;  // per pixel, from the stage or counted by brute force
    std::vector<std::pair<std::string, double>> timingsMs;  // gbuffer, stage passes, total
    double oracleMs = 0.0;
    double referenceMs = 0.0;
    std::optional<ErrorMetrics> error;
    lighting::StageResult reference;  // filled when compareReference

    const scenes::Scene& scene() const { return prepared->scene; }
    const gbuffer::GBuffer& gbuffer() const { return *prepared->gbuffer; }
    uint64_t lightEvaluations() const;
    uint64_t oracleLightEvaluations() const;
};

// Runs under a tbb::task_arena of options.threads. Throws UsageError / scenes::SceneError /
// lighting::StageError on bad input.
// `progress`, when set, is told the name of each step as it starts (for a terminal display).
RenderRun runRender(const RenderOptions& options,
                    const std::function<void(const std::string&)>& progress = {});

ErrorMetrics compareImages(const lighting::StageResult& image, const lighting::StageResult& reference);

}  // namespace experiments
