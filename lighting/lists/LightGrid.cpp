#include "lighting/lists/LightGrid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lighting {

namespace {

// Squared distance from `p` to the box [lo, hi] (0 inside).
float squaredDistanceToBox(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
    const glm::vec3 d = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f));
    return glm::dot(d, d);
}

} // namespace

void LightGrid::build(const std::vector<LightSphere>& spheres, glm::vec3 boxMin, glm::vec3 boxMax) {
    mUnbounded.clear();
    mCellLights.clear();
    mMin = boxMin;
    const glm::vec3 extent = glm::max(boxMax - boxMin, glm::vec3(1e-6f));

    // The bounded lights whose sphere reaches the box, and their median radius: the cell size.
    std::vector<uint32_t> inBox;
    std::vector<float> radii;
    for (uint32_t light = 0; light < spheres.size(); ++light) {
        const LightSphere& s = spheres[light];
        if (s.unbounded) {
            mUnbounded.push_back(light);
            continue;
        }
        if (squaredDistanceToBox(s.centreView, boxMin, boxMax) <= s.radius * s.radius) {
            inBox.push_back(light);
            radii.push_back(s.radius);
        }
    }
    float cellSize = std::max({extent.x, extent.y, extent.z});
    if (!radii.empty()) {
        std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
        cellSize = std::clamp(radii[radii.size() / 2], cellSize / 1024.0f, cellSize);
    }
    auto cellsFor = [&](float size) {
        return glm::ivec3(
            glm::clamp(glm::ceil(extent / size), glm::vec3(1.0f), glm::vec3(4096.0f)));
    };
    mCells = cellsFor(cellSize);
    while (size_t(mCells.x) * mCells.y * mCells.z > kMaxCells) {
        cellSize *= 1.25f;
        mCells = cellsFor(cellSize);
    }
    mCellSize = extent / glm::vec3(mCells);
    const size_t cellCount = size_t(mCells.x) * mCells.y * mCells.z;

    // (cell, light) pairs in light order, then a stable counting sort by cell: each cell's lights
    // stay ascending, whatever the build order.
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    const glm::vec3 widen = mCellSize * kCellSlack;
    for (uint32_t light : inBox) {
        const LightSphere& s = spheres[light];
        const glm::ivec3 lo = cellIndex(s.centreView - s.radius);
        const glm::ivec3 hi = cellIndex(s.centreView + s.radius);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) {
                    const glm::vec3 cellLo = mMin + glm::vec3(x, y, z) * mCellSize - widen;
                    const glm::vec3 cellHi =
                        mMin + glm::vec3(x + 1, y + 1, z + 1) * mCellSize + widen;
                    if (squaredDistanceToBox(s.centreView, cellLo, cellHi) <= s.radius * s.radius)
                        pairs.emplace_back(uint32_t((size_t(z) * mCells.y + y) * mCells.x + x),
                                           light);
                }
    }
    if (pairs.size() > UINT32_MAX)
        throw std::length_error("LightGrid: more than 2^32 - 1 light-cell pairs");
    mCellStart.assign(cellCount + 1, 0);
    for (const auto& [cell, light] : pairs)
        ++mCellStart[cell + 1];
    for (size_t c = 0; c < cellCount; ++c)
        mCellStart[c + 1] += mCellStart[c];
    mCellLights.resize(pairs.size());
    std::vector<uint32_t> next(mCellStart.begin(), mCellStart.end() - 1);
    for (const auto& [cell, light] : pairs)
        mCellLights[next[cell]++] = light;
}

glm::ivec3 LightGrid::cellIndex(glm::vec3 pointView) const {
    // Clamped while still a float: a sphere far larger than the box gives indices beyond int's
    // range, whose conversion would be undefined.
    const glm::vec3 cell = glm::clamp(glm::floor((pointView - mMin) / mCellSize), glm::vec3(0.0f),
                                      glm::vec3(mCells - 1));
    return glm::ivec3(cell);
}

size_t LightGrid::cellOf(glm::vec3 pointView) const {
    const glm::ivec3 cell = cellIndex(pointView);
    return (size_t(cell.z) * mCells.y + cell.y) * mCells.x + cell.x;
}

std::span<const uint32_t> LightGrid::candidatesAt(glm::vec3 pointView) const {
    const size_t cell = cellOf(pointView);
    return {mCellLights.data() + mCellStart[cell], mCellStart[cell + 1] - mCellStart[cell]};
}

} // namespace lighting
