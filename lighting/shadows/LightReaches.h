// lightReaches: whether a light passes its range, spot-cone and facing tests at a surface point,
// with evaluateLight's float operations in its order (lighting/brdf/LightIncidence.h): the
// pixel-light pairs a shadow can darken. The kernel asks the shadow lookup exactly there (its
// early-out phases, lighting/kernel), ShadowError.h counts exactly these pairs, and the kernel's
// tests rebuild the kernel's calls from it. Ambient lights: false (nothing shadows them).
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "lighting/brdf/LightInView.h"

namespace lighting::shadows {

inline bool lightReaches(const gbuffer::Surface& s, const LightInView<float>& light) {
    using scenes::LightType;
    if (light.type == LightType::Ambient)
        return false;
    glm::vec3 toLight = -light.directionView;
    if (light.type != LightType::Directional) {
        const glm::vec3 offset = light.positionView - s.positionView;
        const float distance2 = glm::dot(offset, offset);
        if (!(distance2 < light.rangeMetres * light.rangeMetres))
            return false;
        toLight = distance2 > 0.0f ? offset / std::sqrt(distance2) : s.normalView;
        if (light.type == LightType::Spot &&
            !(-glm::dot(toLight, light.directionView) > light.spotOuterCos))
            return false;
    }
    return glm::dot(s.normalView, toLight) > 0.0f;
}

} // namespace lighting::shadows
