// RenderJob: one planned render (RenderPlan.h) run end to end, in memory: rasterize the G-buffer,
// shade (warm-up runs, then timed repetitions), count the oracle, optionally compare with the
// reference, and compute the run's metrics (RunMetrics.h). Writing files is RenderCommand's
// business; this is what the CLI, the sweep runner, tests and benchmarks drive directly.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/render/Coverage.h"
#include "experiments/render/RenderOptions.h"
#include "experiments/render/RenderPlan.h"
#include "experiments/render/RunMetrics.h"
#include "lighting/PreparedScene.h"
#include "lighting/ShadingStage.h"
#include "lighting/shadows/RayShadows.h"
#include "lighting/shadows/ShadowError.h"
#include "lighting/shadows/ShadowMaps.h"
#include "scenes/Scene.h"

namespace experiments {

struct RenderRun {
    RenderOptions options;
    int threads = 0;                                   // effective
    std::unique_ptr<lighting::PreparedScene> prepared; // scene, G-buffer, exact surface, lights
    lighting::StageResult result;                      // of the last repetition, post-AA'd
    // The post-process anti-aliasing's edge plane of the last repetition (lighting/postaa/PostAa.h:
    // edge weight for edge-blur, blend weight for fxaa), empty for --post-aa none.
    std::vector<float> postAaEdges;
    std::vector<uint32_t> oracle;           // per pixel, from the stage or counted by brute force
    bool oracleFromLosslessGBuffer = false; // the layout lacked channels the oracle needs
    lighting::StageResult reference;        // filled when compared with the reference
    // HDR-ꟻLIP against the reference (FlipMetric.h): the per-pixel map (empty when unavailable)
    // and the package's parameters (null when unavailable); the mean is in metrics.error.
    std::vector<float> flipMap;
    nlohmann::json flipParameters;
    RunMetrics metrics;
    // `--shadows maps`: the last repetition's shadow maps (inputs.shadows points here), and the
    // reference's ray-traced visibility of the same lights (null until the reference is made).
    std::unique_ptr<lighting::ShadowMaps> shadowMaps;
    std::unique_ptr<lighting::shadows::RayShadows> rayShadows;
    // The maps' visibility misclassification against the rays (compared runs with shadows only).
    std::optional<lighting::shadows::ShadowErrorCounts> shadowError;
    // Covered pixels of the last repetition, and the warning when none is (Coverage.h).
    Coverage coverage;
    MemoryEstimate memory; // the plan's estimate (stats.json "memory")

    const scenes::Scene& scene() const { return prepared->scene; }
    const gbuffer::GBuffer& gbuffer() const { return *prepared->gbuffer; }
};

// Runs the plan under a tbb::task_arena of plan.threads. The post-process anti-aliasing
// (plan.postAa) filters each repetition's image right after the stage, timed as the pass post_aa
// (in the total, not in the stage's time); the error and the outputs see the filtered image (the
// light counts are the stage's). The reference is not filtered: it is the exact image at the
// pixel centres. When compared with a reference, the error figures include HDR-ꟻLIP
// (FlipMetric.h; unavailable without the package, saying why). `progress`, when set, is told the
// name of each step as it starts (for a terminal display). When `reference` is given it is the
// image the error is measured against (compareReference is implied) and no reference is rendered:
// a sweep renders it once per scene, lights and size. Throws UsageError when the given reference
// has another size than the render, and when the plan's memory estimate is over its limit (before
// anything is allocated).
RenderRun runRender(RenderPlan plan, const std::function<void(const std::string&)>& progress = {},
                    const lighting::StageResult* reference = nullptr);

// The double-precision reference image of (scene, scene options, lights, seed, width, height,
// reference samples per pixel): lighting::renderSupersampledReference at options.referenceSpp,
// bitwise the `reference` stage's image at 1. It does not depend on the stage or the G-buffer
// layout. Runs under options.threads.
lighting::StageResult renderReference(const RenderOptions& options);

} // namespace experiments
