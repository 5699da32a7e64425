#include "lighting/shadows/RayShadows.h"

#include "lighting/shadows/ShadowMaps.h"

namespace lighting::shadows {

// The maps' view is never jittered (lighting/SupersampledReference.h jitters the projection
// only), so the choice is the one the stage's maps made.
RayShadows::RayShadows(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry,
                       const gbuffer::CameraView& view, const ShadowSettings& settings)
    : RayShadows(scene, geometry, view,
                 ShadowMaps::chooseLights(scene.lights, view, settings.maxShadowLights)) {}

RayShadows::RayShadows(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry,
                       const gbuffer::CameraView& view, const std::vector<uint32_t>& castingLights)
    : mRays(std::make_unique<RayVisibility>(scene, geometry)),
      mWorldFromView(glm::inverse(view.viewFromWorldExact)),
      mWorldFromViewNormal(glm::dmat3(mWorldFromView)), mLights(scene.lights),
      mCasts(scene.lights.size(), false) {
    for (uint32_t light : castingLights)
        if (light < mCasts.size() && !mCasts[light] &&
            scene.lights[light].type != scenes::LightType::Ambient) {
            mCasts[light] = true;
            ++mCastingLightCount;
        }
}

std::vector<uint32_t> RayShadows::everyLightCasts(const scenes::Scene& scene) {
    std::vector<uint32_t> lights;
    for (uint32_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].type != scenes::LightType::Ambient)
            lights.push_back(i);
    return lights;
}

double RayShadows::visibility(size_t lightIndex, const glm::dvec3& positionView,
                              const glm::dvec3& normalView) const {
    const scenes::Light& light = mLights[lightIndex];
    const glm::dvec3 surfaceWorld = glm::dvec3(mWorldFromView * glm::dvec4(positionView, 1.0));
    // The view rotation is orthonormal: it maps a unit normal to a unit normal.
    const glm::dvec3 normalWorld = mWorldFromViewNormal * normalView;
    const bool blocked =
        light.type == scenes::LightType::Directional
            ? mRays->occludedDirectional(surfaceWorld, normalWorld,
                                         glm::dvec3(light.directionWorld))
            : mRays->occluded(surfaceWorld, normalWorld, glm::dvec3(light.positionWorld));
    return blocked ? 0.0 : 1.0;
}

} // namespace lighting::shadows
