// RenderCommand: `testbed render`: runs a RenderJob and writes its results into --out:
//   render.exr   multi-layer OpenEXR (beauty R,G,B; N.X,N.Y,N.Z; Z; albedo.R,G,B;
//                lights.evaluated; lights.oracle; lights.wasted = evaluated - oracle), options
//                and timings in the header
//   preview.png  tone-mapped beauty
//   heatmap.png  lights evaluated per pixel, false colour with a legend
//   error.png    with a reference: the largest channel |render - reference| per pixel, false
//                colour with a legend, linear or log scale (RenderOutputScales)
//   flip.png     with a reference: the HDR-ꟻLIP map, magma from 0 to 1
//   stats.json   configuration, machine, commit, timings, light counts, error metrics
// The command validates every option first (the output scales included), plans the render
// (RenderPlan.h: options validated once, scene loaded, layout derived, peak memory estimated),
// then runs the plan (RenderJob.h: refused before allocating when the estimate is over
// --max-memory). Outputs are written into a staging folder inside --out and moved into place
// only when every one of them was written (output/StagedFolder.h): a failed run leaves --out
// byte for byte as it was (and no --out at all when it did not exist). A successful run also
// removes the outputs of an earlier run there that it did not write (renderOutputNames), so the
// folder never mixes two runs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/output/ImageOutput.h"
#include "experiments/render/RenderJob.h"

namespace experiments {

// The scales of the false-colour PNGs. Give images that are compared side by side the same
// explicit maxima (a sweep file's heatmap-max, error-max and error-scale do that for all its jobs).
struct RenderOutputScales {
    uint32_t heatmapMax = 0;                // 0 = the image's own maximum
    MapScale errorScale = MapScale::Linear; // error.png: linear 0..max, or log (4 decades)
    float errorMax = 0.0f;                  // 0 = the image's largest error
};

struct RenderCommandOptions {
    RenderOptions render;
    std::filesystem::path out = "out";
    RenderOutputScales scales;
    bool explainLayout = false; // print the derived layout and its reasons instead of rendering
};

// The style of error.png for the scales (title, colour map, scale, maximum).
ScalarMapStyle errorMapStyle(const RenderOutputScales& scales);
// Throws UsageError naming the option when a scale cannot be drawn (--error-max negative, NaN or
// infinite as a float): checked before any work, not when error.png is written.
void checkOutputScales(const RenderOutputScales& scales);

// The file names a render writes into its folder (those of writeRenderOutputs).
const std::vector<std::string>& renderOutputNames();

// stats.json: the run's configuration, layout and machine, and its RunMetrics (RunMetrics.h
// names the figures).
nlohmann::json statsJson(const RenderRun& run);

// Writes render.exr (with error.R,G,B when the run was compared with a reference, and flip when
// ꟻLIP was computed), preview.png, heatmap.png, error.png and flip.png (with a reference) and
// stats.json into `dir` (which must exist), each atomically; returns the names written.
std::vector<std::string> writeRenderOutputs(const RenderRun& run, const std::filesystem::path& dir,
                                            const RenderOutputScales& scales = {});

// Plans, renders, writes; returns the process exit code (0 on success). Errors are reported on
// stderr as one line starting with "testbed: error:" (CommandErrors.h) before any file is written.
int runRenderCommand(const RenderCommandOptions& options);

} // namespace experiments
