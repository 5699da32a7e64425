#include "lighting/passes/ForwardGeometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gbuffer/GBufferLayout.h"
#include "lighting/passes/BlendedPass.h"

namespace lighting {

void ForwardGeometry::shadeBlended(const StageInputs& inputs, BlendedPass& blended,
                                   const LightIndexLists& objectLights, StageResult& result) {
    if (blended.prepare(inputs, sampleTarget()))
        blended.shade(
            depth(),
            [&](int, int, const gbuffer::Surface&, uint32_t triangle) {
                return objectLights[objectOfTriangle(triangle)];
            },
            result);
}

void ForwardGeometry::addEmission(StageResult& result) {
    if (!mEmits)
        return;
    const uint32_t* codes = mVisibility.codes().data();
    const int width = mVisibility.view().width;
    const int samples = mSamples;
    SampleRadiance& target = mSampleRadiance;
    tbb::parallel_for(0, mVisibility.view().height, [&](int y) {
        gbuffer::VisibilityPass::RowSurfaces row(mVisibility, y);
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            if (samples > 1) {
                for (int s = 0; s < samples; ++s) {
                    const uint32_t code = codes[pixel * size_t(samples) + size_t(s)];
                    if (code == gbuffer::VisibilityPass::kNoTriangle)
                        continue;
                    const glm::vec3 emitted = row.at(code, x).emissive;
                    for (int c = 0; c < 3; ++c)
                        target.pixel(c, pixel)[s] += emitted[c];
                }
                continue;
            }
            if (codes[pixel] == gbuffer::VisibilityPass::kNoTriangle)
                continue;
            const glm::vec3 emitted = row.at(codes[pixel], x).emissive;
            for (int c = 0; c < 3; ++c)
                result.radiance[c][pixel] += emitted[c];
        }
    });
}

void ForwardGeometry::drawDepthPrepass() {
    mVisibility.draw(*mRasterizer, mDepth, mSamples);
    if (mSamples == 1)
        return;
    // Each sample's shading depth: its fragment's centre depth, as FragmentLayers stores it.
    const std::span<const uint32_t> codes = mVisibility.codes();
    const std::span<const float> centre = mVisibility.centreDepths();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, codes.size(), 16384), [&](const auto& range) {
        for (size_t s = range.begin(); s != range.end(); ++s)
            mCentreDepth[s] = codes[s] == gbuffer::VisibilityPass::kNoTriangle
                                  ? mClearDepth
                                  : shadingDepth(centre[s]);
    });
}

void ForwardGeometry::boundShadedSamples() {
    if (mSamples == 1)
        return;
    const int width = mVisibility.view().width, height = mVisibility.view().height;
    const std::span<const uint32_t> codes = mVisibility.codes();
    const size_t stride = size_t(mSamples);
    struct Outside {
        uint32_t object;
        glm::vec3 positionView;
    };
    std::vector<std::vector<Outside>> rows(static_cast<size_t>(height));
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * size_t(width) + size_t(x);
            for (size_t s = 0; s < stride; ++s) {
                const uint32_t code = codes[pixel * stride + s];
                if (code == gbuffer::VisibilityPass::kNoTriangle)
                    continue;
                const uint32_t object =
                    mObjectOfTriangle[gbuffer::VisibilityPass::triangleOf(code)];
                const glm::vec3 p =
                    mDepthDecoder->positionView(x, y, mCentreDepth[pixel * stride + s]);
                if (!insideBounds(object, p))
                    rows[size_t(y)].push_back({object, p});
            }
        }
    });
    std::vector<uint8_t> grown(mObjects.size(), 0);
    for (const std::vector<Outside>& row : rows)
        for (const Outside& outside : row) {
            ViewBox& box = mObjects[outside.object].boundsView;
            box.lo = glm::min(box.lo, outside.positionView);
            box.hi = glm::max(box.hi, outside.positionView);
            grown[outside.object] = 1;
        }
    for (size_t o = 0; o < mObjects.size(); ++o)
        if (grown[o])
            mObjects[o].boundsView =
                widenedBox(mObjects[o].boundsView.lo, mObjects[o].boundsView.hi);
}

void ForwardGeometry::prepare(const StageInputs& inputs) {
    if (!inputs.scene || !inputs.geometry || !inputs.view)
        throw std::invalid_argument("forward shading needs the frame's scene, geometry and view");
    const gbuffer::SceneGeometry& geometry = *inputs.geometry;
    const gbuffer::CameraView& view = *inputs.view;
    mVisibility.transform(*inputs.scene, geometry, view, inputs.alphaToCoverage);
    mEmits = std::any_of(inputs.scene->materials.begin(), inputs.scene->materials.end(),
                         [](const scenes::Material& material) { return material.emits(); });
    mDepthDecoder =
        gbuffer::GBufferLayout::lossless(view.depthConvention, view.infiniteFar).depthDecoder(view);
    fitRasterizer(mRasterizer, view);
    if (!raster::isRasterSampleCount(inputs.samples))
        throw std::invalid_argument("forward shading: " + std::to_string(inputs.samples) +
                                    " samples per pixel (expected 1, 2, 4 or 8)");
    mSamples = inputs.samples;
    mClearDepth = view.clearDepth();
    mNearerThanClear = std::nextafter(mClearDepth, view.reversedZ() ? 1.0f : 0.0f);
    mDepth.resize(size_t(view.width) * view.height * size_t(mSamples));
    mCentreDepth.resize(mSamples > 1 ? mDepth.size() : 0);

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
    const size_t vertexCount = geometry.positionWorld.size();
    mPositionsView.resize(vertexCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertexCount, 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v)
            mPositionsView[v] =
                glm::vec3(view.viewFromWorld * glm::vec4(geometry.positionWorld[v], 1.0f));
    });
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
        object.boundsView = widenedBox(lo, hi);
    });
}

void ForwardGeometry::objectLightLists(const std::vector<LightSphere>& spheres,
                                       LightIndexLists& lists) {
    mPerObject.resize(mObjects.size());
    tbb::parallel_for(size_t(0), mObjects.size(), [&](size_t o) {
        std::vector<uint32_t>& list = mPerObject[o];
        list.clear();
        for (uint32_t l = 0; l < spheres.size(); ++l)
            if (sphereTouchesObject(spheres[l], mObjects[o]))
                list.push_back(l);
    });
    lists.assign(mPerObject);
}

void fitRasterizer(std::unique_ptr<raster::Rasterizer>& rasterizer,
                   const gbuffer::CameraView& view) {
    if (!rasterizer || rasterizer->width() != view.width || rasterizer->height() != view.height)
        rasterizer = std::make_unique<raster::Rasterizer>(view.width, view.height);
}

} // namespace lighting
