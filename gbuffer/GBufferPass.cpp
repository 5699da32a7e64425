#include "gbuffer/GBufferPass.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gbuffer {

namespace {
double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

// What surfaceOfTriangle reads per triangle, loaded once: resolve() reuses it while consecutive
// pixels show the same triangle (about 3.4 pixels in a row on atrium), which takes the dependent
// index -> vertex loads off most pixels. uv is loaded only for textured materials.
struct TriangleCorners {
    // Clip-space x, y and w of the three vertices (z is not needed: depth comes from the
    // rasterizer).
    glm::vec3 clipX, clipY, clipW;
    glm::vec3 normalView[3];
    // Flat triangles (the three normals bitwise equal: floors, walls) have one normal direction;
    // it is normalised here once, and per pixel only the sign of the weight sum is needed.
    bool flat;
    bool flatNormalIsZero;    // flat with zero-length normals: the (0, 0, +-1) fallback
    glm::vec3 flatNormalView; // unit, valid when flat and not zero
    glm::vec2 uv[3];
    uint32_t materialIndex;
    const scenes::Material* material;
    const scenes::Texture* baseColorTexture; // null when untextured
};

TriangleCorners loadTriangleCorners(const SceneGeometry& geometry, const scenes::Scene& scene,
                                    std::span<const glm::vec4> clipPositions,
                                    std::span<const glm::vec3> normalsView, uint32_t triangle) {
    const uint32_t* index = geometry.indices.data() + 3 * size_t(triangle);
    TriangleCorners corners;
    corners.materialIndex = geometry.triangleMaterial[triangle];
    corners.material = &scene.materials[corners.materialIndex];
    corners.baseColorTexture = corners.material->baseColorTexture >= 0
                                   ? &scene.textures[size_t(corners.material->baseColorTexture)]
                                   : nullptr;
    for (int i = 0; i < 3; ++i) {
        const glm::vec4& clip = clipPositions[index[i]];
        corners.clipX[i] = clip.x;
        corners.clipY[i] = clip.y;
        corners.clipW[i] = clip.w;
        corners.normalView[i] = normalsView[index[i]];
        corners.uv[i] = corners.baseColorTexture ? geometry.uv[index[i]] : glm::vec2(0.0f);
    }
    corners.flat = corners.normalView[0] == corners.normalView[1] &&
                   corners.normalView[0] == corners.normalView[2];
    const float length2 = glm::dot(corners.normalView[0], corners.normalView[0]);
    corners.flatNormalIsZero = !(length2 > 0.0f);
    corners.flatNormalView = corners.flatNormalIsZero
                                 ? glm::vec3(0.0f)
                                 : corners.normalView[0] * (1.0f / std::sqrt(length2));
    return corners;
}

// Perspective-correct barycentrics along one pixel row. The point sum(b_i c_i) of the triangle
// with clip-space vertices c_i projects onto the pixel centre (ndcX, ndcY) when
// sum b_i (x_i - ndcX w_i) = 0 and sum b_i (y_i - ndcY w_i) = 0, so b is the cross product of
// those two rows, up to scale (the barycentrics are b / sum b). The second row is fixed along a
// pixel row, so b = cross(x, rowY) - ndcX cross(w, rowY) is affine in ndcX: two cross products per
// run of pixels, then three multiply-adds per pixel. Homogeneous: valid for triangles crossing
// the near plane.
struct RowWeights {
    glm::vec3 constant;
    glm::vec3 slope;
};
RowWeights rowWeights(const TriangleCorners& corners, float ndcY) {
    const glm::vec3 rowY = corners.clipY - ndcY * corners.clipW;
    return {glm::cross(corners.clipX, rowY), glm::cross(corners.clipW, rowY)};
}

// The parts of a triangle's surface that do not vary over it: material index, albedo factor
// (the whole albedo when untextured) and specular. Normal and textured albedo come per pixel from
// updateSurfaceAt; the G-buffer pass fills this once per run of pixels showing the triangle.
Surface triangleSurface(const TriangleCorners& corners) {
    const scenes::Material& material = *corners.material;
    Surface surface;
    surface.material = corners.materialIndex;
    surface.albedo = glm::vec3(material.baseColorFactor);
    surface.specularIntensity = material.specularIntensity;
    surface.specularPower = material.specularPower;
    return surface;
}

// Sets the pixel-varying parts of `surface` (from triangleSurface of the same corners) at the
// pixel centre ndcX of the row `row` describes.
[[gnu::always_inline]] inline void updateSurfaceAt(Surface& surface, const TriangleCorners& corners,
                                                   const RowWeights& row, bool backFace,
                                                   float ndcX) {
    // Unnormalised weights: the normal is renormalised anyway, so only the sign of the scale
    // matters there, and the division stays off the per-pixel path unless a texture needs the
    // true weights. sum = 0 (pixel ray parallel to the plane) gives equal weights.
    glm::vec3 b = row.constant - ndcX * row.slope;
    float sum = b.x + b.y + b.z;
    if (sum == 0.0f) {
        b = glm::vec3(1.0f);
        sum = 3.0f;
    }
    // Two-sided draws light the visible side; a negative weight sum flips the interpolated sum.
    const float sign = (sum < 0.0f) != backFace ? -1.0f : 1.0f;
    // Zero-length normals (degenerate input) face the viewer.
    const glm::vec3 zeroNormalFallback(0.0f, 0.0f, backFace ? -1.0f : 1.0f);
    if (corners.flat) {
        surface.normalView =
            corners.flatNormalIsZero ? zeroNormalFallback : corners.flatNormalView * sign;
    } else {
        const glm::vec3 normal = raster::interpolate(corners.normalView[0], corners.normalView[1],
                                                     corners.normalView[2], b);
        const float length2 = glm::dot(normal, normal);
        surface.normalView =
            length2 > 0.0f ? normal * (sign / std::sqrt(length2)) : zeroNormalFallback;
    }
    if (corners.baseColorTexture) {
        const glm::vec2 uv =
            raster::interpolate(corners.uv[0], corners.uv[1], corners.uv[2], b * (1.0f / sum));
        surface.albedo = glm::vec3(corners.material->baseColorFactor) *
                         glm::vec3(corners.baseColorTexture->sample(uv));
    }
}

} // namespace

Surface surfaceOfTriangle(const SceneGeometry& geometry, const scenes::Scene& scene,
                          std::span<const glm::vec4> clipPositions,
                          std::span<const glm::vec3> normalsView, uint32_t triangle, bool backFace,
                          glm::vec2 ndc) {
    const TriangleCorners corners =
        loadTriangleCorners(geometry, scene, clipPositions, normalsView, triangle);
    Surface surface = triangleSurface(corners);
    updateSurfaceAt(surface, corners, rowWeights(corners, ndc.y), backFace, ndc.x);
    return surface;
}

GBufferPass::GBufferPass(const scenes::Scene& scene, const SceneGeometry& geometry)
    : mScene(scene), mGeometry(geometry) {
    if (geometry.triangleCount() >= kBackFaceBit)
        throw std::length_error(scene.name + ": too many triangles for the visibility buffer");
}

void GBufferPass::transformVertices(const CameraView& view) {
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
    const CameraView& view = target.view();
    const GBuffer::Writer sharedWriter = target.writer();
    // ndcOfPixel's x per column, computed once: the same floats, without a division per pixel.
    std::vector<float> ndcXOfColumn(static_cast<size_t>(width));
    for (int x = 0; x < width; ++x)
        ndcXOfColumn[size_t(x)] = view.ndcOfPixel(x, 0).x;
    tbb::parallel_for(0, target.height(), [&](int y) {
        // A copy whose address does not escape, so the plane pointers stay in registers (the
        // encoded planes' out-of-line call could otherwise change the shared one).
        const GBuffer::Writer writer = sharedWriter;
        const float ndcY = view.ndcOfPixel(0, y).y;
        uint32_t cornersOf = kNoTriangle; // the triangle `corners` and `row` describe
        TriangleCorners corners;
        RowWeights row;
        Surface surface;
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            const uint32_t visible = mVisibleTriangle[pixel];
            if (visible == kNoTriangle) {
                writer.writeBackground(pixel);
                continue;
            }
            const uint32_t t = visible & ~kBackFaceBit;
            const bool backFace = (visible & kBackFaceBit) != 0;
            if (t != cornersOf) {
                corners = loadTriangleCorners(mGeometry, mScene, mClipPositions, mNormalView, t);
                row = rowWeights(corners, ndcY);
                surface = triangleSurface(corners);
                cornersOf = t;
            }
            updateSurfaceAt(surface, corners, row, backFace, ndcXOfColumn[size_t(x)]);
            writer.write(pixel, surface);
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
    const CameraView& view = target.view();
    auto start = std::chrono::steady_clock::now();
    transformVertices(view);
    timings.transformMs = millisecondsSince(start);

    start = std::chrono::steady_clock::now();
    const std::span<float> depth = target.depthPlane();
    std::fill(depth.begin(), depth.end(), view.clearDepth());
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
    state.barycentrics = false;
    state.depthTest = view.reversedZ() ? raster::DepthTest::Greater : raster::DepthTest::Less;
    rasterizer.draw(raster::TriangleList{mClipPositions, mGeometry.indices}, state, depth.data(),
                    recordVisible);
    timings.rasterMs = millisecondsSince(start);

    start = std::chrono::steady_clock::now();
    target.quantiseDepth();
    if (exact)
        exact->resize(view.width, view.height);
    resolve(target, exact);
    timings.resolveMs = millisecondsSince(start);

    if (exact) {
        start = std::chrono::steady_clock::now();
        exact->computeGeometry(mGeometry, view);
        timings.exactMs = millisecondsSince(start);
    }
    return timings;
}

} // namespace gbuffer
