// LightGrid: a uniform grid over a view-space box (the visible surfaces' bounds) whose cells list
// the lights that can reach them, so that a per-pixel question "which lights contribute here?"
// tests a few candidates instead of every light. Used by the oracle (lighting/Oracle.h), which
// must stay exact: the candidates of a point are a SUPERSET of the lights that contribute there.
//
// Exactness: a light is listed in a cell when its conservative bounding sphere
// (culling/LightBounds.h: the lit region of a point or spot light, widened by the one slack
// policy) overlaps the cell's box widened by kCellSlack of the cell size, which covers the
// rounding of the point-to-cell mapping. A point is mapped to a cell by clamped flooring, so every
// queried point must lie in the box (the oracle builds the box from the very points it queries);
// tests/lighting/stages/stage_exactness_test.cpp compares the grid's oracle with brute force
// pixel by pixel on every test scene. Unbounded lights (directional,
// ambient) are candidates everywhere. This is independent of the tile and cluster culling it
// checks: only the bounding spheres are shared.
//
// Size: cells about the median light radius across, at most kMaxCells in all (memory: 4 bytes per
// cell plus 4 per light-cell pair). Build: O(lights + pairs), serial and deterministic; queries
// are const and thread-safe. Candidates come in ascending light order within the bounded lights,
// the unbounded ones apart.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include <glm/glm.hpp>

#include "lighting/culling/LightBounds.h"

namespace lighting {

class LightGrid {
public:
    // At most this many cells (16 MiB of offsets); beyond it cells grow.
    static constexpr size_t kMaxCells = size_t(1) << 22;
    // A cell's box is widened by this fraction of its size before the overlap test.
    static constexpr float kCellSlack = 1e-3f;

    // Lists the lights of `spheres` (index = light index) over the box [boxMin, boxMax].
    void build(const std::vector<LightSphere>& spheres, glm::vec3 boxMin, glm::vec3 boxMax);

    // The bounded lights that may reach `pointView` (a point inside the box), ascending.
    std::span<const uint32_t> candidatesAt(glm::vec3 pointView) const;
    // The lights that may reach every point: directional and ambient.
    std::span<const uint32_t> everywhere() const { return mUnbounded; }

    size_t cellCount() const { return mCellStart.empty() ? 0 : mCellStart.size() - 1; }
    size_t pairCount() const { return mCellLights.size(); }

private:
    glm::ivec3 cellIndex(glm::vec3 pointView) const; // clamped to the grid
    size_t cellOf(glm::vec3 pointView) const;

    glm::vec3 mMin{0.0f};
    glm::vec3 mCellSize{1.0f};
    glm::ivec3 mCells{1};
    std::vector<uint32_t> mCellStart;  // CSR offsets, one per cell plus one
    std::vector<uint32_t> mCellLights; // the lights of each cell, ascending
    std::vector<uint32_t> mUnbounded;
};

// The view-space box of the covered pixels' surfaces: surfaceAt(x, y, surface) fills a surface
// with a positionView and returns false for background. nullopt when no pixel is covered. Rows in
// parallel; min and max do not depend on the order.
template <class Surface, class SurfaceAt>
std::optional<std::pair<glm::vec3, glm::vec3>> surfaceBox(int width, int height,
                                                          const SurfaceAt& surfaceAt) {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    std::vector<glm::vec3> rowMin(size_t(height), glm::vec3{kInf});
    std::vector<glm::vec3> rowMax(size_t(height), glm::vec3{-kInf});
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            Surface point;
            if (!surfaceAt(x, y, point))
                continue;
            const glm::vec3 p(point.positionView);
            rowMin[size_t(y)] = glm::min(rowMin[size_t(y)], p);
            rowMax[size_t(y)] = glm::max(rowMax[size_t(y)], p);
        }
    });
    glm::vec3 boxMin{kInf}, boxMax{-kInf};
    for (int y = 0; y < height; ++y) {
        boxMin = glm::min(boxMin, rowMin[size_t(y)]);
        boxMax = glm::max(boxMax, rowMax[size_t(y)]);
    }
    if (!(boxMin.x <= boxMax.x))
        return std::nullopt;
    return std::make_pair(boxMin, boxMax);
}

} // namespace lighting
