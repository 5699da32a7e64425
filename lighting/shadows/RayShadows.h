// RayShadows: the reference's shadows (ShadowLookup.h's ExactShadowLookup): exact visibility of
// each casting light by one shadow ray per pixel and light against the unquantised geometry
// (RayVisibility, Embree), the ground truth the shadow maps are measured against. The casting
// lights are the maps' (ShadowMaps::chooseLights with the same budget and the same unjittered
// view), so the reference and a stage shadow the same lights and differ only in how.
//
// Conventions: positions and normals arrive in camera view space (double, the exact surface's);
// the ray is traced in world space through the inverse of the view's exact matrix. A view
// jittered by a sub-pixel offset (the supersampled reference) has the same viewFromWorld, so
// one RayShadows serves every sub-frame. Visibility is 0 or 1 (a point light has no area).
// `scene` and `geometry` must outlive it (the rays' filter of alpha-tested casters reads their
// uvs and textures). Immutable after construction; visibility() is thread-safe.
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/RayVisibility.h"
#include "lighting/shadows/ShadowLookup.h"
#include "lighting/shadows/ShadowSettings.h"
#include "scenes/Scene.h"

namespace lighting::shadows {

class RayShadows final : public ExactShadowLookup {
public:
    // Builds the BVH of `geometry` (RayVisibility: ~0.1 s per 346k triangles on one core) and
    // chooses the casting lights as ShadowMaps::render does for `settings` and `view`.
    RayShadows(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry,
               const gbuffer::CameraView& view, const ShadowSettings& settings);
    // The given casting lights (indices into scene.lights; ambient ones are ignored): every
    // non-ambient light for the occlusion-aware oracle (everyLightCasts).
    RayShadows(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry,
               const gbuffer::CameraView& view, const std::vector<uint32_t>& castingLights);
    static std::vector<uint32_t> everyLightCasts(const scenes::Scene& scene);

    bool casts(size_t lightIndex) const override {
        return lightIndex < mCasts.size() && mCasts[lightIndex];
    }
    double visibility(size_t lightIndex, const glm::dvec3& positionView,
                      const glm::dvec3& normalView) const override;

    const RayVisibility& rays() const { return *mRays; }
    size_t castingLightCount() const { return mCastingLightCount; }

private:
    std::unique_ptr<RayVisibility> mRays;
    glm::dmat4 mWorldFromView{1.0};
    glm::dmat3 mWorldFromViewNormal{1.0};
    std::vector<scenes::Light> mLights; // world space, the scene's order
    std::vector<bool> mCasts;           // per scene light
    size_t mCastingLightCount = 0;
};

} // namespace lighting::shadows
