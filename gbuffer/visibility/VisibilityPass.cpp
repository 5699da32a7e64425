#include "gbuffer/visibility/VisibilityPass.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gbuffer {

void VisibilityPass::checkTriangleCount(const scenes::Scene& scene, const SceneGeometry& geometry) {
    if (geometry.triangleCount() >= kBackFaceBit)
        throw std::length_error(scene.name + ": too many triangles for the visibility buffer");
}

void VisibilityPass::transform(const scenes::Scene& scene, const SceneGeometry& geometry,
                               const CameraView& view, bool alphaToCoverage) {
    checkTriangleCount(scene, geometry);
    ++mFrame;
    mScene = &scene;
    mGeometry = &geometry;
    mView = view;
    const size_t count = geometry.positionWorld.size();
    mClipPositions.resize(count);
    mNormalsView.resize(count);
    mTangentsView.resize(geometry.tangentWorld.size());
    const bool tangents = !geometry.tangentWorld.empty();
    const glm::mat4 clipFromWorld = view.clipFromWorld();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            mClipPositions[v] = clipFromWorld * glm::vec4(geometry.positionWorld[v], 1.0f);
            mNormalsView[v] = view.viewFromWorldNormal * geometry.normalWorld[v];
            // viewFromWorldNormal is a rotation: tangents turn with it too.
            if (tangents)
                mTangentsView[v] =
                    glm::vec4(view.viewFromWorldNormal * glm::vec3(geometry.tangentWorld[v]),
                              geometry.tangentWorld[v].w);
        }
    });
    mAlpha.build(scene, alphaToCoverage);
    mMaterials = MaterialSampling::of(scene, geometry);
    mNdcXOfColumn.resize(size_t(view.width));
    for (int x = 0; x < view.width; ++x)
        mNdcXOfColumn[size_t(x)] = view.ndcOfPixel(x, 0).x;
}

raster::RasterState VisibilityPass::drawState() const {
    raster::RasterState state;
    state.cullMode = raster::CullMode::Back;
    state.barycentrics = false;
    state.depthTest = mView.reversedZ() ? raster::DepthTest::Greater : raster::DepthTest::Less;
    state.depthWrite = true;
    return state;
}

raster::RasterState VisibilityPass::redrawState() const {
    raster::RasterState state = drawState();
    state.depthTest =
        mView.reversedZ() ? raster::DepthTest::GreaterEqual : raster::DepthTest::LessEqual;
    state.depthWrite = false;
    return state;
}

void VisibilityPass::draw(raster::Rasterizer& rasterizer, std::span<float> depth, int samples) {
    const size_t pixelCount = size_t(mView.width) * size_t(mView.height);
    const size_t sampleCount = pixelCount * size_t(std::max(samples, 1));
    if (depth.size() != sampleCount)
        throw std::invalid_argument("visibility draw: the depth plane has " +
                                    std::to_string(depth.size()) + " samples, the view " +
                                    std::to_string(sampleCount));
    // The draw clears what its tiles cover: the rasterizer must be the view's size.
    if (rasterizer.width() != mView.width || rasterizer.height() != mView.height)
        throw std::invalid_argument(
            "visibility draw: the rasterizer is " + std::to_string(rasterizer.width()) + "x" +
            std::to_string(rasterizer.height()) + ", the view " + std::to_string(mView.width) +
            "x" + std::to_string(mView.height));
    mSamples = samples;
    mCodes.resize(sampleCount);
    raster::RasterState state = drawState();
    state.samples = samples;
    const size_t width = size_t(mView.width);
    uint32_t* codes = mCodes.data();
    // Depth and codes cleared tile by tile inside the draw, in the task that then draws the tile
    // (in parallel, and in cache for its triangles: at 4x the two planes are 30 MB).
    state.clearDepth = mView.clearDepth();
    state.alsoClearTile = [codes, width, samples](int x0, int y0, int x1, int y1) {
        const size_t stride = size_t(samples);
        for (int y = y0; y < y1; ++y) {
            uint32_t* row = codes + (size_t(y) * width + size_t(x0)) * stride;
            std::fill(row, row + size_t(x1 - x0) * stride, kNoTriangle);
        }
    };
    if (samples > 1) {
        // Read only where a code was written: resized, not cleared.
        mCentreDepths.resize(sampleCount);
        // Each passing sample records its fragment's code and centre depth; pixels whose samples
        // are all covered take the rasterizer's multisampled span loop.
        const raster::TriangleIds record{codes, width, kBackFaceBit, samples, mCentreDepths.data()};
        if (mAlpha.active())
            rasterizer.draw(triangles(), state, depth.data(), [&](const raster::Fragment& f) {
                raster::Fragment kept = f;
                kept.coverage = keptCoverage(f, samples);
                if (kept.coverage != 0)
                    record(kept);
                return raster::SampleMask{kept.coverage};
            });
        else
            rasterizer.draw(triangles(), state, depth.data(), record);
        return;
    }
    mCentreDepths.clear();
    if (mAlpha.active()) {
        rasterizer.draw(triangles(), state, depth.data(), [&](const raster::Fragment& fragment) {
            if (!keeps(fragment))
                return false;
            codes[size_t(fragment.y) * width + size_t(fragment.x)] =
                code(fragment.triangle, fragment.frontFacing);
            return true;
        });
        return;
    }
    // The rasterizer writes the codes over each row's span in its vector depth loop
    // (raster::TriangleIds: the same value as code()).
    static_assert(raster::TriangleIds{nullptr, 0, kBackFaceBit}.idOf(7, false) == code(7, false));
    rasterizer.draw(triangles(), state, depth.data(),
                    raster::TriangleIds{codes, width, kBackFaceBit});
}

Surface VisibilityPass::surfaceAt(uint32_t code, int x, int y) const {
    RowSurfaces row(*this, y);
    return row.at(code, x);
}

} // namespace gbuffer
