#include "scenes/Scene.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace scenes {

glm::mat4 Camera::viewFromWorld() const {
    return glm::lookAtRH(positionWorld, positionWorld + forwardWorld, upWorld);
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

static bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void validate(const Scene& scene) {
    auto fail = [&](const std::string& what) { throw SceneError(scene.name + ": " + what); };
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const std::string where = "mesh " + std::to_string(m) + " '" + mesh.name + "'";
        if (mesh.indices.size() % 3 != 0)
            fail(where + ": index count is not a multiple of 3");
        if (mesh.normals.size() != mesh.positions.size())
            fail(where + ": " + std::to_string(mesh.normals.size()) + " normals for " +
                 std::to_string(mesh.positions.size()) + " positions");
        if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
            fail(where + ": uv count differs from position count");
        if (!mesh.uvs1.empty() && mesh.uvs1.size() != mesh.positions.size())
            fail(where + ": second uv set's count differs from position count");
        if (!mesh.tangents.empty() && mesh.tangents.size() != mesh.positions.size())
            fail(where + ": tangent count differs from position count");
        for (uint32_t index : mesh.indices)
            if (index >= mesh.positions.size())
                fail(where + ": index " + std::to_string(index) + " out of range (" +
                     std::to_string(mesh.positions.size()) + " vertices)");
        for (const glm::vec3& p : mesh.positions)
            if (!finite(p))
                fail(where + ": position is NaN or infinite");
        for (const glm::vec3& n : mesh.normals)
            if (!finite(n))
                fail(where + ": normal is NaN or infinite");
        if (mesh.material >= scene.materials.size())
            fail(where + ": material " + std::to_string(mesh.material) + " out of range");
    }
    for (const Material& material : scene.materials) {
        for (int t : material.textureIndices())
            if (t >= int(scene.textures.size()))
                fail("material '" + material.name + "': texture index out of range");
        for (const TextureMapping* mapping : material.textureMappings())
            if (mapping->texCoord != 0 && mapping->texCoord != 1)
                fail("material '" + material.name + "': texCoord " +
                     std::to_string(mapping->texCoord) + " (only 0 and 1 are kept)");
    }
    for (const Instance& instance : scene.instances)
        if (instance.mesh >= scene.meshes.size())
            fail("instance refers to a missing mesh");
    if (scene.cameras.empty())
        fail("no camera");
    for (const Camera& camera : scene.cameras) {
        if (!finite(camera.positionWorld) || !finite(camera.forwardWorld))
            fail("camera '" + camera.name + "' is not finite");
        if (!(camera.nearMetres > 0.0f) || !(camera.farMetres > camera.nearMetres))
            fail("camera '" + camera.name + "': need 0 < near < far");
        if (!(camera.verticalFovRadians > 0.0f && camera.verticalFovRadians < 3.1f))
            fail("camera '" + camera.name + "': vertical field of view out of (0, pi)");
    }
    for (const Light& light : scene.lights) {
        if (!finite(light.positionWorld) || !finite(light.color) ||
            !std::isfinite(light.intensity) || !(light.rangeMetres >= 0.0f))
            fail("a light is not finite or has a negative range");
    }
}

} // namespace scenes
