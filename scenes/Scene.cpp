#include "scenes/Scene.h"

#include <cmath>

namespace scenes {

glm::dmat4 viewFromBasis(const glm::dvec3& eye, const glm::dvec3& forward, const glm::dvec3& up) {
    // glm::lookAtRH(eye, eye + forward, up) without forming eye + forward: far from the origin
    // that sum rounds back to eye (in float from ~1e7 m, in double from ~1e15 m) and the
    // direction recovered from it is zero or wrong. The basis comes from forward and up alone.
    const glm::dvec3 f = glm::normalize(forward);
    const glm::dvec3 s = glm::normalize(glm::cross(f, up));
    const glm::dvec3 u = glm::cross(s, f);
    glm::dmat4 view(1.0);
    for (int column = 0; column < 3; ++column) {
        view[column][0] = s[column];
        view[column][1] = u[column];
        view[column][2] = -f[column];
    }
    view[3][0] = -glm::dot(s, eye);
    view[3][1] = -glm::dot(u, eye);
    view[3][2] = glm::dot(f, eye);
    return view;
}

glm::dmat4 Camera::viewFromWorldExact() const {
    return viewFromBasis(glm::dvec3(positionWorld), glm::dvec3(forwardWorld), glm::dvec3(upWorld));
}

glm::mat4 Camera::viewFromWorld() const {
    return glm::mat4(viewFromWorldExact());
}

uint64_t Scene::triangleCount() const {
    uint64_t count = 0;
    for (const Instance& instance : instances)
        count += meshes[instance.mesh].triangleCount();
    return count;
}

Aabb Scene::boundsWorld() const {
    Aabb bounds;
    for (const Instance& instance : instances) {
        for (const glm::vec3& p : meshes[instance.mesh].positions)
            bounds.extend(glm::vec3(instance.worldFromObject * glm::vec4(p, 1.0f)));
    }
    for (const Camera& camera : cameras)
        bounds.extend(camera.positionWorld);
    return bounds;
}

} // namespace scenes
