// GBufferPass: rasterizes a scene's geometry into a GBuffer (and, on request, the ExactSurface
// for the reference). Per frame: vertices to clip space and normals to view space (parallel),
// then one draw with back-face culling and a closer-than depth test that records only the visible
// triangle per pixel (a visibility buffer); a resolve pass then interpolates normals and uvs
// perspective-correctly once per pixel, samples the base colour texture and writes the G-buffer
// planes. Deterministic for any thread count (see raster/Rasterizer.h).
#pragma once

#include <span>
#include <vector>

#include "gbuffer/CameraView.h"
#include "gbuffer/ExactSurface.h"
#include "gbuffer/GBuffer.h"
#include "gbuffer/Plane.h"
#include "gbuffer/SceneGeometry.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace gbuffer {

// The surface of triangle `triangle` at the pixel centre `ndc`: perspective-correct barycentrics
// from the triangle's clip-space vertices, the interpolated, normalised view-space normal (negated
// when the back face is visible: two-sided draws light the visible side), and the material's
// albedo (times the base colour texture) and specular. positionView is left zero: it comes from
// depth (DepthDecoder). This is the one definition of the G-buffer's surface: the G-buffer
// pass and the forward stages both call it, so forward shading sees bitwise the same floats as a
// stage reading the G-buffer. clipPositions / normalsView are per vertex of `geometry`, as made
// by GBufferPass (or the identical transform of another pass). Pure, thread-safe.
Surface surfaceOfTriangle(const SceneGeometry& geometry, const scenes::Scene& scene,
                          std::span<const glm::vec4> clipPositions,
                          std::span<const glm::vec3> normalsView, uint32_t triangle, bool backFace,
                          glm::vec2 ndc);

struct GBufferPassTimings {
    double transformMs = 0.0;
    double rasterMs = 0.0;  // set-up, binning, traversal into the visibility buffer
    double resolveMs = 0.0; // depth rounded to its format; attributes of the visible
                            // triangles encoded into the G-buffer planes
    double exactMs = 0.0;   // double-precision surface reconstruction (0 when not asked)
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
    void transformVertices(const CameraView& view);
    void resolve(GBuffer& target, ExactSurface* exact) const;

    // Visibility buffer: the visible triangle per pixel (kNoTriangle for background, the top bit
    // set when the back face is visible).
    static constexpr uint32_t kNoTriangle = UINT32_MAX;
    static constexpr uint32_t kBackFaceBit = 1u << 31;

    const scenes::Scene& mScene;
    const SceneGeometry& mGeometry;
    std::vector<glm::vec4> mClipPositions;
    std::vector<glm::vec3> mNormalView;
    Plane<uint32_t> mVisibleTriangle;
};

} // namespace gbuffer
