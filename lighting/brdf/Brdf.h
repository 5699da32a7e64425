// The one lighting function of the testbed (DESIGN.md), used by every stage and by the reference:
// evaluateLight shades a surface sample with the material model the sample carries
// (Surface::model): Lambert diffuse plus normalised Blinn-Phong specular (this file), or the glTF
// 2.0 metallic-roughness model (MetallicRoughness.h: GGX, Smith, Schlick), for point, spot,
// directional and ambient lights. Templated on the scalar type so that the reference runs the very
// same formulas in double.
//
// Point and spot lights use the windowed inverse-square falloff and the spot smoothstep of
// LightIncidence.h, shared by both models,
//     attenuation(d) = saturate(1 - (d/r)^4)^2 / (d^2 + 1)
// which is exactly zero at and beyond the range r: culling by the light's sphere is exact for
// either model. A light CONTRIBUTES at a sample when the radiance it adds there is non-zero.
// Conventions: view space, camera at the origin looking down -Z; light.directionView is the
// direction light travels (from a spot light along its axis, from the sun towards the ground).
// Cost: the metallic-roughness branch recomputes its per-sample lobes (a few multiplies) per light,
// which keeps the one entry point; the Blinn-Phong branch is operation for operation the function
// it has always been (its outputs are bitwise those of the code before the dispatch existed).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "lighting/brdf/LightInView.h"
#include "lighting/brdf/LightIncidence.h"
#include "lighting/brdf/MetallicRoughness.h"
#include "scenes/Scene.h"

namespace lighting {

// Lambert + normalised Blinn-Phong: radiance towards the camera from one light. Zero (exactly)
// when the point is at or beyond the light's range, outside a spot cone, or facing away from it.
template <class T>
inline Vec3<T> evaluateLightBlinnPhong(const gbuffer::BasicSurface<T>& s, const Vec3<T>& toViewer,
                                       const LightInView<T>& light) {
    if (light.type == scenes::LightType::Ambient)
        return light.radiance * s.albedo;
    const Incidence<T> incidence = lightIncidence(s.positionView, s.normalView, light);
    if (!(incidence.attenuation > T(0)))
        return Vec3<T>(T(0));
    const T nDotL = glm::dot(s.normalView, incidence.toLight);
    if (!(nDotL > T(0)))
        return Vec3<T>(T(0));
    const Vec3<T> halfway = glm::normalize(incidence.toLight + toViewer);
    const T nDotH = std::max(glm::dot(s.normalView, halfway), T(0));
    const T specular = s.specularIntensity * (s.specularPower + T(8)) * T(1.0 / (8.0 * kPi)) *
                       std::pow(nDotH, s.specularPower);
    return light.radiance * (incidence.attenuation * nDotL) *
           (s.albedo * T(1.0 / kPi) + Vec3<T>(specular));
}

// The one entry: radiance towards the camera from one light at one surface sample, with the
// sample's material model. toViewer is the unit vector from the sample to the camera.
template <class T>
inline Vec3<T> evaluateLight(const gbuffer::BasicSurface<T>& s, const Vec3<T>& toViewer,
                             const LightInView<T>& light) {
    if (s.model == scenes::MaterialModel::MetallicRoughness) {
        const MetallicRoughnessSurface<T> material{s.albedo, s.metallic, s.roughness, s.occlusion};
        return evaluateLightMetallicRoughness(s.positionView, s.normalView,
                                              metallicRoughnessLobes(material), toViewer, light);
    }
    return evaluateLightBlinnPhong(s, toViewer, light);
}

template <class T> inline bool contributes(const Vec3<T>& radiance) {
    return radiance.x != T(0) || radiance.y != T(0) || radiance.z != T(0);
}

} // namespace lighting
