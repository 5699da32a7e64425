// The light-volume options `deferred` and `light-indexed` share, declared (one option table,
// StageOptions.h) and recorded in one place:
//   volume=sphere|rect  spot=cone|sphere (volume=sphere only)  stencil=0|1  vfc=1|0
// (their meaning: DeferredStage.cpp's header and culling/LightVolumes.h).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "lighting/ShadingStage.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightList.h"
#include "lighting/culling/LightVolumes.h"

namespace lighting {

struct VolumeStageOptions {
    VolumeShape shape = VolumeShape::Sphere;
    SpotProxy spotProxy = SpotProxy::Cone;
    bool stencil = false;
    bool frustumCull = true;
};

// The four options' rows, for the stages' option tables.
std::vector<StageOption> volumeStageOptionTable();
// Reads the four options from the checked table values; a StageError when `spot` is given with
// volume=rect (a rule between options the table cannot state).
VolumeStageOptions volumeStageOptions(const StageOptions& options);

// The "cull" pass both volume stages start with: the lights' conservative spheres, the volume
// rasterizer over the G-buffer, and the lights to draw (ascending; only those whose sphere may
// touch the view frustum with vfc=1).
struct VolumeCull {
    std::vector<LightSphere> spheres;
    LightVolumeRasterizer volumes;
    std::vector<uint32_t> drawn;
    size_t culled() const { return spheres.size() - drawn.size(); } // by view-frustum culling
};
// Runs the pass and records its time in result.timingsMs as "cull".
VolumeCull cullLightVolumes(const gbuffer::GBuffer& gb, const LightList& lights,
                            const VolumeStageOptions& options, StageResult& result);

// Records the options and the volume draw's statistics (`culled`: lights removed by view-frustum
// culling) in a stage's parameters.
void recordVolumeParameters(const VolumeStageOptions& options, size_t culled,
                            const LightVolumeStats& stats,
                            std::map<std::string, std::string>& parameters);

} // namespace lighting
