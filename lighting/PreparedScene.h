// PreparedScene: a scene prepared for the shading stages at one camera and size, everything a
// stage reads owned in one place: the scene, its flattened geometry, the camera matrices, the
// rasterized G-buffer in a given layout (and, on request, the exact surface for the reference)
// and the view-space lights, with `inputs` (the StageInputs a stage's shade() takes) pointing
// into them. The runner, the tests and the benchmarks all prepare scenes this way, so a stage
// sees the same inputs everywhere. Construction rasterizes the G-buffer (parallel, under the
// caller's tbb::task_arena); the object is immovable because `inputs` points into it.
#pragma once

#include <memory>

#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferLayout.h"
#include "gbuffer/GBufferPass.h"
#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/ExactSurface.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/ShadingStage.h"
#include "lighting/culling/LightList.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace lighting {

// Multisampled G-buffer passes (gbuffer/GBufferPass.h MultisampleTarget): samples 1 = none.
struct Multisampling {
    int samples = 1;
    gbuffer::FragmentLayerOptions layers;
    // Alpha-masked materials as sample masks (gbuffer/visibility/AlphaCoverage.h); only used with
    // samples > 1 (at one sample the alpha test applies).
    bool alphaToCoverage = false;
};

struct PreparedScene {
    scenes::Scene scene;
    gbuffer::SceneGeometry geometry;
    gbuffer::CameraView view;
    std::unique_ptr<gbuffer::GBuffer> gbuffer;
    std::unique_ptr<gbuffer::ExactSurface> exact; // null unless asked for
    LightList lights;
    StageInputs inputs;
    // Multisampled frames only (null otherwise): the fragment layers and the G-buffers of the
    // layers above 0 (`gbuffer` is layer 0). layerInputs(k) are `inputs` with layer k's G-buffer;
    // inputs.samples is the sample count (1 without multisampling).
    std::unique_ptr<gbuffer::MultisampleTarget> multisample;
    raster::RasterStats rasterStats;
    gbuffer::GBufferPassTimings gbufferTimings;
    int exactSurfacePasses = 0; // G-buffer passes so far that also computed the exact surface

    // Renders `scene` from its first camera at width x height into `layout`; the view's depth
    // convention and far plane follow the layout's depth format. A layout without a material
    // table (GBufferLayout::reference(), lossless()) gets the scene's, and the float32 roughness
    // and metallic its metallic-roughness materials need (gbuffer::addMaterialModels).
    PreparedScene(scenes::Scene scene, int width, int height, bool withExactSurface,
                  const gbuffer::GBufferLayout& layout, const Multisampling& multisampling = {});
    // The reference layout (float32 everything), with standard or reversed float depth.
    PreparedScene(scenes::Scene scene, int width, int height, bool withExactSurface = false,
                  gbuffer::DepthConvention depth = gbuffer::DepthConvention::Reversed);

    // Rasterizes the G-buffer (and the exact surface, if any) again: for timing repetitions.
    // The result is bitwise the same; gbufferTimings and rasterStats are replaced.
    void renderGBuffer();
    // Computes the exact surface when the scene was prepared without it (one more G-buffer pass,
    // writing the same G-buffer bitwise; gbufferTimings and rasterStats keep the last timed
    // pass's values). The runner calls it after the timed repetitions, for the reference only,
    // so that the reference's work never lands in the stage's timed G-buffer pass.
    void addExactSurface();
    // A G-buffer of the same view in the lossless reference layout (float32 depth in the view's
    // convention): what forward stages shade, for measurements on frames whose layout lacks
    // channels. Costs one more G-buffer pass.
    std::unique_ptr<gbuffer::GBuffer> renderLosslessGBuffer();

    int layerCount() const { return multisample ? multisample->layers.layerCount() : 1; }
    StageInputs layerInputs(int layer) const {
        StageInputs layerFrame = inputs;
        layerFrame.fragmentLayer = layer;
        if (layer > 0)
            layerFrame.gbuffer = multisample->upperLayers[size_t(layer - 1)].get();
        return layerFrame;
    }

    // Renders the G-buffer (and the exact surface, if any) again from the same camera with every
    // pixel's sample moved by `pixelOffset` pixels from its centre (y down;
    // gbuffer::CameraView::pixelOffset): the supersampled reference's sub-frames
    // (SupersampledReference.h). The view, the G-buffer (same layout) and the lights are
    // replaced; `inputs` follows. A zero offset gives bitwise the unjittered frame. Only the
    // reference may shade a jittered frame: the culling tests assume a symmetric frustum.
    void setPixelOffset(glm::dvec2 pixelOffset);

    // Replaces the scene's lights (the G-buffer does not depend on them); for tests that place
    // lights by hand after seeing the geometry.
    void setLights(const std::vector<scenes::Light>& sceneLights);

    PreparedScene(const PreparedScene&) = delete;
    PreparedScene& operator=(const PreparedScene&) = delete;

private:
    std::unique_ptr<raster::Rasterizer> mRasterizer;
    std::unique_ptr<gbuffer::GBufferPass> mPass;
};

} // namespace lighting
