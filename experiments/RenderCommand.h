// RenderCommand: `testbed render`: runs a RenderJob and writes its results into --out:
//   render.exr   multi-layer OpenEXR (beauty R,G,B; N.X,N.Y,N.Z; Z; albedo.R,G,B;
//                lights.evaluated; lights.oracle; lights.wasted = evaluated - oracle), options
//                and timings in the header
//   preview.png  tone-mapped beauty
//   heatmap.png  lights evaluated per pixel, false colour with a legend
//   stats.json   configuration, machine, commit, timings, light counts, error metrics
// The command plans the render (RenderPlan.h: options validated once, scene loaded, layout
// derived), checks the output folder for writability, then runs the plan (RenderJob.h). Every
// file is written under a temporary name and renamed, so a failed run leaves no partial output.
#pragma once

#include <cstdint>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "experiments/RenderJob.h"

namespace experiments {

struct RenderCommandOptions {
    RenderOptions render;
    std::filesystem::path out = "out";
    uint32_t heatmapMax = 0;    // 0 = the image's own maximum
    bool explainLayout = false; // print the derived layout and its reasons instead of rendering
};

// stats.json: the run's configuration, layout and machine, and its RunMetrics (RunMetrics.h
// names the figures).
nlohmann::json statsJson(const RenderRun& run);

// Writes render.exr (with error.R,G,B when the run was compared with a reference), preview.png,
// heatmap.png, error.png (false colour |image - reference|, only with a reference) and stats.json
// into `dir` (which must exist), each atomically. heatmapMax 0 = the image's own maximum.
void writeRenderOutputs(const RenderRun& run, const std::filesystem::path& dir,
                        uint32_t heatmapMax);

// The --view value that renders every view of the scene (OUT/views/NAME/ and OUT/views.json).
inline constexpr const char* kEveryView = "all";

// Plans, renders, writes; returns the process exit code (0 on success). Errors are reported on
// stderr as one line starting with "testbed: error:" (CommandErrors.h) before any file is written.
int runRenderCommand(const RenderCommandOptions& options);

} // namespace experiments
