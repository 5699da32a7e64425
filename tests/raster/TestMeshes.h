// Clip-space test meshes shared by the rasterizer's exactness tests (row_span_test.cpp,
// depth_only_test.cpp): an indexed triangle list and the fan both append to their random
// triangles, whose shared edges check that each pixel is covered once.
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

} // namespace raster_test
