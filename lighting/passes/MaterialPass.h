// MaterialPass: the second geometry pass of the stages that light before they know the materials
// (`light-prepass`, `inferred`): the scene is rasterized again with the G-buffer pass's own
// visibility draw (gbuffer::VisibilityPass: back faces culled, closer test), and every visible
// pixel's material (albedo, specular intensity) comes from the visible triangle's surface, never
// from the G-buffer. The stage combines it with its light buffer in forEachSurface.
//
// Because the draw is the G-buffer pass's, the visible triangles and surfaces are bitwise the
// G-buffer's (the normal and material a lossless G-buffer would hold).
//
// Multisampled frames (inputs.fragmentLayers set; MultisampleShading.h shades such a stage once
// per fragment layer): as hardware MSAA would run it, the material pass rasterizes the scene at
// the frame's sample count, once per frame (on layer 0, which is always shaded first), and splits
// its samples into fragments with the G-buffer's own options (gbuffer::FragmentLayers), which
// makes its layers bitwise the G-buffer's: the same draw, the same build. On layer k the pass
// then gives layer k's fragments (codes, instances, surfaces), so the stage combines each
// fragment's material with the light its light buffer holds for that fragment, and the frame's
// resolve weights them by coverage. The background run gives no fragment.
// Thread safety: draw() is parallel inside and not reentrant per object; forEachSurface calls
// its function from several tasks at once, each pixel from one task only (rows in parallel).
#pragma once

#include <bit>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/parallel_for.h>

#include "gbuffer/GBuffer.h"
#include "gbuffer/msaa/FragmentLayers.h"
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
    // inputs.geometry and inputs.view. Cost: one geometry pass without attributes; multisampled,
    // on layer 0 one multisampled pass and the fragment split, on the layers above nothing (they
    // need this frame's layer 0 drawn first: std::logic_error otherwise).
    void draw(const StageInputs& inputs);

    // The visible triangle's code per pixel (VisibilityPass::kNoTriangle for none): the draw's,
    // or multisampled, the drawn layer's fragments (empty for the background run).
    std::span<const uint32_t> codes() const { return mCodes; }

    // Where the pixel's fragment lies in the pixel: the mean of the sample positions it covers,
    // relative to the pixel centre, in pixels (x right, y down; hardware's centroid). Zero without
    // multisampling and for a fragment that covers the whole pixel (the standard patterns are
    // centred, and the sum is taken in integers, so exactly zero).
    glm::vec2 coverageCentroid(size_t pixel) const {
        if (mCoverage.empty())
            return glm::vec2(0.0f);
        int sumX = 0, sumY = 0, count = 0;
        for (uint32_t mask = mCoverage[pixel]; mask != 0; mask &= mask - 1) {
            const raster::SampleOffset offset = mPattern[size_t(std::countr_zero(mask))];
            sumX += offset.x;
            sumY += offset.y;
            ++count;
        }
        return count == 0 ? glm::vec2(0.0f)
                          : glm::vec2(float(sumX), float(sumY)) / (16.0f * float(count));
    }

    // The scene instance of the pixel's visible triangle (SceneGeometry::triangleInstance), or
    // kNoInstance for background.
    uint32_t instanceAt(size_t pixel) const {
        const uint32_t code = mCodes.empty() ? gbuffer::VisibilityPass::kNoTriangle : mCodes[pixel];
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
        if (mCodes.empty())
            return; // the background run: no fragment
        const uint32_t* codes = mCodes.data();
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
    std::vector<float> mDepth;                      // per sample
    gbuffer::FragmentLayers mLayers;                // multisampled frames: the draw's fragments
    bool mLayersDrawn = false;                      // ... built on this frame's layer 0
    std::span<const uint32_t> mCodes;               // the codes forEachSurface and instanceAt read
    std::span<const uint8_t> mCoverage;             // multisampled: the same layer's coverage masks
    std::span<const raster::SampleOffset> mPattern; // ... and the sample positions
};

} // namespace lighting
