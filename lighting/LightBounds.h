// LightBounds: conservative view-space bounding spheres of lights, for culling. Every culling
// stage tests these and never the raw range, so a light is never dropped by rounding: the radius
// is widened by kCullingSlack (relative) + kCullingSlackMetres (absolute), far more than the
// float error of the positions a stage reconstructs, and the widening only ever adds work.
// Directional and ambient lights are unbounded (they reach every pixel).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "lighting/LightList.h"

namespace lighting {

inline constexpr float kCullingSlack = 1e-4f;         // relative to the range
inline constexpr float kCullingSlackMetres = 1e-4f;   // absolute, for tiny ranges

struct LightSphere {
    glm::vec3 centreView{0.0f};
    float radius = 0.0f;
    bool unbounded = false;  // directional / ambient
};

inline std::vector<LightSphere> boundingSpheresView(const LightList& lights) {
    std::vector<LightSphere> spheres;
    spheres.reserve(lights.size());
    for (const LightInView<float>& light : lights.lights) {
        LightSphere sphere;
        sphere.centreView = light.positionView;
        sphere.unbounded = light.type == scenes::LightType::Directional ||
                           light.type == scenes::LightType::Ambient;
        sphere.radius = light.rangeMetres * (1.0f + kCullingSlack) + kCullingSlackMetres;
        spheres.push_back(sphere);
    }
    return spheres;
}

}  // namespace lighting
