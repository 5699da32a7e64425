// AdaptiveClusterGrid: implicit clusters whose size follows the light density (`clustered:
// grid=adaptive`), for light counts from a few to millions (issue 30). A fixed grid (ClusterGrid.h)
// keeps its cluster size while constant-overlap lights shrink, so at 10^6 lights each cluster
// holds lights that reach none of its pixels; here each frame picks the cluster size from the
// lights' projected sizes and stores only the clusters that hold samples.
//
// Geometry. Square screen tiles of tilePixels() pixels (a power of two, 4..256, so a 4x4 shading
// packet never straddles two tiles): tile column j holds the pixels x with x / tilePixels == j,
// rows likewise from the top. Exponential depth slices between the nearest and farthest sample
// (slice k spans view depths [sliceDepth(k), sliceDepth(k + 1))). Each tile keeps the slices its
// own samples' depth range spans ([s0, s1], a 2.5D bound like tiled shading's), so the clusters
// stored are sum over covered tiles of (s1 - s0 + 1), not tiles x slices: thin slices cost memory
// only where a tile's surface spans many of them. Conventions: view space right-handed, camera
// looking down -Z, view depth = -z in metres; symmetric pinhole (scenes::Camera).
//
// Size choice (build): a light's angular diameter is a = 2 radius / view depth of its centre; the
// median a over up to kSizeSamples lights (a fixed stride over the list, so the choice is a
// function of the lights alone) sets tiles of a x focal / cellsPerLight pixels (rounded to a power
// of two in log space) and slices of relative thickness a / cellsPerLight, so a typical light
// spans about cellsPerLight clusters per axis. If the stored clusters exceed maxClusters, slices
// halve and tiles double alternately until they fit: memory is bounded whatever the lights.
//
// Exactness (the one slack policy, CullingTests.h): a tile's depth range is the min/max of its
// samples' decoded depths widened by kTileDepthSlack (relative; the depth decode at another pixel
// or in another code path is within ~1e-6 of it), so every sample's slice lies in its tile's
// [s0, s1]. A cluster's box is the AABB of the tile's frustum between max(slice near, tile near)
// and min(slice far, tile far), widened by rule 3 (widenedBox); a light goes to every cluster
// whose box its (rule 1) sphere touches (sphereTouchesBox): the tests of ClusterGrid, on tighter
// boxes. Unbounded lights go to every stored cluster.
//
// Assignment (assign), in two phases, each parallel with no atomics:
//  1. per light (chunks fixed by the light count): its tile column/row range from the sphere's
//     tangent bounds, its slice range from its depth extent, and the groups of 8x8 tiles whose
//     depth range meets its own; a compact record of the light goes into each such group's stream
//     (chunks scatter into disjoint ranges, chunk order kept, so a stream is in light order);
//  2. per group: its stream against its tiles (depth test) and clusters (box test), its clusters'
//     lists built by this one task, then concatenated in cluster order.
// So each cluster's list holds ascending light indices and never depends on the thread count. A
// group's tiles stay in cache and its lights are read sequentially (the 10^6-light profile:
// reading scattered spheres by index cost a memory round trip per light and group).
//
// Thread safety: build() and assign() are not reentrant; the const queries are thread-safe.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "gbuffer/GBuffer.h"
#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightIndexLists.h"

namespace lighting {

struct AdaptiveClusterOptions {
    // Clusters across a typical light's diameter, per axis: more tightens the lists (shading)
    // and costs more assignment (about (cellsPerLight + 1)^2 tiles per light, and the slices of
    // those whose samples it reaches).
    float cellsPerLight = 2.0f;
    // Stored clusters at most (4 bytes of list offset each; 2^20: 4 MiB); beyond it the grid
    // coarsens.
    size_t maxClusters = size_t(1) << 20;
};

inline constexpr int kMinTilePixels = 4;   // one shading packet
inline constexpr int kMaxTilePixels = 256; // a light wider than this is rare and cheap
inline constexpr int kMaxAdaptiveSlices = 4096;
// Lights sampled for the size choice: enough for a stable median, O(1) per frame.
inline constexpr size_t kSizeSamples = 4096;
// A tile's depth range is widened by this (relative) so that every decode of its samples' depth
// lies inside: ~100x the float error of the reconstruction (rule 3's figure).
inline constexpr float kTileDepthSlack = 1e-5f;

class AdaptiveClusterGrid {
public:
    // Chooses the cluster size from `spheres` and builds the geometry and the per-tile slice
    // ranges from the G-buffer's depth. `wholeDepth`: every tile spans every slice between
    // nearDepthMetres and farDepthMetres (blended surfaces lie anywhere in front of the opaque
    // depth); otherwise the tiles' own ranges. Returns false when no sample is covered and
    // wholeDepth is false (no clusters). 0 < near <= far bound the slices. Cost: O(pixels) for
    // the depth ranges (parallel) + O(tiles) per size tried.
    bool build(const AdaptiveClusterOptions& options, const gbuffer::GBuffer& gbuffer,
               std::span<const LightSphere> spheres, bool wholeDepth = false,
               float nearDepthMetres = 0.0f, float farDepthMetres = 0.0f);
    // The same without a G-buffer (tests): tile depth ranges given per tile in view depth
    // (tileDepth[2 t], tileDepth[2 t + 1]; empty tile when lo > hi), for a fixed tile size and
    // slice count (the size choice skipped). tileDepth holds 2 x tiles of that size.
    void buildFixed(const gbuffer::CameraView& view, int tilePixels, int slices,
                    float nearDepthMetres, float farDepthMetres,
                    std::span<const float> tileDepthMetres);

    // Assigns lights (spheres indexed like the frame's light list); replaces the previous lists.
    // Cost: O(lights x candidate groups + tiles and clusters tested + pairs), parallel.
    void assign(std::span<const LightSphere> spheres);

    int tilePixels() const { return mTilePixels; }
    int tilesX() const { return mTilesX; }
    int tilesY() const { return mTilesY; }
    int slices() const { return int(mSliceDepth.size()) - 1; }
    size_t clusterCount() const { return mClusterCount; }
    // Bytes of the grid and its lists (tiles, slice boundaries, list offsets and indices).
    size_t memoryBytes() const;

    int tileXOfPixel(int x) const { return x >> mTileShift; }
    int tileYOfPixel(int y) const { return y >> mTileShift; }
    // Slice holding depthMetres, by the comparisons that define the slices (clamped to the grid).
    int sliceOfDepth(float depthMetres) const;
    float sliceDepth(int boundary) const { return mSliceDepth[boundary]; }
    float edgeTanX(int j) const { return mEdgeTanX[j]; }
    float edgeTanDownY(int j) const { return mEdgeTanDownY[j]; }
    // The slices [first, last] tile (tileX, tileY) stores (empty when first > last).
    int tileFirstSlice(int tileX, int tileY) const { return mTiles[tileOf(tileX, tileY)].s0; }
    int tileLastSlice(int tileX, int tileY) const { return mTiles[tileOf(tileX, tileY)].s1; }
    // The tile's widened sample depth range (view depth, metres; lo > hi when empty).
    float tileDepthLo(int tileX, int tileY) const { return mTiles[tileOf(tileX, tileY)].depthLo; }
    float tileDepthHi(int tileX, int tileY) const { return mTiles[tileOf(tileX, tileY)].depthHi; }
    // The stored cluster of (tile, slice); the slice is clamped into the tile's range (a sample
    // of the tile always lies in it). A tile without clusters gives an empty list.
    size_t clusterIndex(int tileX, int tileY, int slice) const {
        const Tile& t = mTiles[tileOf(tileX, tileY)];
        if (t.s0 > t.s1)
            return mClusterCount; // the empty list after the last cluster
        return t.base + uint32_t(std::clamp(slice, int(t.s0), int(t.s1)) - t.s0);
    }
    // The conservative box of a stored (tile, slice) cluster (slice within the tile's range).
    // Inline: assign() calls it once per candidate cluster.
    ViewBox clusterBox(int tileX, int tileY, int slice) const {
        const Tile& t = mTiles[tileOf(tileX, tileY)];
        const float zLo = std::max(mSliceDepth[slice], t.depthLo);
        const float zHi = std::min(mSliceDepth[slice + 1], t.depthHi);
        const float x0 = mEdgeTanX[tileX], x1 = mEdgeTanX[tileX + 1];
        const float d0 = mEdgeTanDownY[tileY], d1 = mEdgeTanDownY[tileY + 1];
        const glm::vec3 lo(std::min(x0 * zLo, x0 * zHi), std::min(-d1 * zLo, -d1 * zHi), -zHi);
        const glm::vec3 hi(std::max(x1 * zLo, x1 * zHi), std::max(-d0 * zLo, -d0 * zHi), -zLo);
        return widenedBox(lo, hi);
    }
    std::span<const uint32_t> lightsOf(size_t cluster) const { return mLists[cluster]; }
    size_t pairCount() const { return mLists.pairCount(); }

private:
    struct Tile {
        float depthLo = 1.0f, depthHi = 0.0f; // widened view-depth range of the samples
        int16_t s0 = 1, s1 = 0;               // stored slices, empty when s0 > s1
        uint32_t base = 0;                    // first stored cluster
    };
    static_assert(sizeof(Tile) == 16, "tiles are read once per light and tile: keep them small");
    static_assert(kMaxAdaptiveSlices <= INT16_MAX && kMaxTilePixels >= 4,
                  "slice and tile indices are int16 in Tile and LightReach");
    // A group of kGroupTiles x kGroupTiles tiles: the union of their depth ranges, so that a
    // light far in front of (or behind) a patch of surface is rejected once for the group.
    struct Group {
        float depthLo = 1.0f, depthHi = 0.0f; // empty when lo > hi
        uint32_t base = 0, end = 0;           // its clusters [base, end): groups own ranges
    };
    // What phase 2 of assign() needs of a light, copied into each group's stream by phase 1 so
    // that phase 2 reads its group's lights sequentially (read from the light list by index, the
    // scattered 56-byte spheres cost a memory round trip and a TLB miss each at 10^6 lights).
    struct LightRecord {
        glm::vec3 centreView{0.0f};
        float radius = 0.0f;
        uint32_t light = 0;
        int16_t column0 = 0, column1 = 0, row0 = 0, row1 = 0;
        int16_t slice0 = 0, slice1 = 0; // slice0 < 0: unbounded (every cluster)
        float depthLo = 0.0f, depthHi = 0.0f;
    };
    static_assert(sizeof(LightRecord) == 40, "streamed once per (group, light): keep it small");
    static constexpr int kGroupShift = 3; // groups of 8 x 8 tiles
    size_t tileOf(int tileX, int tileY) const { return size_t(tileY) * mTilesX + tileX; }
    void setGeometry(const gbuffer::CameraView& view, int tilePixels, int slices,
                     float nearDepthMetres, float farDepthMetres);
    // Per tile: its slice range and first cluster; returns the stored cluster count.
    size_t placeClusters();

    int mWidth = 1, mHeight = 1;
    int mTilePixels = 8, mTileShift = 3, mTilesX = 1, mTilesY = 1, mSearchStep = 1;
    std::vector<float> mEdgeTanX, mEdgeTanDownY; // tiles + 1, increasing
    // Tile column of a tangent, estimated (exact edges decide): the pinhole's tangents are linear
    // in pixel x: tan = (2 x / width - 1) / clipFromView[0][0] (likewise rows).
    float mColumnsPerTan = 1.0f, mColumnAtTanZero = 0.0f, mRowsPerTan = 1.0f, mRowAtTanZero = 0.0f;
    std::vector<float> mSliceDepth; // slices + 1, non-decreasing
    std::vector<Tile> mTiles;
    std::vector<Group> mGroups;
    int mGroupsX = 1, mGroupsY = 1;
    size_t mClusterCount = 0;
    LightIndexLists mLists; // clusterCount + 1 lists (the last one empty)
    // build() scratch: per 4x4 pixel block the min/max covered NDC depth.
    std::vector<float> mBlockLo, mBlockHi;
    // assign() scratch, kept across frames: per chunk of lights its (group, record) pairs and
    // per-group counts; the records in group order (CSR); per group its clusters' lists; per
    // cluster its count.
    std::vector<std::vector<std::pair<uint32_t, LightRecord>>> mChunkRecords;
    std::vector<uint32_t> mChunkGroupStart; // chunks x groups
    std::vector<uint32_t> mGroupStart;      // groups + 1
    std::vector<LightRecord> mGroupRecords;
    std::vector<std::vector<uint32_t>> mGroupChunks;
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> mGroupPairs; // (cluster, light)
    std::vector<uint32_t> mCounts;
};

} // namespace lighting
