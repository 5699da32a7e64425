// LightIndexLists: the one light-list format of the culling methods, a CSR (compressed sparse
// rows): list i is indices[offsets[i] .. offsets[i + 1]). Tiles (buildTileLightLists,
// TileFrusta.h), clusters (ClusterGrid), forward objects (ForwardGeometry::objectLightLists) and
// pixels (ContributingLights) all hand their lists over in it; forward-multipass keeps its
// per-light illumination sets (object indices) in it too, as the transpose of the per-object lists.
//
// Every builder fills lists in a fixed order that does not depend on the thread count; the lists
// of the culling methods hold ascending light indices. Offsets are 32-bit: builders throw
// std::length_error beyond 2^32 - 1 pairs. Storage is kept across assign() calls (a stage rebuilds
// its lists every frame). Thread safety: the const queries are thread-safe; assign() is not
// reentrant.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace lighting {

class LightIndexLists {
public:
    size_t listCount() const { return mOffsets.empty() ? 0 : mOffsets.size() - 1; }
    std::span<const uint32_t> operator[](size_t list) const {
        return {mIndices.data() + mOffsets[list], mIndices.data() + mOffsets[list + 1]};
    }
    size_t pairCount() const { return mIndices.size(); }
    const std::vector<uint32_t>& offsets() const { return mOffsets; }
    const std::vector<uint32_t>& indices() const { return mIndices; }

    // Lists given as consecutive chunks: list i has counts[i] entries, and the chunks, concatenated
    // in order, are the lists concatenated in order (a chunk may hold several lists, e.g. one image
    // row of per-pixel lists, or one list). Chunks are copied in parallel.
    void assign(std::span<const uint32_t> counts, std::span<const std::vector<uint32_t>> chunks);
    // One chunk per list.
    void assign(std::span<const std::vector<uint32_t>> lists);
    // From (list, index) pairs produced in batches: a stable counting sort, so each list holds its
    // indices in batch order, then pair order (ascending when the batches are).
    void assignFromPairs(size_t listCount,
                         std::span<const std::vector<std::pair<uint32_t, uint32_t>>> batches);
    // The transpose: list j of the result holds the i with j in list i, ascending;
    // `resultListCount` lists (every index must be below it).
    LightIndexLists transposed(size_t resultListCount) const;

private:
    std::vector<uint32_t> mOffsets; // listCount + 1
    std::vector<uint32_t> mIndices;
};

} // namespace lighting
