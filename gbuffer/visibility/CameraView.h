// CameraView: the camera of one frame as matrices (view, projection, their inverses), for a given
// viewport. Depth is "zero to one"
// (0 <= z <= w in clip space). With standard Z, 0 is the near plane and 1 the far plane; with
// reversed Z (the default), 1 is the near plane and 0 the far plane, which spreads float32
// precision evenly over distance (standard float depth loses ~1e-4 relative position accuracy
// at tens of metres; reversed Z keeps it near float epsilon). View space is right-handed, camera
// looking down -Z. Double-precision copies serve the reference.
//
// Sub-pixel jitter (the supersampled reference, lighting/SupersampledReference.h): `pixelOffset`
// moves every pixel's sample from its centre by (dx, dy) pixels (x right, y down) as a
// translation of the projection in clip space (x' = x - 2 dx / width * w, y' = y + 2 dy / height
// * w), so the rasterizer (clipFromView), the exact surface and position from depth
// (viewFromClip, viewFromClipExact) and ndcOfPixel, which stays the pixel centre in the jittered
// NDC, all see the same sample point. A zero offset leaves the matrices bitwise as they were.
// With an offset the frustum is no longer symmetric: viewRayOfNdc (DepthFormat.h) accounts for
// it; the culling tests (lighting/culling), the kernel's view-ray decode and the light volumes
// assume a symmetric frustum and are only ever given an unjittered view.
#pragma once

#include <glm/glm.hpp>

#include "scenes/Scene.h"

namespace gbuffer {

enum class DepthConvention { Standard, Reversed };

struct CameraView {
    int width = 0;
    int height = 0;
    float nearMetres = 0.1f;
    float farMetres = 100.0f;
    DepthConvention depthConvention = DepthConvention::Reversed;
    bool infiniteFar = false;    // far plane at infinity: farMetres is then only the scene's extent
    glm::dvec2 pixelOffset{0.0}; // sample position - pixel centre, pixels, y down (above)
    glm::mat4 viewFromWorld{1.0f};
    glm::mat4 clipFromView{1.0f};
    glm::mat4 viewFromClip{1.0f};        // inverse projection, for position reconstruction
    glm::mat3 viewFromWorldNormal{1.0f}; // rotation part, for directions and normals
    glm::dmat4 viewFromWorldExact{1.0};
    glm::dmat4 viewFromClipExact{1.0};

    static CameraView fromCamera(const scenes::Camera& camera, int width, int height,
                                 DepthConvention convention = DepthConvention::Reversed,
                                 bool infiniteFar = false,
                                 glm::dvec2 pixelOffset = glm::dvec2(0.0));

    bool reversedZ() const { return depthConvention == DepthConvention::Reversed; }
    // Depth of "nothing here": the far plane's value.
    float clearDepth() const { return reversedZ() ? 0.0f : 1.0f; }

    glm::mat4 clipFromWorld() const { return clipFromView * viewFromWorld; }
    // Normalised device coordinates of pixel (x, y)'s centre; y up, as in clip space.
    glm::vec2 ndcOfPixel(int x, int y) const {
        return {(float(x) + 0.5f) / float(width) * 2.0f - 1.0f,
                1.0f - (float(y) + 0.5f) / float(height) * 2.0f};
    }
    // Positive view depth at NDC (ndcX, ndcY, depth): -p.z / p.w for
    // p = viewFromClip * vec4(ndcX, ndcY, depth, 1), bitwise that product (glm sums the columns
    // as (c0 x + c1 y) + (c2 z + c3 w); -ffp-contract=off keeps both unfused) with only the two
    // rows it needs. For loops that know the pixel's NDC already (a table per column and row).
    float viewDepthOfNdc(float ndcX, float ndcY, float depth) const {
        const glm::mat4& m = viewFromClip;
        const float z = (m[0].z * ndcX + m[1].z * ndcY) + (m[2].z * depth + m[3].z * 1.0f);
        const float w = (m[0].w * ndcX + m[1].w * ndcY) + (m[2].w * depth + m[3].w * 1.0f);
        return -z / w;
    }
};

} // namespace gbuffer
