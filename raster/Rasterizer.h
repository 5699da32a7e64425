// Rasterizer: one generic, sort-middle triangle rasterizer, templated on the fragment function.
//
// Conventions (the contract every pass relies on):
// - Input is clip space (x, y, z, w) after the projection, OpenGL/glTF axes: x right, y up, and
//   depth in [0, w] (D3D/Vulkan "zero to one" clip volume: 0 <= z <= w). Whether z = 0 is the
//   near plane (standard) or the far plane (reversed Z) does not matter here: both planes are
//   clipped homogeneously, so w > 0 for every vertex that reaches set-up (a piece touching the
//   clip-space origin, w = 0, is edge-on and dropped). Triangles with a non-finite coordinate are
//   rejected.
// - Screen space: x right, y DOWN, pixel (px, py) covers [px, px+1) x [py, py+1) and is sampled at
//   its centre. Vertices are snapped to fixed point with 8 sub-pixel bits (kSubpixelBits).
// - Front faces are counter-clockwise in normalised device coordinates (glTF convention).
// - Fill rule: top-left. A pixel centre exactly on an edge belongs to the triangle only if the
//   edge is a top edge (horizontal, interior below) or a left edge; shared edges and vertices of a
//   watertight mesh are therefore covered exactly once.
// - Clipping: against z >= 0 and z <= w (near and far, whichever is which) and a guard band of
//   +-kGuardBandPixels around the screen centre; everything else is handled by the scissor of the
//   tile traversal. Triangles entirely outside one frustum plane are rejected before clipping.
// - Edge functions are evaluated in int64: snapped coordinates stay below 2^23 in magnitude
//   (guard band), differences below 2^24, products below 2^48.
//
// Threading and determinism: triangles are set up in fixed-size batches (kTrianglesPerBatch,
// independent of the thread count) in parallel with TBB, each batch binning its triangles into
// its own per-tile lists. Tiles are then rasterized in parallel; inside a tile, batches and
// triangles are visited in submission order. A pixel is only ever touched by the thread that owns
// its tile, so the result is bitwise identical for any thread count. Use tbb::task_arena to set
// the thread count.
//
// Multisampling (RasterState::samples = 2, 4 or 8): coverage and depth are evaluated at the
// standard Direct3D sample positions of each pixel (standardSamplePattern), each sample with the
// same exact fixed-point edge functions and top-left rule as a pixel centre, so shared edges stay
// watertight per sample. The depth buffer then holds one float per sample (pixel-major:
// depth[(y * width + x) * samples + s]) and the depth test runs per sample, against the
// triangle's depth plane at the sample. The fragment function is called ONCE per pixel and
// triangle, as hardware MSAA shades: Fragment::coverage has a bit per sample that is covered and
// passed the depth test, and Fragment::depth and the barycentrics are the pixel centre's (also
// when the centre itself is outside the triangle: attributes are extrapolated, as a GPU does
// without centroid sampling). The samples it keeps are written to the depth buffer afterwards.
//
// The fragment function is called as fn(const Fragment&) for every covered pixel (one sample
// per pixel without multisampling) that passes the (early) depth test; it may be called
// concurrently for different tiles and must only write data belonging to its own pixel. A fragment
// function that returns bool can discard the fragment (an alpha test): false means no depth write
// and no count in samplesPassed; one that returns SampleMask keeps only the samples of
// Fragment::coverage whose bits it returns (alpha-to-coverage, AlphaToCoverage.h: the other
// samples are neither depth-written nor counted; 0 discards the fragment); one that returns void
// keeps every fragment (the choice is made at compile time, so draws without a discard pay
// nothing for it). A Rasterizer object keeps scratch
// memory between draws: one draw at a time per object.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "raster/DepthSpan.h"
#include "raster/TriangleSetup.h"

namespace raster {

inline constexpr int kSubpixelBits = 8;
inline constexpr int32_t kSubpixelScale = 1 << kSubpixelBits;
// Half-extent of the guard band in pixels around the screen centre; keeps snapped coordinates
// below 2^23 (see the overflow bound above) for any viewport up to kMaxViewportSize.
inline constexpr float kGuardBandPixels = 16384.0f;
inline constexpr int kMaxViewportSize = 16384;
// Screen tiles: 128x128 pixels. Larger tiles mean fewer triangle-tile pairs to bin and visit
// (atrium at 1280x720, one core: raster phase ~0.6-1 ms faster than with 64x64) while 60 tiles
// still balance two threads; a tile's depth and ids (128 KB) stay in L2.
inline constexpr int kTileSize = 128;
// Input triangles per set-up batch: fixed so that binning order never depends on the threads.
inline constexpr uint32_t kTrianglesPerBatch = 2048;

// Multisampling: at most kMaxSamples (DepthSpan.h: 8) samples per pixel (Fragment::coverage is a
// byte).
// A sample position relative to the pixel centre in 1/16 pixel, screen axes (x right, y down).
struct SampleOffset {
    int8_t x, y;
};
// The standard Direct3D 10.1+ sample pattern of 1, 2, 4, 8 or 16 samples (16: for supersampled
// references; the rasterizer takes up to kMaxSamples). Throws std::invalid_argument otherwise.
std::span<const SampleOffset> standardSamplePattern(int samples);
// Whether `samples` is a sample count the rasterizer supports (1, 2, 4, 8).
inline bool isRasterSampleCount(int samples) {
    return samples == 1 || samples == 2 || samples == 4 || samples == 8;
}

enum class CullMode { None, Back, Front };

// Which frustum planes (x, y within +-w, 0 <= z <= w) a clip position is outside of, one bit
// each. The draw rejects a triangle whose three vertices share a bit (no pixel centre can be
// covered) before any other work; a caller may drop such triangles itself (the shadow maps'
// faces do) and get the same image. Comparisons with NaN are false: a non-finite position has
// no bit here (the draw rejects it on its own).
inline uint8_t frustumOutcode(const glm::vec4& c) {
    return uint8_t((c.x > c.w) | (c.x < -c.w) << 1 | (c.y > c.w) << 2 | (c.y < -c.w) << 3 |
                   (c.z < 0.0f) << 4 | (c.z > c.w) << 5);
}
// DepthTest: DepthSpan.h.

struct RasterState {
    CullMode cullMode = CullMode::Back;
    DepthTest depthTest = DepthTest::Less;
    bool depthWrite = true;
    // Compute Fragment::barycentric. Passes that find their attributes another way (from the
    // triangle id and the pixel centre) turn it off and save its set-up; it is then zero.
    bool barycentrics = true;
    // Samples per pixel: 1, 2, 4 or 8 (see the file comment on multisampling); the depth buffer
    // holds this many floats per pixel.
    int samples = 1;
    // When set, every tile first clears its own pixels (all their samples) of the depth buffer
    // to this value, in the task that then rasterizes it: the clear runs in parallel and leaves
    // the tile in cache for its triangles, where a clear before draw() streams the whole buffer
    // through memory once more (shadow maps: 96 faces of 1 MB per frame).
    std::optional<float> clearDepth;
    // With clearDepth, optional: one entry per tile (tileCountX() * tileCountY(), row-major) saying
    // whether the tile of the depth buffer may hold anything but clearDepth, kept by the caller
    // with its buffer (all 1 for a buffer of unknown content, all 0 for one filled with
    // clearDepth). A tile marked 0 that no triangle is binned to is then left as it is instead of
    // being cleared again, and each entry is rewritten to whether triangles were binned to its
    // tile. The depth buffer is bitwise the one a full clear gives; the saving is the clear of
    // empty tiles (shadow maps: about two thirds of the atrium's cube-face tiles hold no caster).
    // The span's elements are written even though the state is const: it is the buffer's record,
    // not a setting.
    std::span<uint8_t> tilesNotClear;
    // With clearDepth, optional: the caller's own per-pixel buffers cleared with each tile's depth,
    // in the same task, so that they too are in cache when the tile is drawn (the visibility
    // draw's codes). Called as alsoClearTile(x0, y0, x1, y1), the tile's pixels [x0, x1) x
    // [y0, y1) with every sample; tiles run in parallel, each called once, before its triangles.
    std::function<void(int, int, int, int)> alsoClearTile;
    // The oracle of the tests: when set, the one-sample traversal edge-tests every pixel of the
    // triangle's bounding box in turn (no per-row span by division, no hierarchical depth, no
    // depth-only span loop). The output is bitwise the same, fragments in the same order and
    // the same statistics; only slower.
    bool referenceTraversal = false;
    // The oracle of the set-up: when set, the depth and barycentric planes are computed one
    // triangle at a time (setUpPlanesScalar, TriangleSetup.h) instead of on SIMD lanes. The
    // planes, and so everything drawn, are bitwise the same; only slower.
    bool scalarSetup = false;
};

// Triangles as indexed clip-space vertices; triangle t uses indices[3t .. 3t+2].
struct TriangleList {
    std::span<const glm::vec4> clipPositions;
    std::span<const uint32_t> indices;
    uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
};

struct Fragment {
    int x = 0;
    int y = 0;
    float depth = 0.0f; // z / w, interpolated linearly in screen space, in [0, 1]
    // Perspective-correct weights of the ORIGINAL triangle's three vertices (also after
    // clipping), so varyings are interpolated with interpolate(a, b, c, fragment.barycentric).
    glm::vec3 barycentric{0.0f};
    uint32_t triangle = 0; // index into the TriangleList
    bool frontFacing = true;
    // Multisampling: bit s set when sample s (standardSamplePattern) is covered and passed the
    // depth test; 1 without multisampling.
    uint8_t coverage = 1;
};

// The fragment function of a depth-only draw (shadow maps, depth pre-passes): draw() given it
// takes the depth-only path, which finds each row's span of covered pixels from the three edge
// functions at once (the same integer tests, so exactly the pixels the generic path covers) and
// runs the depth test and write over the span in a loop without a fragment, with the same depth
// values bitwise. Without multisampling only (a multisampled draw calls it per fragment).
struct DepthOnly {
    void operator()(const Fragment&) const {}
};

// The fragment function of a visibility draw: each passing pixel records its triangle,
// `ids[y * width + x] = triangle | (frontFacing ? 0 : backFaceBit)`. draw() given it takes the
// depth-only path's spans and writes the ids in the same vector loop (DepthSpan.h) when a depth
// buffer is given; otherwise it is called per fragment. Multisampled (`samples` > 1, equal to
// RasterState::samples), ids hold `samples` entries per pixel and each passing sample gets its
// fragment's id and, when `centreDepths` is set (indexed as ids), the fragment's centre depth;
// with a depth buffer each row of a triangle takes DepthSpan.h's multisampled loop.
struct TriangleIds {
    uint32_t* ids = nullptr;
    size_t width = 0;
    uint32_t backFaceBit = 0;
    int samples = 1;
    float* centreDepths = nullptr; // multisampled only
    constexpr uint32_t idOf(uint32_t triangle, bool frontFacing) const {
        return triangle | (frontFacing ? 0u : backFaceBit);
    }
    [[gnu::always_inline]] void operator()(const Fragment& fragment) const {
        const size_t pixel = size_t(fragment.y) * width + size_t(fragment.x);
        const uint32_t id = idOf(fragment.triangle, fragment.frontFacing);
        if (samples == 1) {
            ids[pixel] = id;
            return;
        }
        const size_t first = pixel * size_t(samples);
        for (int s = 0; s < samples; ++s)
            if (fragment.coverage >> s & 1u) {
                ids[first + size_t(s)] = id;
                if (centreDepths)
                    centreDepths[first + size_t(s)] = fragment.depth;
            }
    }
};

// What a fragment function returns to keep a subset of its samples (see the file comment): the
// kept samples are `bits & Fragment::coverage`. Without multisampling, bit 0 keeps the fragment.
struct SampleMask {
    uint8_t bits = 0;
};

template <class T>
inline T interpolate(const T& a, const T& b, const T& c, const glm::vec3& weights) {
    return a * weights.x + b * weights.y + c * weights.z;
}

struct RasterStats {
    uint64_t trianglesIn = 0;
    uint64_t trianglesCulled = 0;  // back/front-face or degenerate
    uint64_t trianglesClipped = 0; // needed polygon clipping
    uint64_t trianglesSetUp = 0;   // after clipping (a clipped triangle can become several)
    uint64_t samplesCovered = 0;   // samples (pixels without multisampling) inside a triangle
    uint64_t samplesPassed = 0;    // passed the depth test and was not discarded
    uint64_t fragments = 0;        // fragment-function calls that kept their fragment
};

// Where a draw's time goes (issue 31's breakdown), wall-clock milliseconds of its phases in the
// order they run. Each phase is parallel inside and the phases are separated by a join (the
// traversal needs every batch's bins): the serial part of a draw is only those joins and the
// fixed-order sums of the statistics. Set-up and bin sorting run in the same parallel loop (one
// task per batch); their wall time is split in proportion to the thread time each took there.
struct RasterPhaseTimes {
    double projectMs = 0.0;   // vertices to fixed point, guard band and frustum outcodes
    double setupMs = 0.0;     // cull, clip, snap, edge and barycentric set-up, tile overlap
    double binSortMs = 0.0;   // counting sort of (tile, triangle) pairs into each batch's bins
    double traversalMs = 0.0; // tiles: coverage, depth test, fragment function, depth writes
    double totalMs() const { return projectMs + setupMs + binSortMs + traversalMs; }
};

// A triangle after clipping, snapping and orientation fix-up, as the traversal reads it for
// every tile it is binned into: one cache line. Set-up writes these for every surviving
// triangle and the traversal reads them back in tile order, so on a dense scene the stream does
// not fit in cache and its size is what both phases pay for: with the barycentric set-up inline
// (104 bytes, two or three lines) the G-buffer pass of atrium rasterized ~1 ms slower on one core.
//
// Depth is an affine function of the pixel index, set up in double from the UNSNAPPED vertex
// positions: snapping may shift a triangle by up to 1/512 pixel, which on a grazing surface
// moves the reconstructed position by ~1e-4 relative (measured on a tilted plane); coverage uses
// the snapped edges, attributes do not inherit their error.
// z(px, py) = z[0] + z[1] px + z[2] py (pixel centres folded in). Positive area in the
// edge-function convention used by the traversal.
struct alignas(64) SetupTriangle {
    double z[3];
    int32_t x[3], y[3];             // fixed point, kSubpixelBits fraction bits
    int16_t minX, minY, maxX, maxY; // inclusive pixel bounds, clamped to the viewport
    uint32_t triangle;
    bool frontFacing;
};
static_assert(sizeof(SetupTriangle) == 64, "the traversal reads one cache line per triangle");

// The set-up of Fragment::barycentric, beside SetupTriangle (same index), written only when
// RasterState::barycentrics is set. Screen-space barycentrics l1, l2 are float, relative to the
// triangle's bounding-box corner to keep their magnitudes small:
// l(px, py) = l[0] + l[1] (px - minX) + l[2] (py - minY), from the same unsnapped positions as
// depth; with invW they give the perspective-correct weights.
struct SetupBarycentrics {
    static constexpr uint32_t kNotClipped = UINT32_MAX;

    float l1[3];
    float l2[3];
    float invW[3];
    // Index into Batch::clippedWeights (vertex i as weights of the original triangle's
    // vertices), or kNotClipped: vertex i is original vertex i (1 and 2 swapped if `swapped`).
    uint32_t clippedWeights;
    bool swapped;
};
static_assert(kMaxViewportSize <= INT16_MAX, "pixel bounds are stored as int16_t");

class Rasterizer {
public:
    Rasterizer(int width, int height);

    int width() const { return mWidth; }
    int height() const { return mHeight; }

    // Rasterizes every triangle; depth (width*height*state.samples floats, row 0 = top) may be
    // null for no depth test. Throws std::invalid_argument for an unsupported sample count or a
    // state.tilesNotClear of the wrong size. Cost:
    // set-up O(triangles), traversal O(covered bounding-box pixels).
    template <class FragmentFn>
    void draw(const TriangleList& triangles, const RasterState& state, float* depth,
              FragmentFn&& fragmentFn);

    const RasterStats& lastStats() const { return mStats; }
    const RasterPhaseTimes& lastPhaseTimes() const { return mPhaseTimes; }
    int tileCountX() const { return mTilesX; }
    int tileCountY() const { return mTilesY; }
    // The screen tile of pixel (x, y): draw() calls the fragment function for one tile's pixels
    // from one task at a time, in submission order, so state kept per tile needs no lock.
    int tileOf(int x, int y) const { return (y / kTileSize) * mTilesX + x / kTileSize; }

private:
    // Cache-line aligned: neighbouring batches are set up by different threads, and their
    // vector ends and counters would otherwise share lines (false sharing measured as a 2-thread
    // slowdown).
    struct alignas(64) Batch {
        std::vector<SetupTriangle> triangles;
        std::vector<SetupBarycentrics> barycentrics; // empty unless RasterState::barycentrics
        std::vector<std::array<glm::vec3, 3>> clippedWeights;
        // Bins as one compressed table: the triangles (indices into `triangles`, in submission
        // order) of tile t are binItems[binOffsets[t] .. binOffsets[t+1]). Built by a counting
        // sort of (tile, triangle) pairs, so steady-state frames allocate nothing.
        std::vector<uint32_t> pairTile;
        std::vector<uint32_t> pairTriangle;
        std::vector<uint32_t> binOffsets;
        std::vector<uint32_t> binItems;
        RasterStats stats;
        double setupSeconds = 0.0, binSortSeconds = 0.0; // thread time of setUpBatch's two parts
    };

    static void checkSampleCount(int samples);
    // Sets the depth of every sample of tile `tileIndex`'s pixels to state.clearDepth, then calls
    // state.alsoClearTile on them.
    void clearTile(int tileIndex, const RasterState& state, float* depth) const;
    // Clip, cull, snap and bin all triangles into mBatches (parallel, deterministic).
    void setUpAndBin(const TriangleList& triangles, const RasterState& state);
    void setUpBatch(const TriangleList& triangles, uint32_t first, uint32_t last,
                    const RasterState& state, Batch& batch) const;
    // A vertex snapped to fixed point; invW == 0 marks one that must not be set up (w <= 0).
    // `outcode` (computed once per vertex, read by each of its ~6 triangles) has one bit per
    // frustum plane the clip position lies outside of, and kNonFinite for NaN/Inf input.
    struct ProjectedVertex {
        int32_t x, y;
        float invW;
        uint8_t outcode;
    };
    static constexpr uint8_t kNonFinite = 1u << 6;
    ProjectedVertex project(const glm::vec4& clip) const;
    // `barycentric` (weights of the original vertices) is null for an unclipped triangle.
    // `clip` points at the three clip positions; they are read only for triangles that survive
    // culling (most culled ones are back faces, decided from `projected` alone). A surviving
    // triangle is appended to the batch with its (tile, triangle) pairs, and its plane inputs to
    // `planes`, which is flushed when full: the integer set-up (cull, orientation, pixel bounds)
    // runs one triangle at a time, the planes a packet at a time (TriangleSetup.h).
    void emitTriangle(const glm::vec4* const clip[3], const ProjectedVertex projected[3],
                      const glm::vec3 barycentric[3], uint32_t triangle, const RasterState& state,
                      SetupPacket& planes, Batch& batch) const;
    // Computes the planes of the packet's triangles, the batch's last planes.count ones, and
    // writes them into their SetupTriangle and SetupBarycentrics.
    void flushPending(SetupPacket& planes, const RasterState& state, Batch& batch) const;

    // The depth test is a template parameter so that the per-sample comparison is one
    // instruction, not a switch (draw() dispatches once per tile).
    // Perspective-correct weights of the original vertices at pixel (px, py) of set-up triangle
    // `index` (`t`) of `batch`.
    static glm::vec3 barycentricAt(const Batch& batch, uint32_t index, const SetupTriangle& t,
                                   int px, int py);

    template <DepthTest kDepthTest, class FragmentFn>
    void rasterizeTile(int tileIndex, const RasterState& state, float* depth,
                       FragmentFn& fragmentFn, RasterStats& tileStats) const;
    // The same with state.samples > 1 (a separate loop: the one-sample path finds each row's
    // span by division, detail::coveredSpan, which per-sample coverage cannot use as it is).
    template <DepthTest kDepthTest, class FragmentFn>
    void rasterizeTileMultisample(int tileIndex, const RasterState& state, float* depth,
                                  FragmentFn& fragmentFn, RasterStats& tileStats) const;

    int mWidth;
    int mHeight;
    int mTilesX;
    int mTilesY;
    std::vector<ProjectedVertex> mProjected; // per input vertex, for unclipped triangles
    std::vector<Batch> mBatches;
    struct alignas(64) TileStats {
        RasterStats stats;
    };
    std::vector<TileStats> mTileStats;
    RasterStats mStats;
    RasterPhaseTimes mPhaseTimes;
};

// ---------------------------------------------------------------------------------------------
// Template implementation: the per-tile traversal is inlined with the fragment function.

namespace detail {
// Whether a discarding fragment function's result keeps the (one-sample) fragment.
inline bool keepsAny(bool kept) {
    return kept;
}
inline bool keepsAny(SampleMask mask) {
    return (mask.bits & 1u) != 0;
}

// Top-left rule as a bias: with our orientation (positive area, y down), an edge a->b is a
// left edge when dy < 0 and a top edge when dy == 0 and dx > 0. Samples exactly on any other
// edge are excluded by requiring edge >= 1 there.
inline int64_t fillBias(int32_t ax, int32_t ay, int32_t bx, int32_t by) {
    int32_t dx = bx - ax, dy = by - ay;
    bool topLeft = dy < 0 || (dy == 0 && dx > 0);
    return topLeft ? 0 : -1;
}

} // namespace detail

template <class FragmentFn>
void Rasterizer::draw(const TriangleList& triangles, const RasterState& state, float* depth,
                      FragmentFn&& fragmentFn) {
    checkSampleCount(state.samples);
    if constexpr (std::is_same_v<std::remove_cvref_t<FragmentFn>, TriangleIds>)
        if (fragmentFn.samples != state.samples)
            throw std::invalid_argument("TriangleIds holds " + std::to_string(fragmentFn.samples) +
                                        " samples per pixel, the draw " +
                                        std::to_string(state.samples));
    setUpAndBin(triangles, state);
    const auto traversalStart = std::chrono::steady_clock::now();
    const int tileCount = mTilesX * mTilesY;
    mTileStats.assign(size_t(tileCount), TileStats{});
    const bool trackClearTiles = depth && state.clearDepth && !state.tilesNotClear.empty();
    if (trackClearTiles && state.tilesNotClear.size() != size_t(tileCount))
        throw std::invalid_argument("RasterState::tilesNotClear holds " +
                                    std::to_string(state.tilesNotClear.size()) + " entries for " +
                                    std::to_string(tileCount) + " tiles");
    auto rasterize = [&](int tile) {
        if (trackClearTiles) {
            bool binned = false;
            for (const Batch& batch : mBatches)
                binned |= batch.binOffsets[size_t(tile) + 1] > batch.binOffsets[size_t(tile)];
            uint8_t& notClear = state.tilesNotClear[size_t(tile)];
            if (binned || notClear)
                clearTile(tile, state, depth);
            notClear = binned ? 1 : 0;
            if (!binned)
                return; // nothing to draw; its statistics stay zero
        } else if (depth && state.clearDepth) {
            clearTile(tile, state, depth);
        }
        RasterStats& stats = mTileStats[size_t(tile)].stats;
        const bool multisample = state.samples > 1;
        switch (state.depthTest) {
        case DepthTest::Always:
            if (multisample)
                rasterizeTileMultisample<DepthTest::Always>(tile, state, depth, fragmentFn, stats);
            else
                rasterizeTile<DepthTest::Always>(tile, state, depth, fragmentFn, stats);
            break;
        case DepthTest::Less:
            if (multisample)
                rasterizeTileMultisample<DepthTest::Less>(tile, state, depth, fragmentFn, stats);
            else
                rasterizeTile<DepthTest::Less>(tile, state, depth, fragmentFn, stats);
            break;
        case DepthTest::LessEqual:
            if (multisample)
                rasterizeTileMultisample<DepthTest::LessEqual>(tile, state, depth, fragmentFn,
                                                               stats);
            else
                rasterizeTile<DepthTest::LessEqual>(tile, state, depth, fragmentFn, stats);
            break;
        case DepthTest::Greater:
            if (multisample)
                rasterizeTileMultisample<DepthTest::Greater>(tile, state, depth, fragmentFn, stats);
            else
                rasterizeTile<DepthTest::Greater>(tile, state, depth, fragmentFn, stats);
            break;
        case DepthTest::GreaterEqual:
            if (multisample)
                rasterizeTileMultisample<DepthTest::GreaterEqual>(tile, state, depth, fragmentFn,
                                                                  stats);
            else
                rasterizeTile<DepthTest::GreaterEqual>(tile, state, depth, fragmentFn, stats);
            break;
        }
    };
    // One task per tile: tiles differ in cost by orders of magnitude (sky against the nave) and
    // there are only tens of them, so ranges of tiles could leave a thread waiting behind the
    // other's expensive range (atrium, 2 threads: 1.9-2.0x faster than 1 with this).
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tileCount, 1),
        [&](const tbb::blocked_range<int>& tiles) {
            for (int tile = tiles.begin(); tile != tiles.end(); ++tile)
                rasterize(tile);
        },
        tbb::simple_partitioner());
    mPhaseTimes.traversalMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - traversalStart)
            .count();
    // Sum in a fixed order so the statistics are as deterministic as the pixels.
    for (const TileStats& tile : mTileStats) {
        mStats.samplesCovered += tile.stats.samplesCovered;
        mStats.samplesPassed += tile.stats.samplesPassed;
        mStats.fragments += tile.stats.fragments;
    }
}

inline glm::vec3 Rasterizer::barycentricAt(const Batch& batch, uint32_t index,
                                           const SetupTriangle& t, int px, int py) {
    const SetupBarycentrics& s = batch.barycentrics[index];
    const float dx = float(px - t.minX), dy = float(py - t.minY);
    const float l1 = s.l1[0] + s.l1[1] * dx + s.l1[2] * dy;
    const float l2 = s.l2[0] + s.l2[1] * dx + s.l2[2] * dy;
    const float q0 = (1.0f - l1 - l2) * s.invW[0], q1 = l1 * s.invW[1], q2 = l2 * s.invW[2];
    const float invSum = 1.0f / (q0 + q1 + q2);
    const glm::vec3 b(q0 * invSum, q1 * invSum, q2 * invSum);
    // Map back to the original vertices (set-up may have clipped the triangle or swapped two
    // vertices to fix the orientation).
    if (s.clippedWeights == SetupBarycentrics::kNotClipped)
        return s.swapped ? glm::vec3(b.x, b.z, b.y) : b;
    const auto& w = batch.clippedWeights[s.clippedWeights];
    return w[0] * b.x + w[1] * b.y + w[2] * b.z;
}

template <DepthTest kDepthTest, class FragmentFn>
void Rasterizer::rasterizeTile(int tileIndex, const RasterState& state, float* depth,
                               FragmentFn& fragmentFn, RasterStats& tileStats) const {
    const int tileMinX = (tileIndex % mTilesX) * kTileSize;
    const int tileMinY = (tileIndex / mTilesX) * kTileSize;
    const int tileMaxX = std::min(tileMinX + kTileSize, mWidth) - 1;
    const int tileMaxY = std::min(tileMinY + kTileSize, mHeight) - 1;
    constexpr int64_t kHalf = kSubpixelScale / 2;
    using Result = std::invoke_result_t<FragmentFn&, const Fragment&>;
    constexpr bool kCanDiscard = std::is_same_v<Result, bool> || std::is_same_v<Result, SampleMask>;
    constexpr bool kDepthOnly = std::is_same_v<std::remove_cvref_t<FragmentFn>, DepthOnly>;
    // Every depth-only span, however short, runs the vector loop (DepthSpan.h): chosen once here,
    // its masked tail costs less than the scalar loop inline even for a pixel or two.
    constexpr bool kTriangleIds = std::is_same_v<std::remove_cvref_t<FragmentFn>, TriangleIds>;
    DepthSpanLoop spanLoop = nullptr;
    if constexpr (kDepthOnly || kTriangleIds)
        spanLoop = depthSpanLoop(kDepthTest, kTriangleIds);

    // Counted in registers, stored once: a memory increment per sample costs measurably.
    uint64_t samplesCovered = 0, samplesPassed = 0;
    for (const Batch& batch : mBatches) {
        const uint32_t binEnd = batch.binOffsets[size_t(tileIndex) + 1];
        for (uint32_t item = batch.binOffsets[size_t(tileIndex)]; item < binEnd; ++item) {
            const uint32_t index = batch.binItems[item];
            const SetupTriangle& t = batch.triangles[index];
            const int minX = std::max(int(t.minX), tileMinX),
                      maxX = std::min(int(t.maxX), tileMaxX);
            const int minY = std::max(int(t.minY), tileMinY),
                      maxY = std::min(int(t.maxY), tileMaxY);
            if (minX > maxX || minY > maxY)
                continue;

            // Edge i is opposite vertex i: e0 = v1->v2, e1 = v2->v0, e2 = v0->v1.
            const int32_t* x = t.x;
            const int32_t* y = t.y;
            const int64_t stepX0 = -int64_t(y[2] - y[1]) * kSubpixelScale;
            const int64_t stepX1 = -int64_t(y[0] - y[2]) * kSubpixelScale;
            const int64_t stepX2 = -int64_t(y[1] - y[0]) * kSubpixelScale;
            const int64_t stepY0 = int64_t(x[2] - x[1]) * kSubpixelScale;
            const int64_t stepY1 = int64_t(x[0] - x[2]) * kSubpixelScale;
            const int64_t stepY2 = int64_t(x[1] - x[0]) * kSubpixelScale;
            const int64_t bias0 = detail::fillBias(x[1], y[1], x[2], y[2]);
            const int64_t bias1 = detail::fillBias(x[2], y[2], x[0], y[0]);
            const int64_t bias2 = detail::fillBias(x[0], y[0], x[1], y[1]);
            auto edge = [](int32_t ax, int32_t ay, int32_t bx, int32_t by, int64_t px, int64_t py) {
                return int64_t(bx - ax) * (py - ay) - int64_t(by - ay) * (px - ax);
            };
            const int64_t px0 = int64_t(minX) * kSubpixelScale + kHalf;
            const int64_t py0 = int64_t(minY) * kSubpixelScale + kHalf;
            int64_t row0 = edge(x[1], y[1], x[2], y[2], px0, py0);
            int64_t row1 = edge(x[2], y[2], x[0], y[0], px0, py0);
            int64_t row2 = edge(x[0], y[0], x[1], y[1], px0, py0);

            const int64_t steps[3] = {stepX0, stepX1, stepX2};
            // A covered pixel: depth from the plane ((z0 + z2 py) + z1 px, px an exact double),
            // depth test, fragment function, depth write.
            auto shadePixel = [&](int px, int py, double zRow, float* depthRow) {
                ++samplesCovered;
                const float z = float(std::clamp(zRow + t.z[1] * double(px), 0.0, 1.0));
                if (depthRow && !detail::depthPasses<kDepthTest>(z, depthRow[px]))
                    return;
                Fragment fragment;
                fragment.x = px;
                fragment.y = py;
                fragment.depth = z;
                if (state.barycentrics)
                    fragment.barycentric = barycentricAt(batch, index, t, px, py);
                fragment.triangle = t.triangle;
                fragment.frontFacing = t.frontFacing;
                if constexpr (kCanDiscard) {
                    // Discard (alpha test) before the depth write.
                    if (!detail::keepsAny(fragmentFn(fragment)))
                        return;
                    ++samplesPassed;
                    if (depthRow && state.depthWrite)
                        depthRow[px] = z;
                } else {
                    ++samplesPassed;
                    if (depthRow && state.depthWrite)
                        depthRow[px] = z;
                    fragmentFn(fragment);
                }
            };

            if (state.referenceTraversal) {
                for (int py = minY; py <= maxY; ++py) {
                    int64_t w0 = row0, w1 = row1, w2 = row2;
                    float* depthRow = depth ? depth + size_t(py) * mWidth : nullptr;
                    const double zRow = t.z[0] + t.z[2] * py;
                    // A triangle's samples in one row are contiguous (the intersection of three
                    // half-planes is convex, biases included), so the row ends at its first
                    // uncovered sample after a covered one.
                    bool spanStarted = false;
                    for (int px = minX; px <= maxX; ++px) {
                        if (((w0 + bias0) | (w1 + bias1) | (w2 + bias2)) < 0) {
                            if (spanStarted)
                                break;
                        } else {
                            spanStarted = true;
                            shadePixel(px, py, zRow, depthRow);
                        }
                        w0 += stepX0;
                        w1 += stepX1;
                        w2 += stepX2;
                    }
                    row0 += stepY0;
                    row1 += stepY1;
                    row2 += stepY2;
                }
                continue;
            }

            for (int py = minY; py <= maxY; ++py) {
                const int64_t values[3] = {row0 + bias0, row1 + bias1, row2 + bias2};
                row0 += stepY0;
                row1 += stepY1;
                row2 += stepY2;
                const detail::RowSpan k = detail::coveredSpan(values, steps, maxX - minX);
                if (k.kLo > k.kHi)
                    continue;
                const int lo = minX + int(k.kLo), hi = minX + int(k.kHi);
                const double zRow = t.z[0] + t.z[2] * py;
                if (kDepthOnly && !depth) {
                    samplesCovered += uint64_t(hi - lo + 1);
                    samplesPassed += uint64_t(hi - lo + 1);
                } else if (kDepthOnly || (kTriangleIds && depth && !state.barycentrics)) {
                    samplesCovered += uint64_t(hi - lo + 1);
                    DepthSpanArgs span;
                    span.row = depth + size_t(py) * mWidth;
                    span.lo = lo;
                    span.hi = hi;
                    span.zRow = zRow;
                    span.zStep = t.z[1];
                    span.write = state.depthWrite;
                    if constexpr (kTriangleIds) {
                        span.values = fragmentFn.ids + size_t(py) * fragmentFn.width;
                        span.value = fragmentFn.idOf(t.triangle, t.frontFacing);
                    }
                    samplesPassed += spanLoop(span);
                } else {
                    float* depthRow = depth ? depth + size_t(py) * mWidth : nullptr;
                    for (int px = lo; px <= hi; ++px)
                        shadePixel(px, py, zRow, depthRow);
                }
            }
        }
    }
    tileStats.samplesCovered = samplesCovered;
    tileStats.samplesPassed = samplesPassed;
    tileStats.fragments = samplesPassed;
}

template <DepthTest kDepthTest, class FragmentFn>
void Rasterizer::rasterizeTileMultisample(int tileIndex, const RasterState& state, float* depth,
                                          FragmentFn& fragmentFn, RasterStats& tileStats) const {
    const int tileMinX = (tileIndex % mTilesX) * kTileSize;
    const int tileMinY = (tileIndex / mTilesX) * kTileSize;
    const int tileMaxX = std::min(tileMinX + kTileSize, mWidth) - 1;
    const int tileMaxY = std::min(tileMinY + kTileSize, mHeight) - 1;
    constexpr int64_t kHalf = kSubpixelScale / 2;
    // Sample offsets are in 1/16 pixel: this many fixed-point units each.
    constexpr int64_t kOffsetUnit = kSubpixelScale / 16;
    using Result = std::invoke_result_t<FragmentFn&, const Fragment&>;
    constexpr bool kCanDiscard = std::is_same_v<Result, bool>;
    constexpr bool kCanMask = std::is_same_v<Result, SampleMask>;
    static_assert(std::is_void_v<Result> || kCanDiscard || kCanMask,
                  "a fragment function returns void, bool or SampleMask");
    const int sampleCount = state.samples;
    const std::span<const SampleOffset> pattern = standardSamplePattern(sampleCount);
    // The depth-only and visibility draws run each row's pixels with a covered sample through
    // DepthSpan.h's multisampled loop: coverage, depth test and writes per sample on lanes. On
    // dense scenes most covered pixels are on a triangle's edge (atrium: ~5 pixels a triangle),
    // so the per-sample tests, not the fully covered runs, are what this loop is for.
    constexpr bool kDepthOnly = std::is_same_v<std::remove_cvref_t<FragmentFn>, DepthOnly>;
    constexpr bool kTriangleIds = std::is_same_v<std::remove_cvref_t<FragmentFn>, TriangleIds>;
    MultisampleTriangleLoop triangleLoop = nullptr;
    if constexpr (kDepthOnly || kTriangleIds)
        if (depth && (kDepthOnly || !state.barycentrics))
            triangleLoop = multisampleTriangleLoop(kDepthTest);
    const size_t rowSamples = size_t(mWidth) * size_t(sampleCount);
    // Per triangle, the edges' and the plane's change from a pixel centre to each sample. Zeroed
    // once per tile, not per triangle (a zeroing per triangle was 6% of this function): the
    // triangle loop loads kMaxSamples entries of each, and only the first sampleCount are set.
    int64_t offset[3][kMaxSamples] = {};
    double depthOffset[kMaxSamples] = {};
    // The triangle loop's arguments: the fixed ones set here, the triangle's below (made per
    // triangle, its zeroing was 18% of this function).
    MultisampleTriangleArgs rows;
    rows.depth = depth;
    rows.rowStride = rowSamples;
    rows.samples = sampleCount;
    rows.sampleOffsets = depthOffset;
    rows.edgeOffsets = offset;
    rows.write = state.depthWrite;
    if constexpr (kTriangleIds) {
        rows.values = fragmentFn.ids;
        rows.centreDepths = fragmentFn.centreDepths;
    }

    uint64_t samplesCovered = 0, samplesPassed = 0, fragments = 0;
    for (const Batch& batch : mBatches) {
        const uint32_t binEnd = batch.binOffsets[size_t(tileIndex) + 1];
        for (uint32_t item = batch.binOffsets[size_t(tileIndex)]; item < binEnd; ++item) {
            const uint32_t index = batch.binItems[item];
            const SetupTriangle& t = batch.triangles[index];
            const int minX = std::max(int(t.minX), tileMinX),
                      maxX = std::min(int(t.maxX), tileMaxX);
            const int minY = std::max(int(t.minY), tileMinY),
                      maxY = std::min(int(t.maxY), tileMaxY);
            if (minX > maxX || minY > maxY)
                continue;

            // Edge i is opposite vertex i, as in rasterizeTile; each edge value is carried at the
            // pixel centre, and a sample's is the centre's plus the edge's exact change over the
            // sample's offset (integers: the same value a direct evaluation gives).
            const int32_t* x = t.x;
            const int32_t* y = t.y;
            const int32_t ax[3] = {x[1], x[2], x[0]}, ay[3] = {y[1], y[2], y[0]};
            const int32_t bx[3] = {x[2], x[0], x[1]}, by[3] = {y[2], y[0], y[1]};
            int64_t stepX[3], stepY[3], bias[3], row[3], maxOffset[3], minOffset[3];
            const int64_t px0 = int64_t(minX) * kSubpixelScale + kHalf;
            const int64_t py0 = int64_t(minY) * kSubpixelScale + kHalf;
            for (int e = 0; e < 3; ++e) {
                const int64_t dx = int64_t(bx[e]) - ax[e], dy = int64_t(by[e]) - ay[e];
                stepX[e] = -dy * kSubpixelScale;
                stepY[e] = dx * kSubpixelScale;
                bias[e] = detail::fillBias(ax[e], ay[e], bx[e], by[e]);
                row[e] = dx * (py0 - ay[e]) - dy * (px0 - ax[e]);
                maxOffset[e] = INT64_MIN;
                minOffset[e] = INT64_MAX;
                for (int s = 0; s < sampleCount; ++s) {
                    offset[e][s] = (dx * pattern[s].y - dy * pattern[s].x) * kOffsetUnit + bias[e];
                    maxOffset[e] = std::max(maxOffset[e], offset[e][s]);
                    minOffset[e] = std::min(minOffset[e], offset[e][s]);
                }
            }
            // Depth at a sample: the centre's plane value plus the plane's change over the offset.
            for (int s = 0; s < sampleCount; ++s)
                depthOffset[s] = t.z[1] * (pattern[s].x / 16.0) + t.z[2] * (pattern[s].y / 16.0);

            // The samples `covered` of pixel (px, py): depth test, fragment function, depth write.
            auto shadeSamples = [&](int px, int py, unsigned covered, double zRow) {
                samplesCovered += unsigned(std::popcount(covered));
                const double zCentre = zRow + t.z[1] * double(px);
                float* depthPixel =
                    depth ? depth + (size_t(py) * mWidth + size_t(px)) * size_t(sampleCount)
                          : nullptr;
                // Every sample's depth and test, covered or not (a pixel's samples are all in
                // the buffer), without a branch: which samples pass an edge pixel's test is as
                // good as random, and a mispredicted branch per sample was this loop's cost.
                float sampleDepth[kMaxSamples];
                unsigned passed = 0;
                for (int s = 0; s < sampleCount; ++s) {
                    sampleDepth[s] = float(std::clamp(zCentre + depthOffset[s], 0.0, 1.0));
                    passed |= unsigned(!depthPixel || detail::depthPasses<kDepthTest>(
                                                          sampleDepth[s], depthPixel[s]))
                              << s;
                }
                passed &= covered;
                if (passed == 0)
                    return;
                Fragment fragment;
                fragment.x = px;
                fragment.y = py;
                fragment.depth = float(std::clamp(zCentre, 0.0, 1.0));
                if (state.barycentrics)
                    fragment.barycentric = barycentricAt(batch, index, t, px, py);
                fragment.triangle = t.triangle;
                fragment.frontFacing = t.frontFacing;
                fragment.coverage = uint8_t(passed);
                bool kept = true;
                if constexpr (kCanMask) {
                    // Alpha-to-coverage: only these samples are written and counted.
                    passed &= fragmentFn(fragment).bits;
                    kept = passed != 0;
                } else if constexpr (kCanDiscard) {
                    kept = fragmentFn(fragment);
                } else {
                    fragmentFn(fragment);
                }
                if (!kept)
                    return;
                ++fragments;
                samplesPassed += unsigned(std::popcount(passed));
                if (depthPixel && state.depthWrite)
                    for (int s = 0; s < sampleCount; ++s)
                        if (passed >> s & 1u)
                            depthPixel[s] = sampleDepth[s];
            };
            // The generic path walks each row's bounding box, as before the span loop: on small
            // triangles that is cheaper than finding spans by division (measured 2026-12-06).
            // A pixel no sample of which an edge can accept is skipped, one every sample of
            // which every edge accepts is covered whole, the others are tested per sample.
            const unsigned allSamples = (1u << sampleCount) - 1u;
            auto boundingBoxRow = [&](const int64_t w[3], int py, double zRow) {
                int64_t w0 = w[0], w1 = w[1], w2 = w[2];
                for (int px = minX; px <= maxX;
                     ++px, w0 += stepX[0], w1 += stepX[1], w2 += stepX[2]) {
                    if (((w0 + maxOffset[0]) | (w1 + maxOffset[1]) | (w2 + maxOffset[2])) < 0)
                        continue;
                    unsigned covered = 0;
                    if (((w0 + minOffset[0]) | (w1 + minOffset[1]) | (w2 + minOffset[2])) >= 0)
                        covered = allSamples;
                    else
                        for (int s = 0; s < sampleCount; ++s)
                            if (((w0 + offset[0][s]) | (w1 + offset[1][s]) | (w2 + offset[2][s])) >=
                                0)
                                covered |= 1u << s;
                    if (covered != 0)
                        shadeSamples(px, py, covered, zRow);
                }
            };

            if (triangleLoop) {
                // The triangle's rows on lanes, each sample's coverage with its depth test.
                rows.minX = minX;
                rows.maxX = maxX;
                rows.minY = minY;
                rows.maxY = maxY;
                rows.zOrigin = t.z[0];
                rows.zStepX = t.z[1];
                rows.zStepY = t.z[2];
                for (int e = 0; e < 3; ++e) {
                    rows.edgeAtMin[e] = row[e];
                    rows.edgeStepX[e] = stepX[e];
                    rows.edgeStepY[e] = stepY[e];
                }
                if constexpr (kTriangleIds)
                    rows.value = fragmentFn.idOf(t.triangle, t.frontFacing);
                const MultisampleSpanCounts counts = triangleLoop(rows);
                samplesCovered += counts.samplesCovered;
                samplesPassed += counts.samplesPassed;
                fragments += counts.fragments;
                continue;
            }
            for (int py = minY; py <= maxY; ++py) {
                boundingBoxRow(row, py, t.z[0] + t.z[2] * py);
                row[0] += stepY[0];
                row[1] += stepY[1];
                row[2] += stepY[2];
            }
        }
    }
    tileStats.samplesCovered = samplesCovered;
    tileStats.samplesPassed = samplesPassed;
    tileStats.fragments = fragments;
}

} // namespace raster
