// ClusterGrid: the implicit cluster grid of clustered shading (Olsson et al. 2012; Örtegren's
// CPU variant) and its per-frame light assignment, usable and testable without a G-buffer.
//
// Geometry. The view frustum is cut into tilesX columns x tilesY rows of screen tiles and
// `slices` depth slices; cluster (tileX, tileY, slice) is the frustum piece between two pairs of
// tile planes and two view depths. Conventions: view space right-handed, camera looking down -Z,
// view depth = -z (metres, positive in front). Tiles are whole pixels: tile column j holds the
// pixels x with floor(x * tilesX / width) == j (rows likewise, y counted from the top), so its
// edges are the integer pixel coordinates ceil(j * width / tilesX) and every pixel centre lies
// strictly inside its tile. The camera is a symmetric pinhole (scenes::Camera), so a tile edge is
// a plane through the eye and x / depth is constant along it (mEdgeTan*). Slice k spans view
// depths [sliceDepth(k), sliceDepth(k+1)]; boundaries are geometric (exponential, self-similar
// clusters) or uniform between the near and far depth given at construction.
//
// Culling volumes. Each cluster has a view-space AABB of its 8 corners, widened by the receiver
// slack of culling/CullingTests.h (rule 3: widenedBox) so that a reconstructed position that
// rounding pushed just outside its cluster is still inside the box; the light spheres
// (lighting/culling/LightBounds.h) are widened far more. The side planes and the candidate ranges
// below use the same kBoundSlack. test=aabb tests sphere vs AABB; test=frustum additionally rejects
// a sphere wholly outside one of the cluster's four side planes (tighter, still conservative).
//
// Assignment. For each bounded light the candidate column, row and slice ranges come from a
// conservative box around the part of its sphere inside the grid's depth range; `walk` finds
// them by walking the sorted tile planes / slice boundaries from the first one (Örtegren's
// plane reduction), `binary` by binary search. Both evaluate the same predicates, so they give
// the same ranges, and every candidate cluster is then tested with the cluster test. Unbounded
// lights (directional, ambient) go into every cluster. The result is a LightIndexLists (CSR)
// with each cluster's light indices ascending. Parallel over fixed batches of lights, merged by a
// stable counting sort in batch order: the lists never depend on the thread count, and no
// atomics are used. `bvh` turns the loop around: a LightBvh (LightBvh.h) over the spheres is
// queried once per tile column of clusters (all slices of one tile) with the union of their
// boxes, and each light it returns meets the same two conditions in each cluster (its candidate
// ranges, by binary search, hold the cluster; the cluster test), so the lists are those of walk
// and binary; parallel over tile columns, each cluster's list written by one task.
//
// Thread safety: construction and assign() are not reentrant; the const queries are.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightBvh.h"
#include "lighting/culling/LightIndexLists.h"

namespace lighting {

enum class SliceSpacing { Exponential, Uniform };
enum class AssignMethod { Walk, Binary, Bvh };
enum class ClusterTest { Aabb, Frustum };

struct ClusterGridOptions {
    int tilesX = 24;
    int tilesY = 12;
    int slices = 32;
    SliceSpacing spacing = SliceSpacing::Exponential;
    AssignMethod assign = AssignMethod::Walk;
    ClusterTest test = ClusterTest::Aabb;
};

// Limits: each dimension at most 1024 and at most 2^20 clusters (offsets 4 MiB, AABBs 24 MiB);
// beyond that the grid costs more to build than it saves.
inline constexpr int kMaxClusterDimension = 1024;
inline constexpr size_t kMaxClusterCount = size_t(1) << 20;

// Parses "XxYxZ" (e.g. "24x12x32"); returns false when malformed, zero or beyond the limits.
bool parseClusterGrid(const std::string& text, int& tilesX, int& tilesY, int& slices);

class ClusterGrid {
public:
    // Inclusive index range; empty when first > last.
    struct Range {
        int first = 0;
        int last = -1;
        bool empty() const { return first > last; }
    };

    // Builds the cluster geometry for the view's viewport. 0 < nearDepthMetres <= farDepthMetres
    // bound the slices (view depths). Cost: O(cluster count).
    ClusterGrid(const ClusterGridOptions& options, const gbuffer::CameraView& view,
                float nearDepthMetres, float farDepthMetres);
    // The same, reusing this grid's storage (a stage rebuilds its grid every frame; fresh
    // allocations of megabytes would cost page faults every frame). Clears the light lists.
    void build(const ClusterGridOptions& options, const gbuffer::CameraView& view,
               float nearDepthMetres, float farDepthMetres);

    const ClusterGridOptions& options() const { return mOptions; }
    size_t clusterCount() const { return mBounds.size(); }
    size_t clusterIndex(int tileX, int tileY, int slice) const {
        return (size_t(slice) * mOptions.tilesY + tileY) * mOptions.tilesX + tileX;
    }
    int tileXOfPixel(int x) const { return int(int64_t(x) * mOptions.tilesX / mWidth); }
    int tileYOfPixel(int y) const { return int(int64_t(y) * mOptions.tilesY / mHeight); }
    // The slice whose depth interval holds depthMetres, by the same comparisons that define the
    // boundaries (depths outside the grid clamp to the first / last slice).
    int sliceOfDepth(float depthMetres) const;
    float sliceDepth(int boundary) const { return mSliceDepth[boundary]; }
    // x / depth of column edge j (0..tilesX), increasing; -y / depth of row edge j, increasing.
    float edgeTanX(int j) const { return mEdgeTanX[j]; }
    float edgeTanDownY(int j) const { return mEdgeTanDownY[j]; }
    const ViewBox& bounds(size_t cluster) const { return mBounds[cluster]; }

    // The cluster test (the option `test`): may the sphere touch the cluster? Conservative.
    bool mayTouch(const LightSphere& sphere, int tileX, int tileY, int slice) const;
    // Candidate ranges of a bounded sphere by the configured method (binary search for bvh);
    // false when it misses the grid.
    bool candidateRanges(const LightSphere& sphere, Range& columns, Range& rows,
                         Range& slices) const;
    bool candidateRanges(const LightSphere& sphere, AssignMethod method, Range& columns,
                         Range& rows, Range& slices) const;

    // Assigns lights (spheres indexed like the frame's light list) to clusters; replaces the
    // previous lists. Cost: walk, binary O(lights * candidate clusters + clusters + pairs),
    // parallel over lights; bvh O(lights log lights + tiles * (log lights + candidates) + pairs),
    // parallel over tiles.
    void assign(const std::vector<LightSphere>& spheres);
    std::span<const uint32_t> lightsOf(size_t cluster) const { return mLists[cluster]; }
    size_t pairCount() const { return mLists.pairCount(); }
    const LightIndexLists& lists() const { return mLists; }

private:
    ClusterGridOptions mOptions;
    int mWidth = 1;
    int mHeight = 1;
    std::vector<float> mEdgeTanX;     // tilesX + 1
    std::vector<float> mEdgeTanDownY; // tilesY + 1
    std::vector<glm::vec2> mPlaneX;   // normalised (1, tan) of each column edge plane: x + tan*z
    std::vector<glm::vec2> mPlaneY;   // same for rows with y flipped: -y + tanDown*z
    std::vector<float> mSliceDepth;   // slices + 1, non-decreasing
    int mSearchStep = 0;              // largest power of two <= max(slices - 1, 1)
    std::vector<ViewBox> mBounds;
    LightIndexLists mLists;                                              // per cluster
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> mBatchPairs; // assign() scratch
    // assign=bvh scratch, reused across frames: the hierarchy, each light's candidate ranges.
    void assignWithBvh(const std::vector<LightSphere>& spheres);
    struct LightRanges {
        Range columns, rows, slices; // empty when the light misses the grid
    };
    LightBvh mBvh;
    std::vector<LightRanges> mLightRanges;
    std::vector<std::vector<uint32_t>> mClusterLights; // per cluster, capacity kept
};

} // namespace lighting
