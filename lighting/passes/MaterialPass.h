// MaterialPass: the second geometry pass of the stages that light before they know the materials
// (`light-prepass`, `inferred`): the scene is rasterized again with the G-buffer pass's own
// visibility draw (gbuffer::VisibilityPass: back faces culled, closer test), and every visible
// pixel's material (albedo, specular intensity) comes from the visible triangle's surface, never
// from the G-buffer. The stage combines it with its light buffer in forEachSurface.
//
// Because the draw is the G-buffer pass's, the visible triangles and surfaces are bitwise the
// G-buffer's (the normal and material a lossless G-buffer would hold).
// Thread safety: draw() is parallel inside and not reentrant per object; forEachSurface calls
// its function from several tasks at once, each pixel from one task only (rows in parallel).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <tbb/parallel_for.h>

#include "gbuffer/GBuffer.h"
#include "gbuffer/visibility/VisibilityPass.h"
#include "lighting/ShadingStage.h"
#include "raster/Rasterizer.h"

namespace lighting {

class MaterialPass {
public:
    // What the stages with a material pass read from the G-buffer: depth, normal and specular
    // (only its power is used: the layout has no power-only channel). Albedo and specular
    // intensity come from the material pass.
    static StageRequirements gbufferRequirements() {
        return {{gbuffer::Channel::Depth, gbuffer::Channel::Normal, gbuffer::Channel::Specular},
                false};
    }

    // Object ID of background (no triangle): never equal to a scene instance.
    static constexpr uint32_t kNoInstance = UINT32_MAX;

    // Transforms inputs.scene and draws it into the visibility buffer. Requires inputs.scene,
    // inputs.geometry and inputs.view. Cost: one geometry pass without attributes.
    void draw(const StageInputs& inputs);

    // The scene instance of the pixel's visible triangle (SceneGeometry::triangleInstance), or
    // kNoInstance for background.
    uint32_t instanceAt(size_t pixel) const {
        const uint32_t code = mVisibility.codes()[pixel];
        return code == gbuffer::VisibilityPass::kNoTriangle
                   ? kNoInstance
                   : mVisibility.geometry()
                         .triangleInstance[gbuffer::VisibilityPass::triangleOf(code)];
    }

    // Calls combine(x, y, pixel, surface) for every pixel that has a visible triangle and is
    // covered in `gb`, with the triangle's surface at the pixel (positionView zero: the stage's
    // position comes from `gb`). Rows in parallel, pixels of a row in order.
    template <class Combine>
    void forEachSurface(const gbuffer::GBuffer& gb, const Combine& combine) const {
        const uint32_t* codes = mVisibility.codes().data();
        const int width = gb.width();
        tbb::parallel_for(0, gb.height(), [&](int y) {
            gbuffer::VisibilityPass::RowSurfaces row(mVisibility, y);
            for (int x = 0; x < width; ++x) {
                const size_t pixel = size_t(y) * width + x;
                const uint32_t code = codes[pixel];
                if (code == gbuffer::VisibilityPass::kNoTriangle || !gb.covered(pixel))
                    continue;
                combine(x, y, pixel, row.at(code, x));
            }
        });
    }

private:
    gbuffer::VisibilityPass mVisibility;
    std::unique_ptr<raster::Rasterizer> mRasterizer;
    std::vector<float> mDepth;
};

} // namespace lighting
