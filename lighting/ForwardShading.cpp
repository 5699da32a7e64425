#include "lighting/ForwardShading.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lighting {

void ForwardFrame::prepare(const StageInputs& inputs) {
    if (!inputs.scene || !inputs.geometry || !inputs.view)
        throw std::invalid_argument("forward shading needs the frame's scene, geometry and view");
    mScene = inputs.scene;
    mGeometry = inputs.geometry;
    mView = inputs.view;
    mDepthDecoder =
        gbuffer::GBufferLayout::lossless(inputs.view->depthConvention, inputs.view->infiniteFar)
            .depthDecoder(*inputs.view);
    const gbuffer::SceneGeometry& geometry = *inputs.geometry;
    const gbuffer::CameraView& view = *inputs.view;
    if (geometry.triangleCount() >= kBackFaceBit)
        throw std::length_error(inputs.scene->name + ": too many triangles for forward shading");

    // The same expressions as GBufferPass::transformVertices (and -ffp-contract=off), so clip
    // positions, hence coverage, depth and barycentrics, are bitwise the G-buffer pass's.
    const size_t vertexCount = geometry.positionWorld.size();
    mClipPositions.resize(vertexCount);
    mNormalsView.resize(vertexCount);
    mPositionsView.resize(vertexCount);
    const glm::mat4 clipFromWorld = view.clipFromWorld();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertexCount, 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            const glm::vec4 world(geometry.positionWorld[v], 1.0f);
            mClipPositions[v] = clipFromWorld * world;
            mNormalsView[v] = view.viewFromWorldNormal * geometry.normalWorld[v];
            mPositionsView[v] = glm::vec3(view.viewFromWorld * world);
        }
    });

    // Objects: maximal runs of one instance (SceneGeometry appends instances one after another,
    // so this is one object per instance).
    const uint32_t triangleCount = geometry.triangleCount();
    mObjects.clear();
    mObjectOfTriangle.resize(triangleCount);
    for (uint32_t t = 0; t < triangleCount; ++t) {
        const uint32_t instance = geometry.triangleInstance[t];
        if (mObjects.empty() || mObjects.back().instance != instance)
            mObjects.push_back({t, 0, instance, glm::vec3(0.0f), glm::vec3(0.0f)});
        ++mObjects.back().triangleCount;
        mObjectOfTriangle[t] = uint32_t(mObjects.size() - 1);
    }

    // Bounds over the objects' vertices in view space: every surface point of a triangle lies in
    // the box of its corners.
    tbb::parallel_for(size_t(0), mObjects.size(), [&](size_t o) {
        ForwardObject& object = mObjects[o];
        glm::vec3 lo(INFINITY), hi(-INFINITY);
        const uint32_t* index = geometry.indices.data() + 3 * size_t(object.firstTriangle);
        const uint32_t* end = index + 3 * size_t(object.triangleCount);
        for (; index != end; ++index) {
            const glm::vec3& p = mPositionsView[*index];
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        const glm::vec3 magnitude = glm::max(glm::abs(lo), glm::abs(hi));
        const float pad = kObjectBoxSlack * std::max({magnitude.x, magnitude.y, magnitude.z});
        object.minView = lo - glm::vec3(pad);
        object.maxView = hi + glm::vec3(pad);
    });
}

void depthPrepass(raster::Rasterizer& rasterizer, const ForwardFrame& forward,
                  const gbuffer::CameraView& view, std::vector<float>& depth,
                  std::vector<uint32_t>& visible) {
    const size_t pixelCount = size_t(view.width) * view.height;
    depth.assign(pixelCount, view.clearDepth());
    visible.assign(pixelCount, kNoVisibleTriangle);
    const int width = view.width;
    raster::RasterState state;
    state.barycentrics = false; // the surface comes from surfaceOfTriangle
    state.cullMode = raster::CullMode::Back;
    state.depthTest = closerTest(view);
    rasterizer.draw(forward.triangles(), state, depth.data(),
                    [&](const raster::Fragment& fragment) {
                        visible[size_t(fragment.y) * width + fragment.x] =
                            visibilityCode(fragment.triangle, fragment.frontFacing);
                    });
}

void fitRasterizer(std::unique_ptr<raster::Rasterizer>& rasterizer,
                   const gbuffer::CameraView& view) {
    if (!rasterizer || rasterizer->width() != view.width || rasterizer->height() != view.height)
        rasterizer = std::make_unique<raster::Rasterizer>(view.width, view.height);
}

} // namespace lighting
