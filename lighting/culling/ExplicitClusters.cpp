#include "lighting/culling/ExplicitClusters.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

namespace lighting {

ClusterKeying ClusterKeying::make(const gbuffer::CameraView& view, int tileCountY,
                                  int normalDivisions) {
    ClusterKeying keying;
    keying.nearMetres = view.nearMetres;
    // clipFromView[1][1] = 1 / tan(theta) for the symmetric pinhole of scenes::Camera.
    const double tanTheta = 1.0 / double(view.clipFromView[1][1]);
    keying.slicesPerLogDepth =
        float(1.0 / std::log(1.0 + 2.0 * tanTheta / double(std::max(tileCountY, 1))));
    keying.normalDivisions = normalDivisions;
    return keying;
}

uint32_t ClusterKeying::normalBin(const glm::vec3& n) const {
    if (normalDivisions <= 0)
        return 0;
    const int d = normalDivisions;
    const glm::vec3 a = glm::abs(n);
    // The face of the largest component (ties to the first axis), then the cell of the two others
    // projected on it. Keys only group samples: bounds come from the samples, so any rounding
    // here changes the clustering, never the exactness.
    int axis = 0;
    if (a.y > a[axis])
        axis = 1;
    if (a.z > a[axis])
        axis = 2;
    const float major = a[axis];
    if (!(major > 0.0f))
        return uint32_t(6 * d * d); // zero (or NaN) normal: a bin of its own
    const int face = axis * 2 + (n[axis] < 0.0f ? 1 : 0);
    const float u = n[(axis + 1) % 3] / major, v = n[(axis + 2) % 3] / major;
    const auto cell = [d](float t) {
        return std::clamp(int((t + 1.0f) * 0.5f * float(d)), 0, d - 1);
    };
    return uint32_t((face * d + cell(u)) * d + cell(v));
}

ExplicitCluster clusterOfSamples(std::span<const glm::vec3> positionsView,
                                 std::span<const glm::vec3> normalsView) {
    ClusterBoundsAccumulator bounds;
    for (size_t i = 0; i < positionsView.size(); ++i)
        bounds.add(positionsView[i], ClusterBoundsAccumulator::unit(normalsView[i]));
    bounds.axis();
    if (!bounds.coneOpen)
        for (const glm::vec3& n : normalsView)
            bounds.addToCone(ClusterBoundsAccumulator::unit(n));
    return bounds.finish();
}

ClusterCone backfaceClusterCone(const ExplicitCluster& cluster) {
    ClusterCone result;
    TileBox& box = result.box;
    const glm::vec3& lo = cluster.boundsView.lo;
    const glm::vec3& hi = cluster.boundsView.hi;
    glm::vec3 sum(0.0f);
    for (int i = 0; i < 8; ++i) {
        box.corners[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
        sum += box.corners[i];
    }
    box.boxMin = lo;
    box.boxMax = hi;
    box.centre = sum * 0.125f;
    TileSurfaceBounds bounds;
    bounds.covered = true;
    bounds.normalAxisView = cluster.normalAxisView;
    bounds.normalHalfAngle = cluster.normalHalfAngle;
    result.cone = backfaceTileCone(box, bounds);
    return result;
}

uint64_t appendClusterLights(const ExplicitCluster& cluster, const ClusterCone* backface,
                             std::span<const LightSphere> spheres,
                             std::span<const uint32_t> candidates, std::vector<uint32_t>& list) {
    uint64_t rejected = 0;
    const bool cone = backface != nullptr && backface->cone.enabled;
    for (const uint32_t light : candidates) {
        const LightSphere& sphere = spheres[light];
        if (!sphere.unbounded) {
            if (!sphereTouchesBox(sphere.centreView, sphere.radius, cluster.boundsView.lo,
                                  cluster.boundsView.hi))
                continue;
            if (cone && lightBackFacesTile(backface->box, backface->cone, sphere.positionView)) {
                ++rejected;
                continue;
            }
        }
        list.push_back(light);
    }
    return rejected;
}

void ExplicitClusters::find(const gbuffer::GBuffer& gb, const ExplicitClusterOptions& options) {
    const int tileCountY = (gb.height() + options.tileSizePixels - 1) / options.tileSizePixels;
    const ClusterKeying keying =
        ClusterKeying::make(gb.view(), tileCountY, options.normalDivisions);
    // Positions from the depth decoder and normals from the float planes are bitwise
    // GBuffer::decode's (which reads them the same way); layouts with encoded normals go through
    // decode().
    const gbuffer::DepthDecoder& decoder = gb.depthDecoder();
    const std::span<const float> depth = gb.depth();
    const std::span<const float> normal[3] = {gb.normalPlane(0), gb.normalPlane(1),
                                              gb.normalPlane(2)};
    const bool planes = !normal[0].empty();
    find(gb.width(), gb.height(), keying, options.tileSizePixels,
         [&](int x, int y, glm::vec3& positionView, glm::vec3& normalView) {
             const size_t pixel = size_t(y) * size_t(gb.width()) + size_t(x);
             if (!gb.covered(pixel))
                 return false;
             if (planes) {
                 positionView = decoder.positionView(x, y, depth[pixel]);
                 normalView = {normal[0][pixel], normal[1][pixel], normal[2][pixel]};
             } else {
                 const gbuffer::Surface s = gb.decode(x, y);
                 positionView = s.positionView;
                 normalView = s.normalView;
             }
             return true;
         });
}

uint64_t ExplicitClusters::assignLights(const gbuffer::CameraView& view,
                                        const std::vector<LightSphere>& spheres, bool backface) {
    const TileEdgePlanes edges = TileEdgePlanes::make(view, mGrid);
    const std::vector<CandidateLight> candidates =
        candidateLights(view, mGrid, edges, spheres, true);
    const size_t tileCount = size_t(mGrid.tileCount());

    // Bin the candidates into the covered tiles of their column and row ranges: fixed batches of
    // candidates, merged by a stable counting sort in batch order, so each tile's list holds
    // candidate positions (hence light indices) ascending whatever the thread count.
    constexpr size_t kBatch = 1024;
    const size_t batchCount = (candidates.size() + kBatch - 1) / kBatch;
    mBatchPairs.resize(batchCount);
    tbb::parallel_for(size_t(0), batchCount, [&](size_t batch) {
        std::vector<std::pair<uint32_t, uint32_t>>& pairs = mBatchPairs[batch];
        pairs.clear();
        const size_t end = std::min(candidates.size(), (batch + 1) * kBatch);
        for (size_t k = batch * kBatch; k < end; ++k) {
            const CandidateLight& c = candidates[k];
            const bool all = c.unbounded;
            const int rowMin = all ? 0 : c.rowMin, rowMax = all ? mGrid.tileCountY - 1 : c.rowMax;
            const int colMin = all ? 0 : c.columnMin;
            const int colMax = all ? mGrid.tileCountX - 1 : c.columnMax;
            for (int ty = rowMin; ty <= rowMax; ++ty)
                for (int tx = colMin; tx <= colMax; ++tx) {
                    const size_t tile = size_t(ty) * size_t(mGrid.tileCountX) + size_t(tx);
                    if (mTileFirst[tile + 1] > mTileFirst[tile])
                        pairs.emplace_back(uint32_t(tile), uint32_t(k));
                }
        }
    });
    mTileLights.assignFromPairs(tileCount, std::span(mBatchPairs.data(), batchCount));

    // Per tile: its lights against the union box of its clusters, then each cluster's test on
    // the survivors. Each tile writes its own chunk (its clusters' lists, in cluster order).
    mChunks.resize(tileCount);
    mCounts.assign(mClusters.size(), 0);
    std::vector<uint64_t> tileRejected(tileCount, 0);
    tbb::parallel_for(size_t(0), tileCount, [&](size_t tile) {
        std::vector<uint32_t>& chunk = mChunks[tile];
        chunk.clear();
        const uint32_t first = mTileFirst[tile], last = mTileFirst[tile + 1];
        if (first == last)
            return;
        glm::vec3 lo = mClusters[first].boundsView.lo, hi = mClusters[first].boundsView.hi;
        for (uint32_t c = first + 1; c < last; ++c) {
            lo = glm::min(lo, mClusters[c].boundsView.lo);
            hi = glm::max(hi, mClusters[c].boundsView.hi);
        }
        thread_local std::vector<uint32_t> survivors;
        survivors.clear();
        for (const uint32_t k : mTileLights[tile]) {
            const CandidateLight& light = candidates[k];
            if (light.unbounded || sphereTouchesBox(light.centreView, light.radius, lo, hi))
                survivors.push_back(light.index);
        }
        uint64_t rejected = 0;
        for (uint32_t c = first; c < last; ++c) {
            const size_t before = chunk.size();
            if (backface) {
                const ClusterCone cone = backfaceClusterCone(mClusters[c]);
                rejected += appendClusterLights(mClusters[c], &cone, spheres, survivors, chunk);
            } else {
                rejected += appendClusterLights(mClusters[c], nullptr, spheres, survivors, chunk);
            }
            mCounts[c] = uint32_t(chunk.size() - before);
        }
        tileRejected[tile] = rejected;
    });
    mLists.assign(mCounts, mChunks);
    uint64_t rejected = 0;
    for (uint64_t r : tileRejected)
        rejected += r;
    return rejected;
}

size_t ExplicitClusters::bytes() const {
    return sizeof(uint32_t) * (mPixelCluster.size() + mTileFirst.size() + mLists.offsets().size() +
                               mLists.indices().size()) +
           sizeof(ExplicitCluster) * mClusters.size();
}

} // namespace lighting
