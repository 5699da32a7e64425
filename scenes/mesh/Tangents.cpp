#include "scenes/mesh/Tangents.h"

#include <array>
#include <cmath>
#include <cstring>
#include <unordered_map>

namespace scenes {

namespace {

// The bits of one vertex's position, normal and uv: vertices equal here are welded.
struct VertexKey {
    std::array<uint32_t, 8> bits;
    bool operator==(const VertexKey& other) const { return bits == other.bits; }
};

struct VertexKeyHash {
    size_t operator()(const VertexKey& key) const {
        uint64_t hash = 1469598103934665603ull; // FNV-1a over the eight words
        for (uint32_t word : key.bits) {
            hash ^= word;
            hash *= 1099511628211ull;
        }
        return size_t(hash);
    }
};

VertexKey keyOf(const glm::vec3& position, const glm::vec3& normal, const glm::vec2& uv) {
    const float values[8] = {position.x, position.y, position.z, normal.x,
                             normal.y,   normal.z,   uv.x,       uv.y};
    VertexKey key;
    std::memcpy(key.bits.data(), values, sizeof(values));
    // +0 and -0 weld: they are the same attribute value.
    for (uint32_t& word : key.bits)
        if (word == 0x80000000u)
            word = 0;
    return key;
}

// Projects v onto the plane perpendicular to the unit normal n and normalises it; zero when v
// is (nearly) parallel to n.
glm::vec3 tangentialUnit(const glm::vec3& v, const glm::vec3& n) {
    const glm::vec3 projected = v - n * glm::dot(n, v);
    const float length = glm::length(projected);
    return length > 0.0f ? projected / length : glm::vec3(0.0f);
}

// A unit vector perpendicular to the unit vector n (Frisvad-style branch on the largest axis).
glm::vec3 anyPerpendicular(const glm::vec3& n) {
    const glm::vec3 axis =
        std::abs(n.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    return glm::normalize(glm::cross(axis, n));
}

} // namespace

std::vector<glm::vec4> generateTangents(const std::vector<glm::vec3>& positions,
                                        const std::vector<glm::vec3>& normals,
                                        const std::vector<glm::vec2>& uvs,
                                        const std::vector<uint32_t>& indices) {
    const size_t vertexCount = positions.size();
    // 1. Weld.
    std::vector<uint32_t> weldedOf(vertexCount);
    std::unordered_map<VertexKey, uint32_t, VertexKeyHash> firstOfKey;
    firstOfKey.reserve(vertexCount);
    for (size_t v = 0; v < vertexCount; ++v)
        weldedOf[v] =
            firstOfKey.emplace(keyOf(positions[v], normals[v], uvs[v]), uint32_t(v)).first->second;

    // 2.-3. Angle-weighted sums of the projected triangle tangents, one per orientation.
    struct Sum {
        glm::vec3 tangent{0.0f};
        float weight = 0.0f;
    };
    std::vector<std::array<Sum, 2>> sums(vertexCount); // [0] orientation +1, [1] -1 (glTF's w)
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
        const uint32_t corner[3] = {indices[i], indices[i + 1], indices[i + 2]};
        const glm::vec3 e1 = positions[corner[1]] - positions[corner[0]];
        const glm::vec3 e2 = positions[corner[2]] - positions[corner[0]];
        const glm::vec2 d1 = uvs[corner[1]] - uvs[corner[0]];
        const glm::vec2 d2 = uvs[corner[2]] - uvs[corner[0]];
        const float signedUvArea = d1.x * d2.y - d1.y * d2.x;
        if (!(signedUvArea != 0.0f) || !std::isfinite(signedUvArea))
            continue;
        // dP/du up to the positive factor 1 / |area|.
        const glm::vec3 uDirection = (signedUvArea > 0.0f ? 1.0f : -1.0f) * (d2.y * e1 - d1.y * e2);
        // MikkTSpace's orientation on (u, 1 - v) is the opposite of the raw uv area's sign.
        const size_t orientation = signedUvArea > 0.0f ? 1 : 0;
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = corner[c];
            const glm::vec3& n = normals[v];
            const glm::vec3 tangent = tangentialUnit(uDirection, n);
            const glm::vec3 toNext =
                tangentialUnit(positions[corner[(c + 1) % 3]] - positions[v], n);
            const glm::vec3 toPrevious =
                tangentialUnit(positions[corner[(c + 2) % 3]] - positions[v], n);
            const float angle = std::acos(glm::clamp(glm::dot(toNext, toPrevious), -1.0f, 1.0f));
            Sum& sum = sums[weldedOf[v]][orientation];
            sum.tangent += angle * tangent;
            sum.weight += angle;
        }
    }

    // 4. Normalise per welded vertex; every vertex takes its welded representative's frame.
    std::vector<glm::vec4> tangents(vertexCount);
    for (size_t v = 0; v < vertexCount; ++v) {
        if (weldedOf[v] != v) {
            tangents[v] = tangents[weldedOf[v]]; // representatives come first
            continue;
        }
        const size_t dominant = sums[v][1].weight > sums[v][0].weight ? 1 : 0;
        const glm::vec3 n = normals[v];
        const glm::vec3 tangent = tangentialUnit(sums[v][dominant].tangent, n);
        if (tangent == glm::vec3(0.0f))
            tangents[v] = glm::vec4(anyPerpendicular(n), 1.0f);
        else
            tangents[v] = glm::vec4(tangent, dominant == 0 ? 1.0f : -1.0f);
    }
    return tangents;
}

} // namespace scenes
