#include "gbuffer/GBufferPass.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gbuffer {

namespace {
double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}
// Perspective-correct barycentrics of the pixel centre at `ndc` in the triangle with clip-space
// vertices c0, c1, c2. The point sum(b_i c_i) projects onto ndc when
// sum b_i (x_i - ndc.x w_i) = 0 and sum b_i (y_i - ndc.y w_i) = 0, so b is the cross product of
// those two rows, up to scale (the barycentrics are b / sum b). Homogeneous: valid for triangles
// crossing the near plane.
// Returned unnormalised (b, not b / sum): the normal is renormalised anyway, so only the sign of
// the scale matters there, and the division stays off the per-pixel critical path unless a
// texture needs the true weights. sum = 0 (pixel ray parallel to the plane) gives equal weights.
struct UnnormalisedWeights {
    glm::vec3 b;
    float sum;
};
UnnormalisedWeights perspectiveBarycentrics(const glm::vec4& c0, const glm::vec4& c1,
                                            const glm::vec4& c2, glm::vec2 ndc) {
    const glm::vec3 rowX(c0.x - ndc.x * c0.w, c1.x - ndc.x * c1.w, c2.x - ndc.x * c2.w);
    const glm::vec3 rowY(c0.y - ndc.y * c0.w, c1.y - ndc.y * c1.w, c2.y - ndc.y * c2.w);
    const glm::vec3 b = glm::cross(rowX, rowY);
    const float sum = b.x + b.y + b.z;
    return sum != 0.0f ? UnnormalisedWeights{b, sum} : UnnormalisedWeights{glm::vec3(1.0f), 3.0f};
}

}  // namespace

Surface surfaceOfTriangle(const SceneGeometry& geometry, const scenes::Scene& scene,
                          std::span<const glm::vec4> clipPositions,
                          std::span<const glm::vec3> normalsView, uint32_t triangle, bool backFace,
                          glm::vec2 ndc) {
    const uint32_t* corners = geometry.indices.data() + 3 * size_t(triangle);
    const uint32_t i0 = corners[0], i1 = corners[1], i2 = corners[2];
    const UnnormalisedWeights weights =
        perspectiveBarycentrics(clipPositions[i0], clipPositions[i1], clipPositions[i2], ndc);
    Surface surface;
    glm::vec3 normal = raster::interpolate(normalsView[i0], normalsView[i1], normalsView[i2], weights.b);
    const float length2 = glm::dot(normal, normal);
    // Two-sided draws light the visible side; a negative weight sum flips the interpolated sum.
    const float sign = (weights.sum < 0.0f) != backFace ? -1.0f : 1.0f;
    surface.normalView = length2 > 0.0f ? normal * (sign / std::sqrt(length2))
                                        : glm::vec3(0.0f, 0.0f, backFace ? -1.0f : 1.0f);
    surface.material = geometry.triangleMaterial[triangle];
    const scenes::Material& material = scene.materials[surface.material];
    glm::vec3 albedo(material.baseColorFactor);
    if (material.baseColorTexture >= 0) {
        const glm::vec2 uv = raster::interpolate(geometry.uv[i0], geometry.uv[i1], geometry.uv[i2],
                                                 weights.b * (1.0f / weights.sum));
        albedo *= glm::vec3(scene.textures[size_t(material.baseColorTexture)].sample(uv));
    }
    surface.albedo = albedo;
    surface.specularIntensity = material.specularIntensity;
    surface.specularPower = material.specularPower;
    return surface;
}

glm::vec3 positionViewOfPixel(const FrameView& view, int x, int y, float depth) {
    const glm::vec2 ndc = view.ndcOfPixel(x, y);
    const glm::vec4 p = view.viewFromClip * glm::vec4(ndc, depth, 1.0f);
    return glm::vec3(p) / p.w;
}

GBufferPass::GBufferPass(const scenes::Scene& scene, const SceneGeometry& geometry)
    : mScene(scene), mGeometry(geometry) {
    if (geometry.triangleCount() >= kBackFaceBit)
        throw std::length_error(scene.name + ": too many triangles for the visibility buffer");
}

void GBufferPass::transformVertices(const FrameView& view) {
    const size_t count = mGeometry.positionWorld.size();
    mClipPositions.resize(count);
    mNormalView.resize(count);
    const glm::mat4 clipFromWorld = view.clipFromWorld();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            mClipPositions[v] = clipFromWorld * glm::vec4(mGeometry.positionWorld[v], 1.0f);
            mNormalView[v] = view.viewFromWorldNormal * mGeometry.normalWorld[v];
        }
    });
}

void GBufferPass::resolve(GBuffer& target, ExactSurface* exact) const {
    const int width = target.width();
    const FrameView& view = target.view();
    tbb::parallel_for(0, target.height(), [&](int y) {
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            const uint32_t visible = mVisibleTriangle[pixel];
            if (visible == kNoTriangle) {
                target.writeBackground(pixel);
                continue;
            }
            const uint32_t t = visible & ~kBackFaceBit;
            const bool backFace = (visible & kBackFaceBit) != 0;
            const Surface surface = surfaceOfTriangle(mGeometry, mScene, mClipPositions, mNormalView, t,
                                                      backFace, view.ndcOfPixel(x, y));
            target.writeSurface(pixel, surface);
            if (exact) {
                exact->triangle[pixel] = t;
                exact->backFacing[pixel] = backFace ? 1 : 0;
                exact->albedo[pixel] = surface.albedo;
                exact->specular[pixel] = {surface.specularIntensity, surface.specularPower};
            }
        }
    });
}

GBufferPassTimings GBufferPass::render(raster::Rasterizer& rasterizer, GBuffer& target,
                                       ExactSurface* exact) {
    GBufferPassTimings timings;
    const FrameView& view = target.view();
    auto start = std::chrono::steady_clock::now();
    transformVertices(view);
    timings.transformMs = millisecondsSince(start);

    start = std::chrono::steady_clock::now();
    target.clearDepth();
    mVisibleTriangle.assign(target.pixelCount(), kNoTriangle);
    const int width = view.width;
    // Only the triangle is recorded: its barycentrics are computed once per pixel in resolve()
    // rather than for every sample that passes the depth test (the compiler drops the unused
    // interpolation from the inlined traversal).
    auto recordVisible = [&](const raster::Fragment& fragment) {
        const size_t pixel = size_t(fragment.y) * width + fragment.x;
        mVisibleTriangle[pixel] = fragment.triangle | (fragment.frontFacing ? 0u : kBackFaceBit);
    };
    raster::RasterState state;
    state.cullMode = raster::CullMode::Back;
    state.depthTest = view.reversedZ() ? raster::DepthTest::Greater : raster::DepthTest::Less;
    rasterizer.draw(raster::TriangleList{mClipPositions, mGeometry.indices}, state,
                    target.depthPlane(), recordVisible);
    timings.rasterMs = millisecondsSince(start);

    start = std::chrono::steady_clock::now();
    target.quantiseDepth();
    if (exact) exact->resize(view.width, view.height);
    resolve(target, exact);
    timings.resolveMs = millisecondsSince(start);

    if (exact) {
        start = std::chrono::steady_clock::now();
        exact->computeGeometry(mGeometry, view);
        timings.exactMs = millisecondsSince(start);
    }
    return timings;
}

}  // namespace gbuffer
