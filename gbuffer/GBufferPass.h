// GBufferPass: rasterizes a scene's geometry into a GBuffer (and, on request, the ExactSurface
// for the reference). It is the visibility pass (VisibilityPass.h: vertices to clip space and
// normals to view space, then one draw with back-face culling and a closer-than depth test that
// records only the visible triangle per pixel) plus its resolve: depth rounded to the layout's
// format, then per pixel the visible triangle's surface (perspective-correct normal and uv once
// per pixel, base colour texture) encoded into the G-buffer planes. Deterministic for any thread
// count (see raster/Rasterizer.h).
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "gbuffer/msaa/FragmentLayers.h"
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
    double layersMs = 0.0;  // multisampled: complex-pixel detection and the fragment layers
                            // (the layers' resolve counts in resolveMs)
    // rasterMs broken down by the rasterizer (raster::RasterPhaseTimes: project, set-up, bin sort,
    // traversal; their sum is rasterMs less the visibility buffer's clear).
    raster::RasterPhaseTimes rasterPhases;
};

// What a multisampled G-buffer pass fills besides its target (layer 0): the fragment layers
// (msaa/FragmentLayers.h) and one more G-buffer per layer above 0, in the target's layout and
// view, each covered only where the layer has a fragment.
struct MultisampleTarget {
    int samples = 4; // 2, 4 or 8
    // Alpha-masked materials as sample masks instead of the alpha test (visibility/AlphaCoverage.h,
    // `--alpha-to-coverage on`).
    bool alphaToCoverage = false;
    FragmentLayerOptions options;
    FragmentLayers layers;
    std::vector<std::unique_ptr<GBuffer>> upperLayers; // layers 1 .. layerCount - 1
    // Per row, the columns where the last frame's upper layers hold a surface, and in how many
    // layers (1 .. layers): the upper layers' resolve writes only this frame's fragments and
    // resets only the layers the last frame wrote and this one does not, so its cost follows the
    // complex pixels and their fragment counts, not the screen or the deepest pixel.
    struct WrittenColumn {
        uint32_t x;
        uint32_t layers;
    };
    std::vector<std::vector<WrittenColumn>> upperWrittenColumns;
    int upperWrittenWidth = 0;      // the frame width those columns are of
    std::vector<float> sampleDepth; // the per-sample depth buffer
    // The G-buffer of layer k: `target` for 0.
    const GBuffer& layer(const GBuffer& target, int k) const {
        return k == 0 ? target : *upperLayers[size_t(k - 1)];
    }
};

class GBufferPass {
public:
    // The scene and geometry must outlive the pass. Throws std::length_error when the scene has
    // too many triangles for the visibility codes.
    GBufferPass(const scenes::Scene& scene, const SceneGeometry& geometry);

    // Clears and fills `target`; fills `exact` too when non-null. Not thread-safe per object
    // (keeps the per-frame visibility pass); parallel inside, under the caller's tbb::task_arena.
    // With `multisample`, the draw is multisampled and `target` holds layer 0 (every pixel's main
    // fragment, FragmentLayers.h), multisample->upperLayers the others; `exact` then describes
    // layer 0 (the reference of a multisampled frame is rendered apart, supersampled).
    GBufferPassTimings render(raster::Rasterizer& rasterizer, GBuffer& target,
                              ExactSurface* exact = nullptr,
                              MultisampleTarget* multisample = nullptr);

private:
    // The upper fragment layers a multisampled resolve fills beside layer 0 (resolve()).
    struct UpperLayers {
        const FragmentLayers& layers;
        std::span<GBuffer* const> targets;        // layer k's G-buffer at k - 1
        std::span<const GBuffer::Writer> writers; // the same order
        // Per row, where the last frame's upper layers hold a surface (reset to the background
        // value and clear depth where this frame has no fragment), replaced by this frame's as
        // each row is resolved.
        std::vector<std::vector<MultisampleTarget::WrittenColumn>>& written;
    };
    // Encodes the surfaces of `codes` (one per pixel) into `target`, whose depth plane holds
    // their depths already; with `upper`, each row's upper-layer fragments right after the row
    // (an upper fragment's triangle is mostly the main fragment of a neighbouring pixel, so its
    // vertices are still in cache: resolved in passes of their own, they missed it at every
    // pixel and cost four times a main fragment).
    void resolve(std::span<const uint32_t> codes, GBuffer& target, ExactSurface* exact,
                 const UpperLayers* upper = nullptr) const;
    void resolveUpperRow(const UpperLayers& upper, int y) const;
    // Visibility-buffer layouts: `codes` copied into the target, which then fetches its surfaces
    // from this pass's visibility pass.
    void storeCodes(std::span<const uint32_t> codes, GBuffer& target) const;
    // Sets up multisample->upperLayers for this frame's layers (a new layer: background
    // everywhere) and resolves them: beside layer 0 in resolve(), or for a visibility-buffer
    // layout by copying each layer's codes and depths whole.
    void resolveLayers(std::span<const uint32_t> codes, GBuffer& target, ExactSurface* exact,
                       MultisampleTarget& multisample) const;

    const scenes::Scene& mScene;
    const SceneGeometry& mGeometry;
    VisibilityPass mVisibility;
};

} // namespace gbuffer
