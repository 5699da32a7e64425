// The one lighting model of the testbed (DESIGN.md), in one function used by every stage and by
// the reference: Lambert diffuse plus normalised Blinn-Phong specular, for point, spot,
// directional and ambient lights. Templated on the scalar type so that the reference runs the
// very same formula in double.
//
// Point and spot lights use the windowed inverse-square falloff
//     attenuation(d) = saturate(1 - (d/r)^4)^2 / (d^2 + 1)
// which is exactly zero at and beyond the range r: culling by the light's sphere is exact.
// A light CONTRIBUTES at a sample when the radiance it adds there is non-zero.
// Conventions: view space, camera at the origin looking down -Z; light.directionView is the
// direction light travels (from a spot light along its axis, from the sun towards the ground).
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "scenes/Scene.h"

namespace lighting {

template <class T> using Vec3 = glm::vec<3, T, glm::defaultp>;

// A scene light in view space, with its colour and intensity folded into one radiance.
template <class T> struct LightInView {
    scenes::LightType type = scenes::LightType::Point;
    Vec3<T> positionView{T(0)};
    Vec3<T> directionView{T(0), T(0), T(-1)};
    Vec3<T> radiance{T(0)};
    T rangeMetres = T(0);
    T spotInnerCos = T(1);
    T spotOuterCos = T(1);
};

inline constexpr double kPi = 3.14159265358979323846;

// Radiance towards the camera from one light at one surface point. Zero (exactly) when the point
// is at or beyond the light's range, outside a spot cone, or facing away from the light.
template <class T>
inline Vec3<T> evaluateLight(const gbuffer::BasicSurface<T>& s, const Vec3<T>& toViewer,
                             const LightInView<T>& light) {
    using scenes::LightType;
    if (light.type == LightType::Ambient)
        return light.radiance * s.albedo;

    Vec3<T> toLight;
    T attenuation = T(1);
    if (light.type == LightType::Directional) {
        toLight = -light.directionView;
    } else {
        const Vec3<T> offset = light.positionView - s.positionView;
        const T distance2 = glm::dot(offset, offset);
        const T range2 = light.rangeMetres * light.rangeMetres;
        if (!(distance2 < range2))
            return Vec3<T>(T(0));
        // A light exactly on the surface has no direction; treat it as overhead.
        toLight = distance2 > T(0) ? offset / std::sqrt(distance2) : s.normalView;
        const T ratio2 = distance2 / range2;
        const T window = T(1) - ratio2 * ratio2;
        attenuation = window * window / (distance2 + T(1));
        if (light.type == LightType::Spot) {
            const T cosAngle = -glm::dot(toLight, light.directionView);
            if (!(cosAngle > light.spotOuterCos))
                return Vec3<T>(T(0));
            const T width = light.spotInnerCos - light.spotOuterCos;
            const T t = width > T(0)
                            ? glm::clamp((cosAngle - light.spotOuterCos) / width, T(0), T(1))
                            : T(1);
            attenuation *= t * t * (T(3) - T(2) * t);
        }
    }
    const T nDotL = glm::dot(s.normalView, toLight);
    if (!(nDotL > T(0)))
        return Vec3<T>(T(0));
    const Vec3<T> halfway = glm::normalize(toLight + toViewer);
    const T nDotH = std::max(glm::dot(s.normalView, halfway), T(0));
    const T specular = s.specularIntensity * (s.specularPower + T(8)) * T(1.0 / (8.0 * kPi)) *
                       std::pow(nDotH, s.specularPower);
    return light.radiance * (attenuation * nDotL) * (s.albedo * T(1.0 / kPi) + Vec3<T>(specular));
}

template <class T> inline bool contributes(const Vec3<T>& radiance) {
    return radiance.x != T(0) || radiance.y != T(0) || radiance.z != T(0);
}

} // namespace lighting
