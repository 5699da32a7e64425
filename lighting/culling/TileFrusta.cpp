#include "lighting/culling/TileFrusta.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace lighting {

TileGrid TileGrid::make(int widthPixels, int heightPixels, int tileSizePixels) {
    TileGrid grid;
    grid.widthPixels = widthPixels;
    grid.heightPixels = heightPixels;
    grid.tileSizePixels = tileSizePixels;
    grid.tileCountX = (widthPixels + tileSizePixels - 1) / tileSizePixels;
    grid.tileCountY = (heightPixels + tileSizePixels - 1) / tileSizePixels;
    return grid;
}

namespace {

// Whether some sample of the pixels [x0, x1) of the row starting at pixel `rowStart` of a
// pixel-major depth buffer (`samples` floats per pixel) differs from `clear`: one branch-free
// pass over contiguous floats (vectorised).
bool anyDepthOtherThan(std::span<const float> depth, size_t rowStart, int x0, int x1, int samples,
                       float clear) {
    const float* first = depth.data() + (rowStart + size_t(x0)) * size_t(samples);
    const size_t count = size_t(x1 - x0) * size_t(samples);
    bool any = false;
    for (size_t i = 0; i < count; ++i)
        any |= first[i] != clear;
    return any;
}

// The bounds of every tile from its samples. sampleAt(x, y, depthMetres, normalView) returns
// false for an uncovered pixel, else sets the sample's positive view depth and (read only when
// options.normalCone) its normal. Templated so the per-pixel call is inlined, not virtual.
// samplesPerPixel: sampleAt(x, y, s, ...) is called for s in [0, samplesPerPixel).
// anyCovered(y, x0, x1): whether some pixel of row y in [x0, x1) is covered, a cheap test that
// skips a row of a tile before any sample is read: an upper MSAA fragment layer's tiles are mostly
// empty, and its cost should follow its fragments, not the screen.
template <typename SampleAt, typename AnyCovered>
std::vector<TileSurfaceBounds>
boundsOfSamples(const TileGrid& grid, const TileBoundsOptions& options, const SampleAt& sampleAt,
                const AnyCovered& anyCovered, int samplesPerPixel = 1) {
    std::vector<TileSurfaceBounds> bounds(size_t(grid.tileCount()));
    const size_t maxSamples =
        size_t(grid.tileSizePixels) * grid.tileSizePixels * size_t(samplesPerPixel);
    tbb::parallel_for(
        tbb::blocked_range<int>(0, grid.tileCount()), [&](const tbb::blocked_range<int>& range) {
            // Per-task scratch: the second passes (mask, cone half-angle) need the bounds first.
            std::vector<float> depths;
            std::vector<glm::vec3> normals;
            depths.reserve(maxSamples);
            normals.reserve(maxSamples);
            for (int tile = range.begin(); tile != range.end(); ++tile) {
                const int tx = tile % grid.tileCountX, ty = tile / grid.tileCountX;
                TileSurfaceBounds& b = bounds[size_t(tile)];
                depths.clear();
                normals.clear();
                float minDepth = INFINITY, maxDepth = -INFINITY;
                glm::vec3 normalSum(0.0f);
                for (int y = grid.y0(ty); y < grid.y1(ty); ++y) {
                    if (!anyCovered(y, grid.x0(tx), grid.x1(tx)))
                        continue;
                    for (int x = grid.x0(tx); x < grid.x1(tx); ++x)
                        for (int s = 0; s < samplesPerPixel; ++s) {
                            float depth = 0.0f;
                            glm::vec3 normalView(0.0f);
                            if (!sampleAt(x, y, s, depth, normalView))
                                continue;
                            minDepth = std::min(minDepth, depth);
                            maxDepth = std::max(maxDepth, depth);
                            if (options.depthMask)
                                depths.push_back(depth);
                            if (options.normalCone) {
                                const float length = glm::length(normalView);
                                // A zero normal has no facing: the BRDF's sign test then never
                                // passes, but keep the tile's cone open rather than reason about
                                // it.
                                const glm::vec3 n =
                                    length > 0.0f ? normalView / length : glm::vec3(0.0f);
                                normals.push_back(n);
                                normalSum += n;
                            }
                        }
                }
                if (!(minDepth <= maxDepth))
                    continue; // no covered pixel
                b.covered = true;
                b.minDepthMetres = minDepth;
                b.maxDepthMetres = maxDepth;
                if (options.depthMask) {
                    const float perMetre = depthBinsPerMetre(minDepth, maxDepth);
                    uint32_t mask = 0;
                    for (float d : depths)
                        mask |= 1u << depthBin(d, minDepth, perMetre);
                    b.depthMask = mask;
                }
                if (options.normalCone) {
                    const float sumLength = glm::length(normalSum);
                    // Normals cancelling out (sum ~ 0) leave no meaningful axis: the cone stays
                    // open.
                    if (!(sumLength > 1e-3f * float(normals.size())))
                        continue;
                    const glm::vec3 axis = normalSum / sumLength;
                    float minDot = 1.0f;
                    for (const glm::vec3& n : normals)
                        minDot = std::min(minDot, glm::dot(axis, n));
                    b.normalAxisView = axis;
                    b.normalHalfAngle = std::acos(std::clamp(minDot, -1.0f, 1.0f));
                    if (std::find(normals.begin(), normals.end(), glm::vec3(0.0f)) != normals.end())
                        b.normalHalfAngle = 3.14159265f;
                }
            }
        });
    return bounds;
}

} // namespace

std::vector<TileSurfaceBounds> computeTileSurfaceBounds(const gbuffer::GBuffer& gb,
                                                        const TileGrid& grid,
                                                        const TileBoundsOptions& options) {
    // Without the normal cone only depth is read: from the depth plane, not a whole decoded
    // surface (which a visibility buffer would fetch from its triangle). Bitwise the same range.
    if (!options.normalCone)
        return computeTileDepthBounds(gb.depthDecoder(), gb.depth(), grid, options.depthMask);
    return boundsOfSamples(
        grid, options,
        [&gb](int x, int y, int, float& depthMetres, glm::vec3& normalView) {
            if (!gb.covered(size_t(y) * gb.width() + x))
                return false;
            const gbuffer::Surface s = gb.decode(x, y);
            depthMetres = -s.positionView.z;
            normalView = s.normalView;
            return true;
        },
        [&gb](int y, int x0, int x1) {
            const size_t row = size_t(y) * gb.width();
            bool any = false;
            for (int x = x0; x < x1; ++x)
                any |= gb.covered(row + size_t(x));
            return any;
        });
}

std::vector<TileSurfaceBounds>
computeTileSurfaceBounds(std::span<const gbuffer::GBuffer* const> layers, const TileGrid& grid,
                         const TileBoundsOptions& options) {
    return boundsOfSamples(
        grid, options,
        [&](int x, int y, int s, float& depthMetres, glm::vec3& normalView) {
            const gbuffer::GBuffer& gb = *layers[size_t(s)];
            const size_t pixel = size_t(y) * gb.width() + size_t(x);
            if (!gb.covered(pixel))
                return false;
            if (!options.normalCone) {
                depthMetres = gb.depthDecoder().viewDepthMetres(x, y, gb.depth()[pixel]);
                return true;
            }
            const gbuffer::Surface surface = gb.decode(x, y);
            depthMetres = -surface.positionView.z;
            normalView = surface.normalView;
            return true;
        },
        [&](int y, int x0, int x1) {
            bool any = false;
            for (const gbuffer::GBuffer* gb : layers)
                any |= anyDepthOtherThan(gb->depth(), size_t(y) * gb->width(), x0, x1, 1,
                                         gb->view().clearDepth());
            return any;
        },
        int(layers.size()));
}

std::vector<TileSurfaceBounds> computeTileDepthBounds(const gbuffer::DepthDecoder& decoder,
                                                      std::span<const float> depth,
                                                      const TileGrid& grid, bool depthMask) {
    const float clearDepth = decoder.view().clearDepth();
    const int samples = int(depth.size() / (size_t(grid.widthPixels) * size_t(grid.heightPixels)));
    return boundsOfSamples(
        grid, {depthMask, false},
        [&](int x, int y, int s, float& depthMetres, glm::vec3&) {
            const float d =
                depth[(size_t(y) * grid.widthPixels + size_t(x)) * size_t(samples) + size_t(s)];
            if (d == clearDepth)
                return false;
            depthMetres = decoder.viewDepthMetres(x, y, d);
            return true;
        },
        [&](int y, int x0, int x1) {
            return anyDepthOtherThan(depth, size_t(y) * grid.widthPixels, x0, x1, samples,
                                     clearDepth);
        },
        samples);
}

TileEdgePlanes TileEdgePlanes::make(const gbuffer::CameraView& view, const TileGrid& grid) {
    TileEdgePlanes edges;
    const int nx = grid.tileCountX + 1, ny = grid.tileCountY + 1;
    auto rayAt = [&](int px, int py) {
        const float ndcX = float(px) / float(grid.widthPixels) * 2.0f - 1.0f;
        const float ndcY = 1.0f - float(py) / float(grid.heightPixels) * 2.0f;
        const glm::vec4 p = view.viewFromClip * glm::vec4(ndcX, ndcY, 0.5f, 1.0f);
        const glm::vec3 pView = glm::vec3(p) / p.w;
        return pView / -pView.z;
    };
    edges.cornerRays.resize(size_t(nx) * ny);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
            edges.cornerRays[size_t(j) * nx + i] =
                rayAt(std::min(i * grid.tileSizePixels, grid.widthPixels),
                      std::min(j * grid.tileSizePixels, grid.heightPixels));
    // Each edge plane from the two image-border rays of its line; all rays of one pixel-edge
    // line lie in one plane through the eye (no skew in a pinhole projection).
    for (int i = 0; i < nx; ++i) {
        const int px = std::min(i * grid.tileSizePixels, grid.widthPixels);
        glm::vec3 n = glm::normalize(glm::cross(rayAt(px, 0), rayAt(px, grid.heightPixels)));
        if (n.x < 0.0f)
            n = -n;
        edges.columnNormals.push_back(n);
    }
    for (int j = 0; j < ny; ++j) {
        const int py = std::min(j * grid.tileSizePixels, grid.heightPixels);
        glm::vec3 n = glm::normalize(glm::cross(rayAt(0, py), rayAt(grid.widthPixels, py)));
        if (n.y > 0.0f)
            n = -n; // increasing pixel y = decreasing view y
        edges.rowNormals.push_back(n);
    }
    return edges;
}

TileBox tileBox(const TileEdgePlanes& edges, const TileGrid& grid, int tx, int ty,
                float minDepthMetres, float maxDepthMetres) {
    TileBox box;
    const glm::vec3 rays[4] = {edges.cornerRay(grid, tx, ty), edges.cornerRay(grid, tx + 1, ty),
                               edges.cornerRay(grid, tx, ty + 1),
                               edges.cornerRay(grid, tx + 1, ty + 1)};
    box.boxMin = glm::vec3(INFINITY);
    box.boxMax = glm::vec3(-INFINITY);
    glm::vec3 sum(0.0f);
    for (int k = 0; k < 8; ++k) {
        const glm::vec3 corner = rays[k & 3] * (k < 4 ? minDepthMetres : maxDepthMetres);
        box.corners[k] = corner;
        box.boxMin = glm::min(box.boxMin, corner);
        box.boxMax = glm::max(box.boxMax, corner);
        sum += corner;
    }
    box.centre = sum * 0.125f;
    return box;
}

BackfaceTileCone backfaceTileCone(const TileBox& box, const TileSurfaceBounds& bounds) {
    constexpr float kHalfPi = 1.57079632679f;
    BackfaceTileCone cone;
    cone.enabled = bounds.covered && bounds.normalHalfAngle + kBackfaceSlackRadians < kHalfPi;
    if (!cone.enabled)
        return cone;
    cone.normalAxisView = bounds.normalAxisView;
    cone.normalHalfAngle = bounds.normalHalfAngle;
    cone.minAxisCos =
        std::sin(bounds.normalHalfAngle + kBackfaceSlackRadians) - kBackfaceEarlyOutMargin;
    // Centre in or next to the box: some sample may surround it; delta is undefined or >= pi/2.
    const glm::vec3 pad = 1e-4f * (box.boxMax - box.boxMin) + glm::vec3(1e-5f);
    cone.padMin = box.boxMin - pad;
    cone.padMax = box.boxMax + pad;
    return cone;
}

bool lightBackFacesTile(const TileBox& box, const BackfaceTileCone& cone,
                        const glm::vec3& lightCentreView) {
    constexpr float kHalfPi = 1.57079632679f;
    if (!cone.enabled)
        return false;
    const glm::vec3 toCentre = box.centre - lightCentreView;
    const float centreDistance = glm::length(toCentre);
    if (!(centreDistance > 0.0f))
        return false;
    const glm::vec3 lightAxis = toCentre / centreDistance;
    const float axisCos = glm::dot(cone.normalAxisView, lightAxis);
    // The early-out (header): acos(axisCos) + alpha + slack > pi/2 already, whatever delta is.
    if (!(axisCos >= cone.minAxisCos))
        return false;
    if (sphereTouchesBox(lightCentreView, 0.0f, cone.padMin, cone.padMax))
        return false;
    float minCos = 1.0f;
    for (const glm::vec3& corner : box.corners) {
        const glm::vec3 toCorner = corner - lightCentreView;
        const float length = glm::length(toCorner);
        if (!(length > 0.0f))
            return false;
        minCos = std::min(minCos, glm::dot(lightAxis, toCorner) / length);
    }
    if (!(minCos > 0.0f))
        return false; // delta >= pi/2: the light cone is not convex
    const float delta = std::acos(std::min(minCos, 1.0f));
    // Angle between the normal axis and the direction light travels; the thesis' omega (to the
    // light) is pi minus this, and omega > pi/2 + alpha + delta is the same condition.
    const float axisAngle = std::acos(std::clamp(axisCos, -1.0f, 1.0f));
    return axisAngle + cone.normalHalfAngle + delta + kBackfaceSlackRadians <= kHalfPi;
}

namespace {

// One candidate: the light's sphere and the tile columns and rows whose slabs it reaches.
CandidateLight candidateOf(const TileGrid& grid, const TileEdgePlanes& edges, const LightSphere& s,
                           uint32_t index) {
    CandidateLight c;
    c.index = index;
    c.centreView = s.centreView;
    c.positionView = s.positionView;
    c.radius = s.radius;
    c.unbounded = s.unbounded;
    if (s.unbounded)
        return c;
    int columnMin = grid.tileCountX, columnMax = -1, rowMin = grid.tileCountY, rowMax = -1;
    for (int tx = 0; tx < grid.tileCountX; ++tx)
        if (sphereInColumnSlab(edges, tx, tx + 1, s.centreView, s.radius)) {
            columnMin = std::min(columnMin, tx);
            columnMax = tx;
        }
    for (int ty = 0; ty < grid.tileCountY; ++ty)
        if (sphereInRowSlab(edges, ty, ty + 1, s.centreView, s.radius)) {
            rowMin = std::min(rowMin, ty);
            rowMax = ty;
        }
    c.columnMin = columnMin;
    c.columnMax = columnMax;
    c.rowMin = rowMin;
    c.rowMax = rowMax;
    return c;
}

} // namespace

std::vector<CandidateLight> candidateLights(const gbuffer::CameraView& view, const TileGrid& grid,
                                            const TileEdgePlanes& edges,
                                            const std::vector<LightSphere>& spheres,
                                            bool frustumCull) {
    const std::vector<uint32_t> visible = ViewFrustum(view).visibleLights(spheres, frustumCull);
    std::vector<CandidateLight> candidates(visible.size());
    tbb::parallel_for(size_t(0), visible.size(), [&](size_t k) {
        candidates[k] = candidateOf(grid, edges, spheres[visible[k]], visible[k]);
    });
    return candidates;
}

uint64_t appendTileLights(std::span<const CandidateLight> candidates, int tx, int ty,
                          const TileSurfaceBounds& b, const TileBox& box,
                          const TileCullOptions& options, std::vector<uint32_t>& list) {
    uint64_t backfaceRejected = 0;
    const BackfaceTileCone cone = options.backface ? backfaceTileCone(box, b) : BackfaceTileCone{};
    for (const CandidateLight& c : candidates) {
        if (c.unbounded) {
            list.push_back(c.index);
            continue;
        }
        if (!boundedCandidateTouchesTile(c, tx, ty, b, box))
            continue;
        const float centreDepth = -c.centreView.z;
        if (options.depthMask && (depthRangeMask(centreDepth - c.radius, centreDepth + c.radius,
                                                 b.minDepthMetres, b.maxDepthMetres) &
                                  b.depthMask) == 0)
            continue;
        if (cone.enabled && lightBackFacesTile(box, cone, c.positionView)) {
            ++backfaceRejected;
            continue;
        }
        list.push_back(c.index);
    }
    return backfaceRejected;
}

namespace {

// A unit of the list build: one tile, or with `hierarchical` a group of kTileGroupTiles^2 tiles,
// bounded by the union of its covered tiles' bounds.
struct TileGroup {
    bool covered = false;
    int tx0 = 0, tx1 = -1, ty0 = 0, ty1 = -1; // inclusive tile ranges
    float minDepthMetres = INFINITY, maxDepthMetres = -INFINITY;
    ViewBox box{glm::vec3(INFINITY), glm::vec3(-INFINITY)};
};

// May the candidate pass appendTileLights' basic tests in some tile of the group? The tests are
// those of appendTileLights with the group's union bounds, each monotone in its bound (integer
// range overlap, depth interval, sphereTouchesBox: a larger box only shrinks the float distance),
// so every light a tile of the group keeps passes here.
bool mayTouchGroup(const CandidateLight& c, const TileGroup& g) {
    if (c.unbounded)
        return true;
    if (g.tx1 < c.columnMin || g.tx0 > c.columnMax || g.ty1 < c.rowMin || g.ty0 > c.rowMax)
        return false;
    const float centreDepth = -c.centreView.z;
    const float low = centreDepth - c.radius, high = centreDepth + c.radius;
    if (high < g.minDepthMetres || low > g.maxDepthMetres)
        return false;
    return sphereTouchesBox(c.centreView, c.radius, g.box.lo, g.box.hi);
}

} // namespace

TileLightListStats buildTileLightLists(const gbuffer::CameraView& view, const TileGrid& grid,
                                       const std::vector<TileSurfaceBounds>& bounds,
                                       const std::vector<LightSphere>& spheres,
                                       const TileCullOptions& options, LightIndexLists& lists,
                                       LightBvh* bvh) {
    const TileEdgePlanes edges = TileEdgePlanes::make(view, grid);
    const size_t tileCount = size_t(grid.tileCount());
    std::vector<std::vector<uint32_t>> tileLights(tileCount);
    std::vector<uint64_t> tileBackfaceRejected(tileCount, 0);
    TileLightListStats stats;

    if (options.assign == TileAssign::Loop && !options.hierarchical) {
        // Every candidate against every tile.
        const std::vector<CandidateLight> candidates =
            candidateLights(view, grid, edges, spheres, options.frustumCull);
        tbb::parallel_for(0, grid.tileCount(), [&](int tile) {
            const TileSurfaceBounds& b = bounds[size_t(tile)];
            if (!b.covered)
                return;
            const int tx = tile % grid.tileCountX, ty = tile / grid.tileCountX;
            const TileBox box = tileBox(edges, grid, tx, ty, b.minDepthMetres, b.maxDepthMetres);
            tileBackfaceRejected[size_t(tile)] =
                appendTileLights(candidates, tx, ty, b, box, options, tileLights[size_t(tile)]);
        });
        stats.lightsAfterVfc = candidates.size();
    } else {
        // Units (tiles or groups of tiles) and their bounds.
        const int groupTiles = options.hierarchical ? kTileGroupTiles : 1;
        const int groupsX = (grid.tileCountX + groupTiles - 1) / groupTiles;
        const int groupsY = (grid.tileCountY + groupTiles - 1) / groupTiles;
        const size_t groupCount = size_t(groupsX) * size_t(groupsY);
        std::vector<TileBox> boxes(tileCount);
        std::vector<TileGroup> groups(groupCount);
        tbb::parallel_for(size_t(0), groupCount, [&](size_t group) {
            TileGroup& g = groups[group];
            g.tx0 = int(group % size_t(groupsX)) * groupTiles;
            g.ty0 = int(group / size_t(groupsX)) * groupTiles;
            g.tx1 = std::min(g.tx0 + groupTiles, grid.tileCountX) - 1;
            g.ty1 = std::min(g.ty0 + groupTiles, grid.tileCountY) - 1;
            for (int ty = g.ty0; ty <= g.ty1; ++ty)
                for (int tx = g.tx0; tx <= g.tx1; ++tx) {
                    const size_t tile = size_t(ty) * size_t(grid.tileCountX) + size_t(tx);
                    const TileSurfaceBounds& b = bounds[tile];
                    if (!b.covered)
                        continue;
                    boxes[tile] = tileBox(edges, grid, tx, ty, b.minDepthMetres, b.maxDepthMetres);
                    g.covered = true;
                    g.minDepthMetres = std::min(g.minDepthMetres, b.minDepthMetres);
                    g.maxDepthMetres = std::max(g.maxDepthMetres, b.maxDepthMetres);
                    g.box.lo = glm::min(g.box.lo, boxes[tile].boxMin);
                    g.box.hi = glm::max(g.box.hi, boxes[tile].boxMax);
                }
        });

        // Each unit's candidates, ascending (what its fine tiles test), gathered by its own task
        // into per-thread scratch, then its tiles' lists: no per-frame storage per candidate.
        tbb::enumerable_thread_specific<std::vector<CandidateLight>> scratch;
        auto listTilesOf = [&](size_t group, std::span<const CandidateLight> unitCandidates) {
            const TileGroup& g = groups[group];
            for (int ty = g.ty0; ty <= g.ty1; ++ty)
                for (int tx = g.tx0; tx <= g.tx1; ++tx) {
                    const size_t tile = size_t(ty) * size_t(grid.tileCountX) + size_t(tx);
                    const TileSurfaceBounds& b = bounds[tile];
                    if (b.covered)
                        tileBackfaceRejected[tile] = appendTileLights(
                            unitCandidates, tx, ty, b, boxes[tile], options, tileLights[tile]);
                }
        };
        if (options.assign == TileAssign::Loop) {
            const std::vector<CandidateLight> candidates =
                candidateLights(view, grid, edges, spheres, options.frustumCull);
            stats.lightsAfterVfc = candidates.size();
            tbb::parallel_for(size_t(0), groupCount, [&](size_t group) {
                if (!groups[group].covered)
                    return;
                std::vector<CandidateLight>& unitCandidates = scratch.local();
                unitCandidates.clear();
                for (const CandidateLight& c : candidates)
                    if (mayTouchGroup(c, groups[group]))
                        unitCandidates.push_back(c);
                listTilesOf(group, unitCandidates);
            });
        } else {
            LightBvh localBvh;
            LightBvh& tree = bvh ? *bvh : localBvh;
            tree.build(spheres);
            // View-frustum culling as candidateLights does it, as a flag per light.
            const ViewFrustum frustum(view);
            std::vector<uint8_t> visible(spheres.size(), 1);
            if (options.frustumCull)
                tbb::parallel_for(size_t(0), spheres.size(), [&](size_t light) {
                    visible[light] = frustum.mayTouch(spheres[light]) ? 1 : 0;
                });
            stats.lightsAfterVfc = size_t(std::count(visible.begin(), visible.end(), uint8_t(1)));
            // The hierarchy's candidates of each unit's box (a superset of the lights whose
            // sphere touches any of its tiles' boxes), without the culled ones.
            std::vector<std::vector<uint32_t>> unitLights(groupCount);
            std::vector<uint8_t> needed(spheres.size(), 0);
            tbb::parallel_for(size_t(0), groupCount, [&](size_t group) {
                if (!groups[group].covered)
                    return;
                std::vector<uint32_t>& found = unitLights[group];
                tree.candidates(groups[group].box, found);
                std::erase_if(found, [&](uint32_t light) { return visible[light] == 0; });
                // Every writer stores the same value: the flags do not depend on the schedule.
                for (uint32_t light : found)
                    std::atomic_ref<uint8_t>(needed[light]).store(1, std::memory_order_relaxed);
            });
            // Column and row ranges only for lights some unit found (O(tile columns + rows)
            // each), in a compact array indexed through `slot`.
            std::vector<uint32_t> neededLights, slot(spheres.size(), 0);
            for (uint32_t light = 0; light < uint32_t(spheres.size()); ++light)
                if (needed[light]) {
                    slot[light] = uint32_t(neededLights.size());
                    neededLights.push_back(light);
                }
            std::vector<CandidateLight> records(neededLights.size());
            tbb::parallel_for(size_t(0), neededLights.size(), [&](size_t k) {
                records[k] = candidateOf(grid, edges, spheres[neededLights[k]], neededLights[k]);
            });
            tbb::parallel_for(size_t(0), groupCount, [&](size_t group) {
                if (!groups[group].covered)
                    return;
                std::vector<CandidateLight>& unitCandidates = scratch.local();
                unitCandidates.clear();
                for (uint32_t light : unitLights[group]) {
                    const CandidateLight& c = records[slot[light]];
                    if (!options.hierarchical || mayTouchGroup(c, groups[group]))
                        unitCandidates.push_back(c);
                }
                listTilesOf(group, unitCandidates);
            });
        }
    }
    lists.assign(tileLights);
    for (uint64_t rejected : tileBackfaceRejected)
        stats.backfaceRejected += rejected;
    return stats;
}

} // namespace lighting
