// `tiled-forward`: tile-based forward shading, "Forward+" (Ishmukhametov 2013, section 2.4.2,
// after Harada et al. 2012). Three passes over the scene's own geometry, no G-buffer:
//   1. "prepass": depth-only pre-pass (the visibility draw, gbuffer/visibility/VisibilityPass.h),
//   which also
//      records each pixel's visible triangle;
//   2. "cull": the screen is split into square tiles; the pre-pass depths bound each tile's
//      frustum (computeTileDepthBounds in culling/TileFrusta.h: min/max view depth of the
//      covered pixels' reconstructed positions) and every light whose conservative sphere
//      (LightBounds.h) may touch it goes into the tile's list, in ascending light index. The lists
//      come from `tiled`'s builder (buildTileLightLists), so the same depths give the same lists;
//   3. "shading": the scene is rasterized again with a closer-or-equal test and no depth writes;
//      only the pre-pass's visible fragment of each pixel is shaded (exact "depth equal"), with
//      its tile's list. "transform" (vertices to clip/view space) precedes them.
//
// Options:
//   tile=16   tile size in pixels, 4..128
//   vfc=1     first cull lights against the camera frustum (ViewFrustum); only speed
//   mask=0    Harada's 2.5D culling (his proposal was for Forward+): a 32-bin depth mask per
//             tile from the pre-pass depths against each light's depth range, as in `tiled`
//   assign=loop|bvh, hier=0  as in `tiled` (TiledStage.cpp): how tiles find their lights; only
//             speed, the lists are the same
// Parameters record the options and lights_after_vfc, vfc_culled and tile_light_pairs.
//
// Shading on the light kernel (FragmentShading.h): the shading draw queues each visible fragment
// with its tile's list; 16 consecutive fragments of a raster tile form a packet the kernel shades
// on inputs.isa (lanes of different tiles masked to their own lists), and the results are stored
// in fragment order (FragmentApply::Replace). Records "isa" (what ran) and the SIMT counters (one
// warp = 32 or 64 consecutive visible fragments).
//
// Multisampling (inputs.samples > 1, hardware-style MSAA, ForwardGeometry.h): pre-pass and
// shading draw run at the frame's sample count; the tiles are bounded by every covered sample's
// shading depth (its fragment's centre depth: the surfaces actually shaded); each visible
// (pixel, triangle) is shaded once and replaces the samples whose pre-pass code is its triangle;
// the samples are averaged at the end ("resolve"). Records "shaded_fragments".
//
// Exactness: the visible fragment's surface and position are computed by the G-buffer's own
// functions (ForwardGeometry::surfaceAt) and each pixel sums its tile's lights in ascending order
// with the kernel's arithmetic, so the image is bitwise `brute`'s on the same ISA. Per pixel,
// lightsEvaluated is the list length of its one shaded fragment (0 for background); with the
// G-buffer's depth equal to the pre-pass depth this equals `tiled`'s count at the same tile size.
// Deterministic: tiles' lists are built in parallel, each by one task; the shading draw writes each
// pixel from the task owning its raster tile, and only one fragment per pixel passes the
// visible-triangle test.
#include "lighting/StageRegistry.h"

#include <algorithm>
#include <memory>
#include <span>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/ForwardGeometry.h"
#include "lighting/passes/FragmentShading.h"
#include "lighting/passes/PassNames.h"
#include "lighting/stages/TiledStageOptions.h"

namespace lighting {

namespace {

struct TiledForwardOptions {
    int tileSizePixels = 16;
    bool viewFrustumCulling = true;
    bool depthMask = false;
    TileAssign assign = TileAssign::Loop;
    bool hierarchical = false;
};

class TiledForwardStage final : public ShadingStage {
public:
    explicit TiledForwardStage(const TiledForwardOptions& options) : mOptions(options) {}

    std::string name() const override { return "tiled-forward"; }
    // Reads no G-buffer channel: it rasterizes the scene itself (inputs.scene, .geometry).
    StageRequirements requirements() const override { return {{}, false}; }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::CameraView& view = *inputs.view;
        mForward.beginFrame(inputs, result, true);

        PassTimer cull(result, pass::kCull);
        const TileGrid grid = TileGrid::make(view.width, view.height, mOptions.tileSizePixels);
        const std::vector<TileSurfaceBounds> bounds = computeTileDepthBounds(
            mForward.depthDecoder(), mForward.shadedDepth(), grid, mOptions.depthMask);
        const size_t lightsAfterVfc =
            buildTileLightLists(view, grid, bounds, boundingSpheresView(*inputs.lights),
                                {mOptions.viewFrustumCulling, mOptions.depthMask, false,
                                 mOptions.assign, mOptions.hierarchical},
                                mTileLights, &mBvh)
                .lightsAfterVfc;
        cull.stop();

        PassTimer shading(result, pass::kShading);
        const int tileSize = grid.tileSizePixels, tileCountX = grid.tileCountX;
        const gbuffer::VisibilityPass& visibility = mForward.visibility();
        mShading.begin(inputs, FragmentApply::Replace, result, mForward.sampleTarget());
        const bool multisampled = mForward.samples() > 1;
        auto shadeFragment = [&](const raster::Fragment& drawn) {
            raster::Fragment fragment = drawn;
            if (multisampled)
                fragment.coverage = visibility.visibleCoverage(drawn, drawn.triangle);
            if (multisampled ? fragment.coverage == 0
                             : !visibility.isVisible(drawn, drawn.triangle))
                return;
            const uint32_t tile =
                uint32_t(fragment.y / tileSize) * uint32_t(tileCountX) + fragment.x / tileSize;
            mShading.add(fragment, fragment.triangle,
                         mForward.surfaceAt(fragment, fragment.triangle), tile, mTileLights[tile]);
        };
        mForward.draw(visibility.triangles(), visibility.redrawState(), shadeFragment);
        mShading.flush();
        mShading.end();
        shading.stop();
        result.parameters["shaded_fragments"] = std::to_string(mShading.fragmentCount());
        if (mBlended.prepare(inputs, mForward.sampleTarget()))
            mBlended.shadeWithTileLists(mForward.depth(), mOptions.tileSizePixels,
                                        mOptions.viewFrustumCulling, result);
        mForward.endFrame(result);

        result.parameters["tile"] = std::to_string(mOptions.tileSizePixels);
        result.parameters["vfc"] = mOptions.viewFrustumCulling ? "1" : "0";
        result.parameters["mask"] = mOptions.depthMask ? "1" : "0";
        result.parameters["assign"] = mOptions.assign == TileAssign::Bvh ? "bvh" : "loop";
        result.parameters["hier"] = mOptions.hierarchical ? "1" : "0";
        result.parameters["lights_after_vfc"] = std::to_string(lightsAfterVfc);
        result.parameters["vfc_culled"] =
            std::to_string(inputs.lights->lights.size() - lightsAfterVfc);
        result.parameters["tile_light_pairs"] = std::to_string(mTileLights.pairCount());
    }

    bool multisamplesNatively() const override { return true; }

private:
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
    TiledForwardOptions mOptions;
    ForwardGeometry mForward;
    FragmentShading mShading;
    LightIndexLists mTileLights; // per tile, ascending light indices (buildTileLightLists)
    LightBvh mBvh;               // assign=bvh; storage reused across frames
};

const StageRegistrar kRegistrar(
    {.name = "tiled-forward",
     .description = "Forward+: depth pre-pass, per-tile light lists, forward shading",
     .kind = StageKind::Exact,
     .options = {StageOption::integer("tile", 16, 4, 128, "tile size in pixels"),
                 StageOption::boolean("vfc", true,
                                      "cull lights against the camera frustum first (speed only)"),
                 StageOption::boolean("mask", false,
                                      "Harada's 2.5D culling: a 32-bin depth mask per tile"),
                 tiledAssignOption(), tiledHierOption()},
     .listOrder = 120,
     .msaaNative = true},
    [](const StageOptions& table) {
        TiledForwardOptions options;
        options.tileSizePixels = table.integer("tile");
        options.viewFrustumCulling = table.boolean("vfc");
        options.depthMask = table.boolean("mask");
        options.assign = table.text("assign") == "bvh" ? TileAssign::Bvh : TileAssign::Loop;
        options.hierarchical = table.boolean("hier");
        return std::make_unique<TiledForwardStage>(options);
    });

} // namespace

} // namespace lighting
