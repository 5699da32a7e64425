#include "lighting/passes/MaterialPass.h"

#include <stdexcept>

#include "lighting/passes/ForwardGeometry.h"

namespace lighting {

void MaterialPass::draw(const StageInputs& inputs) {
    if (!inputs.scene || !inputs.geometry || !inputs.view)
        throw std::invalid_argument("the material pass needs the frame's scene, geometry and view");
    const gbuffer::CameraView& view = *inputs.view;
    const gbuffer::FragmentLayers* frameLayers = inputs.fragmentLayers;
    if (frameLayers && inputs.fragmentLayer != 0) {
        // A later run of a multisampled frame: layer 0's draw is this frame's.
        if (inputs.fragmentLayer == StageInputs::kBackgroundRun) {
            mCodes = {};
            mCoverage = {};
            return;
        }
        if (!mLayersDrawn || inputs.fragmentLayer >= mLayers.layerCount())
            throw std::logic_error("the material pass draws a multisampled frame on its layer 0, "
                                   "before the layers above");
        mCodes = mLayers.codes(inputs.fragmentLayer);
        mCoverage = mLayers.coverage(inputs.fragmentLayer);
        return;
    }
    const int samples = frameLayers ? frameLayers->samples() : 1;
    // Alpha-to-coverage as the G-buffer pass drew it, so that the layers are its layers (at one
    // sample it is the alpha test, AlphaCoverage.h).
    mVisibility.transform(*inputs.scene, *inputs.geometry, view, inputs.alphaToCoverage);
    fitRasterizer(mRasterizer, view);
    mDepth.resize(size_t(view.width) * size_t(view.height) * size_t(samples));
    mVisibility.draw(*mRasterizer, mDepth, samples);
    mLayersDrawn = frameLayers != nullptr;
    if (frameLayers) {
        mLayers.build(mVisibility, frameLayers->options());
        mCodes = mLayers.codes(0);
        mCoverage = mLayers.coverage(0);
        mPattern = raster::standardSamplePattern(samples);
    } else {
        mCodes = mVisibility.codes();
        mCoverage = {};
    }
}

} // namespace lighting
