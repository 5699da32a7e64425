#include "lighting/culling/ClusterGrid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace lighting {

namespace {

// Lights per assignment task: large enough to amortise a task, small enough to balance 1000
// lights over a few cores. Fixed, so the pair order never depends on the thread count.
constexpr size_t kLightsPerBatch = 32;
// assign=bvh: consecutive slices of one tile per BVH query (measured, light_bvh_bench).
constexpr int kSlicesPerQuery = 4;

// x / depth (or -y / depth) of a screen edge, by unprojecting it at the near plane.
glm::vec3 unprojectNdc(const gbuffer::CameraView& view, float ndcX, float ndcY) {
    const float nearNdc = view.reversedZ() ? 1.0f : 0.0f;
    const glm::vec4 p = view.viewFromClip * glm::vec4(ndcX, ndcY, nearNdc, 1.0f);
    return glm::vec3(p) / p.w;
}

// First tile whose far edge reaches `lo` and last tile whose near edge is at most `hi`, over
// non-decreasing edges e[0..n]: the one predicate pair both methods evaluate.
ClusterGrid::Range walkRange(const std::vector<float>& e, float lo, float hi) {
    const int n = int(e.size()) - 1;
    int first = 0;
    while (first < n && e[first + 1] < lo)
        ++first;
    if (first == n || e[first] > hi)
        return {};
    int last = first;
    while (last + 1 < n && e[last + 1] <= hi)
        ++last;
    return {first, last};
}

ClusterGrid::Range binaryRange(const std::vector<float>& e, float lo, float hi) {
    const int n = int(e.size()) - 1;
    const int first = int(std::lower_bound(e.begin() + 1, e.end(), lo) - (e.begin() + 1));
    const int last = int(std::upper_bound(e.begin(), e.end() - 1, hi) - e.begin()) - 1;
    if (first >= n || last < 0)
        return {};
    return {first, last};
}

} // namespace

bool parseClusterGrid(const std::string& text, int& tilesX, int& tilesY, int& slices) {
    int values[3] = {0, 0, 0};
    size_t position = 0;
    for (int i = 0; i < 3; ++i) {
        if (i > 0) {
            if (position >= text.size() || text[position] != 'x')
                return false;
            ++position;
        }
        const size_t begin = position;
        int64_t value = 0;
        while (position < text.size() && text[position] >= '0' && text[position] <= '9') {
            value = value * 10 + (text[position] - '0');
            if (value > kMaxClusterDimension)
                return false;
            ++position;
        }
        if (position == begin || value < 1)
            return false;
        values[i] = int(value);
    }
    if (position != text.size())
        return false;
    if (size_t(values[0]) * values[1] * values[2] > kMaxClusterCount)
        return false;
    tilesX = values[0];
    tilesY = values[1];
    slices = values[2];
    return true;
}

ClusterGrid::ClusterGrid(const ClusterGridOptions& options, const gbuffer::CameraView& view,
                         float nearDepthMetres, float farDepthMetres) {
    build(options, view, nearDepthMetres, farDepthMetres);
}

void ClusterGrid::build(const ClusterGridOptions& options, const gbuffer::CameraView& view,
                        float nearDepthMetres, float farDepthMetres) {
    const int nx = options.tilesX, ny = options.tilesY, nz = options.slices;
    if (nx < 1 || ny < 1 || nz < 1 || nx > kMaxClusterDimension || ny > kMaxClusterDimension ||
        nz > kMaxClusterDimension || size_t(nx) * ny * nz > kMaxClusterCount || view.width < 1 ||
        view.height < 1)
        throw std::invalid_argument("ClusterGrid: grid dimensions or viewport out of range");
    if (!(nearDepthMetres > 0.0f) || !(farDepthMetres >= nearDepthMetres))
        throw std::invalid_argument("ClusterGrid: need 0 < near depth <= far depth");
    mOptions = options;
    mWidth = view.width;
    mHeight = view.height;

    // Tile edges: whole pixels (see the header), as tangents in view space.
    mEdgeTanX.resize(nx + 1);
    mPlaneX.resize(nx + 1);
    for (int j = 0; j <= nx; ++j) {
        const int64_t pixel = (int64_t(j) * view.width + nx - 1) / nx; // ceil(j * width / nx)
        const glm::vec3 p =
            unprojectNdc(view, float(pixel) / float(view.width) * 2.0f - 1.0f, 0.0f);
        mEdgeTanX[j] = p.x / -p.z;
        mPlaneX[j] = glm::vec2(1.0f, mEdgeTanX[j]) / std::sqrt(1.0f + mEdgeTanX[j] * mEdgeTanX[j]);
    }
    mEdgeTanDownY.resize(ny + 1);
    mPlaneY.resize(ny + 1);
    for (int j = 0; j <= ny; ++j) {
        const int64_t pixel = (int64_t(j) * view.height + ny - 1) / ny;
        const glm::vec3 p =
            unprojectNdc(view, 0.0f, 1.0f - float(pixel) / float(view.height) * 2.0f);
        mEdgeTanDownY[j] = -p.y / -p.z;
        mPlaneY[j] = glm::vec2(1.0f, mEdgeTanDownY[j]) /
                     std::sqrt(1.0f + mEdgeTanDownY[j] * mEdgeTanDownY[j]);
    }

    // Slice boundaries, in double so that rounding cannot reorder them; ends exact.
    mSliceDepth.resize(nz + 1);
    const double nearD = nearDepthMetres, farD = farDepthMetres;
    for (int k = 0; k <= nz; ++k) {
        const double t = double(k) / nz;
        const double depth = options.spacing == SliceSpacing::Exponential
                                 ? nearD * std::pow(farD / nearD, t)
                                 : nearD + (farD - nearD) * t;
        mSliceDepth[k] = float(depth);
    }
    mSearchStep = 0;
    while (mSearchStep * 2 <= nz - 1)
        mSearchStep = std::max(1, mSearchStep * 2);
    mSliceDepth[0] = nearDepthMetres;
    mSliceDepth[nz] = farDepthMetres;
    for (int k = 1; k <= nz; ++k)
        mSliceDepth[k] = std::max(mSliceDepth[k], mSliceDepth[k - 1]);

    // AABBs of the 8 corners, widened by the receiver slack (CullingTests.h).
    mBounds.resize(size_t(nx) * ny * nz);
    tbb::parallel_for(0, nz, [&](int k) {
        const float depths[2] = {mSliceDepth[k], mSliceDepth[k + 1]};
        for (int ty = 0; ty < ny; ++ty)
            for (int tx = 0; tx < nx; ++tx) {
                glm::vec3 lo(INFINITY), hi(-INFINITY);
                for (float d : depths)
                    for (int cx = 0; cx < 2; ++cx)
                        for (int cy = 0; cy < 2; ++cy) {
                            const glm::vec3 corner(mEdgeTanX[tx + cx] * d,
                                                   -mEdgeTanDownY[ty + cy] * d, -d);
                            lo = glm::min(lo, corner);
                            hi = glm::max(hi, corner);
                        }
                mBounds[clusterIndex(tx, ty, k)] = widenedBox(lo, hi);
            }
    });
    mLists.assignFromPairs(mBounds.size(), {});
}

int ClusterGrid::sliceOfDepth(float depthMetres) const {
    // The largest k in [0, slices) with b_k <= depth (0 when none): slice k holds [b_k, b_k+1).
    // Branch-free binary lifting (conditional moves): one call per pixel, and std::upper_bound's
    // unpredictable branches cost more than the shading of a few lights.
    const float* boundary = mSliceDepth.data();
    const int sliceCount = mOptions.slices;
    int slice = 0;
    for (int step = mSearchStep; step > 0; step >>= 1) {
        const int candidate = slice + step;
        slice = candidate < sliceCount && boundary[candidate] <= depthMetres ? candidate : slice;
    }
    return slice;
}

bool ClusterGrid::mayTouch(const LightSphere& sphere, int tileX, int tileY, int slice) const {
    if (sphere.unbounded)
        return true;
    if (!sphereTouchesBox(sphere, mBounds[clusterIndex(tileX, tileY, slice)]))
        return false;
    const float r = sphere.radius;
    if (mOptions.test == ClusterTest::Frustum) {
        // Signed distances to the side planes (positive to the right / below the edge).
        const glm::vec3& c = sphere.centreView;
        const float slack = r + boundSlackMetres(glm::length(c));
        if (mPlaneX[tileX].x * c.x + mPlaneX[tileX].y * c.z < -slack)
            return false;
        if (mPlaneX[tileX + 1].x * c.x + mPlaneX[tileX + 1].y * c.z > slack)
            return false;
        if (-mPlaneY[tileY].x * c.y + mPlaneY[tileY].y * c.z < -slack)
            return false;
        if (-mPlaneY[tileY + 1].x * c.y + mPlaneY[tileY + 1].y * c.z > slack)
            return false;
    }
    return true;
}

bool ClusterGrid::candidateRanges(const LightSphere& sphere, Range& columns, Range& rows,
                                  Range& slices) const {
    return candidateRanges(sphere, mOptions.assign, columns, rows, slices);
}

bool ClusterGrid::candidateRanges(const LightSphere& sphere, AssignMethod method, Range& columns,
                                  Range& rows, Range& slices) const {
    if (sphere.unbounded) {
        columns = {0, mOptions.tilesX - 1};
        rows = {0, mOptions.tilesY - 1};
        slices = {0, mOptions.slices - 1};
        return true;
    }
    const glm::vec3& c = sphere.centreView;
    const float r = sphere.radius;
    // The part of the sphere inside the grid's depth range, as a box [x] x [y] x [depthLo,
    // depthHi].
    const float depthLo = std::max(-c.z - r, mSliceDepth.front());
    const float depthHi = std::min(-c.z + r, mSliceDepth.back());
    if (!(depthLo <= depthHi))
        return false;
    // Over that box (depth > 0) x / depth is extreme at a corner.
    const float xLo = c.x - r, xHi = c.x + r, downLo = -c.y - r, downHi = -c.y + r;
    const float tanXLo = std::min(xLo / depthLo, xLo / depthHi),
                tanXHi = std::max(xHi / depthLo, xHi / depthHi);
    const float tanDownLo = std::min(downLo / depthLo, downLo / depthHi);
    const float tanDownHi = std::max(downHi / depthLo, downHi / depthHi);
    auto range = method == AssignMethod::Walk ? walkRange : binaryRange;
    // The ranges are exact frustum geometry (tighter than the AABBs, which overhang their tiles);
    // widened by the cluster slack so that rounding of reconstructed positions is covered too.
    const float absoluteSlack = 2.0f * kBoundSlackMetres / depthLo;
    const float tanSlack =
        2.0f * kBoundSlack * (1.0f + std::abs(tanXLo) + std::abs(tanXHi)) + absoluteSlack;
    const float downSlack =
        2.0f * kBoundSlack * (1.0f + std::abs(tanDownLo) + std::abs(tanDownHi)) + absoluteSlack;
    columns = range(mEdgeTanX, tanXLo - tanSlack, tanXHi + tanSlack);
    rows = range(mEdgeTanDownY, tanDownLo - downSlack, tanDownHi + downSlack);
    const float depthSlack = 2.0f * (kBoundSlack * depthHi + kBoundSlackMetres);
    slices = range(mSliceDepth, depthLo - depthSlack, depthHi + depthSlack);
    return !columns.empty() && !rows.empty() && !slices.empty();
}

void ClusterGrid::assign(const std::vector<LightSphere>& spheres) {
    if (mOptions.assign == AssignMethod::Bvh) {
        assignWithBvh(spheres);
        return;
    }
    const size_t batchCount = (spheres.size() + kLightsPerBatch - 1) / kLightsPerBatch;
    // Per batch: (cluster, light) pairs in light order.
    auto& batches = mBatchPairs;
    batches.resize(batchCount);
    tbb::parallel_for(size_t(0), batchCount, [&](size_t batch) {
        auto& pairs = batches[batch];
        pairs.clear();
        const size_t end = std::min(spheres.size(), (batch + 1) * kLightsPerBatch);
        for (size_t light = batch * kLightsPerBatch; light < end; ++light) {
            const LightSphere& sphere = spheres[light];
            Range columns, rows, slices;
            if (!candidateRanges(sphere, columns, rows, slices))
                continue;
            for (int k = slices.first; k <= slices.last; ++k)
                for (int ty = rows.first; ty <= rows.last; ++ty)
                    for (int tx = columns.first; tx <= columns.last; ++tx)
                        if (mayTouch(sphere, tx, ty, k))
                            pairs.emplace_back(uint32_t(clusterIndex(tx, ty, k)), uint32_t(light));
        }
    });
    // Stable counting sort by cluster, batches in order: each list comes out ascending.
    mLists.assignFromPairs(mBounds.size(), batches);
}

void ClusterGrid::assignWithBvh(const std::vector<LightSphere>& spheres) {
    mBvh.build(spheres);
    // Each light's candidate ranges, as walk and binary compute them (they agree).
    mLightRanges.resize(spheres.size());
    tbb::parallel_for(size_t(0), spheres.size(), [&](size_t light) {
        LightRanges& r = mLightRanges[light];
        if (!candidateRanges(spheres[light], AssignMethod::Binary, r.columns, r.rows, r.slices))
            r = {};
    });
    // One query per run of kSlicesPerQuery slices of one tile (the union of their cluster boxes:
    // it holds every light the cluster test keeps in any of them, as sphereTouchesBox only
    // shrinks the float distance as a box grows). Each light found goes to the clusters of the run
    // within its candidate ranges that the cluster test keeps, in the ascending order of the
    // query: each cluster's list is written by one task, ascending.
    const int nx = mOptions.tilesX, ny = mOptions.tilesY, nz = mOptions.slices;
    const int runs = (nz + kSlicesPerQuery - 1) / kSlicesPerQuery;
    mClusterLights.resize(mBounds.size());
    tbb::parallel_for(0, nx * ny * runs, [&](int query) {
        const int tx = query % nx, ty = query / nx % ny, run = query / (nx * ny);
        const int k0 = run * kSlicesPerQuery, k1 = std::min(k0 + kSlicesPerQuery, nz) - 1;
        ViewBox box = mBounds[clusterIndex(tx, ty, k0)];
        for (int k = k0; k <= k1; ++k) {
            const ViewBox& b = mBounds[clusterIndex(tx, ty, k)];
            box.lo = glm::min(box.lo, b.lo);
            box.hi = glm::max(box.hi, b.hi);
            mClusterLights[clusterIndex(tx, ty, k)].clear();
        }
        std::vector<uint32_t> found;
        mBvh.candidates(box, found);
        for (uint32_t light : found) {
            const LightRanges& r = mLightRanges[light];
            if (tx < r.columns.first || tx > r.columns.last || ty < r.rows.first ||
                ty > r.rows.last)
                continue;
            for (int k = std::max(k0, r.slices.first); k <= std::min(k1, r.slices.last); ++k)
                if (mayTouch(spheres[light], tx, ty, k))
                    mClusterLights[clusterIndex(tx, ty, k)].push_back(light);
        }
    });
    mLists.assign(mClusterLights);
}

} // namespace lighting
