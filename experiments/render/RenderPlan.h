// RenderPlan: everything decided about a render before any heavy work. planRender validates the
// options once (RenderOptions.h), loads the scene (its materials decide the derived layout), makes
// the stage and derives the G-buffer layout; runRender (RenderJob.h) then rasterizes and shades
// exactly that. `testbed render` (also for --explain-layout, which stops at the plan) and every
// job of a sweep go through this pair, so the CLI and the sweep cannot plan a render differently.
//
// The layout is derived from the stage's requirements plus what the post-process anti-aliasing
// reads (edge-blur: depth and normals, lighting/postaa/PostAa.h), so that it runs after any stage;
// a channel only the filter reads says so in the layout's reasons (--explain-layout, stats.json).
// plan.requirements stays the stage's own.
//
// Cost: planning loads the scene (a glTF file with its textures; refused first when parsing the
// file alone is estimated over the memory limit) but rasterizes nothing and allocates no image.
// Errors: UsageError for bad options and a layout lacking a channel the stage reads,
// lighting::StageError for a bad stage spec, scenes::SceneError for a bad scene file.
#pragma once

#include <memory>

#include "experiments/render/MemoryEstimate.h"
#include "experiments/render/RenderOptions.h"
#include "gbuffer/GBufferLayout.h"
#include "lighting/ShadingStage.h"
#include "scenes/Scene.h"

namespace experiments {

struct RenderPlan {
    RenderOptions options; // validated
    int threads = 0;       // effective: options.threads, or every hardware thread for 0
    scenes::Scene scene;   // loaded with the requested lights, seed and scene options
    std::unique_ptr<lighting::ShadingStage> stage;
    lighting::StageRequirements requirements; // stage->requirements()
    gbuffer::GBufferLayout layout;            // derived, or the requested preset with overrides
    lighting::kernel::KernelIsa isa = lighting::kernel::KernelIsa::scalar(); // options.isa
    lighting::postaa::PostAa postAa = lighting::postaa::PostAa::None;        // options.postAa
    std::optional<lighting::ShadowSettings> shadows; // options.shadow*; empty: --shadows off
    // The run's peak memory, estimated from the scene, size, layout and stage; runRender refuses
    // the plan before allocating when it is over its limit (MemoryEstimate.h).
    MemoryEstimate memory;
};

RenderPlan planRender(const RenderOptions& options);
// The same with the scene already loaded (loadRequestedScene(options)): the sweep plans every job
// before running any (SweepPreflight.h) and loads each scene once for its jobs.
RenderPlan planRenderWithScene(const RenderOptions& options, scenes::Scene scene);

// The scene of the options (lights generated with the seed, scene options applied, the requested
// view made cameras[0]). Throws scenes::SceneError for a bad file, option or view name.
scenes::Scene loadRequestedScene(const RenderOptions& options);

// The worker threads of a thread option: itself, or every hardware thread for 0.
int effectiveThreads(int requested);

} // namespace experiments
