// GBufferPass: rasterizes a scene's geometry into a GBuffer (and, on request, the ExactSurface
// for the reference). Per frame: vertices to clip space and normals to view space (parallel),
// then one draw with back-face culling and a closer-than depth test; the fragment function
// interpolates normals and uvs perspective-correctly, samples the base colour texture and writes
// the G-buffer planes. Deterministic for any thread count (see raster/Rasterizer.h).
#pragma once

#include <vector>

#include "gbuffer/ExactSurface.h"
#include "gbuffer/FrameView.h"
#include "gbuffer/GBuffer.h"
#include "gbuffer/SceneGeometry.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace gbuffer {

struct GBufferPassTimings {
    double transformMs = 0.0;
    double rasterMs = 0.0;     // set-up, binning, traversal into the visibility buffer
    double resolveMs = 0.0;    // attributes of the visible triangles into the G-buffer planes
    double exactMs = 0.0;      // double-precision surface reconstruction (0 when not asked)
};

class GBufferPass {
public:
    // The scene and geometry must outlive the pass.
    GBufferPass(const scenes::Scene& scene, const SceneGeometry& geometry);

    // Clears and fills `target`; fills `exact` too when non-null. Not thread-safe per object
    // (keeps per-frame vertex scratch); parallel inside, under the caller's tbb::task_arena.
    GBufferPassTimings render(raster::Rasterizer& rasterizer, GBuffer& target,
                              ExactSurface* exact = nullptr);

    // Clip-space positions of the last render, for passes that rasterize the scene again.
    const std::vector<glm::vec4>& clipPositions() const { return mClipPositions; }
    const std::vector<glm::vec3>& normalsView() const { return mNormalView; }

private:
    void transformVertices(const FrameView& view);
    void resolve(GBuffer& target, ExactSurface* exact) const;

    // Visibility buffer: the visible triangle per pixel (kNoTriangle for background, the top bit
    // set when the back face is visible).
    static constexpr uint32_t kNoTriangle = UINT32_MAX;
    static constexpr uint32_t kBackFaceBit = 1u << 31;

    const scenes::Scene& mScene;
    const SceneGeometry& mGeometry;
    std::vector<glm::vec4> mClipPositions;
    std::vector<glm::vec3> mNormalView;
    std::vector<uint32_t> mVisibleTriangle;
};

}  // namespace gbuffer
