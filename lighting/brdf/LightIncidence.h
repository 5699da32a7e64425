// How much of a point, spot or directional light reaches a surface point, and from where: the
// finite-support distance window and the spot cone of DESIGN.md, apart from any BRDF, so that every
// material model attenuates lights with the very same arithmetic (and culling by a light's sphere
// or cone stays exact for all of them). Both of Brdf.h's models call it; its arithmetic is,
// operation for operation, what Brdf.h computed inline before (the Blinn-Phong outputs did not
// change); tests/lighting/brdf/brdf_closed_form_test.cpp checks it against closed forms. Templated
// on the scalar type (float for the stages, double for the reference).
//
//     attenuation(d) = saturate(1 - (d/r)^4)^2 / (d^2 + 1)      exactly 0 at and beyond d = r
//     spot(cos)      = smoothstep(outerCos, innerCos, cos)      exactly 0 at and outside outerCos
//
// Conventions: those of Brdf.h (view space; light.directionView is the way the light travels).
// Ambient lights have no direction and are not handled here. Pure functions, thread-safe.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "lighting/brdf/LightInView.h"

namespace lighting {

template <class T> struct Incidence {
    Vec3<T> toLight{T(0)}; // unit, from the surface point towards the light
    T attenuation = T(0);  // window x spot factor; exactly 0 when the light does not reach
};

// Where a point, spot or directional light comes from at positionView and how strongly. A light
// exactly at the surface point has no direction; it is taken as overhead (normalView).
template <class T>
inline Incidence<T> lightIncidence(const Vec3<T>& positionView, const Vec3<T>& normalView,
                                   const LightInView<T>& light) {
    using scenes::LightType;
    Incidence<T> incidence;
    if (light.type == LightType::Directional) {
        incidence.toLight = -light.directionView;
        incidence.attenuation = T(1);
        return incidence;
    }
    const Vec3<T> offset = light.positionView - positionView;
    const T distance2 = glm::dot(offset, offset);
    const T range2 = light.rangeMetres * light.rangeMetres;
    if (!(distance2 < range2))
        return incidence;
    incidence.toLight = distance2 > T(0) ? offset / std::sqrt(distance2) : normalView;
    const T ratio2 = distance2 / range2;
    const T window = T(1) - ratio2 * ratio2;
    T attenuation = window * window / (distance2 + T(1));
    if (light.type == LightType::Spot) {
        const T cosAngle = -glm::dot(incidence.toLight, light.directionView);
        if (!(cosAngle > light.spotOuterCos))
            return Incidence<T>{incidence.toLight, T(0)};
        const T width = light.spotInnerCos - light.spotOuterCos;
        const T t =
            width > T(0) ? glm::clamp((cosAngle - light.spotOuterCos) / width, T(0), T(1)) : T(1);
        attenuation *= t * t * (T(3) - T(2) * t);
    }
    incidence.attenuation = attenuation;
    return incidence;
}

} // namespace lighting
