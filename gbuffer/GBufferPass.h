// GBufferPass: rasterizes a scene's geometry into a GBuffer (and, on request, the ExactSurface
// for the reference). It is the visibility pass (VisibilityPass.h: vertices to clip space and
// normals to view space, then one draw with back-face culling and a closer-than depth test that
// records only the visible triangle per pixel) plus its resolve: depth rounded to the layout's
// format, then per pixel the visible triangle's surface (perspective-correct normal and uv once
// per pixel, base colour texture) encoded into the G-buffer planes. Deterministic for any thread
// count (see raster/Rasterizer.h).
#pragma once

#include "gbuffer/GBuffer.h"
#include "gbuffer/visibility/ExactSurface.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "gbuffer/visibility/VisibilityPass.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace gbuffer {

struct GBufferPassTimings {
    double transformMs = 0.0;
    double rasterMs = 0.0;  // set-up, binning, traversal into the visibility buffer
    double resolveMs = 0.0; // depth rounded to its format; attributes of the visible
                            // triangles encoded into the G-buffer planes
    double exactMs = 0.0;   // double-precision surface reconstruction (0 when not asked)
};

class GBufferPass {
public:
    // The scene and geometry must outlive the pass. Throws std::length_error when the scene has
    // too many triangles for the visibility codes.
    GBufferPass(const scenes::Scene& scene, const SceneGeometry& geometry);

    // Clears and fills `target`; fills `exact` too when non-null. Not thread-safe per object
    // (keeps the per-frame visibility pass); parallel inside, under the caller's tbb::task_arena.
    GBufferPassTimings render(raster::Rasterizer& rasterizer, GBuffer& target,
                              ExactSurface* exact = nullptr);

private:
    void resolve(GBuffer& target, ExactSurface* exact) const;

    const scenes::Scene& mScene;
    const SceneGeometry& mGeometry;
    VisibilityPass mVisibility;
};

} // namespace gbuffer
