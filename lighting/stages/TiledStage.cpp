// `tiled` and `tiled-backface`: tiled deferred shading (Ishmukhametov 2013, section 2.4.1, after
// Andersson 2009 and Lauritzen 2010) and the thesis' own extension with per-tile back-face
// culling of lights (chapter 4).
//
// tiled: the screen is split into square tiles; per tile, the view-depth range of its covered
// pixels bounds a frustum (4 side planes through the eye along the tile's pixel edges, near/far
// at the min/max depth); every light whose conservative sphere (LightBounds.h) may touch it goes
// into the tile's list, in ascending light index; then every pixel is shaded with its tile's
// list (accumulateLights, LightAccumulation.h), which makes the image bitwise equal to `brute`
// with the same ISA. Tiles without a
// covered pixel get no lights.
// tiled-backface: as tiled, plus a normal cone per tile and a light cone per (tile, light); a
// light that faces the back of every normal in the tile is dropped (lightBackFacesTile in
// culling/TileFrusta.h explains why the test is exactly conservative).
//
// Options (both stages):
//   tile=16   tile size in pixels, 4..128
//   vfc=1     first cull lights against the camera frustum (thesis 4.1 item 4); only speed
//   mask=0    Harada's 2.5D culling: 32-bin depth mask per tile against the light's depth range
//   assign=loop|bvh  how a tile finds the lights to test: every light, or the lights a light BVH
//             (culling/LightBvh.h) returns for the tile's box; only speed, the lists are the same
//   hier=0    hierarchical tile culling: 4x4 groups of tiles get a list first, fine tiles test
//             only their group's list; only speed (buildTileLightLists in culling/TileFrusta.h)
// Passes: "cull" (light spheres, view-frustum culling, tile bounds and cones, light lists) and
// "shading". Parameters record the options and counts: lights_after_vfc, vfc_culled,
// tile_light_pairs and (tiled-backface) backface_rejected.
// Threads: tiles in parallel; each tile's list and pixels are written by one task only.
// Cost note (CPU): a light that faces away from a whole packet is rejected by the kernel's n.l
// early-out at almost no cost, so the samples tiled-backface removes are the cheap ones; the
// thesis' GPU gains (uniform cost per evaluated light) are larger than what we measure here. The
// test itself is made cheap instead (BackfaceTileCone in culling/TileFrusta.h: per-tile data once,
// a one-dot early-out for lights that cannot be rejected, no test at all in tiles whose normal
// cone is too wide).
#include "lighting/StageRegistry.h"

#include <algorithm>
#include <span>

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PackedFragments.h"
#include "lighting/passes/PassNames.h"
#include "lighting/stages/TiledStageOptions.h"

namespace lighting {

namespace {

struct TiledOptions {
    int tileSizePixels = 16;
    bool viewFrustumCulling = true;
    bool depthMask = false;
    bool backface = false;
    TileAssign assign = TileAssign::Loop;
    bool hierarchical = false;
};

// A packed fragment's list: its tile's, layer 0's list where the tile kept it, else the one
// culled for the fragments (TiledStage::shadeFragments).
class TileFragmentLists final : public FragmentListSource {
public:
    TileFragmentLists(const TileGrid& grid, const std::vector<uint8_t>& kept,
                      const LightIndexLists& frameLights, const LightIndexLists& fragmentLights)
        : mGrid(grid), mKept(kept), mFrameLights(frameLights), mFragmentLights(fragmentLights) {}
    std::span<const uint32_t> listOf(int x, int y, const glm::vec3&) const override {
        const size_t tile =
            size_t((y / mGrid.tileSizePixels) * mGrid.tileCountX + x / mGrid.tileSizePixels);
        return mKept[tile] ? mFrameLights[tile] : mFragmentLights[tile];
    }

private:
    const TileGrid& mGrid;
    const std::vector<uint8_t>& mKept;
    const LightIndexLists& mFrameLights;
    const LightIndexLists& mFragmentLights;
};

// The depth bounds of a run's packed fragments per tile (no depth mask, no normal cone), straight
// from the list: each fragment's view depth read as computeTileSurfaceBounds reads a covered
// pixel's (its layer's DepthDecoder on its stored depth), so the same bounds as over the layers'
// G-buffers, at a cost that follows the fragments. Tile rows in parallel (min and max: the same
// for any order).
std::vector<TileSurfaceBounds> fragmentDepthBounds(const PackedFragmentRun& run,
                                                   const TileGrid& grid) {
    const PackedFragments& fragments = *run.fragments;
    std::vector<TileSurfaceBounds> bounds(size_t(grid.tileCount()));
    tbb::parallel_for(0, grid.tileCountY, [&](int ty) {
        for (size_t i = fragments.rowFirst(grid.y0(ty)); i < fragments.rowFirst(grid.y1(ty)); ++i) {
            const uint32_t pixel = fragments.pixel(i);
            const int x = fragments.x(i), y = fragments.y(i);
            const gbuffer::GBuffer& gb = run.gbufferOf(i);
            const float depth = gb.depthDecoder().viewDepthMetres(x, y, gb.depth()[pixel]);
            TileSurfaceBounds& b = bounds[size_t(ty * grid.tileCountX + x / grid.tileSizePixels)];
            b.minDepthMetres = b.covered ? std::min(b.minDepthMetres, depth) : depth;
            b.maxDepthMetres = b.covered ? std::max(b.maxDepthMetres, depth) : depth;
            b.covered = true;
        }
    });
    return bounds;
}

class TiledStage final : public ShadingStage, public PackedFragmentShading {
public:
    explicit TiledStage(const TiledOptions& options) : mOptions(options) {}

    std::string name() const override { return mOptions.backface ? "tiled-backface" : "tiled"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const gbuffer::CameraView& view = gb.view();
        result.resize(gb.width(), gb.height(), false);
        PassTimer cull(result, pass::kCull);

        const TileGrid grid = TileGrid::make(gb.width(), gb.height(), mOptions.tileSizePixels);
        const std::vector<LightSphere> spheres = boundingSpheresView(*inputs.lights);
        std::vector<TileSurfaceBounds> bounds =
            computeTileSurfaceBounds(gb, grid, {mOptions.depthMask, mOptions.backface});
        const TileLightListStats lists =
            buildTileLightLists(view, grid, bounds, spheres,
                                {mOptions.viewFrustumCulling, mOptions.depthMask, mOptions.backface,
                                 mOptions.assign, mOptions.hierarchical},
                                mTileLights, &mBvh);
        // A multisampled frame's layer 0: its tiles' bounds, which its packed fragments are
        // checked against (shadeFragments).
        if (inputs.fragmentLayer == 0 && inputs.fragmentLayers)
            mFrameBounds = std::move(bounds);
        else
            mFrameBounds.clear();
        cull.stop();

        PassTimer shading(result, pass::kShading);
        accumulateLights(inputs, TileListSource(grid.tileSizePixels, grid.tileCountX, mTileLights),
                         {}, result);
        shading.stop();

        if (mBlended.prepare(inputs))
            mBlended.shadeWithTileLists(gb.depth(), mOptions.tileSizePixels,
                                        mOptions.viewFrustumCulling, result);
        result.parameters["tile"] = std::to_string(mOptions.tileSizePixels);
        result.parameters["vfc"] = mOptions.viewFrustumCulling ? "1" : "0";
        result.parameters["mask"] = mOptions.depthMask ? "1" : "0";
        result.parameters["assign"] = mOptions.assign == TileAssign::Bvh ? "bvh" : "loop";
        result.parameters["hier"] = mOptions.hierarchical ? "1" : "0";
        result.parameters["lights_after_vfc"] = std::to_string(lists.lightsAfterVfc);
        result.parameters["vfc_culled"] = std::to_string(spheres.size() - lists.lightsAfterVfc);
        result.parameters["tile_light_pairs"] = std::to_string(mTileLights.pairCount());
        if (mOptions.backface)
            result.parameters["backface_rejected"] = std::to_string(lists.backfaceRejected);
    }

    // A multisampled frame's other fragments in one run (PackedFragments.h): the survey's per-tile
    // MSAA choice made once for the frame. Per tile, the bounds of its fragments in every layer
    // above 0. Where they lie inside the depth range of layer 0's bounds for the tile (the usual
    // case: at an edge both surfaces are some pixel's main fragment in the tile), the tile's
    // layer-0 list holds every light that may reach them: it is kept (not with the depth mask or
    // the normal cone, whose bins and cones layer 0's samples alone made). The other tiles are
    // culled as shade() culls, with the same options. Then the kernel over packets of fragments.
    bool shadeFragments(const PackedFragmentRun& run, StageResult& result) override {
        const StageInputs& inputs = *run.frame;
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const TileGrid grid = TileGrid::make(gb.width(), gb.height(), mOptions.tileSizePixels);
        if (mFrameBounds.size() != size_t(grid.tileCount()))
            return false; // shade() did not run on this frame's layer 0
        result.resize(int(run.fragments->size()), 1, false);
        PassTimer cull(result, pass::kCull);
        const std::vector<LightSphere> spheres = boundingSpheresView(*inputs.lights);
        const std::span<const gbuffer::GBuffer* const> upper =
            std::span(run.layerGBuffers).subspan(1);
        const bool reusable = !mOptions.depthMask && !mOptions.backface;
        std::vector<TileSurfaceBounds> bounds =
            reusable
                ? fragmentDepthBounds(run, grid)
                : computeTileSurfaceBounds(upper, grid, {mOptions.depthMask, mOptions.backface});
        mKeptTiles.assign(bounds.size(), 0);
        for (size_t tile = 0; tile < bounds.size(); ++tile) {
            const TileSurfaceBounds& frame = mFrameBounds[tile];
            if (reusable && bounds[tile].covered && frame.covered &&
                bounds[tile].minDepthMetres >= frame.minDepthMetres &&
                bounds[tile].maxDepthMetres <= frame.maxDepthMetres) {
                mKeptTiles[tile] = 1;
                bounds[tile].covered = false; // no new list
            }
        }
        buildTileLightLists(gb.view(), grid, bounds, spheres,
                            {mOptions.viewFrustumCulling, mOptions.depthMask, mOptions.backface,
                             mOptions.assign, mOptions.hierarchical},
                            mFragmentTileLights, &mBvh);
        cull.stop();
        PassTimer shading(result, pass::kShading);
        accumulatePackedFragments(
            run, TileFragmentLists(grid, mKeptTiles, mTileLights, mFragmentTileLights), result);
        return true;
    }

private:
    TiledOptions mOptions;
    LightIndexLists mTileLights;         // per tile, ascending; storage reused across frames
    LightIndexLists mFragmentTileLights; // the same for a frame's packed fragments
    std::vector<TileSurfaceBounds> mFrameBounds; // a multisampled frame's layer-0 tile bounds
    std::vector<uint8_t> mKeptTiles;             // per tile: its packed fragments use mTileLights
    LightBvh mBvh;                               // assign=bvh; storage reused across frames
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
};

// The options of both stages.
std::vector<StageOption> tiledOptionTable() {
    return {
        StageOption::integer("tile", 16, 4, 128, "tile size in pixels"),
        StageOption::boolean("vfc", true,
                             "cull lights against the camera frustum first (speed only)"),
        StageOption::boolean("mask", false, "Harada's 2.5D culling: a 32-bin depth mask per tile"),
        tiledAssignOption(), tiledHierOption()};
}

StageFactory tiledFactory(bool backface) {
    return [backface](const StageOptions& table) {
        TiledOptions options;
        options.tileSizePixels = table.integer("tile");
        options.viewFrustumCulling = table.boolean("vfc");
        options.depthMask = table.boolean("mask");
        options.assign = table.text("assign") == "bvh" ? TileAssign::Bvh : TileAssign::Loop;
        options.hierarchical = table.boolean("hier");
        options.backface = backface;
        return std::make_unique<TiledStage>(options);
    };
}

// What `testbed list` says of both stages with --msaa (MultisampleShading.h).
constexpr const char* kTiledMsaaNote =
    "layer 0 tiled as at 1x; the complex pixels' other fragments in one packed run, full "
    "packets by screen block, a tile's layer-0 list kept where they lie inside its depth "
    "bounds (not with the depth mask or the normal cone), else culled for them; tiles without "
    "a complex pixel pay nothing (per-layer runs with blended surfaces)";

const StageRegistrar
    kTiledRegistrar({.name = "tiled",
                     .description = "tiled deferred: per-tile depth-bounded frusta",
                     .kind = StageKind::Exact,
                     .options = tiledOptionTable(),
                     .listOrder = 60,
                     .msaaNote = kTiledMsaaNote},
                    tiledFactory(false));

const StageRegistrar kTiledBackfaceRegistrar(
    {.name = "tiled-backface",
     .description = "tiled deferred plus per-tile normal-cone back-face culling of lights",
     .kind = StageKind::Exact,
     .options = tiledOptionTable(),
     .listOrder = 70,
     .msaaNote = kTiledMsaaNote},
    tiledFactory(true));

} // namespace

} // namespace lighting
