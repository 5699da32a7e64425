// ExplicitClusters: the explicit (unique) clusters of Olsson, Billeter and Assarsson, "Clustered
// Deferred and Forward Shading" (HPG 2012), and their light assignment, usable and testable
// without a G-buffer.
//
// Keys. Every covered sample gets a cluster key from
//   - its screen tile (square, tileSizePixels; 32x32 by default, as the paper),
//   - its depth slice, the paper's exponential spacing
//       k = floor(log(depth / near) / log(1 + 2 tan(theta) / S_y)),
//     depth the positive view depth -z of the sample's decoded position, near the camera's near
//     plane, theta half the vertical field of view and S_y the number of tile rows (so a
//     cluster is about as deep as it is wide); depths below near give k = 0, and k is clamped to
//     kMaxExplicitSlice,
//   - optionally (normalDivisions > 0) its normal direction quantised on the cube: the face of
//     the normal's largest component, then normalDivisions x normalDivisions cells of that face
//     (the paper's 3x3 per face); a zero normal has a bin of its own.
// Within a tile the key is slice * normalBins + normalBin; the tile's unique keys, ascending, are
// its clusters, and clusters are numbered tile by tile (tiles row-major). Each tile finds its
// distinct keys on its own (a short list searched linearly, neighbours mostly sharing a key;
// sort and bisection past 32 distinct keys) and accumulates its clusters' bounds in pixel order,
// so the numbering and every bound never depend on the thread count.
//
// Bounds. Per cluster, from its samples alone (nothing from slice or tile geometry):
//   - a view-space AABB: the min/max of the samples' positions. Rule 2 of the slack policy
//     (CullingTests.h): positions are the decoded ones, bitwise those shading uses, so the box
//     holds every shaded sample exactly and takes no slack;
//   - a normal cone: axis the normalised sum of the unit normals, half-angle the arc cosine of
//     the smallest dot of a normal with the axis (pi, "faces everywhere", when the sum nearly
//     cancels or a normal is zero), as TileFrusta's tile cones.
//
// Assignment. A light is in a cluster's list when it is unbounded, or its conservative sphere
// (LightBounds.h, rule 1) touches the cluster's AABB (sphereTouchesBox) and, with back-face
// culling, the light does not face the back of every sample of the cluster: the test of
// `tiled-backface` (lightBackFacesTile, TileFrusta.h, with its angular slack
// kBackfaceSlackRadians) on the AABB's corners and the cluster's cone. appendClusterLights is the
// per-cluster test over any ascending candidate set, so a light hierarchy can supply candidates
// later; assignLights gives it the lights binned per tile: view-frustum culling, the tile
// column and row ranges of candidateLights (TileFrusta.h), then each tile's lights tested once
// against the union box of the tile's clusters. Lists hold ascending light indices.
//
// Conventions: view space right-handed, camera at the origin looking down -Z, metres; pixel
// (x, y) with y down. Thread safety: find() and assignLights() are not reentrant (parallel
// inside, TBB); the const queries are thread-safe.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <tbb/parallel_for.h>

#include "gbuffer/GBuffer.h"
#include "gbuffer/visibility/CameraView.h"
#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightIndexLists.h"
#include "lighting/culling/TileFrusta.h"

namespace lighting {

// Slices beyond this are merged into the last (keeps keys within 32 bits with any normal bins:
// 2^20 x (6 x 8 x 8 + 1) < 2^32). 2^20 slices of ratio >= 1 + 2 tan(theta) / S_y reach far beyond
// any float depth for the image sizes of this testbed.
inline constexpr uint32_t kMaxExplicitSlice = (1u << 20) - 1;
inline constexpr int kMaxNormalDivisions = 8;
// "No cluster": the cluster index of an uncovered pixel.
inline constexpr uint32_t kNoCluster = UINT32_MAX;

struct ExplicitClusterOptions {
    int tileSizePixels = 32; // the paper's 32x32 tiles
    int normalDivisions = 0; // 0: no normal clustering; n: n x n cells per cube face (paper: 3)
    bool backface = true;    // back-face culling of lights with the clusters' normal cones
};

struct ExplicitCluster {
    ViewBox boundsView;                         // min/max of the samples' positions, no slack
    glm::vec3 normalAxisView{0.0f, 0.0f, 1.0f}; // unit
    float normalHalfAngle = 3.14159265f;        // radians; >= pi/2: faces everywhere
    uint32_t tile = 0;                          // ty * tileCountX + tx
    uint32_t key = 0;                           // slice * normalBins + normalBin
    uint32_t sampleCount = 0;
};

// The key of one sample within its tile (see the file comment). Pure; the cluster finder's one
// definition, exposed for the tests.
struct ClusterKeying {
    float nearMetres = 0.1f;
    float slicesPerLogDepth = 1.0f; // 1 / log(1 + 2 tan(theta) / S_y)
    int normalDivisions = 0;

    static ClusterKeying make(const gbuffer::CameraView& view, int tileCountY, int normalDivisions);
    uint32_t normalBins() const {
        return normalDivisions > 0 ? uint32_t(6 * normalDivisions * normalDivisions + 1) : 1u;
    }
    uint32_t sliceOfDepth(float depthMetres) const {
        const float k = std::floor(std::log(depthMetres / nearMetres) * slicesPerLogDepth);
        return k >= 1.0f ? uint32_t(std::min(k, float(kMaxExplicitSlice))) : 0u;
    }
    uint32_t normalBin(const glm::vec3& normalView) const;
    uint32_t key(const glm::vec3& positionView, const glm::vec3& normalView) const {
        return sliceOfDepth(-positionView.z) * normalBins() + normalBin(normalView);
    }
};

class ExplicitClusters {
public:
    // Finds the unique clusters of a frame's samples. sampleAt(x, y, positionView, normalView)
    // returns false for an uncovered pixel, else sets the sample's position and normal (for the
    // G-buffer: GBuffer::decode's, find(gb, ...) below). Replaces the previous clusters (the
    // lists are stale until assignLights, which keeps their storage across frames). Parallel over
    // tiles, each tile sorted alone; cost O(pixels log tile pixels).
    template <class SampleAt>
    void find(int widthPixels, int heightPixels, const ClusterKeying& keying, int tileSizePixels,
              const SampleAt& sampleAt);
    // The same on a G-buffer: every covered pixel's decoded surface (bitwise what shading reads).
    void find(const gbuffer::GBuffer& gb, const ExplicitClusterOptions& options);

    const TileGrid& grid() const { return mGrid; }
    size_t clusterCount() const { return mClusters.size(); }
    const ExplicitCluster& cluster(size_t index) const { return mClusters[index]; }
    std::span<const ExplicitCluster> clusters() const { return mClusters; }
    // Clusters of a tile: [tileFirstCluster(t), tileFirstCluster(t + 1)).
    uint32_t tileFirstCluster(int tile) const { return mTileFirst[size_t(tile)]; }
    // The cluster of pixel (x, y), kNoCluster when uncovered.
    uint32_t clusterOfPixel(int x, int y) const {
        return mPixelCluster[size_t(y) * size_t(mGrid.widthPixels) + size_t(x)];
    }
    std::span<const uint32_t> pixelClusters() const { return mPixelCluster; }

    // Assigns lights (spheres indexed like the frame's light list) to the clusters; replaces the
    // previous lists. Cost O(lights x (tile columns + rows) + (tile, light) pairs + pairs
    // surviving the tile box x the tile's clusters); parallel over lights then over tiles,
    // deterministic. Returns the (cluster, light) pairs the back-face test removed.
    uint64_t assignLights(const gbuffer::CameraView& view, const std::vector<LightSphere>& spheres,
                          bool backface);
    std::span<const uint32_t> lightsOf(size_t cluster) const { return mLists[cluster]; }
    const LightIndexLists& lists() const { return mLists; }
    size_t pairCount() const { return mLists.pairCount(); }
    // Bytes of the frame's structure: per-pixel cluster indices, clusters, tile offsets, lists.
    size_t bytes() const;

private:
    TileGrid mGrid;
    std::vector<uint32_t> mPixelCluster; // per pixel; tile-local index until find() ends
    std::vector<uint32_t> mTileFirst;    // tileCount + 1
    std::vector<ExplicitCluster> mClusters;
    std::vector<std::vector<ExplicitCluster>> mTileClusters; // find() scratch, per tile
    LightIndexLists mLists;
    LightIndexLists mTileLights;                                         // assignLights scratch
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> mBatchPairs; // assignLights scratch
    std::vector<std::vector<uint32_t>> mChunks;                          // assignLights scratch
    std::vector<uint32_t> mCounts;                                       // assignLights scratch
};

// The per-cluster test of the file comment, over `candidates` (ascending light indices into
// `spheres`): appends the kept ones to `list` in that order. `backface` with a cone that can
// reject (backfaceClusterCone) adds the back-face test. Returns how many it rejected. Pure.
struct ClusterCone {
    TileBox box; // the AABB's corners, box and centre
    BackfaceTileCone cone;
};
ClusterCone backfaceClusterCone(const ExplicitCluster& cluster);
uint64_t appendClusterLights(const ExplicitCluster& cluster, const ClusterCone* backface,
                             std::span<const LightSphere> spheres,
                             std::span<const uint32_t> candidates, std::vector<uint32_t>& list);

// Bounds of a cluster from its samples (positions and normals in one order): box, cone and count;
// the cluster's tile and key are left to the caller. What find() computes, exposed for the tests.
ExplicitCluster clusterOfSamples(std::span<const glm::vec3> positionsView,
                                 std::span<const glm::vec3> normalsView);

// Accumulates one cluster's bounds from its samples in a fixed order (what find() and
// clusterOfSamples share): add() every sample, then axis(), then addToCone() every normal again,
// then finish().
struct ClusterBoundsAccumulator {
    glm::vec3 lo{INFINITY}, hi{-INFINITY};
    glm::vec3 normalSum{0.0f};
    uint32_t count = 0;
    bool zeroNormal = false;
    float minDot = 1.0f;
    glm::vec3 axisView{0.0f, 0.0f, 1.0f};
    bool coneOpen = true;

    // The unit normal the bounds use (zero for a zero or non-finite-length normal): computed once
    // per sample by the caller and given to add() and addToCone().
    static glm::vec3 unit(const glm::vec3& n) {
        const float length = glm::length(n);
        return length > 0.0f ? n / length : glm::vec3(0.0f);
    }
    void add(const glm::vec3& positionView, const glm::vec3& unitNormalView) {
        lo = glm::min(lo, positionView);
        hi = glm::max(hi, positionView);
        normalSum += unitNormalView;
        zeroNormal = zeroNormal || unitNormalView == glm::vec3(0.0f);
        ++count;
    }
    // Normals cancelling out (sum ~ 0) or a zero normal leave the cone open, as TileFrusta's.
    void axis() {
        const float sumLength = glm::length(normalSum);
        coneOpen = zeroNormal || !(sumLength > 1e-3f * float(count));
        if (!coneOpen)
            axisView = normalSum / sumLength;
    }
    void addToCone(const glm::vec3& unitNormalView) {
        minDot = std::min(minDot, glm::dot(axisView, unitNormalView));
    }
    ExplicitCluster finish() const {
        ExplicitCluster c;
        c.sampleCount = count;
        if (count == 0)
            return c;
        c.boundsView = {lo, hi};
        if (!coneOpen) {
            c.normalAxisView = axisView;
            c.normalHalfAngle = std::acos(std::clamp(minDot, -1.0f, 1.0f));
        }
        return c;
    }
};

template <class SampleAt>
void ExplicitClusters::find(int widthPixels, int heightPixels, const ClusterKeying& keying,
                            int tileSizePixels, const SampleAt& sampleAt) {
    mGrid = TileGrid::make(widthPixels, heightPixels, tileSizePixels);
    const size_t tileCount = size_t(mGrid.tileCount());
    mPixelCluster.resize(size_t(widthPixels) * size_t(heightPixels));
    mTileClusters.resize(tileCount);
    tbb::parallel_for(size_t(0), tileCount, [&](size_t tile) {
        const int tx = int(tile) % mGrid.tileCountX, ty = int(tile) / mGrid.tileCountX;
        // The tile's covered samples in pixel order: positions, unit normals, keys, pixels.
        struct Scratch {
            std::vector<glm::vec3> positions, normals;
            std::vector<uint32_t> keys, pixels, slots, distinct, sorted, rank;
            std::vector<ClusterBoundsAccumulator> bounds;
        };
        thread_local Scratch t;
        t.positions.clear();
        t.normals.clear();
        t.keys.clear();
        t.pixels.clear();
        for (int y = mGrid.y0(ty); y < mGrid.y1(ty); ++y)
            for (int x = mGrid.x0(tx); x < mGrid.x1(tx); ++x) {
                const size_t pixel = size_t(y) * size_t(widthPixels) + size_t(x);
                mPixelCluster[pixel] = kNoCluster;
                glm::vec3 position, normal;
                if (!sampleAt(x, y, position, normal))
                    continue;
                t.positions.push_back(position);
                t.normals.push_back(ClusterBoundsAccumulator::unit(normal));
                t.keys.push_back(keying.key(position, normal));
                t.pixels.push_back(uint32_t(pixel));
            }
        const size_t n = t.keys.size();
        // Each sample's slot among the tile's distinct keys: a short list searched linearly
        // (neighbours mostly share a key), or, past kLinear distinct keys, the sorted unique
        // keys searched by bisection. Either way the slots end as ranks in ascending key order.
        constexpr size_t kLinear = 32;
        t.slots.resize(n);
        t.distinct.clear();
        bool many = false;
        uint32_t lastKey = UINT32_MAX, lastSlot = 0;
        for (size_t i = 0; i < n && !many; ++i) {
            if (t.keys[i] != lastKey) {
                lastKey = t.keys[i];
                const auto it = std::find(t.distinct.begin(), t.distinct.end(), lastKey);
                if (it != t.distinct.end()) {
                    lastSlot = uint32_t(it - t.distinct.begin());
                } else if (t.distinct.size() == kLinear) {
                    many = true;
                    break;
                } else {
                    lastSlot = uint32_t(t.distinct.size());
                    t.distinct.push_back(lastKey);
                }
            }
            t.slots[i] = lastSlot;
        }
        if (many) {
            t.sorted.assign(t.keys.begin(), t.keys.end());
            std::sort(t.sorted.begin(), t.sorted.end());
            t.sorted.erase(std::unique(t.sorted.begin(), t.sorted.end()), t.sorted.end());
            for (size_t i = 0; i < n; ++i)
                t.slots[i] =
                    uint32_t(std::lower_bound(t.sorted.begin(), t.sorted.end(), t.keys[i]) -
                             t.sorted.begin());
        } else {
            t.sorted.assign(t.distinct.begin(), t.distinct.end());
            std::sort(t.sorted.begin(), t.sorted.end());
            t.rank.resize(t.distinct.size());
            for (size_t d = 0; d < t.distinct.size(); ++d)
                t.rank[d] =
                    uint32_t(std::lower_bound(t.sorted.begin(), t.sorted.end(), t.distinct[d]) -
                             t.sorted.begin());
            for (size_t i = 0; i < n; ++i)
                t.slots[i] = t.rank[t.slots[i]];
        }
        // Bounds in pixel order, per cluster: box and normal sum, axis, then the cone.
        t.bounds.assign(t.sorted.size(), ClusterBoundsAccumulator{});
        for (size_t i = 0; i < n; ++i) {
            t.bounds[t.slots[i]].add(t.positions[i], t.normals[i]);
            mPixelCluster[t.pixels[i]] = t.slots[i];
        }
        for (ClusterBoundsAccumulator& b : t.bounds)
            b.axis();
        for (size_t i = 0; i < n; ++i)
            if (!t.bounds[t.slots[i]].coneOpen)
                t.bounds[t.slots[i]].addToCone(t.normals[i]);
        std::vector<ExplicitCluster>& clusters = mTileClusters[tile];
        clusters.resize(t.sorted.size());
        for (size_t c = 0; c < clusters.size(); ++c) {
            clusters[c] = t.bounds[c].finish();
            clusters[c].tile = uint32_t(tile);
            clusters[c].key = t.sorted[c];
        }
    });
    mTileFirst.resize(tileCount + 1);
    mTileFirst[0] = 0;
    for (size_t tile = 0; tile < tileCount; ++tile)
        mTileFirst[tile + 1] = mTileFirst[tile] + uint32_t(mTileClusters[tile].size());
    mClusters.resize(mTileFirst[tileCount]);
    tbb::parallel_for(size_t(0), tileCount, [&](size_t tile) {
        std::copy(mTileClusters[tile].begin(), mTileClusters[tile].end(),
                  mClusters.begin() + mTileFirst[tile]);
        if (mTileFirst[tile] == 0 || mTileClusters[tile].empty())
            return;
        const int tx = int(tile) % mGrid.tileCountX, ty = int(tile) / mGrid.tileCountX;
        for (int y = mGrid.y0(ty); y < mGrid.y1(ty); ++y)
            for (int x = mGrid.x0(tx); x < mGrid.x1(tx); ++x) {
                uint32_t& c = mPixelCluster[size_t(y) * size_t(widthPixels) + size_t(x)];
                if (c != kNoCluster)
                    c += mTileFirst[tile];
            }
    });
}

} // namespace lighting
