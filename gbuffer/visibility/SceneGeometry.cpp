#include "gbuffer/visibility/SceneGeometry.h"

#include <stdexcept>

namespace gbuffer {

namespace {

// Tangents serve normal maps only: a mesh whose material has none (every procedural mesh carries
// tangents) keeps none, so a scene without normal maps transforms no tangents per frame.
bool keepsTangents(const scenes::Scene& scene, const scenes::Mesh& mesh) {
    return !mesh.tangents.empty() && mesh.material < scene.materials.size() &&
           scene.materials[mesh.material].normalTexture >= 0;
}

} // namespace

SceneGeometry SceneGeometry::build(const scenes::Scene& scene) {
    SceneGeometry g;
    size_t vertexCount = 0, indexCount = 0;
    bool anyUv1 = false, anyTangents = false;
    for (const scenes::Instance& instance : scene.instances) {
        const scenes::Mesh& mesh = scene.meshes[instance.mesh];
        vertexCount += mesh.positions.size();
        indexCount += mesh.indices.size();
        anyUv1 = anyUv1 || !mesh.uvs1.empty();
        anyTangents = anyTangents || keepsTangents(scene, mesh);
    }
    if (vertexCount > UINT32_MAX || indexCount / 3 > UINT32_MAX)
        throw std::length_error(scene.name + ": too many vertices for 32-bit indices");
    g.positionWorld.reserve(vertexCount);
    g.positionWorldExact.reserve(vertexCount);
    g.normalWorld.reserve(vertexCount);
    g.uv.reserve(vertexCount);
    g.indices.reserve(indexCount);
    g.triangleMaterial.reserve(indexCount / 3);
    g.triangleInstance.reserve(indexCount / 3);

    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const scenes::Instance& instance = scene.instances[i];
        const scenes::Mesh& mesh = scene.meshes[instance.mesh];
        const glm::dmat4 worldFromObject(instance.worldFromObject);
        // Normals transform with the inverse transpose; it also handles non-uniform scale.
        const glm::dmat3 normalFromObject =
            glm::transpose(glm::inverse(glm::dmat3(worldFromObject)));
        const bool mirrored = glm::determinant(glm::dmat3(worldFromObject)) < 0.0;
        const uint32_t base = uint32_t(g.positionWorld.size());
        for (size_t v = 0; v < mesh.positions.size(); ++v) {
            const glm::dvec3 p =
                glm::dvec3(worldFromObject * glm::dvec4(glm::dvec3(mesh.positions[v]), 1.0));
            g.positionWorldExact.push_back(p);
            g.positionWorld.push_back(glm::vec3(p));
            glm::dvec3 n = normalFromObject * glm::dvec3(mesh.normals[v]);
            const double length = glm::length(n);
            g.normalWorld.push_back(length > 0.0 ? glm::vec3(n / length) : glm::vec3(0, 0, 1));
            g.uv.push_back(mesh.uvs.empty() ? glm::vec2(0.0f) : mesh.uvs[v]);
            if (anyUv1)
                g.uv1.push_back(mesh.uvs1.empty() ? glm::vec2(0.0f) : mesh.uvs1[v]);
            if (anyTangents) {
                glm::vec4 tangent(0.0f);
                if (keepsTangents(scene, mesh)) {
                    // Tangents are surface directions: they transform with the matrix itself.
                    const glm::dvec3 t =
                        glm::dmat3(worldFromObject) * glm::dvec3(glm::vec3(mesh.tangents[v]));
                    const double tLength = glm::length(t);
                    const float sign = (mesh.tangents[v].w < 0.0f) != mirrored ? -1.0f : 1.0f;
                    if (tLength > 0.0)
                        tangent = glm::vec4(glm::vec3(t / tLength), sign);
                }
                g.tangentWorld.push_back(tangent);
            }
        }
        for (size_t t = 0; t < mesh.triangleCount(); ++t) {
            const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1],
                           c = mesh.indices[3 * t + 2];
            // A mirroring transform flips the winding; swap to keep counter-clockwise = front.
            g.indices.push_back(base + a);
            g.indices.push_back(base + (mirrored ? c : b));
            g.indices.push_back(base + (mirrored ? b : c));
            g.triangleMaterial.push_back(mesh.material);
            g.triangleInstance.push_back(uint32_t(i));
        }
    }
    return g;
}

} // namespace gbuffer
