#include "lighting/passes/MaterialPass.h"

#include <stdexcept>

#include "lighting/passes/ForwardGeometry.h"

namespace lighting {

void MaterialPass::draw(const StageInputs& inputs) {
    if (!inputs.scene || !inputs.geometry || !inputs.view)
        throw std::invalid_argument("the material pass needs the frame's scene, geometry and view");
    const gbuffer::CameraView& view = *inputs.view;
    // One sample per pixel: alpha-to-coverage is the alpha test here (AlphaCoverage.h).
    mVisibility.transform(*inputs.scene, *inputs.geometry, view, inputs.alphaToCoverage);
    fitRasterizer(mRasterizer, view);
    mDepth.resize(size_t(view.width) * view.height);
    mVisibility.draw(*mRasterizer, mDepth);
}

} // namespace lighting
