// MeshBuilder: every shape is one or more parametric grids appended by appendGrid(), which owns
// the vertex layout, the uv and tangent conventions and the winding; the shapes only say where a
// grid node is and which way its surface faces. Conventions: see MeshBuilder.h.
//
// Exactness: positions along a shared edge come from the same floats (coordinate tables, an
// endpoint-exact lerp), so neighbouring patches meet without cracks. Angles are evaluated in
// double and the points that must be exact (seams, poles, quarter turns) are snapped.
#include "scenes/mesh/MeshBuilder.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "scenes/input/Limits.h"

namespace scenes {

namespace {

// uint32 indices would allow 4G vertices, but memory runs out long before (a vertex costs 48
// bytes): a typo in a scene file must give an error, not an out-of-memory kill. The cap is the
// scene-wide limits::kMaxVertices, far above any built-in mesh (the largest, atrium's walls at
// detail=16, has 375k).
constexpr size_t kMaxVertexCount = size_t(limits::kMaxVertices);

struct GridNode {
    glm::vec3 position;
    glm::vec3 normal;  // unit, towards the side the grid faces before mirroring
    glm::vec3 tangent; // unit, along increasing i (uv.x)
    glm::vec3 alongJ;  // any non-zero vector along increasing j
};

enum class Facing {
    AsGiven,  // cross(d/di, d/dj) points along the node normals
    Mirrored, // the other side: normals negated, winding reversed
};

[[noreturn]] void fail(const Mesh& mesh, const char* function, const std::string& what) {
    throw SceneError(std::string(function) + " on mesh '" + mesh.name + "': " + what);
}

void requirePositive(const Mesh& mesh, const char* function, const char* parameter, float value) {
    if (!(value > 0.0f) || !std::isfinite(value))
        fail(mesh, function,
             std::string(parameter) + " must be positive and finite, got " + std::to_string(value));
}

void requireFinite(const Mesh& mesh, const char* function, const char* parameter, float value) {
    if (!std::isfinite(value))
        fail(mesh, function, std::string(parameter) + " must be finite");
}

void requireFinite(const Mesh& mesh, const char* function, const char* parameter,
                   const glm::vec3& value) {
    for (int axis = 0; axis < 3; ++axis)
        requireFinite(mesh, function, parameter, value[axis]);
}

void requireCount(const Mesh& mesh, const char* function, const char* parameter, int value,
                  int minimum) {
    if (value < minimum)
        fail(mesh, function,
             std::string(parameter) + " must be at least " + std::to_string(minimum) + ", got " +
                 std::to_string(value));
}

// Checks that the mesh can take vertexCount more vertices and reserves room for them, before
// anything is appended, so that a failing call leaves the mesh unchanged.
void beginAppend(Mesh& mesh, const char* function, size_t vertexCount) {
    const size_t existing = mesh.positions.size();
    if (mesh.normals.size() != existing || mesh.tangents.size() != existing ||
        mesh.uvs.size() != existing)
        fail(mesh, function, "the mesh lacks normals, tangents or uvs for some vertices");
    if (vertexCount > kMaxVertexCount || existing + vertexCount > kMaxVertexCount)
        fail(mesh, function,
             std::to_string(vertexCount) + " more vertices would exceed the limit of " +
                 std::to_string(kMaxVertexCount) + " per mesh");
    const size_t total = existing + vertexCount;
    mesh.positions.reserve(total);
    mesh.normals.reserve(total);
    mesh.tangents.reserve(total);
    mesh.uvs.reserve(total);
}

size_t gridVertexCount(int cellCountU, int cellCountV) {
    return size_t(cellCountU + 1) * size_t(cellCountV + 1);
}

// Exact at both ends (t = 0 gives a, t = 1 gives b), unlike a + t * (b - a): shared edges and
// corners computed from the same endpoints then coincide bitwise.
template <class T> T lerpExact(const T& a, const T& b, float t) {
    return (1.0f - t) * a + t * b;
}

// Appends the (cellCountU + 1) x (cellCountV + 1) nodes nodeAt(i, j) and two triangles per cell.
// Triangles with two coincident corners (a pole, a cap centre) are dropped.
template <class NodeAt>
void appendGrid(Mesh& mesh, int cellCountU, int cellCountV, Facing facing, NodeAt&& nodeAt) {
    const uint32_t base = uint32_t(mesh.positions.size());
    const float side = facing == Facing::Mirrored ? -1.0f : 1.0f;
    for (int j = 0; j <= cellCountV; ++j) {
        for (int i = 0; i <= cellCountU; ++i) {
            const GridNode node = nodeAt(i, j);
            const glm::vec3 normal = side * node.normal;
            // uv.y decreases along j, so the bitangent (towards decreasing uv.y, glTF's "up in
            // the image") is alongJ.
            const float bitangentSign =
                glm::dot(glm::cross(normal, node.tangent), node.alongJ) >= 0.0f ? 1.0f : -1.0f;
            mesh.positions.push_back(node.position);
            mesh.normals.push_back(normal);
            mesh.tangents.push_back(glm::vec4(node.tangent, bitangentSign));
            mesh.uvs.push_back(
                glm::vec2(float(i) / float(cellCountU), 1.0f - float(j) / float(cellCountV)));
        }
    }
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        const glm::vec3 &pa = mesh.positions[a], &pb = mesh.positions[b], &pc = mesh.positions[c];
        if (pa == pb || pb == pc || pc == pa)
            return;
        if (facing == Facing::Mirrored)
            std::swap(b, c);
        mesh.indices.insert(mesh.indices.end(), {a, b, c});
    };
    const uint32_t rowLength = uint32_t(cellCountU) + 1;
    for (int j = 0; j < cellCountV; ++j) {
        for (int i = 0; i < cellCountU; ++i) {
            const uint32_t a = base + uint32_t(j) * rowLength + uint32_t(i);
            const uint32_t b = a + 1, c = a + rowLength + 1, d = a + rowLength;
            emit(a, b, c);
            emit(a, c, d);
        }
    }
}

struct CosSin {
    float cos;
    float sin;
};

// cos and sin of turnFraction * 2 pi * k / count for k = 0..count, in double, with the points on
// the axes snapped exactly so that seams close and poles and springings are exact.
std::vector<CosSin> circleTable(int count, double turnFraction) {
    std::vector<CosSin> table(size_t(count) + 1);
    for (int k = 0; k <= count; ++k) {
        const double quarterTurns = 4.0 * turnFraction * k / count;
        if (quarterTurns == std::floor(quarterTurns)) {
            constexpr CosSin kAxes[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
            table[k] = kAxes[int(quarterTurns) % 4];
        } else {
            const double angle = 2.0 * std::numbers::pi * turnFraction * k / count;
            table[k] = {float(std::cos(angle)), float(std::sin(angle))};
        }
    }
    return table;
}

} // namespace

void appendQuad(Mesh& mesh, const glm::vec3& cornerObject, const glm::vec3& edgeU,
                const glm::vec3& edgeV, int cellCountU, int cellCountV) {
    constexpr const char* kFunction = "appendQuad";
    requireFinite(mesh, kFunction, "corner", cornerObject);
    requireFinite(mesh, kFunction, "edgeU", edgeU);
    requireFinite(mesh, kFunction, "edgeV", edgeV);
    requireCount(mesh, kFunction, "cellCountU", cellCountU, 1);
    requireCount(mesh, kFunction, "cellCountV", cellCountV, 1);
    const glm::vec3 area = glm::cross(edgeU, edgeV);
    if (!(glm::dot(area, area) > 0.0f))
        fail(mesh, kFunction, "edgeU and edgeV are parallel");
    beginAppend(mesh, kFunction, gridVertexCount(cellCountU, cellCountV));

    const glm::vec3 c00 = cornerObject, c10 = cornerObject + edgeU, c01 = cornerObject + edgeV,
                    c11 = cornerObject + edgeU + edgeV;
    const glm::vec3 normal = glm::normalize(area), tangent = glm::normalize(edgeU);
    appendGrid(mesh, cellCountU, cellCountV, Facing::AsGiven, [&](int i, int j) {
        const float s = float(i) / float(cellCountU), t = float(j) / float(cellCountV);
        return GridNode{lerpExact(lerpExact(c00, c10, s), lerpExact(c01, c11, s), t), normal,
                        tangent, edgeV};
    });
}

void appendBox(Mesh& mesh, const Aabb& boxObject, float maxCellMetres) {
    constexpr const char* kFunction = "appendBox";
    requirePositive(mesh, kFunction, "maxCellMetres", maxCellMetres);
    requireFinite(mesh, kFunction, "box min", boxObject.min);
    requireFinite(mesh, kFunction, "box max", boxObject.max);
    const glm::vec3 size = boxObject.size();
    for (int axis = 0; axis < 3; ++axis)
        requirePositive(mesh, kFunction, "box size", size[axis]);

    // One coordinate table per axis, shared by the four faces that span it: watertight edges.
    glm::ivec3 cellCount;
    std::vector<float> coordinates[3];
    for (int axis = 0; axis < 3; ++axis) {
        const double cells = std::ceil(double(size[axis]) / double(maxCellMetres));
        if (cells > double(kMaxVertexCount))
            fail(mesh, kFunction, "maxCellMetres is too small for the box");
        cellCount[axis] = std::max(1, int(cells));
        for (int k = 0; k <= cellCount[axis]; ++k)
            coordinates[axis].push_back(lerpExact(boxObject.min[axis], boxObject.max[axis],
                                                  float(k) / float(cellCount[axis])));
    }

    struct Face {
        int normalAxis;
        bool maxSide; // at the box's max along normalAxis (normal +axis) or min (normal -axis)
        int axisU;
        bool forwardU; // uv.x grows along +axisU (else along -axisU)
        int axisV;
        bool forwardV;
    };
    // Each face's (U, V) is oriented so that cross(U, V) is its outward normal.
    constexpr Face kFaces[6] = {
        {0, true, 2, false, 1, true}, {0, false, 2, true, 1, true}, {1, true, 0, true, 2, false},
        {1, false, 0, true, 2, true}, {2, true, 0, true, 1, true},  {2, false, 0, false, 1, true},
    };
    size_t vertexCount = 0;
    for (const Face& face : kFaces)
        vertexCount += gridVertexCount(cellCount[face.axisU], cellCount[face.axisV]);
    beginAppend(mesh, kFunction, vertexCount);

    for (const Face& face : kFaces) {
        const int countU = cellCount[face.axisU], countV = cellCount[face.axisV];
        glm::vec3 normal(0.0f), tangent(0.0f), alongJ(0.0f);
        normal[face.normalAxis] = face.maxSide ? 1.0f : -1.0f;
        tangent[face.axisU] = face.forwardU ? 1.0f : -1.0f;
        alongJ[face.axisV] = face.forwardV ? 1.0f : -1.0f;
        const float fixedCoordinate =
            face.maxSide ? boxObject.max[face.normalAxis] : boxObject.min[face.normalAxis];
        appendGrid(mesh, countU, countV, Facing::AsGiven, [&](int i, int j) {
            glm::vec3 position;
            position[face.normalAxis] = fixedCoordinate;
            position[face.axisU] = coordinates[face.axisU][face.forwardU ? i : countU - i];
            position[face.axisV] = coordinates[face.axisV][face.forwardV ? j : countV - j];
            return GridNode{position, normal, tangent, alongJ};
        });
    }
}

void appendCylinder(Mesh& mesh, const glm::vec3& baseCentreObject, float radiusMetres,
                    float heightMetres, int radialSegmentCount, int heightSegmentCount) {
    constexpr const char* kFunction = "appendCylinder";
    requireFinite(mesh, kFunction, "baseCentre", baseCentreObject);
    requirePositive(mesh, kFunction, "radiusMetres", radiusMetres);
    requirePositive(mesh, kFunction, "heightMetres", heightMetres);
    requireCount(mesh, kFunction, "radialSegmentCount", radialSegmentCount, 3);
    requireCount(mesh, kFunction, "heightSegmentCount", heightSegmentCount, 1);
    // Ring spacing radius / rings matches the side's segment length 2 pi radius / segments.
    const int capRingCount =
        std::max(1, int(std::lround(radialSegmentCount / (2.0 * std::numbers::pi))));
    beginAppend(mesh, kFunction,
                gridVertexCount(radialSegmentCount, heightSegmentCount) +
                    2 * gridVertexCount(radialSegmentCount, capRingCount));

    // Angle phi runs counter-clockwise seen from +Y: x = cos phi, z = -sin phi.
    const std::vector<CosSin> circle = circleTable(radialSegmentCount, 1.0);
    auto radial = [&](int i) { return glm::vec3(circle[i].cos, 0.0f, -circle[i].sin); };
    auto around = [&](int i) { return glm::vec3(-circle[i].sin, 0.0f, -circle[i].cos); };
    auto at = [&](int i, float rho, float y) {
        return baseCentreObject + glm::vec3(rho * circle[i].cos, y, -rho * circle[i].sin);
    };

    appendGrid(mesh, radialSegmentCount, heightSegmentCount, Facing::AsGiven, [&](int i, int j) {
        const float y = heightMetres * (float(j) / float(heightSegmentCount));
        return GridNode{at(i, radiusMetres, y), radial(i), around(i), glm::vec3(0, 1, 0)};
    });
    // Caps: polar grids from the centre outwards. Around-then-outwards faces -Y, so the bottom
    // cap is as given and the top cap mirrored.
    for (const float y : {0.0f, heightMetres}) {
        const Facing facing = y == 0.0f ? Facing::AsGiven : Facing::Mirrored;
        appendGrid(mesh, radialSegmentCount, capRingCount, facing, [&](int i, int k) {
            const float rho = radiusMetres * (float(k) / float(capRingCount));
            return GridNode{at(i, rho, y), glm::vec3(0, -1, 0), around(i), radial(i)};
        });
    }
}

void appendArch(Mesh& mesh, const ArchShape& shape) {
    constexpr const char* kFunction = "appendArch";
    const float inner = shape.innerRadiusMetres, outer = shape.outerRadiusMetres;
    requirePositive(mesh, kFunction, "innerRadiusMetres", inner);
    requirePositive(mesh, kFunction, "outerRadiusMetres - innerRadiusMetres", outer - inner);
    requirePositive(mesh, kFunction, "depthMetres", shape.depthMetres);
    const int arcCount = shape.arcSegmentCount, bandCount = shape.bandSegmentCount,
              depthCount = shape.depthSegmentCount;
    const bool square = shape.outline == ArchOutline::Square;
    requireCount(mesh, kFunction, "arcSegmentCount", arcCount, square ? 4 : 2);
    if (square && arcCount % 4 != 0)
        fail(mesh, kFunction,
             "arcSegmentCount must be a multiple of 4 for a square outline, got " +
                 std::to_string(arcCount));
    requireCount(mesh, kFunction, "bandSegmentCount", bandCount, 1);
    requireCount(mesh, kFunction, "depthSegmentCount", depthCount, 1);
    beginAppend(mesh, kFunction,
                2 * gridVertexCount(arcCount, bandCount) +              // front, back
                    2 * gridVertexCount(arcCount, depthCount) +         // intrados, extrados
                    (square ? 2 * gridVertexCount(0, depthCount) : 0) + // extrados corners
                    2 * gridVertexCount(bandCount, depthCount));        // springings

    // theta runs from the right springing (+X) over the top to the left one (-X).
    const std::vector<CosSin> arc = circleTable(arcCount, 0.5);
    const float halfDepth = 0.5f * shape.depthMetres;
    const glm::vec3 zAxis(0, 0, 1);
    auto radial = [&](int i) { return glm::vec3(arc[i].cos, arc[i].sin, 0.0f); };
    auto intrados = [&](int i) { return glm::vec2(inner * arc[i].cos, inner * arc[i].sin); };
    // Where the ray at theta leaves the outline: the circle, or the half square's three sides.
    auto extrados = [&](int i) {
        if (!square)
            return glm::vec2(outer * arc[i].cos, outer * arc[i].sin);
        if (4 * i == arcCount)
            return glm::vec2(outer, outer);
        if (4 * i == 3 * arcCount)
            return glm::vec2(-outer, outer);
        if (4 * i < arcCount)
            return glm::vec2(outer, outer * arc[i].sin / arc[i].cos);
        if (4 * i < 3 * arcCount)
            return glm::vec2(outer * arc[i].cos / arc[i].sin, outer);
        return glm::vec2(-outer, -outer * arc[i].sin / arc[i].cos);
    };
    // Band point k of arc point i: k = 0 on the extrados, k = bandCount on the intrados.
    auto band = [&](int i, int k) {
        return lerpExact(extrados(i), intrados(i), float(k) / float(bandCount));
    };
    auto depthZ = [&](int m) {
        return lerpExact(-halfDepth, halfDepth, float(m) / float(depthCount));
    };

    // Front and back: along the arc then inwards faces +Z.
    for (const float z : {halfDepth, -halfDepth}) {
        const Facing facing = z > 0.0f ? Facing::AsGiven : Facing::Mirrored;
        appendGrid(mesh, arcCount, bandCount, facing, [&](int i, int k) {
            const glm::vec3 tangent(-arc[i].sin, arc[i].cos, 0.0f);
            return GridNode{glm::vec3(band(i, k), z), zAxis, tangent, -radial(i)};
        });
    }
    // Along the arc then along +Z faces away from the centre: as given for the extrados, mirrored
    // for the intrados (which faces into the opening).
    appendGrid(mesh, arcCount, depthCount, Facing::Mirrored, [&](int i, int m) {
        return GridNode{glm::vec3(intrados(i), depthZ(m)), radial(i), glm::cross(zAxis, radial(i)),
                        zAxis};
    });
    // The square outline's extrados is three flat faces: one grid each, so that the corners get
    // a vertex per face and shading stays flat.
    struct Piece {
        int first, last;
        glm::vec3 normal; // of a flat face; unused for the ring, whose normal is radial
    };
    std::vector<Piece> pieces;
    if (square)
        pieces = {{0, arcCount / 4, {1, 0, 0}},
                  {arcCount / 4, 3 * arcCount / 4, {0, 1, 0}},
                  {3 * arcCount / 4, arcCount, {-1, 0, 0}}};
    else
        pieces = {{0, arcCount, glm::vec3(0.0f)}};
    for (const Piece& piece : pieces) {
        appendGrid(mesh, piece.last - piece.first, depthCount, Facing::AsGiven, [&](int i, int m) {
            const int arcIndex = piece.first + i;
            const glm::vec3 normal = square ? piece.normal : radial(arcIndex);
            return GridNode{glm::vec3(extrados(arcIndex), depthZ(m)), normal,
                            glm::cross(zAxis, normal), zAxis};
        });
    }
    // Springings at y = 0, facing down; uv.x runs along +X on both.
    for (const int arcIndex : {0, arcCount}) {
        appendGrid(mesh, bandCount, depthCount, Facing::AsGiven, [&](int k, int m) {
            const int bandIndex = arcIndex == 0 ? bandCount - k : k;
            return GridNode{glm::vec3(band(arcIndex, bandIndex), depthZ(m)), glm::vec3(0, -1, 0),
                            glm::vec3(1, 0, 0), zAxis};
        });
    }
}

void appendUvSphere(Mesh& mesh, const glm::vec3& centreObject, float radiusMetres,
                    int longitudeSegmentCount, int latitudeSegmentCount) {
    constexpr const char* kFunction = "appendUvSphere";
    requireFinite(mesh, kFunction, "centre", centreObject);
    requirePositive(mesh, kFunction, "radiusMetres", radiusMetres);
    requireCount(mesh, kFunction, "longitudeSegmentCount", longitudeSegmentCount, 3);
    requireCount(mesh, kFunction, "latitudeSegmentCount", latitudeSegmentCount, 2);
    beginAppend(mesh, kFunction, gridVertexCount(longitudeSegmentCount, latitudeSegmentCount));

    const std::vector<CosSin> longitude = circleTable(longitudeSegmentCount, 1.0);
    // theta from the south pole (0) to the north pole (pi); y = -cos theta.
    const std::vector<CosSin> latitude = circleTable(latitudeSegmentCount, 0.5);
    appendGrid(
        mesh, longitudeSegmentCount, latitudeSegmentCount, Facing::AsGiven, [&](int i, int j) {
            const CosSin phi = longitude[i], theta = latitude[j];
            // Normalised in double so that the float direction is as close to unit as
            // float allows; the position is then exactly centre + radius * normal.
            const glm::dvec3 direction = glm::normalize(glm::dvec3(
                double(theta.sin) * phi.cos, -double(theta.cos), -double(theta.sin) * phi.sin));
            const glm::vec3 normal(direction);
            const glm::vec3 alongTheta(theta.cos * phi.cos, theta.sin, -theta.cos * phi.sin);
            return GridNode{centreObject + radiusMetres * normal, normal,
                            glm::vec3(-phi.sin, 0.0f, -phi.cos), alongTheta};
        });
}

void appendCloth(Mesh& mesh, const ClothShape& shape) {
    constexpr const char* kFunction = "appendCloth";
    requirePositive(mesh, kFunction, "widthMetres", shape.widthMetres);
    requirePositive(mesh, kFunction, "heightMetres", shape.heightMetres);
    requireFinite(mesh, kFunction, "amplitudeMetres", shape.amplitudeMetres);
    requireFinite(mesh, kFunction, "waveCount", shape.waveCount);
    requireFinite(mesh, kFunction, "phaseRadians", shape.phaseRadians);
    requireCount(mesh, kFunction, "cellCountU", shape.cellCountU, 1);
    requireCount(mesh, kFunction, "cellCountV", shape.cellCountV, 1);
    beginAppend(mesh, kFunction, 2 * gridVertexCount(shape.cellCountU, shape.cellCountV));

    const double amplitude = shape.amplitudeMetres, height = shape.heightMetres;
    const double waveNumber = 2.0 * std::numbers::pi * shape.waveCount / shape.widthMetres;
    const double phase = shape.phaseRadians;
    constexpr double kRipple = 0.3; // weight of the ripple running down the sheet
    constexpr double kRippleFrequency = 3.0 * std::numbers::pi;
    const float halfWidth = 0.5f * shape.widthMetres;
    // z(x, t) = A t (t sin(k x + phase) + kRipple sin(kRippleFrequency t + phase)), with
    // t = -y / height: 0 along the top edge (no displacement where it hangs), 1 at the bottom.
    auto node = [&](int i, int j) {
        const float x = lerpExact(-halfWidth, halfWidth, float(i) / float(shape.cellCountU));
        const float y = lerpExact(-shape.heightMetres, 0.0f, float(j) / float(shape.cellCountV));
        const double t = -double(y) / height;
        const double sway = std::sin(waveNumber * x + phase);
        const double ripple = std::sin(kRippleFrequency * t + phase);
        const double z = amplitude * t * (t * sway + kRipple * ripple);
        const double dzdx = amplitude * t * t * waveNumber * std::cos(waveNumber * x + phase);
        const double dzdt =
            amplitude * (2.0 * t * sway + kRipple * ripple +
                         kRipple * kRippleFrequency * t * std::cos(kRippleFrequency * t + phase));
        const double dzdy = -dzdt / height;
        // d/dx = (1, 0, dzdx) and d/dy = (0, 1, dzdy): their cross product faces +Z.
        const glm::vec3 normal(glm::normalize(glm::dvec3(-dzdx, -dzdy, 1.0)));
        const glm::vec3 tangent(glm::normalize(glm::dvec3(1.0, 0.0, dzdx)));
        return GridNode{glm::vec3(x, y, float(z)), normal, tangent, glm::vec3(0.0f, 1.0f, dzdy)};
    };
    appendGrid(mesh, shape.cellCountU, shape.cellCountV, Facing::AsGiven, node);
    appendGrid(mesh, shape.cellCountU, shape.cellCountV, Facing::Mirrored, node);
}

} // namespace scenes
