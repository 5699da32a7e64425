// LightBounds: conservative view-space bounding spheres of lights, for culling. Every culling
// stage tests these and never the raw range, so a light is never dropped by rounding: the radius
// is widened by kCullingSlack (relative) + kCullingSlackMetres (absolute; rule 1 of the one slack
// policy, culling/README.md), far more than the
// float error of the positions a stage reconstructs, and the widening only ever adds work.
// Directional and ambient lights are unbounded (they reach every pixel). A spot light lights only
// the points within its range AND its outer cone, so its sphere is the smallest sphere around that
// spherical sector (cone plus cap), which for narrow cones is far smaller than the range sphere:
//   half-angle t <= 45 deg: centre apex + r / (2 cos t) along the axis, radius r / (2 cos t)
//   45 deg < t < 90 deg:    centre apex + r cos t along the axis,     radius r sin t
//   t >= 90 deg:            the range sphere
// (each contains the apex, the rim and the whole cap; derivation in the function). The emitter's
// own position stays in `positionView`: tests about where light comes from (back-face culling)
// use it, tests about where light lands use the sphere. Such spot lights also keep their raw cone
// (apex positionView, axis, outer cosine, range; `spot` set) for bounds tighter than a sphere
// (the cone proxies of LightVolumes.h), which must add their own slack.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <glm/glm.hpp>

#include "lighting/culling/LightList.h"

namespace lighting {

inline constexpr float kCullingSlack = 1e-4f;       // relative to the range
inline constexpr float kCullingSlackMetres = 1e-4f; // absolute, for tiny ranges

struct LightSphere {
    glm::vec3 centreView{0.0f}; // centre of the bounding sphere of the lit region
    float radius = 0.0f;
    bool unbounded = false;       // directional / ambient
    glm::vec3 positionView{0.0f}; // the emitter (equal to centreView for point lights)
    // Spot lights with a half-angle below 90 degrees: the raw cone, as the light is evaluated.
    bool spot = false;
    glm::vec3 axisView{0.0f, 0.0f, -1.0f}; // unit, the direction the light travels
    float spotOuterCos = -1.0f;            // cosine of the outer half-angle
    float rangeMetres = 0.0f;
};

inline LightSphere boundingSphereView(const LightInView<float>& light) {
    LightSphere sphere;
    sphere.centreView = light.positionView;
    sphere.positionView = light.positionView;
    sphere.unbounded =
        light.type == scenes::LightType::Directional || light.type == scenes::LightType::Ambient;
    double radius = light.rangeMetres;
    if (light.type == scenes::LightType::Spot && light.spotOuterCos > 0.0f) {
        // A lit point p = apex + d u with d < r and u . axis > cos t. For a centre c = apex + k
        // axis, |p - c|^2 = d^2 + k^2 - 2 d k (u . axis) <= d^2 + k^2 - 2 d k cos t, largest
        // at d = r (it is convex in d and d = 0 gives k^2 <= R^2). With k = R = r / (2 cos t)
        // this is r^2 - 2 r R cos t + R^2 = R^2; with k = r cos t, R = r sin t it is
        // r^2 - r^2 cos^2 t = R^2, and k <= R (the apex) holds for t >= 45 degrees.
        const double cosT = light.spotOuterCos, r = light.rangeMetres;
        const double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
        const bool narrow = cosT >= std::sqrt(0.5);
        const double offset = narrow ? r / (2.0 * cosT) : r * cosT;
        radius = narrow ? offset : r * sinT;
        const glm::dvec3 axis = glm::normalize(glm::dvec3(light.directionView));
        sphere.centreView = glm::vec3(glm::dvec3(light.positionView) + offset * axis);
        // The centre was rounded to float: grow by its rounding (relative to its magnitude).
        radius += 4e-7 * (glm::length(glm::dvec3(sphere.centreView)) + r);
        sphere.spot = true;
        sphere.axisView = light.directionView;
        sphere.spotOuterCos = light.spotOuterCos;
        sphere.rangeMetres = light.rangeMetres;
    }
    sphere.radius = float(radius) * (1.0f + kCullingSlack) + kCullingSlackMetres;
    return sphere;
}

// Every light's sphere (index = light index). Lights in parallel (10^6 lights: a few ms), each
// sphere a function of its light alone: the same spheres for any thread count.
inline std::vector<LightSphere> boundingSpheresView(const std::vector<LightInView<float>>& lights) {
    std::vector<LightSphere> spheres(lights.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lights.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t k = range.begin(); k < range.end(); ++k)
                              spheres[k] = boundingSphereView(lights[k]);
                      });
    return spheres;
}

inline std::vector<LightSphere> boundingSpheresView(const LightList& lights) {
    return boundingSpheresView(lights.lights);
}

// The same into `spheres`, reusing its storage: a stage that keeps the vector across frames pays
// no allocation (at 10^6 lights a fresh 56 MB vector, zeroed on one thread and page-faulted, cost
// more than the assignment itself; measured in lighting/culling/README.md).
inline void boundingSpheresView(const LightList& lights, std::vector<LightSphere>& spheres) {
    spheres.resize(lights.lights.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lights.lights.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t k = range.begin(); k < range.end(); ++k)
                              spheres[k] = boundingSphereView(lights.lights[k]);
                      });
}

} // namespace lighting
