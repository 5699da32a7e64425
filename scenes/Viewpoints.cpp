// Viewpoints: see Viewpoints.h.
#include "scenes/Viewpoints.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "scenes/SceneLoader.h"
#include "scenes/input/ClosestName.h"

namespace scenes {

std::vector<std::string> viewNames(const Scene& scene) {
    std::vector<std::string> names;
    for (const Camera& camera : scene.cameras)
        names.push_back(camera.name);
    return names;
}

void selectView(Scene& scene, const std::string& name) {
    const auto found = std::find_if(scene.cameras.begin(), scene.cameras.end(),
                                    [&](const Camera& camera) { return camera.name == name; });
    if (found == scene.cameras.end()) {
        std::string valid;
        for (const std::string& view : viewNames(scene))
            valid += (valid.empty() ? "" : ", ") + view;
        throw SceneError(scene.name + ": no view '" + name + "'" +
                         didYouMean(name, viewNames(scene)) + "; views: " + valid);
    }
    // Rotating [begin, found] keeps the other views in their order.
    std::rotate(scene.cameras.begin(), found, found + 1);
}

void makeViewNamesUnique(std::vector<Camera>& cameras) {
    std::map<std::string, int> seen;
    for (size_t i = 0; i < cameras.size(); ++i) {
        if (cameras[i].name.empty())
            cameras[i].name = "camera " + std::to_string(i);
        const std::string base = cameras[i].name;
        int& count = seen[base];
        if (++count > 1) {
            // "x (2)" may itself be taken by a camera of that name: keep counting until free.
            std::string candidate;
            do
                candidate = base + " (" + std::to_string(count++) + ")";
            while (seen.count(candidate));
            --count;
            cameras[i].name = candidate;
            seen[candidate] = 1;
        }
    }
}

namespace {

glm::vec3 directionBetween(const glm::vec3& a, const glm::vec3& b, float t) {
    return glm::normalize((1.0f - t) * a + t * b);
}

float lerp(float a, float b, float t) {
    return (1.0f - t) * a + t * b;
}

} // namespace

std::vector<Camera> cameraPath(const std::string& name, const std::vector<Camera>& keys,
                               int frames) {
    if (keys.size() < 2)
        throw SceneError("camera path '" + name + "': needs at least 2 keys");
    if (frames < 2)
        throw SceneError("camera path '" + name + "': needs at least 2 frames");
    for (size_t k = 0; k + 1 < keys.size(); ++k)
        if (glm::dot(keys[k].forwardWorld, keys[k + 1].forwardWorld) < -0.999f)
            throw SceneError("camera path '" + name + "': keys " + std::to_string(k) + " and " +
                             std::to_string(k + 1) + " look in opposite directions");
    const int digits = int(std::to_string(frames - 1).size());
    std::vector<Camera> path;
    const int segments = int(keys.size()) - 1;
    for (int frame = 0; frame < frames; ++frame) {
        // The path's parameter in [0, segments]; the last frame lands exactly on the last key.
        const double s = double(frame) * segments / double(frames - 1);
        const int segment = std::min(int(s), segments - 1);
        const float t = float(s - segment);
        const Camera& a = keys[size_t(segment)];
        const Camera& b = keys[size_t(segment) + 1];
        Camera camera;
        std::string number = std::to_string(frame);
        number.insert(0, size_t(digits) - number.size(), '0');
        camera.name = name + "/" + number;
        camera.positionWorld = glm::mix(a.positionWorld, b.positionWorld, t);
        camera.forwardWorld = directionBetween(a.forwardWorld, b.forwardWorld, t);
        camera.upWorld = directionBetween(a.upWorld, b.upWorld, t);
        camera.verticalFovRadians = lerp(a.verticalFovRadians, b.verticalFovRadians, t);
        camera.nearMetres = lerp(a.nearMetres, b.nearMetres, t);
        camera.farMetres = lerp(a.farMetres, b.farMetres, t);
        path.push_back(camera);
    }
    return path;
}

std::vector<Camera> orbitViews(const Camera& front, const Aabb& boundsWorld) {
    const glm::vec3 centre = boundsWorld.empty() ? glm::vec3(0.0f) : boundsWorld.centre();
    const glm::vec3 offset = front.positionWorld - centre;
    const float distance = glm::length(offset);
    const auto around = [&](const char* name, const glm::vec3& direction) {
        Camera camera = front;
        camera.name = name;
        camera.positionWorld = centre + distance * glm::normalize(direction);
        camera.forwardWorld = -glm::normalize(direction);
        // Looking straight down would make +Y parallel to the view: "above" is 60 degrees up.
        camera.upWorld = glm::vec3(0.0f, 1.0f, 0.0f);
        return camera;
    };
    const glm::vec3 horizontal = glm::length(glm::vec2(offset.x, offset.z)) > 0.0f
                                     ? glm::normalize(glm::vec3(offset.x, 0.0f, offset.z))
                                     : glm::vec3(0.0f, 0.0f, 1.0f);
    const glm::vec3 side = glm::cross(glm::vec3(0.0f, 1.0f, 0.0f), horizontal); // to the right
    const float up = offset.y / std::max(distance, 1e-6f);
    const float level = std::sqrt(std::max(0.0f, 1.0f - up * up));
    return {around("left", level * -side + up * glm::vec3(0, 1, 0)),
            around("right", level * side + up * glm::vec3(0, 1, 0)),
            around("above", 0.5f * horizontal + 0.8660254f * glm::vec3(0, 1, 0))};
}

} // namespace scenes
