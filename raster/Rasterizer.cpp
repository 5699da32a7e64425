// Triangle set-up and binning for the Rasterizer (see Rasterizer.h for the conventions).
#include "raster/Rasterizer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>

namespace raster {

namespace {

// A polygon vertex during clipping: clip position plus its weights of the original vertices.
struct ClipVertex {
    glm::vec4 clip;
    glm::vec3 barycentric;
};

// Clip planes as signed distances (inside >= 0): z >= 0, w - z >= 0, and the guard band.
constexpr int kClipPlaneCount = 6;

float planeDistance(int plane, const glm::vec4& c, float guardX, float guardY) {
    switch (plane) {
    case 0:
        return c.z;
    case 1:
        return c.w - c.z;
    case 2:
        return guardX * c.w - c.x;
    case 3:
        return guardX * c.w + c.x;
    case 4:
        return guardY * c.w - c.y;
    default:
        return guardY * c.w + c.y;
    }
}

bool isFinite(const glm::vec4& c) {
    return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(c.w);
}

// Sutherland-Hodgman against one plane. A triangle clipped by 6 planes has at most 9 vertices.
constexpr int kMaxPolygon = 3 + kClipPlaneCount;

int clipPolygon(const ClipVertex* in, int count, ClipVertex* out, int plane, float guardX,
                float guardY) {
    int outCount = 0;
    for (int i = 0; i < count; ++i) {
        const ClipVertex& a = in[i];
        const ClipVertex& b = in[(i + 1) % count];
        const float da = planeDistance(plane, a.clip, guardX, guardY);
        const float db = planeDistance(plane, b.clip, guardX, guardY);
        if (da >= 0.0f)
            out[outCount++] = a;
        if ((da >= 0.0f) != (db >= 0.0f)) {
            // Always interpolate from the inside vertex so that an edge shared by two
            // triangles is cut at exactly the same point whichever triangle clips it.
            const bool aInside = da >= 0.0f;
            const ClipVertex& from = aInside ? a : b;
            const ClipVertex& to = aInside ? b : a;
            const float dFrom = aInside ? da : db, dTo = aInside ? db : da;
            const float t = dFrom / (dFrom - dTo);
            out[outCount++] = {from.clip + (to.clip - from.clip) * t,
                               from.barycentric + (to.barycentric - from.barycentric) * t};
        }
    }
    return outCount;
}

} // namespace

std::span<const SampleOffset> standardSamplePattern(int samples) {
    // Direct3D's standard multisample patterns (D3D11_STANDARD_MULTISAMPLE_PATTERN), in 1/16
    // pixel from the centre, y down.
    static constexpr SampleOffset kOne[] = {{0, 0}};
    static constexpr SampleOffset kTwo[] = {{4, 4}, {-4, -4}};
    static constexpr SampleOffset kFour[] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
    static constexpr SampleOffset kEight[] = {{1, -3}, {-1, 3},  {5, 1}, {-3, -5},
                                              {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
    static constexpr SampleOffset kSixteen[] = {
        {1, 1},  {-1, -3}, {-3, 2},  {4, -1}, {-5, -2}, {2, 5},  {5, 3}, {3, -5},
        {-2, 6}, {0, -7},  {-4, -6}, {-6, 4}, {-8, 0},  {7, -4}, {6, 7}, {-7, -8}};
    switch (samples) {
    case 1:
        return kOne;
    case 2:
        return kTwo;
    case 4:
        return kFour;
    case 8:
        return kEight;
    case 16:
        return kSixteen;
    default:
        throw std::invalid_argument("no standard sample pattern of " + std::to_string(samples) +
                                    " samples (1, 2, 4, 8 or 16)");
    }
}

void Rasterizer::checkSampleCount(int samples) {
    if (!isRasterSampleCount(samples))
        throw std::invalid_argument("Rasterizer: " + std::to_string(samples) +
                                    " samples per pixel; supported: 1, 2, 4, 8");
}

Rasterizer::ProjectedVertex Rasterizer::project(const glm::vec4& clip) const {
    // After clipping, w = 0 is only possible at the clip-space origin (the eye of a zero-near
    // projection): a piece touching it is seen edge-on and covers nothing (invW = 0 marks it).
    if (!(clip.w > 0.0f))
        return {0, 0, 0.0f, 0};
    const float invW = 1.0f / clip.w;
    const float screenX = (clip.x * invW + 1.0f) * (0.5f * float(mWidth));
    const float screenY = (1.0f - clip.y * invW) * (0.5f * float(mHeight));
    return {int32_t(std::lrint(screenX * float(kSubpixelScale))),
            int32_t(std::lrint(screenY * float(kSubpixelScale))), invW, 0};
}

Rasterizer::Rasterizer(int width, int height) : mWidth(width), mHeight(height) {
    if (width <= 0 || height <= 0 || width > kMaxViewportSize || height > kMaxViewportSize)
        throw std::invalid_argument("Rasterizer: viewport " + std::to_string(width) + "x" +
                                    std::to_string(height) + " outside 1.." +
                                    std::to_string(kMaxViewportSize));
    mTilesX = (width + kTileSize - 1) / kTileSize;
    mTilesY = (height + kTileSize - 1) / kTileSize;
}

void Rasterizer::setUpAndBin(const TriangleList& triangles, const RasterState& state) {
    const uint32_t triangleCount = triangles.triangleCount();
    const uint32_t batchCount = (triangleCount + kTrianglesPerBatch - 1) / kTrianglesPerBatch;
    // Project and snap every vertex once: a vertex is shared by about six triangles. Vertices
    // outside the guard band are projected too (finite, unused: their triangles are clipped).
    using Clock = std::chrono::steady_clock;
    auto millisecondsSince = [](Clock::time_point start) {
        return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    };
    mPhaseTimes = RasterPhaseTimes{};
    auto start = Clock::now();
    const size_t vertexCount = triangles.clipPositions.size();
    mProjected.resize(vertexCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertexCount, 8192), [&](const auto& range) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
            const glm::vec4& c = triangles.clipPositions[v];
            const bool insideGuardBand =
                std::abs(c.x) <= kGuardBandPixels / (0.5f * float(mWidth)) * c.w &&
                std::abs(c.y) <= kGuardBandPixels / (0.5f * float(mHeight)) * c.w;
            ProjectedVertex projected =
                insideGuardBand ? project(c) : ProjectedVertex{0, 0, 0.0f, 0};
            projected.outcode = isFinite(c) ? frustumOutcode(c) : kNonFinite;
            mProjected[v] = projected;
        }
    });
    mPhaseTimes.projectMs = millisecondsSince(start);
    start = Clock::now();
    mBatches.resize(batchCount);
    tbb::parallel_for(uint32_t(0), batchCount, [&](uint32_t b) {
        const uint32_t first = b * kTrianglesPerBatch;
        const uint32_t last = std::min(first + kTrianglesPerBatch, triangleCount);
        setUpBatch(triangles, first, last, state, mBatches[b]);
    });
    const double batchesMs = millisecondsSince(start);
    double setupSeconds = 0.0, binSortSeconds = 0.0;
    for (const Batch& batch : mBatches) {
        setupSeconds += batch.setupSeconds;
        binSortSeconds += batch.binSortSeconds;
    }
    const double sortShare = setupSeconds + binSortSeconds > 0.0
                                 ? binSortSeconds / (setupSeconds + binSortSeconds)
                                 : 0.0;
    mPhaseTimes.binSortMs = batchesMs * sortShare;
    mPhaseTimes.setupMs = batchesMs - mPhaseTimes.binSortMs;
    mStats = RasterStats{};
    for (const Batch& batch : mBatches) {
        mStats.trianglesIn += batch.stats.trianglesIn;
        mStats.trianglesCulled += batch.stats.trianglesCulled;
        mStats.trianglesClipped += batch.stats.trianglesClipped;
        mStats.trianglesSetUp += batch.stats.trianglesSetUp;
    }
}

void Rasterizer::setUpBatch(const TriangleList& triangles, uint32_t first, uint32_t last,
                            const RasterState& state, Batch& batch) const {
    const auto setupStart = std::chrono::steady_clock::now();
    batch.triangles.clear();
    batch.triangles.reserve(last - first); // address space only; pages are touched on use
    batch.barycentrics.clear();
    if (state.barycentrics)
        batch.barycentrics.reserve(last - first);
    batch.clippedWeights.clear();
    batch.pairTile.clear();
    batch.pairTriangle.clear();
    batch.stats = RasterStats{};
    batch.stats.trianglesIn = last - first;

    const float guardX = kGuardBandPixels / (0.5f * float(mWidth));
    const float guardY = kGuardBandPixels / (0.5f * float(mHeight));
    // The planes of the triangles set up last, computed a packet at a time. Value-initialised
    // once per batch, so the vector lanes past a packet's count read zeros or an earlier
    // packet's values, never indeterminate memory.
    SetupPacket planes{};

    for (uint32_t t = first; t < last; ++t) {
        uint32_t index[3];
        ProjectedVertex projected[3];
        for (int i = 0; i < 3; ++i) {
            index[i] = triangles.indices[size_t(t) * 3 + i];
            projected[i] = mProjected[index[i]];
        }
        // Non-finite input has no meaningful coverage; reject it rather than draw garbage.
        // Trivial reject against the view frustum: all three vertices outside one plane.
        const uint8_t code0 = projected[0].outcode, code1 = projected[1].outcode,
                      code2 = projected[2].outcode;
        if (((code0 | code1 | code2) & kNonFinite) || (code0 & code1 & code2)) {
            ++batch.stats.trianglesCulled;
            continue;
        }
        const glm::vec4* const clipOfVertex[3] = {&triangles.clipPositions[index[0]],
                                                  &triangles.clipPositions[index[1]],
                                                  &triangles.clipPositions[index[2]]};
        // The clip volume contains the frustum: only a vertex outside the frustum can need
        // clipping, so the common case (all inside) skips the plane tests.
        bool needsClip = false;
        if (code0 | code1 | code2)
            for (int plane = 0; plane < kClipPlaneCount && !needsClip; ++plane)
                for (int i = 0; i < 3; ++i)
                    if (planeDistance(plane, *clipOfVertex[i], guardX, guardY) < 0.0f)
                        needsClip = true;

        if (!needsClip) {
            emitTriangle(clipOfVertex, projected, nullptr, t, state, planes, batch);
            continue;
        }
        ++batch.stats.trianglesClipped;
        ClipVertex polygon[2][kMaxPolygon];
        int count = 3;
        for (int i = 0; i < 3; ++i)
            polygon[0][i] = {*clipOfVertex[i], glm::vec3(i == 0, i == 1, i == 2)};
        int current = 0;
        for (int plane = 0; plane < kClipPlaneCount && count >= 3; ++plane) {
            count =
                clipPolygon(polygon[current], count, polygon[1 - current], plane, guardX, guardY);
            current = 1 - current;
        }
        // Fan-triangulate the convex result; every piece keeps the original triangle's id.
        for (int i = 1; i + 1 < count; ++i) {
            const ClipVertex& a = polygon[current][0];
            const ClipVertex& b = polygon[current][i];
            const ClipVertex& c = polygon[current][i + 1];
            const glm::vec4* const pieceClip[3] = {&a.clip, &b.clip, &c.clip};
            const glm::vec3 pieceBarycentric[3] = {a.barycentric, b.barycentric, c.barycentric};
            const ProjectedVertex pieceProjected[3] = {project(a.clip), project(b.clip),
                                                       project(c.clip)};
            emitTriangle(pieceClip, pieceProjected, pieceBarycentric, t, state, planes, batch);
        }
    }
    flushPending(planes, state, batch);
    // Counting sort of the (tile, triangle) pairs; stable, so each bin keeps submission order.
    const auto sortStart = std::chrono::steady_clock::now();
    batch.setupSeconds = std::chrono::duration<double>(sortStart - setupStart).count();
    const size_t tileCount = size_t(mTilesX) * mTilesY;
    batch.binOffsets.assign(tileCount + 1, 0);
    for (uint32_t tile : batch.pairTile)
        ++batch.binOffsets[tile + 1];
    for (size_t tile = 0; tile < tileCount; ++tile)
        batch.binOffsets[tile + 1] += batch.binOffsets[tile];
    batch.binItems.resize(batch.pairTile.size());
    for (size_t pair = 0; pair < batch.pairTile.size(); ++pair) {
        const uint32_t tile = batch.pairTile[pair];
        batch.binItems[batch.binOffsets[tile]++] = batch.pairTriangle[pair];
    }
    // The loop advanced every offset to its bin's end; shift back to starts.
    for (size_t tile = tileCount; tile > 0; --tile)
        batch.binOffsets[tile] = batch.binOffsets[tile - 1];
    batch.binOffsets[0] = 0;
    batch.binSortSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sortStart).count();
}

void Rasterizer::emitTriangle(const glm::vec4* const clip[3], const ProjectedVertex projected[3],
                              const glm::vec3 barycentric[3], uint32_t triangle,
                              const RasterState& state, SetupPacket& planes, Batch& batch) const {
    SetupTriangle s;
    float invW[3];
    for (int i = 0; i < 3; ++i) {
        if (projected[i].invW == 0.0f) {
            ++batch.stats.trianglesCulled;
            return;
        }
        s.x[i] = projected[i].x;
        s.y[i] = projected[i].y;
        invW[i] = projected[i].invW;
    }
    // Signed doubled area in fixed point; with y down, counter-clockwise in NDC is negative.
    const int64_t area =
        int64_t(s.x[1] - s.x[0]) * (s.y[2] - s.y[0]) - int64_t(s.y[1] - s.y[0]) * (s.x[2] - s.x[0]);
    if (area == 0) {
        ++batch.stats.trianglesCulled; // degenerate after snapping: covers nothing
        return;
    }
    s.frontFacing = area < 0;
    if ((state.cullMode == CullMode::Back && !s.frontFacing) ||
        (state.cullMode == CullMode::Front && s.frontFacing)) {
        ++batch.stats.trianglesCulled;
        return;
    }
    int order[3] = {0, 1, 2}; // which input vertex each set-up vertex is
    if (area < 0) {           // traversal wants positive area: swap vertices 1 and 2
        std::swap(s.x[1], s.x[2]);
        std::swap(s.y[1], s.y[2]);
        std::swap(invW[1], invW[2]);
        std::swap(order[1], order[2]);
    }
    // Pixel bounds: pixel p is sampled at p + 0.5 (plus a sample's offset when multisampling),
    // so the first candidate column is ceil(minX - 0.5 - largest offset) and the last
    // floor(maxX - 0.5 - smallest offset), in fixed point.
    const int32_t minXf = std::min({s.x[0], s.x[1], s.x[2]});
    const int32_t maxXf = std::max({s.x[0], s.x[1], s.x[2]});
    const int32_t minYf = std::min({s.y[0], s.y[1], s.y[2]});
    const int32_t maxYf = std::max({s.y[0], s.y[1], s.y[2]});
    int32_t offsetMinX = 0, offsetMaxX = 0, offsetMinY = 0, offsetMaxY = 0;
    for (const SampleOffset& o : standardSamplePattern(state.samples)) {
        constexpr int32_t kUnit = kSubpixelScale / 16;
        offsetMinX = std::min(offsetMinX, o.x * kUnit);
        offsetMaxX = std::max(offsetMaxX, o.x * kUnit);
        offsetMinY = std::min(offsetMinY, o.y * kUnit);
        offsetMaxY = std::max(offsetMaxY, o.y * kUnit);
    }
    constexpr int32_t kHalf = kSubpixelScale / 2;
    auto ceilDiv = [](int32_t a) { return -((-a) >> kSubpixelBits); }; // ceil(a / 256)
    const int minX = std::max(0, ceilDiv(minXf - kHalf - offsetMaxX));
    const int minY = std::max(0, ceilDiv(minYf - kHalf - offsetMaxY));
    const int maxX = std::min(mWidth - 1, (maxXf - kHalf - offsetMinX) >> kSubpixelBits);
    const int maxY = std::min(mHeight - 1, (maxYf - kHalf - offsetMinY) >> kSubpixelBits);
    if (minX > maxX || minY > maxY) {
        ++batch.stats.trianglesCulled; // between sample points or off screen
        return;
    }
    s.minX = int16_t(minX);
    s.minY = int16_t(minY);
    s.maxX = int16_t(maxX);
    s.maxY = int16_t(maxY);
    s.triangle = triangle;
    // The planes come from the unsnapped positions in double, computed only for triangles that
    // survived culling (most culled triangles are back faces), a packet at a time.
    const int lane = planes.count++;
    for (int i = 0; i < 3; ++i) {
        const glm::vec4& c = *clip[order[i]];
        planes.clipX[i][lane] = double(c.x);
        planes.clipY[i][lane] = double(c.y);
        planes.clipZ[i][lane] = double(c.z);
        planes.clipW[i][lane] = double(c.w);
        planes.snappedX[i][lane] = double(s.x[i]);
        planes.snappedY[i][lane] = double(s.y[i]);
    }
    planes.minX[lane] = double(s.minX);
    planes.minY[lane] = double(s.minY);
    // The triangle joins the batch now, in submission order; its planes are filled in by the
    // packet's flush.
    const uint32_t index = uint32_t(batch.triangles.size());
    batch.triangles.push_back(s);
    ++batch.stats.trianglesSetUp;
    if (state.barycentrics) {
        SetupBarycentrics& barycentrics = batch.barycentrics.emplace_back();
        for (int i = 0; i < 3; ++i)
            barycentrics.invW[i] = invW[i];
        barycentrics.swapped = order[1] == 2;
        barycentrics.clippedWeights = SetupBarycentrics::kNotClipped;
        if (barycentric) {
            barycentrics.clippedWeights = uint32_t(batch.clippedWeights.size());
            batch.clippedWeights.push_back(
                {barycentric[order[0]], barycentric[order[1]], barycentric[order[2]]});
        }
    }
    for (int ty = s.minY / kTileSize; ty <= s.maxY / kTileSize; ++ty)
        for (int tx = s.minX / kTileSize; tx <= s.maxX / kTileSize; ++tx)
            batch.pairTile.push_back(uint32_t(ty * mTilesX + tx)),
                batch.pairTriangle.push_back(index);
    if (planes.count == kSetupPacketSize)
        flushPending(planes, state, batch);
}

void Rasterizer::flushPending(SetupPacket& planes, const RasterState& state, Batch& batch) const {
    if (planes.count == 0)
        return;
    const SetupViewport viewport{mWidth, mHeight, state.barycentrics};
    if (state.scalarSetup)
        setUpPlanesScalar(planes, viewport);
    else
        setUpPlanes(planes, viewport);
    // The packet's lanes are the batch's last `count` triangles.
    const size_t first = batch.triangles.size() - size_t(planes.count);
    for (int lane = 0; lane < planes.count; ++lane) {
        SetupTriangle& s = batch.triangles[first + size_t(lane)];
        for (int k = 0; k < 3; ++k)
            s.z[k] = planes.z[k][lane];
        if (!state.barycentrics)
            continue;
        SetupBarycentrics& barycentrics = batch.barycentrics[first + size_t(lane)];
        for (int k = 0; k < 3; ++k) {
            barycentrics.l1[k] = planes.l1[k][lane];
            barycentrics.l2[k] = planes.l2[k][lane];
        }
    }
    planes.count = 0;
}

void Rasterizer::clearTile(int tileIndex, const RasterState& state, float* depth) const {
    const int minX = (tileIndex % mTilesX) * kTileSize;
    const int minY = (tileIndex / mTilesX) * kTileSize;
    const int maxX = std::min(minX + kTileSize, mWidth);
    const int maxY = std::min(minY + kTileSize, mHeight);
    const size_t samples = size_t(state.samples);
    for (int y = minY; y < maxY; ++y) {
        float* row = depth + (size_t(y) * size_t(mWidth) + size_t(minX)) * samples;
        std::fill(row, row + size_t(maxX - minX) * samples, *state.clearDepth);
    }
    if (state.alsoClearTile)
        state.alsoClearTile(minX, minY, maxX, maxY);
}

} // namespace raster
