// RayVisibility: ray-traced shadow visibility of the reference, against the scene's unquantised
// geometry (gbuffer::SceneGeometry::positionWorldExact), with Intel Embree 3 (Debian's
// libembree-dev): one BVH over every triangle, built once per scene, then "is anything between
// this surface point and this light?" for any number of points and lights.
//
// Conventions: world space, metres. Every triangle in the BVH is two-sided; given the materials'
// casting policy (CasterMaterials.h), those of non-casting materials (blended, masked below the
// cutoff) are not in it. Built from a scene, the triangles of alpha-tested materials (textured
// masks) are a second Embree geometry whose occlusion filter tests the alpha at each hit's
// barycentrics (CasterAlphaTest), so a hit in a cut-out's hole does not block; built from casting
// flags alone, every triangle in the BVH is opaque. The query is the segment
// of ShadowRay.h: the origin offset along the normal by a distance relative to the coordinates'
// magnitude, the far end stopped as far short of the light; the exact oracle (ExactRayCast.h)
// follows the same rule.
//
// What float costs. Embree stores vertices and rays in float, so each coordinate moves by up to
// 2^-24 of its magnitude (0.6 um at 10 m) and its watertight intersection test (the scene is
// built RTC_SCENE_FLAG_ROBUST) adds a few such errors. The answer can therefore differ from the
// exact double-precision one only for a segment that passes within a few float ulps of a
// triangle's edge (a shadow boundary, where the disagreement moves the boundary by that much) or
// that ends within them of a triangle. The origin offset, 2^-14 of the magnitude (61 um at 1 m),
// is 1024 times larger: it dominates, so self-shadowing never comes from float, and float moves
// no boundary by more than the rounding of the geometry the rasterizer already sees. The tests
// count the disagreements with the double oracle outside a band of 2^-18 of the scene's magnitude
// around edges and endpoints: none.
//
// Degenerate triangles (repeated or collinear vertices after rounding to float, non-finite or
// out-of-range indices) are left out of the BVH: they cannot block a segment except along an
// edge, and Embree need not see them. droppedTriangleCount() says how many.
//
// Threads: construction builds the BVH with Embree's own TBB tasks (in the caller's TBB arena).
// After construction the object is immutable and every query is thread-safe; the batched query
// runs in parallel (TBB), each ray's answer written by one task only, so answers never depend on
// the thread count or the schedule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include <glm/glm.hpp>

#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/ShadowRay.h"

// Embree's handles (rtcore_device.h, rtcore_scene.h), kept out of this header.
struct RTCDeviceTy;
struct RTCSceneTy;

namespace scenes {
struct Scene;
}

namespace lighting::shadows {

class CasterAlphaTest;
struct RayAlphaFilter; // what the occlusion filter of alpha-tested casters reads
                       // (RayVisibility.cpp)

class RayVisibility {
public:
    // Builds the BVH (RTC_BUILD_QUALITY_HIGH, RTC_SCENE_FLAG_ROBUST) over `geometry`'s triangles,
    // with positionWorldExact rounded to float. Called once per scene; costs about 0.35 s of one
    // core per million triangles (atrium, 346k triangles: 118 ms on 1 thread, 56 ms on 2) and
    // about 90 bytes per triangle (embreeBytes()). Throws std::runtime_error with Embree's
    // message when Embree fails (no device, out of memory), std::length_error beyond 2^32 - 1
    // vertices or triangles.
    // castingMaterial, when not empty, has one flag per material (CasterMaterials.h): triangles
    // of a material flagged 0 are left out (they cast no shadow), counted as dropped.
    explicit RayVisibility(const gbuffer::SceneGeometry& geometry,
                           std::span<const uint8_t> castingMaterial = {});
    // The scene's casters by its materials' policy (castingMaterials), the alpha-tested ones
    // filtered per hit: `scene` and `geometry` must outlive the object when the scene has
    // alpha-tested materials (the filter reads their uvs and textures).
    RayVisibility(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry);
    ~RayVisibility();
    RayVisibility(const RayVisibility&) = delete;
    RayVisibility& operator=(const RayVisibility&) = delete;

    // True when a triangle blocks the segment from `surfaceWorld` (offset along `normalWorld`) to
    // the point light at `lightWorld` (ShadowRay.h). One Embree occlusion ray; thread-safe.
    bool occluded(const glm::dvec3& surfaceWorld, const glm::dvec3& normalWorld,
                  const glm::dvec3& lightWorld) const;
    // Directional light: the unbounded ray toward -directionWorld (the direction the light
    // travels). One Embree occlusion ray; thread-safe.
    bool occludedDirectional(const glm::dvec3& surfaceWorld, const glm::dvec3& normalWorld,
                             const glm::dvec3& directionWorld) const;
    // Any ShadowRay (either kind).
    bool occluded(const ShadowRay& ray) const;
    // Many rays at once: result[i] = occluded(rays[i]) ? 1 : 0, the same answers as the single
    // calls (tested). Packets of 16 (rtcOccluded16), packets in parallel. Throws
    // std::invalid_argument when the spans' sizes differ. Thread-safe.
    void occluded(std::span<const ShadowRay> rays, std::span<uint8_t> result) const;

    // Triangles in the BVH (the scene's less the dropped ones).
    size_t triangleCount() const { return mTriangleCount; }
    // Of those, the alpha-tested ones (in the filtered geometry).
    size_t alphaTestedTriangleCount() const;
    // Triangles left out: degenerate (see above) or of a material that casts no shadow.
    size_t droppedTriangleCount() const { return mDroppedTriangleCount; }
    // Wall time of the constructor (filtering, conversion to float, BVH build).
    double buildMilliseconds() const { return mBuildMilliseconds; }
    // Bytes Embree holds for the scene (vertex and index buffers, BVH), as its memory monitor
    // counted them during construction.
    size_t embreeBytes() const { return mEmbreeBytes; }

private:
    struct DeviceRelease {
        void operator()(RTCDeviceTy* device) const;
    };
    struct SceneRelease {
        void operator()(RTCSceneTy* scene) const;
    };

    void build(const gbuffer::SceneGeometry& geometry, std::span<const uint8_t> castingMaterial,
               const CasterAlphaTest* alphaTest);

    // Declared in this order so that the scene is released before its device, and both before
    // the filter's data.
    std::unique_ptr<RayAlphaFilter> mAlphaFilter;
    std::unique_ptr<RTCDeviceTy, DeviceRelease> mDevice;
    std::unique_ptr<RTCSceneTy, SceneRelease> mScene;
    size_t mTriangleCount = 0;
    size_t mDroppedTriangleCount = 0;
    double mBuildMilliseconds = 0.0;
    size_t mEmbreeBytes = 0;
};

} // namespace lighting::shadows
