// MeshBuilder: helpers that append procedural geometry (boxes, tessellated quads, cylinders,
// arches, spheres, cloth) to a Mesh, with outward normals, tangents and uvs. Used by the built-in
// scenes; everything is deterministic.
//
// Conventions every function keeps:
// - Right-handed, metres, object space of the mesh given. Triangles are counter-clockwise seen
//   from the front, and the front is the side the normals point to: outward for closed shapes.
// - Normals are unit length and analytic where the surface has a formula (sphere, cylinder,
//   cloth), so they do not depend on the tessellation.
// - Tangents (glTF's convention, as Mesh::tangents): xyz is the unit direction of increasing
//   uv.x; w = +-1 such that w * cross(normal, tangent.xyz) points towards decreasing uv.y, i.e.
//   up in the image, where a normal map's +Y (green) points.
// - uvs: each tessellated patch (a quad, a box face, a cylinder's side) spans [0,1]^2, with
//   uv.y = 0 at its top for upright faces (glTF: (0,0) is the image's top-left corner).
// - Within one shape, vertices shared by two patches along an edge are computed from the same
//   numbers, so the edges match bitwise and a closed shape has no cracks.
// - A mesh appended to must either be empty or carry tangents and uvs for every vertex.
// Every function throws SceneError naming the mesh and the parameter for an invalid argument
// (non-positive or non-finite size, too small a count, more than 2^26 vertices in one mesh) and
// leaves the mesh unchanged. Cost is linear in the vertices appended. Not thread-safe on one
// mesh; different meshes may be built concurrently.
#pragma once

#include "scenes/Scene.h"

namespace scenes {

// A flat parallelogram corner + s * edgeU + t * edgeV for s, t in [0,1], split into
// cellCountU x cellCountV cells of two triangles. Its front (normal) is
// normalize(cross(edgeU, edgeV)); uv.x follows edgeU.
void appendQuad(Mesh& mesh, const glm::vec3& cornerObject, const glm::vec3& edgeU,
                const glm::vec3& edgeV, int cellCountU, int cellCountV);

// An axis-aligned box, closed, each face split into cells no longer than maxCellMetres along
// either side. Faces sharing an edge use the same split, so the box is watertight.
void appendBox(Mesh& mesh, const Aabb& boxObject, float maxCellMetres);

// A capped cylinder around +Y standing on baseCentreObject: radialSegmentCount around,
// heightSegmentCount along the side, and concentric rings on the caps chosen so that the cap
// triangles are about as large as the side's.
void appendCylinder(Mesh& mesh, const glm::vec3& baseCentreObject, float radiusMetres,
                    float heightMetres, int radialSegmentCount, int heightSegmentCount);

enum class ArchOutline {
    Ring,   // extrados is a half circle: a free-standing arch band
    Square, // extrados is the half square around the ring: an arch in a wall, spandrels filled
};

// A semicircular arch: a thick band around a half-circular opening, extruded along Z.
struct ArchShape {
    float innerRadiusMetres = 1.0f; // radius of the opening (intrados)
    float outerRadiusMetres = 1.3f; // Ring: extrados radius; Square: half-width and height
    float depthMetres = 0.5f;       // extrusion, from z = -depth/2 to +depth/2
    ArchOutline outline = ArchOutline::Ring;
    int arcSegmentCount = 32; // around the half circle; a multiple of 4 for Square (corners)
    int bandSegmentCount = 2; // from intrados to extrados on the front and back faces
    int depthSegmentCount = 2;
};

// The opening's centre is the object origin; the arch springs at y = 0 from x = +-inner..outer
// and rises towards +Y. Closed: front (+Z), back (-Z), intrados, extrados, two springing faces.
void appendArch(Mesh& mesh, const ArchShape& shape);

// An analytic UV sphere: every position is exactly centre + radius * n and every normal is that
// unit direction n, so shading can be compared against the true sphere. Latitude rings run from
// the south pole (-Y) to the north pole; the polar rows have one triangle per segment (no
// degenerate triangles).
void appendUvSphere(Mesh& mesh, const glm::vec3& centreObject, float radiusMetres,
                    int longitudeSegmentCount, int latitudeSegmentCount);

// A hanging sheet, e.g. a banner: a grid displaced along Z by a smooth function of its position
// that is zero along the top edge (where it hangs) and grows towards the free bottom edge.
struct ClothShape {
    float widthMetres = 2.0f;  // along X, from -width/2 to +width/2
    float heightMetres = 3.0f; // hangs from y = 0 down to y = -height
    // Scale of the displacement along Z: |z| stays below 1.3 x this, most of it at the bottom.
    float amplitudeMetres = 0.1f;
    float waveCount = 1.5f;    // sideways waves across the width
    float phaseRadians = 0.0f; // shifts the waves so that copies do not look alike
    int cellCountU = 20;       // across the width
    int cellCountV = 30;       // down the height
};

// Both sides are emitted (the renderer culls back faces, and a sheet is seen from both): the
// front faces +Z, the back is the same positions with negated normals and reversed winding.
// Normals are the analytic normals of the displaced surface.
void appendCloth(Mesh& mesh, const ClothShape& shape);

} // namespace scenes
