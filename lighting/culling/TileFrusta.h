// TileFrusta: the screen-tile machinery of tiled light culling (tiled deferred, tiled forward):
// a grid of square screen tiles, per-tile surface bounds read from the G-buffer (view depth
// range, Harada's 2.5D depth mask, a normal cone), the tile's depth-bounded frustum in view
// space, and the conservative tests of a light's bounding sphere against them.
//
// Conventions: view space right-handed, camera at the origin looking down -Z; "depth" is the
// positive view distance -z in metres. Pixel (x, y) covers [x, x+1) x [y, y+1) in pixel units
// with y down; its sample is the pixel centre, as in CameraView::ndcOfPixel. Tile side planes
// pass through pixel EDGES, so every sample of a tile lies half a pixel inside them: float
// rounding of reconstructed positions (~1e-7 relative) never puts a sample outside its frustum.
// Depth bounds are the min/max of the decoded positions themselves (bitwise the ones shading
// uses), so samples lie inside them exactly.
//
// Every test here is conservative: it may keep a light that touches no sample, never the
// reverse. Spheres must be the widened ones of LightBounds.h. Thread safety: all functions are
// pure or write only their own outputs; computeTileSurfaceBounds runs in parallel over tiles.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/GBuffer.h"
#include "gbuffer/visibility/CameraView.h"
#include "lighting/culling/CullingTests.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightBvh.h"
#include "lighting/culling/LightIndexLists.h"

namespace lighting {

struct TileGrid {
    int widthPixels = 0;
    int heightPixels = 0;
    int tileSizePixels = 16;
    int tileCountX = 0;
    int tileCountY = 0;

    static TileGrid make(int widthPixels, int heightPixels, int tileSizePixels);
    int tileCount() const { return tileCountX * tileCountY; }
    // Pixel range [x0, x1) x [y0, y1) of a tile; edge tiles are clipped to the image.
    int x0(int tx) const { return tx * tileSizePixels; }
    int x1(int tx) const { return std::min((tx + 1) * tileSizePixels, widthPixels); }
    int y0(int ty) const { return ty * tileSizePixels; }
    int y1(int ty) const { return std::min((ty + 1) * tileSizePixels, heightPixels); }
};

// Per-tile surface bounds from the G-buffer's covered pixels.
struct TileSurfaceBounds {
    bool covered = false;        // false: no covered pixel, the tile gets no bounded light
    float minDepthMetres = 0.0f; // over covered pixels' decoded positions
    float maxDepthMetres = 0.0f;
    uint32_t depthMask = 0; // bit i: some sample in the i-th of 32 bins of [min, max]
    glm::vec3 normalAxisView{0.0f, 0.0f, 1.0f}; // unit; normalised sum of the unit normals
    float normalHalfAngle = 3.14159265f;        // radians; >= pi/2 means "faces everywhere"
};

struct TileBoundsOptions {
    bool depthMask = false;
    bool normalCone = false;
};

std::vector<TileSurfaceBounds> computeTileSurfaceBounds(const gbuffer::GBuffer& gb,
                                                        const TileGrid& grid,
                                                        const TileBoundsOptions& options);
// The bounds of the covered pixels of several G-buffers of one view (a multisampled frame's
// fragment layers above 0, lighting/passes/PackedFragments.h): each covered pixel of each is a
// sample of its tile, read as computeTileSurfaceBounds reads one G-buffer. A tile row none of
// them covers costs one vectorised test per G-buffer.
std::vector<TileSurfaceBounds>
computeTileSurfaceBounds(std::span<const gbuffer::GBuffer* const> layers, const TileGrid& grid,
                         const TileBoundsOptions& options);

// Depth bounds (and optionally the depth mask; no normal cone) from a depth plane in the view's
// convention, for stages without a G-buffer (tiled forward's depth pre-pass). A pixel is covered
// when its depth differs from the view's clear depth, as GBuffer::covered; positions come from
// `decoder` (the decoder of the layout the plane is in), so the same depth plane in a G-buffer
// of that layout gives bitwise computeTileSurfaceBounds' depth bounds. A plane of several
// samples per pixel (pixel-major, size a multiple of the grid's pixels: multisampled forward
// shading) bounds every covered sample, each at its pixel's centre ray.
std::vector<TileSurfaceBounds> computeTileDepthBounds(const gbuffer::DepthDecoder& decoder,
                                                      std::span<const float> depth,
                                                      const TileGrid& grid, bool depthMask);

// Harada's 2.5D culling: bin of a depth inside [minDepth, maxDepth] split into 32 bins. The
// same monotone float expression serves samples and light ranges, so a sample whose depth is
// inside a light's depth range always lands in one of the light's bins.
inline int depthBin(float depthMetres, float minDepthMetres, float binsPerMetre) {
    float t = (depthMetres - minDepthMetres) * binsPerMetre;
    t = std::min(std::max(t, 0.0f), 31.0f);
    return int(t);
}
inline float depthBinsPerMetre(float minDepthMetres, float maxDepthMetres) {
    const float span = maxDepthMetres - minDepthMetres;
    return span > 0.0f ? 32.0f / span : 0.0f;
}
inline uint32_t depthRangeMask(float lowMetres, float highMetres, float minDepthMetres,
                               float maxDepthMetres) {
    const float perMetre = depthBinsPerMetre(minDepthMetres, maxDepthMetres);
    const int first = depthBin(lowMetres, minDepthMetres, perMetre);
    const int last = depthBin(highMetres, minDepthMetres, perMetre);
    const uint32_t upToLast = last >= 31 ? 0xFFFFFFFFu : (2u << last) - 1u;
    return upToLast & ~((1u << first) - 1u);
}

// The planes through the eye along the tile grid's edges, shared by all tiles of a column or
// row: columnPlanes[i] contains the rays of pixel-edge column x = min(i * tile, width), with its
// unit normal pointing to increasing x; rowPlanes[j] likewise for y = min(j * tile, height),
// pointing to increasing y (down the image). Rays are view directions scaled to depth 1.
struct TileEdgePlanes {
    std::vector<glm::vec3> columnNormals; // tileCountX + 1
    std::vector<glm::vec3> rowNormals;    // tileCountY + 1
    std::vector<glm::vec3> cornerRays;    // (tileCountX + 1) * (tileCountY + 1), row-major

    static TileEdgePlanes make(const gbuffer::CameraView& view, const TileGrid& grid);
    const glm::vec3& cornerRay(const TileGrid& grid, int i, int j) const {
        return cornerRays[size_t(j) * (grid.tileCountX + 1) + i];
    }
};

// Does the sphere reach the wedge between column planes i0 and i1 (i0 < i1)? Conservative.
inline bool sphereInColumnSlab(const TileEdgePlanes& edges, int i0, int i1, const glm::vec3& c,
                               float r) {
    return glm::dot(edges.columnNormals[i0], c) >= -r &&
           -glm::dot(edges.columnNormals[i1], c) >= -r;
}
inline bool sphereInRowSlab(const TileEdgePlanes& edges, int j0, int j1, const glm::vec3& c,
                            float r) {
    return glm::dot(edges.rowNormals[j0], c) >= -r && -glm::dot(edges.rowNormals[j1], c) >= -r;
}

// The 8 corners of a tile's frustum between two depths, and their bounding box.
struct TileBox {
    glm::vec3 corners[8];
    glm::vec3 boxMin{0.0f};
    glm::vec3 boxMax{0.0f};
    glm::vec3 centre{0.0f}; // mean of the corners
};
TileBox tileBox(const TileEdgePlanes& edges, const TileGrid& grid, int tx, int ty,
                float minDepthMetres, float maxDepthMetres);

// A light that survived view-frustum culling, with the tile columns and rows its sphere may
// reach (empty when min > max): the cheap integer pre-test before per-tile tests.
struct CandidateLight {
    uint32_t index = 0;
    glm::vec3 centreView{0.0f};
    glm::vec3 positionView{0.0f}; // the emitter (LightSphere::positionView)
    float radius = 0.0f;
    bool unbounded = false;
    int columnMin = 0, columnMax = -1, rowMin = 0, rowMax = -1;
};

// The candidates in ascending light order: every light, or with `frustumCull` only those
// view-frustum culling keeps (ViewFrustum, CullingTests.h). Parallel over lights.
std::vector<CandidateLight> candidateLights(const gbuffer::CameraView& view, const TileGrid& grid,
                                            const TileEdgePlanes& edges,
                                            const std::vector<LightSphere>& spheres,
                                            bool frustumCull);

// Back-face test of the thesis (Ishmukhametov 2013, ch. 4) made exactly conservative. A light
// is a point source at its centre for the BRDF: radiance needs dot(n, centre - p) > 0. The
// directions from the centre to every point p of the tile's (convex) depth-bounded frustum lie
// within delta of the axis centre->box centre (a cone of half-angle < pi/2 is convex, so the
// corners bound the hull), every normal lies within alpha of the normal axis, so when
// angle(axis_n, axis_l) + alpha + delta + slack <= pi/2 every n has dot(n, p - centre) >= 0:
// the light faces the back of every sample. Returns true when the light can be rejected.
// Degenerate cases (centre in or on the box, delta >= pi/2, alpha >= pi/2) never reject.
inline constexpr float kBackfaceSlackRadians = 1e-3f; // >> float error of the angles (~1e-6)
// Cost: what the test needs of the tile alone is computed once per tile (BackfaceTileCone), and a
// tile whose normal cone is too wide to reject anything (alpha + slack >= pi/2) skips the test.
// Per (tile, light), the angle between the normal axis and the light's direction to the tile is
// compared first, as a cosine: when it exceeds pi/2 - alpha - slack, no delta >= 0 can make the
// test reject, so the light is kept after one square root and one dot product (every light in
// front of a wall, say) instead of the eight corner directions and two arc cosines; the margin of
// that comparison (kBackfaceEarlyOutMargin, >> the float error of sin and acos) makes it keep only
// lights the full test keeps too, so the lists are exactly those of the full test.
inline constexpr float kBackfaceEarlyOutMargin = 1e-5f;
struct BackfaceTileCone {
    bool enabled = false; // alpha + slack < pi/2: the test can reject some light
    glm::vec3 normalAxisView{0.0f, 0.0f, 1.0f};
    float normalHalfAngle = 0.0f;
    float minAxisCos = 1.0f; // sin(alpha + slack) - margin: a lower axis cosine never rejects
    glm::vec3 padMin{0.0f}, padMax{0.0f}; // the box grown by the "centre next to it" pad
};
BackfaceTileCone backfaceTileCone(const TileBox& box, const TileSurfaceBounds& bounds);
bool lightBackFacesTile(const TileBox& box, const BackfaceTileCone& cone,
                        const glm::vec3& lightCentreView);

// Which tests the tile lists use beyond the basic ones (tile-column/row slabs, depth range,
// sphere vs tile box): view-frustum culling first (ViewFrustum), Harada's 2.5D depth mask, the
// thesis' back-face normal-cone test (needs bounds computed with normalCone). And how a tile finds
// the lights to test (speed only: the lists are the same for every choice, tested):
//   assign   Loop: every candidate light against every tile (the cheap integer column/row test
//            first); Bvh: the tile's box queries a LightBvh over the spheres, and only the lights
//            it returns meet the per-tile test
//   hierarchical: coarse groups of kTileGroupTiles x kTileGroupTiles tiles get a list first (the
//            union of their covered tiles' boxes, depth ranges, columns and rows: tests that are
//            monotone in the bound, so a light a fine tile keeps is always in its group's list);
//            fine tiles then test only their group's list
enum class TileAssign { Loop, Bvh };
inline constexpr int kTileGroupTiles = 4; // 4x4 tiles: 64x64 pixels at the default tile size
struct TileCullOptions {
    bool frustumCull = false;
    bool depthMask = false;
    bool backface = false;
    TileAssign assign = TileAssign::Loop;
    bool hierarchical = false;
};

// The basic test of one bounded candidate against covered tile (tx, ty) with bounds `b` and
// frustum `box`: inside the tile's column/row range, the depth range, and the box
// (sphereTouchesBox). What appendTileLights tests before its optional ones, and the per-tile test
// of the z-binned masks (ZBins.h).
inline bool boundedCandidateTouchesTile(const CandidateLight& c, int tx, int ty,
                                        const TileSurfaceBounds& b, const TileBox& box) {
    if (tx < c.columnMin || tx > c.columnMax || ty < c.rowMin || ty > c.rowMax)
        return false;
    const float centreDepth = -c.centreView.z;
    const float low = centreDepth - c.radius, high = centreDepth + c.radius;
    if (high < b.minDepthMetres || low > b.maxDepthMetres)
        return false;
    return sphereTouchesBox(c.centreView, c.radius, box.boxMin, box.boxMax);
}

// The per-tile light test: appends to `list`, in the candidates' (ascending) order, every
// candidate that may touch covered tile (tx, ty) with bounds `b` and frustum `box`: unbounded
// lights always; bounded ones when inside the tile's column/row range, the depth range, and the
// box (sphereTouchesBox); with `depthMask` also Harada's 2.5D test, with `backface` the thesis'
// normal-cone test (lightBackFacesTile). Returns how many the back-face test rejected.
uint64_t appendTileLights(std::span<const CandidateLight> candidates, int tx, int ty,
                          const TileSurfaceBounds& b, const TileBox& box,
                          const TileCullOptions& options, std::vector<uint32_t>& list);

struct TileLightListStats {
    size_t lightsAfterVfc = 0;     // candidates (all lights without frustumCull)
    uint64_t backfaceRejected = 0; // (tile, light) pairs removed by the back-face test
};

// The one builder of per-tile light lists, used by `tiled`, `tiled-backface`, `tiled-forward`,
// `light-prepass`, `inferred` and the overflow path of `light-indexed`: one list per tile of
// `grid` (row-major), ascending light indices, empty for tiles without a covered sample.
// `bounds` must come from computeTileSurfaceBounds / computeTileDepthBounds with the depth mask
// and normal cone that `options` uses. Tiles (or tile groups) in parallel, each list written by
// one task, then concatenated in tile order: the lists never depend on the thread count. With
// assign = Bvh the hierarchy is built into `bvh` (storage reused across frames) or, when null,
// into a local one; the build is part of the call.
TileLightListStats buildTileLightLists(const gbuffer::CameraView& view, const TileGrid& grid,
                                       const std::vector<TileSurfaceBounds>& bounds,
                                       const std::vector<LightSphere>& spheres,
                                       const TileCullOptions& options, LightIndexLists& lists,
                                       LightBvh* bvh = nullptr);

} // namespace lighting
