// LightInView: a scene light in view space, the form every lighting function (Brdf.h,
// LightIncidence.h, MetallicRoughness.h) and every stage consume, with the constants and the
// vector alias they share. Apart from Brdf.h so that the per-model headers can include it without
// including the dispatch that includes them.
// Conventions: view space right-handed, camera at the origin looking down -Z, metres;
// directionView is the direction light travels (from a spot light along its axis, from the sun
// towards the ground). Plain data.
#pragma once

#include <glm/glm.hpp>

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

} // namespace lighting
