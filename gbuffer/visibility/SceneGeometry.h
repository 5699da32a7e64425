// SceneGeometry: a Scene's instances flattened into one world-space triangle list, built once per
// scene and shared by every pass of every frame (G-buffer, forward shading, the reference).
// Vertex i of triangle t is vertices[indices[3t + i]]; triangle t has material triangleMaterial[t].
// Instance transforms are applied here, in double, and rounded once.
// Tangents (for normal maps) exist only when some mesh has them and its material a normal map, the
// second uv set only when some mesh has it; then every vertex has one (zero where its mesh has
// none or its material no normal map: a zero tangent means "no normal mapping").
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/Scene.h"

namespace gbuffer {

struct SceneGeometry {
    std::vector<glm::vec3> positionWorld;
    std::vector<glm::dvec3> positionWorldExact; // unrounded instance transform, for the reference
    std::vector<glm::vec3> normalWorld;         // unit
    std::vector<glm::vec2> uv;                  // (0,0) where the mesh has none
    std::vector<glm::vec2> uv1;                 // TEXCOORD_1; empty when no mesh has it
    // World-space unit tangent, w = +-1 the bitangent sign (Mesh::tangents, with the sign
    // flipped by mirroring instance transforms); empty when no normal-mapped mesh has tangents.
    std::vector<glm::vec4> tangentWorld;
    std::vector<uint32_t> indices;
    std::vector<uint32_t> triangleMaterial;
    std::vector<uint32_t> triangleInstance;

    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
    static SceneGeometry build(const scenes::Scene& scene);
};

} // namespace gbuffer
