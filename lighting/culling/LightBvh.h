// LightBvh: a bounding-volume hierarchy over the lights' conservative view-space bounding spheres
// (boundingSpheresView, LightBounds.h), so that a tile or a cluster finds the lights that may touch
// it in O(log N + k) instead of testing all N lights. Used by `clustered:assign=bvh` (ClusterGrid)
// and by the tiled stages' `assign=bvh` (buildTileLightLists, TileFrusta.h).
//
// Build (per frame, the spheres are in view space): a linear BVH (Karras 2012, "Maximizing
// parallelism in the construction of BVHs, octrees and k-d trees"). Each bounded light gets a
// 63-bit Morton code of its sphere centre, quantised to 2^21 cells per axis over the box of the
// centres; (code, light index) pairs are sorted with tbb::parallel_sort. The pairs are unique, so
// the order is unique, whatever the thread count. The tree is binary with one light per leaf;
// internal node i covers a range of sorted positions that has i at one end, its split is the
// highest bit where the keys (code, then sorted position for equal codes) of the range's ends
// differ, and its children are internal nodes split and split + 1 or leaves (Karras' layout: node
// indices follow from the keys, so no counter is shared between threads). The top-down recursion
// runs the two children of a large range in parallel (tbb::parallel_invoke) and returns each
// subtree's box, so the bounds need no atomics either: the tree and its boxes are bitwise the same
// for 1 or 8 threads. Depth is at most 96 (every level fixes one more bit of the 96-bit key), also
// when every light sits at one point. Cost: O(N log N) for the sort and the split searches.
//
// Bounds. A leaf's box is the axis-aligned box of its sphere grown by boundSlackMetres(|centre| +
// radius) (rule 3 of the one slack policy, CullingTests.h, with the largest view-space distance
// involved): whenever the float test sphereTouchesBox(sphere, box) holds, this box overlaps `box`
// in float too (the test's rounding is a few ulps of |centre| + radius, the slack 1e-5 of it), so
// the hierarchy never loses a light the exact test keeps. An internal node stores its two
// children's boxes (min/max: exact), so a query tests a child before descending into it.
// Lights the box cannot bound (directional, ambient, a non-finite centre or radius) are kept apart
// and returned by every query.
//
// Queries return light indices in ascending order, the order of every light list
// (LightIndexLists.h) and of the shading sums. candidates() is conservative (a superset of the
// lights whose sphere touches the box); lightsTouching() applies the exact test on top and equals
// brute force over every sphere. Conventions: view space right-handed, -Z forward, metres.
// Thread safety: build() is not reentrant; the const queries are thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"

namespace lighting {

class LightBvh {
public:
    // A child reference: an internal node index, or with kLeafBit a sorted position (leafLights).
    static constexpr uint32_t kLeafBit = 0x80000000u;
    // An internal node: its two children's boxes and references. 56 bytes; N - 1 nodes for N
    // bounded lights (56 MB at 10^6 lights).
    struct Node {
        glm::vec3 lo[2];
        glm::vec3 hi[2];
        uint32_t child[2];
    };

    // Builds the hierarchy over `spheres` (indexed like the frame's light list), replacing the
    // previous one and reusing its storage. Parallel (TBB), deterministic; O(N log N).
    void build(std::span<const LightSphere> spheres);

    size_t lightCount() const { return mLightCount; }
    // Lights in the tree (bounded by a finite sphere) and lights every query returns.
    size_t boundedCount() const { return mLeafLights.size(); }
    const std::vector<uint32_t>& unboundedLights() const { return mUnbounded; }

    // Appends to `out`, ascending, every light whose leaf box overlaps `box`, and every unbounded
    // light: a superset of the lights with sphereTouchesBox(sphere, box). Cost: O(log N + k) for a
    // box that k leaves overlap, plus sorting the k found.
    void candidates(const ViewBox& box, std::vector<uint32_t>& out) const;
    // Appends to `out`, ascending, exactly the lights with sphereTouchesBox(spheres[i], box) (the
    // spheres the tree was built from).
    void lightsTouching(std::span<const LightSphere> spheres, const ViewBox& box,
                        std::vector<uint32_t>& out) const;

    // The structure, for tests (determinism, coverage) and statistics.
    const std::vector<Node>& nodes() const { return mNodes; }
    const std::vector<uint32_t>& leafLights() const { return mLeafLights; } // by sorted position
    uint32_t root() const { return mRoot; }
    const ViewBox& rootBox() const { return mRootBox; }

private:
    struct Key {
        uint64_t code;
        uint32_t light;
    };
    int delta(uint32_t i, uint32_t j) const; // common-prefix length of the keys at i and j
    ViewBox buildRange(uint32_t first, uint32_t last, uint32_t node);

    size_t mLightCount = 0;
    std::vector<Key> mKeys;            // bounded lights, sorted by (code, light)
    std::vector<uint32_t> mLeafLights; // light index by sorted position
    std::vector<ViewBox> mLightBoxes;  // leaf box by light index (bounded lights only)
    std::vector<Node> mNodes;          // internal nodes, Karras' indexing; root is node 0
    std::vector<uint32_t> mUnbounded;  // ascending
    uint32_t mRoot = kLeafBit;         // node 0, or a leaf when one light is bounded
    ViewBox mRootBox{glm::vec3(INFINITY), glm::vec3(-INFINITY)};
};

} // namespace lighting
