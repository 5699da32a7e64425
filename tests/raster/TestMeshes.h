// Clip-space test meshes shared by the rasterizer's exactness tests (row_span_test.cpp,
// depth_only_test.cpp, triangle_setup_test.cpp): an indexed triangle list, seeded random
// triangles of seven kinds, and the fan both append to their random triangles, whose shared
// edges check that each pixel is covered once.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/glm.hpp>

namespace raster_test {

struct Mesh {
    std::vector<glm::vec4> positions;
    std::vector<uint32_t> indices;
};

// A fan of 64 triangles around a point: shared edges, each pixel covered once; the rim's depths
// drawn from `rng` (uniform in [0.3, 0.5)).
inline void appendFan(Mesh& mesh, std::mt19937& rng) {
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const uint32_t centre = uint32_t(mesh.positions.size());
    mesh.positions.emplace_back(0.1f, -0.05f, 0.4f, 1.0f);
    for (int k = 0; k <= 64; ++k) {
        const float angle = float(k) / 64.0f * 6.2831853f;
        mesh.positions.emplace_back(0.7f * std::cos(angle), 0.7f * std::sin(angle),
                                    0.3f + 0.2f * unit(rng), 1.0f);
    }
    for (uint32_t k = 0; k < 64; ++k)
        mesh.indices.insert(mesh.indices.end(), {centre, centre + 1 + k, centre + 2 + k});
}

// Random clip-space triangles of seven kinds, in an order that puts big occluders before smaller
// triangles behind them and in front of them.
inline Mesh randomMesh(uint32_t seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    auto signedUnit = [&] { return unit(rng) * 2.0f - 1.0f; };
    Mesh mesh;
    auto add = [&](glm::vec4 a, glm::vec4 b, glm::vec4 c) {
        const uint32_t base = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {a, b, c});
        mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    };
    auto vertex = [&](float spread, float w, float zLo, float zHi) {
        const float z = zLo + unit(rng) * (zHi - zLo);
        return glm::vec4(signedUnit() * spread * w, signedUnit() * spread * w, z * w, w);
    };
    for (int i = 0; i < count; ++i) {
        const int kind = i % 7;
        const float w = 0.5f + 2.0f * unit(rng);
        switch (kind) {
        case 0: // large, across tiles, some crossing the near or far plane
            add(vertex(1.5f, w, -0.1f, 1.1f), vertex(1.5f, 0.5f + 2.0f * unit(rng), -0.1f, 1.1f),
                vertex(1.5f, 0.5f + 2.0f * unit(rng), -0.1f, 1.1f));
            break;
        case 1: { // sub-pixel and a few pixels: near a
            const glm::vec4 a = vertex(1.0f, w, 0.0f, 1.0f);
            const float size = i % 2 ? 0.002f : 0.03f;
            add(a, a + size * (vertex(1.0f, w, 0.0f, 1.0f) - a),
                a + size * (vertex(1.0f, w, 0.0f, 1.0f) - a));
            break;
        }
        case 2: // huge: beyond the guard band
            add(vertex(40.0f, w, 0.0f, 1.0f), vertex(40.0f, w, 0.0f, 1.0f),
                vertex(40.0f, w, 0.0f, 1.0f));
            break;
        case 3: { // degenerate: collinear or repeated vertices
            const glm::vec4 a = vertex(1.0f, w, 0.0f, 1.0f), b = vertex(1.0f, w, 0.0f, 1.0f);
            add(a, b, i % 2 ? a : 0.5f * (a + b));
            break;
        }
        case 4: { // grazing: the plane nearly contains the view direction (w from 0.05 to 50)
            const glm::vec2 p = glm::vec2(signedUnit(), signedUnit()) * 0.8f;
            const glm::vec2 d = glm::vec2(signedUnit(), signedUnit()) * 0.3f;
            auto at = [&](glm::vec2 ndc, float depth, float vw) {
                return glm::vec4(ndc.x * vw, ndc.y * vw, depth * vw, vw);
            };
            add(at(p, 0.01f + 0.02f * unit(rng), 0.05f), at(p + d, 0.999f * unit(rng), 50.0f),
                at(p + glm::vec2(-d.y, d.x) * 0.01f, 0.5f, 0.05f + 50.0f * unit(rng)));
            break;
        }
        case 5: { // a nearly flat pair: two triangles at almost the same depth over one quad
            const glm::vec2 p = glm::vec2(signedUnit(), signedUnit()) * 0.8f;
            const float depth = unit(rng);
            const float e = 1e-7f * float(i % 3);
            add(glm::vec4(p, depth, 1.0f), glm::vec4(p + glm::vec2(0.3f, 0.0f), depth + e, 1.0f),
                glm::vec4(p + glm::vec2(0.0f, 0.3f), depth, 1.0f));
            add(glm::vec4(p + glm::vec2(0.3f, 0.3f), depth, 1.0f),
                glm::vec4(p + glm::vec2(0.0f, 0.3f), depth, 1.0f),
                glm::vec4(p + glm::vec2(0.3f, 0.0f), depth + e, 1.0f));
            break;
        }
        default: { // medium: a few blocks
            const glm::vec4 a = vertex(1.0f, w, 0.0f, 1.0f);
            add(a, a + 0.1f * (vertex(1.0f, w, 0.0f, 1.0f) - a),
                a + 0.1f * (vertex(1.0f, w, 0.0f, 1.0f) - a));
            break;
        }
        }
    }
    raster_test::appendFan(mesh, rng);
    return mesh;
}

} // namespace raster_test
