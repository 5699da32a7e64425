#include "lighting/culling/AdaptiveClusterGrid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace lighting {

namespace {

// The smallest chunk of lights of a phase-1 task (a task costs more than a few lights).
constexpr size_t kMinChunkLights = 64;
constexpr int kBlockPixels = 4;
// assign()'s phase 1 runs over at most this many chunks of lights (fixed by the light count, so
// the record order never depends on the thread count): enough to balance 2..16 threads, few
// enough that the chunk x group counters stay small (64 x 920 groups at 4-pixel tiles).
constexpr size_t kMaxChunks = 64; // depth min/max granularity: the smallest tile

// x / depth (or -y / depth) of a screen edge, by unprojecting it at the near plane.
glm::vec3 unprojectNdc(const gbuffer::CameraView& view, float ndcX, float ndcY) {
    const float nearNdc = view.reversedZ() ? 1.0f : 0.0f;
    const glm::vec4 p = view.viewFromClip * glm::vec4(ndcX, ndcY, nearNdc, 1.0f);
    return glm::vec3(p) / p.w;
}

// Over increasing edges e[0..n]: the columns whose right edge reaches lo and whose left edge is
// at most hi (ClusterGrid's binary range), walked from estimates of the first and last column
// (usually exact, so O(1)); first > last when none.
void edgeRange(const std::vector<float>& e, float lo, float hi, float perTan, float atZero,
               int& first, int& last) {
    const int n = int(e.size()) - 1;
    auto estimate = [&](float tan) {
        return int(std::clamp(std::floor(tan * perTan + atZero), 0.0f, float(n - 1)));
    };
    first = estimate(lo);
    while (first > 0 && e[first] >= lo)
        --first;
    while (first < n && e[first + 1] < lo)
        ++first;
    last = estimate(hi);
    while (last < n - 1 && e[last + 1] <= hi)
        ++last;
    while (last >= 0 && e[last] > hi)
        --last;
    if (first >= n)
        last = first - 1;
}

int log2Floor(int v) {
    return 31 - __builtin_clz(uint32_t(v));
}

} // namespace

void AdaptiveClusterGrid::setGeometry(const gbuffer::CameraView& view, int tilePixels, int slices,
                                      float nearDepthMetres, float farDepthMetres) {
    if (tilePixels < kMinTilePixels || tilePixels > kMaxTilePixels ||
        (tilePixels & (tilePixels - 1)) != 0 || slices < 1 || slices > kMaxAdaptiveSlices ||
        view.width < 1 || view.height < 1)
        throw std::invalid_argument("AdaptiveClusterGrid: tile size, slices or viewport invalid");
    if (!(nearDepthMetres > 0.0f) || !(farDepthMetres >= nearDepthMetres))
        throw std::invalid_argument("AdaptiveClusterGrid: need 0 < near depth <= far depth");
    mWidth = view.width;
    mHeight = view.height;
    mTilePixels = tilePixels;
    mTileShift = log2Floor(tilePixels);
    mTilesX = (mWidth + tilePixels - 1) / tilePixels;
    mTilesY = (mHeight + tilePixels - 1) / tilePixels;
    if (mTilesX >= INT16_MAX || mTilesY >= INT16_MAX)
        throw std::invalid_argument("AdaptiveClusterGrid: more than 32766 tiles across");
    mEdgeTanX.resize(mTilesX + 1);
    for (int j = 0; j <= mTilesX; ++j) {
        const int pixel = std::min(j * tilePixels, mWidth);
        const glm::vec3 p = unprojectNdc(view, float(pixel) / float(mWidth) * 2.0f - 1.0f, 0.0f);
        mEdgeTanX[j] = p.x / -p.z;
    }
    mEdgeTanDownY.resize(mTilesY + 1);
    for (int j = 0; j <= mTilesY; ++j) {
        const int pixel = std::min(j * tilePixels, mHeight);
        const glm::vec3 p = unprojectNdc(view, 0.0f, 1.0f - float(pixel) / float(mHeight) * 2.0f);
        mEdgeTanDownY[j] = -p.y / -p.z;
    }
    // Slice boundaries in double so that rounding cannot reorder them; ends exact.
    mColumnsPerTan = view.clipFromView[0][0] * 0.5f * float(mWidth) / float(tilePixels);
    mColumnAtTanZero = 0.5f * float(mWidth) / float(tilePixels);
    mRowsPerTan = view.clipFromView[1][1] * 0.5f * float(mHeight) / float(tilePixels);
    mRowAtTanZero = 0.5f * float(mHeight) / float(tilePixels);
    mSliceDepth.resize(slices + 1);
    const double nearD = nearDepthMetres, farD = farDepthMetres;
    for (int k = 0; k <= slices; ++k)
        mSliceDepth[k] = float(nearD * std::pow(farD / nearD, double(k) / slices));
    mSliceDepth[0] = nearDepthMetres;
    mSliceDepth[slices] = farDepthMetres;
    for (int k = 1; k <= slices; ++k)
        mSliceDepth[k] = std::max(mSliceDepth[k], mSliceDepth[k - 1]);
    mSearchStep = 0;
    while (mSearchStep * 2 <= slices - 1)
        mSearchStep = std::max(1, mSearchStep * 2);
    mTiles.assign(size_t(mTilesX) * mTilesY, Tile{});
    mGroupsX = ((mTilesX - 1) >> kGroupShift) + 1;
    mGroupsY = ((mTilesY - 1) >> kGroupShift) + 1;
}

int AdaptiveClusterGrid::sliceOfDepth(float depthMetres) const {
    // The largest k in [0, slices) with b_k <= depth (0 when none), by branch-free binary lifting
    // (ClusterGrid::sliceOfDepth's comparisons).
    const float* boundary = mSliceDepth.data();
    const int sliceCount = slices();
    int slice = 0;
    for (int step = mSearchStep; step > 0; step >>= 1) {
        const int candidate = slice + step;
        slice = candidate < sliceCount && boundary[candidate] <= depthMetres ? candidate : slice;
    }
    return slice;
}

size_t AdaptiveClusterGrid::placeClusters() {
    // Clusters numbered group by group (tiles row-major inside a group, then slices), so that
    // each group's clusters are one range and assign() builds each group's lists alone.
    mGroups.assign(size_t(mGroupsX) * mGroupsY, Group{});
    size_t count = 0;
    for (int gy = 0; gy < mGroupsY; ++gy)
        for (int gx = 0; gx < mGroupsX; ++gx) {
            Group& g = mGroups[size_t(gy) * mGroupsX + gx];
            g.base = uint32_t(std::min<size_t>(count, UINT32_MAX));
            for (int ty = gy << kGroupShift; ty < std::min(mTilesY, (gy + 1) << kGroupShift); ++ty)
                for (int tx = gx << kGroupShift; tx < std::min(mTilesX, (gx + 1) << kGroupShift);
                     ++tx) {
                    Tile& t = mTiles[tileOf(tx, ty)];
                    if (t.depthLo > t.depthHi) {
                        t.s0 = 1;
                        t.s1 = 0;
                        continue;
                    }
                    t.s0 = int16_t(sliceOfDepth(t.depthLo));
                    t.s1 = int16_t(sliceOfDepth(t.depthHi));
                    t.base = uint32_t(std::min<size_t>(count, UINT32_MAX));
                    count += size_t(t.s1 - t.s0 + 1);
                    if (g.depthLo > g.depthHi) {
                        g.depthLo = t.depthLo;
                        g.depthHi = t.depthHi;
                    } else {
                        g.depthLo = std::min(g.depthLo, t.depthLo);
                        g.depthHi = std::max(g.depthHi, t.depthHi);
                    }
                }
            g.end = uint32_t(std::min<size_t>(count, UINT32_MAX));
        }
    if (count >= UINT32_MAX)
        throw std::length_error("AdaptiveClusterGrid: more than 2^32 - 1 clusters");
    return count;
}

void AdaptiveClusterGrid::buildFixed(const gbuffer::CameraView& view, int tilePixels, int slices,
                                     float nearDepthMetres, float farDepthMetres,
                                     std::span<const float> tileDepthMetres) {
    setGeometry(view, tilePixels, slices, nearDepthMetres, farDepthMetres);
    if (tileDepthMetres.size() != 2 * mTiles.size())
        throw std::invalid_argument("AdaptiveClusterGrid::buildFixed: one depth range per tile");
    for (size_t t = 0; t < mTiles.size(); ++t) {
        mTiles[t].depthLo = tileDepthMetres[2 * t];
        mTiles[t].depthHi = tileDepthMetres[2 * t + 1];
    }
    mClusterCount = placeClusters();
    mLists.assignFromPairs(mClusterCount + 1, {});
}

bool AdaptiveClusterGrid::build(const AdaptiveClusterOptions& options,
                                const gbuffer::GBuffer& gbuffer,
                                std::span<const LightSphere> spheres, bool wholeDepth,
                                float nearDepthMetres, float farDepthMetres) {
    const gbuffer::CameraView& view = gbuffer.view();
    const int width = gbuffer.width(), height = gbuffer.height();
    const std::span<const float> depth = gbuffer.depth();
    const float clear = view.clearDepth();

    // Per 4x4 block the min/max covered NDC depth (min/max: order-independent, deterministic).
    const int blocksX = (width + kBlockPixels - 1) / kBlockPixels;
    const int blocksY = (height + kBlockPixels - 1) / kBlockPixels;
    mBlockLo.resize(size_t(blocksX) * blocksY);
    mBlockHi.resize(size_t(blocksX) * blocksY);
    tbb::parallel_for(0, blocksY, [&](int by) {
        float* lo = mBlockLo.data() + size_t(by) * blocksX;
        float* hi = mBlockHi.data() + size_t(by) * blocksX;
        std::fill(lo, lo + blocksX, INFINITY);
        std::fill(hi, hi + blocksX, -INFINITY);
        for (int y = by * kBlockPixels; y < std::min(height, (by + 1) * kBlockPixels); ++y) {
            const float* row = depth.data() + size_t(y) * width;
            for (int x = 0; x < width; ++x) {
                const float d = row[x];
                if (d == clear)
                    continue;
                const int bx = x / kBlockPixels;
                lo[bx] = std::min(lo[bx], d);
                hi[bx] = std::max(hi[bx], d);
            }
        }
    });
    float ndcLo = INFINITY, ndcHi = -INFINITY;
    for (size_t b = 0; b < mBlockLo.size(); ++b) {
        ndcLo = std::min(ndcLo, mBlockLo[b]);
        ndcHi = std::max(ndcHi, mBlockHi[b]);
    }
    const bool covered = ndcLo <= ndcHi;
    if (!covered && !wholeDepth) {
        mClusterCount = 0;
        mTiles.clear();
        mLists.assignFromPairs(1, {});
        return false;
    }

    // View depths of NDC extremes (for a pinhole, depth along -Z does not depend on the pixel),
    // widened so that every sample's own decode lies inside.
    const gbuffer::DepthDecoder& decoder = gbuffer.depthDecoder();
    auto depthRange = [&](float a, float b, float& lo, float& hi) {
        const float depthA = decoder.viewDepthMetres(width / 2, height / 2, a);
        const float depthB = decoder.viewDepthMetres(width / 2, height / 2, b);
        lo = std::max(std::min(depthA, depthB) * (1.0f - kTileDepthSlack), 1e-6f);
        hi = std::max(std::max(depthA, depthB) * (1.0f + kTileDepthSlack), lo);
    };
    float nearDepth = nearDepthMetres, farDepth = farDepthMetres;
    if (covered) {
        float lo = 0.0f, hi = 0.0f;
        depthRange(ndcLo, ndcHi, lo, hi);
        nearDepth = wholeDepth ? std::min(lo, nearDepthMetres) : lo;
        farDepth = wholeDepth ? std::max(hi, farDepthMetres) : hi;
    }

    // Size choice: the median angular diameter of the lights that reach the depth range.
    const size_t stride = std::max<size_t>(1, spheres.size() / kSizeSamples);
    std::vector<float> angular;
    for (size_t i = 0; i < spheres.size(); i += stride) {
        const LightSphere& s = spheres[i];
        const float d = -s.centreView.z;
        if (s.unbounded || d + s.radius < nearDepth || d - s.radius > farDepth)
            continue;
        angular.push_back(2.0f * s.radius / std::max(d, nearDepth));
    }
    const float focalPixels = view.clipFromView[1][1] * 0.5f * float(height);
    int tilePixels = kMaxTilePixels, sliceCount = 1;
    if (!angular.empty()) {
        std::nth_element(angular.begin(), angular.begin() + angular.size() / 2, angular.end());
        const double a = angular[angular.size() / 2];
        const double cells = std::max(options.cellsPerLight, 1e-3f);
        const double idealTile = std::max(a * focalPixels / cells, 1.0);
        const int exponent = int(std::lround(std::log2(idealTile)));
        tilePixels = std::clamp(1 << std::clamp(exponent, 0, 16), kMinTilePixels, kMaxTilePixels);
        const double slices = std::ceil(std::log(double(farDepth) / nearDepth) /
                                        std::log1p(std::max(a / cells, 1e-6)));
        sliceCount = int(std::clamp(slices, 1.0, double(kMaxAdaptiveSlices)));
    }

    // Tile indices are int16 (Tile, LightRecord): tiles no smaller than a huge image needs.
    while (tilePixels < kMaxTilePixels &&
           std::max(width, height) / tilePixels >= int(INT16_MAX) - 1)
        tilePixels *= 2;
    // Fit the budget: coarsen slices and tiles alternately (tile depth ranges per tile size).
    for (bool coarsenSlices = true;; coarsenSlices = !coarsenSlices) {
        setGeometry(view, tilePixels, sliceCount, nearDepth, farDepth);
        const int blocksPerTile = tilePixels / kBlockPixels;
        tbb::parallel_for(0, mTilesY, [&](int ty) {
            for (int tx = 0; tx < mTilesX; ++tx) {
                Tile& t = mTiles[tileOf(tx, ty)];
                if (wholeDepth) {
                    t.depthLo = nearDepth;
                    t.depthHi = farDepth;
                    continue;
                }
                float lo = INFINITY, hi = -INFINITY;
                for (int by = ty * blocksPerTile; by < std::min(blocksY, (ty + 1) * blocksPerTile);
                     ++by)
                    for (int bx = tx * blocksPerTile;
                         bx < std::min(blocksX, (tx + 1) * blocksPerTile); ++bx) {
                        lo = std::min(lo, mBlockLo[size_t(by) * blocksX + bx]);
                        hi = std::max(hi, mBlockHi[size_t(by) * blocksX + bx]);
                    }
                if (lo <= hi)
                    depthRange(lo, hi, t.depthLo, t.depthHi);
            }
        });
        mClusterCount = placeClusters();
        if (mClusterCount <= options.maxClusters)
            break;
        const bool canSlices = sliceCount > 1, canTiles = tilePixels < kMaxTilePixels;
        if (!canSlices && !canTiles)
            break; // coarsest grid: one slice of 256-pixel tiles (at most 15 clusters at 720p)
        if ((coarsenSlices && canSlices) || !canTiles)
            sliceCount = std::max(1, sliceCount / 2);
        else
            tilePixels *= 2;
    }
    mLists.assignFromPairs(mClusterCount + 1, {});
    return true;
}

void AdaptiveClusterGrid::assign(std::span<const LightSphere> spheres) {
    if (mClusterCount == 0) {
        mLists.assignFromPairs(1, {});
        return;
    }
    const size_t lightCount = spheres.size();
    const size_t groupCount = mGroups.size();
    if (lightCount >= UINT32_MAX)
        throw std::length_error("AdaptiveClusterGrid: more than 2^32 - 1 lights");
    const float nearDepth = mSliceDepth.front(), farDepth = mSliceDepth.back();

    // Phase 1, per light (parallel over chunks fixed by the light count alone): its candidate
    // tiles and slices, and the groups it may reach (those whose depth range meets its own), as
    // (group, record) pairs in light order.
    const size_t chunkSize = std::max(kMinChunkLights, (lightCount + kMaxChunks - 1) / kMaxChunks);
    const size_t chunkCount = (lightCount + chunkSize - 1) / chunkSize;
    mChunkRecords.resize(chunkCount);
    mChunkGroupStart.assign(chunkCount * groupCount, 0u);
    tbb::parallel_for(size_t(0), chunkCount, [&](size_t chunk) {
        auto& records = mChunkRecords[chunk];
        records.clear();
        uint32_t* groupCounts = mChunkGroupStart.data() + chunk * groupCount;
        const size_t end = std::min(lightCount, (chunk + 1) * chunkSize);
        for (size_t light = chunk * chunkSize; light < end; ++light) {
            const LightSphere& sphere = spheres[light];
            LightRecord record;
            record.light = uint32_t(light);
            if (sphere.unbounded) {
                record.slice0 = -1;
                for (size_t g = 0; g < groupCount; ++g)
                    if (mGroups[g].base < mGroups[g].end) {
                        records.emplace_back(uint32_t(g), record);
                        ++groupCounts[g];
                    }
                continue;
            }
            const glm::vec3& c = sphere.centreView;
            const float r = sphere.radius;
            // The part of the sphere inside the grid's depth range, and its tangent bounds (over
            // a box of depths > 0, x / depth is extreme at a corner), widened as ClusterGrid's
            // candidate ranges are.
            const float depthLo = std::max(-c.z - r, nearDepth);
            const float depthHi = std::min(-c.z + r, farDepth);
            if (!(depthLo <= depthHi))
                continue;
            const float xLo = c.x - r, xHi = c.x + r, downLo = -c.y - r, downHi = -c.y + r;
            const float tanXLo = std::min(xLo / depthLo, xLo / depthHi);
            const float tanXHi = std::max(xHi / depthLo, xHi / depthHi);
            const float tanDownLo = std::min(downLo / depthLo, downLo / depthHi);
            const float tanDownHi = std::max(downHi / depthLo, downHi / depthHi);
            const float absoluteSlack = 2.0f * kBoundSlackMetres / depthLo;
            const float tanSlack =
                2.0f * kBoundSlack * (1.0f + std::abs(tanXLo) + std::abs(tanXHi)) + absoluteSlack;
            const float downSlack =
                2.0f * kBoundSlack * (1.0f + std::abs(tanDownLo) + std::abs(tanDownHi)) +
                absoluteSlack;
            int column0, column1, row0, row1;
            edgeRange(mEdgeTanX, tanXLo - tanSlack, tanXHi + tanSlack, mColumnsPerTan,
                      mColumnAtTanZero, column0, column1);
            if (column0 > column1)
                continue;
            edgeRange(mEdgeTanDownY, tanDownLo - downSlack, tanDownHi + downSlack, mRowsPerTan,
                      mRowAtTanZero, row0, row1);
            if (row0 > row1)
                continue;
            const float depthSlack = 2.0f * (kBoundSlack * depthHi + kBoundSlackMetres);
            record.centreView = c;
            record.radius = r;
            record.column0 = int16_t(column0);
            record.column1 = int16_t(column1);
            record.row0 = int16_t(row0);
            record.row1 = int16_t(row1);
            record.depthLo = depthLo - depthSlack;
            record.depthHi = depthHi + depthSlack;
            record.slice0 = int16_t(sliceOfDepth(record.depthLo));
            record.slice1 = int16_t(sliceOfDepth(record.depthHi));
            // A light off the depth range of a whole patch of surface (in front of it, or hidden
            // behind it) costs one test per group, not one per tile.
            for (int gy = row0 >> kGroupShift; gy <= row1 >> kGroupShift; ++gy)
                for (int gx = column0 >> kGroupShift; gx <= column1 >> kGroupShift; ++gx) {
                    const size_t g = size_t(gy) * mGroupsX + gx;
                    if (mGroups[g].depthHi >= record.depthLo &&
                        mGroups[g].depthLo <= record.depthHi) {
                        records.emplace_back(uint32_t(g), record);
                        ++groupCounts[g];
                    }
                }
        }
    });
    // The records in group order, chunks in order within a group (so lights ascend): counts to
    // start positions (group-major), then each chunk scatters its own records (disjoint ranges).
    mGroupStart.assign(groupCount + 1, 0u);
    uint64_t total = 0;
    for (size_t g = 0; g < groupCount; ++g) {
        mGroupStart[g] = uint32_t(total);
        for (size_t chunk = 0; chunk < chunkCount; ++chunk) {
            uint32_t& slot = mChunkGroupStart[chunk * groupCount + g];
            const uint32_t count = slot;
            slot = uint32_t(total);
            total += count;
        }
        if (total >= UINT32_MAX)
            throw std::length_error("AdaptiveClusterGrid: more than 2^32 - 1 group records");
    }
    mGroupStart[groupCount] = uint32_t(total);
    mGroupRecords.resize(size_t(total));
    tbb::parallel_for(size_t(0), chunkCount, [&](size_t chunk) {
        uint32_t* cursor = mChunkGroupStart.data() + chunk * groupCount;
        for (const auto& [g, record] : mChunkRecords[chunk])
            mGroupRecords[cursor[g]++] = record;
    });

    // Phase 2, per group (parallel): its lights in ascending order against its tiles and
    // clusters; its clusters' lists built in its own chunk, so each list is ascending and written
    // by one task.
    mCounts.assign(mClusterCount + 1, 0u);
    mGroupChunks.resize(groupCount);
    mGroupPairs.resize(groupCount);
    tbb::parallel_for(size_t(0), groupCount, [&](size_t g) {
        const Group& group = mGroups[g];
        std::vector<uint32_t>& chunk = mGroupChunks[g];
        chunk.clear();
        if (group.base == group.end)
            return;
        const int gx = int(g % size_t(mGroupsX)), gy = int(g / size_t(mGroupsX));
        const int tileX0 = gx << kGroupShift, tileY0 = gy << kGroupShift;
        const int tileX1 = std::min(mTilesX, (gx + 1) << kGroupShift) - 1;
        const int tileY1 = std::min(mTilesY, (gy + 1) << kGroupShift) - 1;
        // (local cluster, light) pairs in light order, then a counting sort into the chunk.
        std::vector<std::pair<uint32_t, uint32_t>>& pairs = mGroupPairs[g];
        pairs.clear();
        for (size_t i = mGroupStart[g]; i < mGroupStart[g + 1]; ++i) {
            const LightRecord& record = mGroupRecords[i];
            if (record.slice0 < 0) {
                for (uint32_t cluster = group.base; cluster < group.end; ++cluster)
                    pairs.emplace_back(cluster - group.base, record.light);
                continue;
            }
            for (int ty = std::max<int>(record.row0, tileY0),
                     ty1 = std::min<int>(record.row1, tileY1);
                 ty <= ty1; ++ty)
                for (int tx = std::max<int>(record.column0, tileX0),
                         tx1 = std::min<int>(record.column1, tileX1);
                     tx <= tx1; ++tx) {
                    const Tile& t = mTiles[tileOf(tx, ty)];
                    if (t.s0 > t.s1 || t.depthHi < record.depthLo || t.depthLo > record.depthHi)
                        continue;
                    const int k1 = std::min<int>(record.slice1, t.s1);
                    for (int k = std::max<int>(record.slice0, t.s0); k <= k1; ++k) {
                        const ViewBox box = clusterBox(tx, ty, k);
                        if (sphereTouchesBox(record.centreView, record.radius, box.lo, box.hi))
                            pairs.emplace_back(t.base + uint32_t(k - t.s0) - group.base,
                                               record.light);
                    }
                }
        }
        uint32_t* counts = mCounts.data() + group.base;
        for (const auto& pair : pairs)
            ++counts[pair.first];
        std::vector<uint32_t> cursor(group.end - group.base);
        for (size_t i = 1; i < cursor.size(); ++i)
            cursor[i] = cursor[i - 1] + counts[i - 1];
        chunk.resize(pairs.size());
        for (const auto& pair : pairs)
            chunk[cursor[pair.first]++] = pair.second;
    });
    // The groups' chunks concatenated are the lists in cluster order; the last list (tiles
    // without clusters point at it) stays empty.
    mLists.assign(mCounts, mGroupChunks);
}

size_t AdaptiveClusterGrid::memoryBytes() const {
    return mTiles.capacity() * sizeof(Tile) +
           (mEdgeTanX.capacity() + mEdgeTanDownY.capacity() + mSliceDepth.capacity()) *
               sizeof(float) +
           (mBlockLo.capacity() + mBlockHi.capacity()) * sizeof(float) +
           (mLists.offsets().capacity() + mLists.indices().capacity()) * sizeof(uint32_t) + [&] {
               size_t bytes = 0;
               for (const auto& records : mChunkRecords)
                   bytes += records.capacity() * sizeof(records[0]);
               return bytes;
           }();
}

} // namespace lighting
