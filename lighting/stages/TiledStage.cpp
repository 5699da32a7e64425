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
// Multisampled frames (`tiled` without mask, lighting/MultisampleShading.h): the lists are built
// once per frame, on layer 0's run, from tile depth bounds over every layer's fragments (layer 0's
// G-buffer and the upper layers' centre depths as their G-buffers store them), as Lauritzen culls
// once per tile for all samples. An upper layer's run reuses them only after checking that they
// cover it: the same lights, the same view, and each of its tiles' depth range inside the range
// the lists were built for; otherwise it builds its own. Parameter tile_lists: "own" or
// "shared" (taken from layer 0's run).
// Threads: tiles in parallel; each tile's list and pixels are written by one task only.
// Cost note (CPU): a light that faces away from a whole packet is rejected by the kernel's n.l
// early-out at almost no cost, so the samples tiled-backface removes are the cheap ones; the
// thesis' GPU gains (uniform cost per evaluated light) are larger than what we measure here. The
// test itself is made cheap instead (BackfaceTileCone in culling/TileFrusta.h: per-tile data once,
// a one-dot early-out for lights that cannot be rejected, no test at all in tiles whose normal
// cone is too wide).
#include "lighting/StageRegistry.h"

#include <algorithm>
#include <optional>
#include <span>

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PassNames.h"
#include "lighting/stages/TiledStageOptions.h"

namespace lighting {

namespace {

bool sameSphere(const LightSphere& a, const LightSphere& b) {
    return a.centreView == b.centreView && a.radius == b.radius && a.unbounded == b.unbounded &&
           a.positionView == b.positionView && a.spot == b.spot && a.axisView == b.axisView &&
           a.spotOuterCos == b.spotOuterCos && a.rangeMetres == b.rangeMetres;
}

// Tile depth bounds over every fragment layer of a multisampled frame: layer 0's G-buffer `gb`
// and the layers above, whose depths are their fragments' centre depths as a G-buffer of gb's
// layout stores them (quantised by its depth format, as GBuffer::quantiseDepth does).
std::vector<TileSurfaceBounds> boundsOverEveryLayer(const gbuffer::GBuffer& gb,
                                                    const gbuffer::FragmentLayers& layers,
                                                    const TileGrid& grid) {
    std::vector<TileSurfaceBounds> bounds = computeTileSurfaceBounds(gb, grid, {});
    const gbuffer::DepthDecoder& decoder = gb.depthDecoder();
    const float clear = gb.view().clearDepth();
    tbb::parallel_for(0, grid.tileCount(), [&](int tile) {
        const int tx = tile % grid.tileCountX, ty = tile / grid.tileCountX;
        TileSurfaceBounds& b = bounds[size_t(tile)];
        for (int k = 1; k < layers.layerCount(); ++k) {
            const std::span<const float> depths = layers.depths(k);
            for (int y = grid.y0(ty); y < grid.y1(ty); ++y)
                for (int x = grid.x0(tx); x < grid.x1(tx); ++x) {
                    const float d = depths[size_t(y) * size_t(grid.widthPixels) + size_t(x)];
                    if (d == clear)
                        continue;
                    const float stored = decoder.lossless() ? d : decoder.storedDepthNdc(d);
                    const float metres = decoder.viewDepthMetres(x, y, stored);
                    if (!b.covered) {
                        b.covered = true;
                        b.minDepthMetres = b.maxDepthMetres = metres;
                    }
                    b.minDepthMetres = std::min(b.minDepthMetres, metres);
                    b.maxDepthMetres = std::max(b.maxDepthMetres, metres);
                }
        }
    });
    return bounds;
}

struct TiledOptions {
    int tileSizePixels = 16;
    bool viewFrustumCulling = true;
    bool depthMask = false;
    bool backface = false;
    TileAssign assign = TileAssign::Loop;
    bool hierarchical = false;
};

class TiledStage final : public ShadingStage {
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
        std::vector<LightSphere> spheres = boundingSpheresView(*inputs.lights);
        const size_t lightCount = spheres.size();
        // Only depth ranges can be shared between layers (a depth mask's bins or a normal cone
        // would have to be rebuilt over the union to stay conservative).
        const bool layered = inputs.fragmentLayers && !mOptions.depthMask && !mOptions.backface;
        std::vector<TileSurfaceBounds> bounds =
            layered && inputs.fragmentLayer == 0
                ? boundsOverEveryLayer(gb, *inputs.fragmentLayers, grid)
                : computeTileSurfaceBounds(gb, grid, {mOptions.depthMask, mOptions.backface});
        const bool shared =
            layered && inputs.fragmentLayer != 0 && sharedListsCover(gb, bounds, spheres);
        TileLightListStats lists;
        if (shared) {
            lists = mSharedStats;
        } else {
            lists = buildTileLightLists(view, grid, bounds, spheres,
                                        {mOptions.viewFrustumCulling, mOptions.depthMask,
                                         mOptions.backface, mOptions.assign, mOptions.hierarchical},
                                        mTileLights, &mBvh);
            mShared.reset();
            if (layered && inputs.fragmentLayer == 0) {
                mShared = SharedLists{std::move(bounds), std::move(spheres), view.clipFromView,
                                      gb.width(), gb.height()};
                mSharedStats = lists;
            }
        }
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
        result.parameters["vfc_culled"] = std::to_string(lightCount - lists.lightsAfterVfc);
        result.parameters["tile_light_pairs"] = std::to_string(mTileLights.pairCount());
        if (inputs.fragmentLayers)
            result.parameters["tile_lists"] = shared ? "shared" : "own";
        if (mOptions.backface)
            result.parameters["backface_rejected"] = std::to_string(lists.backfaceRejected);
    }

private:
    // What layer 0's lists of a multisampled frame were built for (see the file comment).
    struct SharedLists {
        std::vector<TileSurfaceBounds> bounds;
        std::vector<LightSphere> spheres;
        glm::mat4 clipFromView;
        int width, height;
    };
    // Whether the lists built on layer 0's run cover a layer with tile bounds `bounds`: the same
    // view and lights, and each covered tile's depth range inside the one they were built for.
    bool sharedListsCover(const gbuffer::GBuffer& gb, const std::vector<TileSurfaceBounds>& bounds,
                          const std::vector<LightSphere>& spheres) const {
        if (!mShared || mShared->width != gb.width() || mShared->height != gb.height() ||
            mShared->clipFromView != gb.view().clipFromView ||
            mShared->bounds.size() != bounds.size() || mShared->spheres.size() != spheres.size())
            return false;
        for (size_t i = 0; i < spheres.size(); ++i)
            if (!sameSphere(spheres[i], mShared->spheres[i]))
                return false;
        for (size_t tile = 0; tile < bounds.size(); ++tile) {
            const TileSurfaceBounds& own = bounds[tile];
            const TileSurfaceBounds& built = mShared->bounds[tile];
            if (own.covered && !(built.covered && built.minDepthMetres <= own.minDepthMetres &&
                                 own.maxDepthMetres <= built.maxDepthMetres))
                return false;
        }
        return true;
    }

    TiledOptions mOptions;
    std::optional<SharedLists> mShared;
    TileLightListStats mSharedStats;
    LightIndexLists mTileLights; // per tile, ascending; storage reused across frames
    LightBvh mBvh;               // assign=bvh; storage reused across frames
    BlendedPass mBlended;        // blended surfaces after the opaque pass (BlendedPass.h)
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

const StageRegistrar
    kTiledRegistrar({.name = "tiled",
                     .description = "tiled deferred: per-tile depth-bounded frusta",
                     .kind = StageKind::Exact,
                     .options = tiledOptionTable(),
                     .listOrder = 60},
                    tiledFactory(false));

const StageRegistrar kTiledBackfaceRegistrar(
    {.name = "tiled-backface",
     .description = "tiled deferred plus per-tile normal-cone back-face culling of lights",
     .kind = StageKind::Exact,
     .options = tiledOptionTable(),
     .listOrder = 70},
    tiledFactory(true));

} // namespace

} // namespace lighting
