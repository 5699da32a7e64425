// PreparedFrame: everything a shading stage reads for one frame, owned in one place: the scene,
// its flattened geometry, the camera matrices, the rasterized G-buffer (and, on request, the
// exact surface for the reference) and the view-space lights. The runner, the tests and the
// benchmarks all build frames this way, so a stage sees the same inputs everywhere.
// Construction rasterizes the G-buffer (parallel, under the caller's tbb::task_arena); the
// object is immovable because `frame` points into it.
#pragma once

#include <memory>

#include "gbuffer/ExactSurface.h"
#include "gbuffer/FrameView.h"
#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferPass.h"
#include "gbuffer/SceneGeometry.h"
#include "lighting/LightList.h"
#include "lighting/ShadingStage.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace lighting {

struct PreparedFrame {
    scenes::Scene scene;
    gbuffer::SceneGeometry geometry;
    gbuffer::FrameView view;
    std::unique_ptr<gbuffer::GBuffer> gbuffer;
    std::unique_ptr<gbuffer::ExactSurface> exact;  // null unless asked for
    LightList lights;
    Frame frame;
    raster::RasterStats rasterStats;
    gbuffer::GBufferPassTimings gbufferTimings;

    // Renders `scene` from its first camera at width x height into the reference layout.
    PreparedFrame(scenes::Scene scene, int width, int height, bool withExactSurface = false,
                  gbuffer::DepthConvention depth = gbuffer::DepthConvention::Reversed);
    // Replaces the scene's lights (the G-buffer does not depend on them); for tests that place
    // lights by hand after seeing the geometry.
    void setLights(const std::vector<scenes::Light>& sceneLights);

    PreparedFrame(const PreparedFrame&) = delete;
    PreparedFrame& operator=(const PreparedFrame&) = delete;
};

}  // namespace lighting
