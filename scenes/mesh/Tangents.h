// Tangents: per-vertex tangent frames for tangent-space normal maps, generated the way glTF 2.0
// asks when a mesh brings none ("MikkTSpace with the positions, normals and the normal texture's
// texture coordinates"). No MikkTSpace library is packaged for Debian 12, so this file follows its
// convention itself:
//   1. Vertices with bit-identical position, normal and uv are welded (MikkTSpace does the same,
//      so an unindexed or duplicated mesh gets the same frames as an indexed one).
//   2. Per triangle, the tangent is the direction of increasing u, from the uv derivatives
//      (dP/du = (dv2 * e1 - dv1 * e2) / (du1 * dv2 - du2 * dv1)), normalised; its orientation is
//      the sign of the uv area. Triangles with zero uv area add nothing.
//   3. Per corner, the triangle tangent is projected onto the plane of that corner's vertex
//      normal (Gram-Schmidt), normalised, and added weighted by the corner's angle, measured
//      between the two edges projected onto the same plane (MikkTSpace's weights).
//   4. Per welded vertex the sum is normalised: that is the tangent. The handedness w is the
//      orientation of the triangles that contributed, in glTF's convention: the bitangent
//      w * cross(normal, tangent) points up the image (towards decreasing v, where a normal map's
//      +Y points), i.e. w is MikkTSpace's sign computed on (u, 1 - v), the negation of its sign on
//      glTF's raw uvs (a viewer that runs MikkTSpace on glTF uvs negates w for the same reason).
// How this differs from full MikkTSpace:
//   - MikkTSpace splits a vertex whose triangles have different orientations (a mirrored uv seam
//     whose vertices are shared) or form separate fans, and emits one frame per part; this keeps
//     the mesh's vertices and gives such a vertex one frame: the sum of the corners whose
//     orientation has the larger total angle (the other corners' tangents are left out).
//   - MikkTSpace gives a vertex only on zero-uv-area triangles the frame of a neighbour through
//     its degenerate-triangle pass; here such a vertex gets an arbitrary unit tangent
//     perpendicular to its normal and w = +1 (its normal map lookups are meaningless anyway: the
//     map is not spread over the triangle).
//   - MikkTSpace also keeps the magnitudes of dP/du and dP/dv (unused by its default output,
//     which glTF uses) and merges corners whose tangents differ by more than a threshold only
//     when asked to (the default threshold merges all), so neither changes the result here.
// tests/scenes/mesh/tangents_test.cpp measures the angle to the tangents that BoomBox and Suzanne
// ship. Cost: linear in vertices and triangles (one hash map for welding). Pure function,
// thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace scenes {

// One tangent per vertex: xyz unit and perpendicular to the vertex normal, w = +-1 (see above).
// normals must be unit length; uvs and positions have the normals' count; indices is a triangle
// list into them.
std::vector<glm::vec4> generateTangents(const std::vector<glm::vec3>& positions,
                                        const std::vector<glm::vec3>& normals,
                                        const std::vector<glm::vec2>& uvs,
                                        const std::vector<uint32_t>& indices);

} // namespace scenes
