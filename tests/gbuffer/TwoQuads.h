// A test scene shared by the G-buffer layout tests: two quads side by side facing a camera at the
// origin, one material each, so that layout rules can be checked per material.
#pragma once

#include <glm/glm.hpp>

#include "scenes/Scene.h"

namespace gbuffertest {

inline scenes::Scene twoQuads(scenes::Material left, scenes::Material right) {
    scenes::Scene scene;
    scene.name = "two-quads";
    for (int i = 0; i < 2; ++i) {
        scenes::Mesh mesh;
        const float x0 = i == 0 ? -2.0f : 0.0f, x1 = x0 + 2.0f;
        mesh.positions = {{x0, -1, -4}, {x1, -1, -4}, {x1, 1, -4}, {x0, 1, -4}};
        mesh.normals.assign(4, glm::vec3(0, 0, 1));
        mesh.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
        mesh.indices = {0, 1, 2, 0, 2, 3};
        mesh.material = uint32_t(i);
        scene.meshes.push_back(mesh);
        scene.instances.push_back({uint32_t(i), glm::mat4(1.0f)});
    }
    scene.materials = {left, right};
    scenes::Camera camera;
    camera.forwardWorld = {0, 0, -1};
    scene.cameras.push_back(camera);
    scenes::validate(scene);
    return scene;
}

} // namespace gbuffertest
