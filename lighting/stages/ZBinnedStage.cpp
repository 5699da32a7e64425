// `zbinned`: Drobot's z-binning (SIGGRAPH 2017, "Improved Culling for Tiled and Clustered
// Rendering", Call of Duty: Infinite Warfare) on the G-buffer: lights sorted by view depth, per
// z-bin the range of sorted lights whose depth extent overlaps it, per screen tile a bit mask over
// the sorted lights whose sphere touches the tile's depth-bounded frustum (lighting/culling/
// ZBins.h). A pixel's candidate lights are its tile's mask bits inside its bin's range (plus the
// unbounded lights); memory O(tiles x lights / 32 + bins) instead of a list per cluster.
//
// Assignment ("assign" pass, as `clustered`'s): light spheres (LightBounds.h), view-frustum culling
// and each light's tile column/row range (candidateLights, TileFrusta.h), the tiles' depth bounds
// from the G-buffer's depth plane (computeTileDepthBounds), the sort and the bins between the
// nearest and farthest covered depth, the masks over each covered tile's window of bins. Shading
// ("shading" pass): accumulateLights (LightAccumulation.h) by 4x4 packets; per packet the lanes are
// grouped by tile and each lane's bin found from its decoded depth, the group's words are walked
// over the hull of its lanes' bin ranges, each set bit gives a light and the lanes whose own bin
// range holds it (so every lane sums exactly its own candidates and lights.evaluated is the
// per-pixel count, as in `clustered`), and the lights are sorted by light index: the kernel sums in
// ascending light order (ShadingStage.h), so the image is bitwise `brute`'s on the same ISA. This
// per-packet gathering is the stage's lookup cost, the z-binned counterpart of reading a cluster's
// list, and is timed in the shading pass, as it runs in the shader on a GPU.
//
// Options (defaults first):
//   tile=32          tile size in pixels (4..128): 920 tiles at 1280x720, which keeps the masks
//                    small at 10^6 lights (see lighting/culling/README.md for the measured bytes)
//   bins=1024        z-bins (1..65536)
//   spacing=uniform|exp  bin boundaries linear in view depth (Drobot's) or geometric, between the
//                    G-buffer's nearest and farthest covered depth
// Parameters: the options, lights_after_vfc, vfc_culled, binned_lights (bounded lights overlapping
// the depth range), tile_light_pairs (mask bits set), mask_words, mask_bytes, bin_bytes,
// sorted_bytes, zbin_near_m, zbin_far_m.
// MSAA: through the fragment layers, as `tiled` (MultisampleShading.h): each layer gets its own
// bins and masks from its own depth. Blended surfaces: the near-to-opaque tile lists of the tiled
// stages (BlendedPass::shadeWithTileLists), as `tiled`.
// Threads: the builds are deterministic (ZBins.h); each pixel is written by one task; per-packet
// scratch is per thread and only ever read back by the packet that wrote it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "lighting/StageRegistry.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/culling/ZBins.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

struct ZBinnedOptions {
    int tileSizePixels = 32;
    int binCount = 1024;
    ZBinSpacing spacing = ZBinSpacing::Uniform;
};

// The lists of a packet from the bins and the masks (see the file comment).
class ZBinListSource final : public PacketListSource {
public:
    ZBinListSource(const TileGrid& grid, const ZBins& bins, const ZBinTileMasks& masks)
        : mGrid(grid), mBins(bins), mMasks(masks) {}

    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        Scratch& scratch = mScratch.local();
        scratch.keys.clear();
        int tileOfLane[kernel::kPacketLanes];
        int binOfLane[kernel::kPacketLanes];
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const int lane = __builtin_ctz(lanes);
            const int x = packet.x0 + kernel::laneX(lane), y = packet.y0 + kernel::laneY(lane);
            tileOfLane[lane] =
                (y / mGrid.tileSizePixels) * mGrid.tileCountX + x / mGrid.tileSizePixels;
            binOfLane[lane] = mBins.binOfDepth(-packet.positionView[2][lane]);
        }
        struct Group {
            uint32_t laneMask;
            size_t begin, end;
            bool perLane; // lanes in several bins: per-light lane masks
        };
        Group groups[kernel::kPacketLanes];
        int groupCount = 0;
        const std::span<const uint32_t> unbounded = mBins.unboundedLights();
        for (uint32_t remaining = packet.laneMask; remaining != 0;) {
            const int tile = tileOfLane[__builtin_ctz(remaining)];
            uint32_t groupMask = 0;
            // The group's distinct bins, the lanes in each and their ranges.
            int binCount = 0;
            int bins[kernel::kPacketLanes];
            uint32_t binLanes[kernel::kPacketLanes];
            for (uint32_t lanes = remaining; lanes != 0; lanes &= lanes - 1) {
                const int lane = __builtin_ctz(lanes);
                if (tileOfLane[lane] != tile)
                    continue;
                groupMask |= 1u << lane;
                int k = 0;
                while (k < binCount && bins[k] != binOfLane[lane])
                    ++k;
                if (k == binCount) {
                    bins[binCount] = binOfLane[lane];
                    binLanes[binCount++] = 0;
                }
                binLanes[k] |= 1u << lane;
            }
            remaining &= ~groupMask;
            ZBins::Range ranges[kernel::kPacketLanes];
            uint32_t first = UINT32_MAX, last = 0;
            for (int k = 0; k < binCount; ++k) {
                ranges[k] = mBins.range(bins[k]);
                if (!ranges[k].empty()) {
                    first = std::min(first, ranges[k].first);
                    last = std::max(last, ranges[k].last);
                }
            }
            const size_t begin = scratch.keys.size();
            // Key: light index above, the lanes that evaluate it below; sorting the keys sorts
            // by light index (each light once per group).
            if (binCount == 1)
                mMasks.forEachSetBit(size_t(tile), first, last, [&](uint32_t position) {
                    scratch.keys.push_back(uint64_t(mBins.sortedLight(position)) << 16 | groupMask);
                });
            else
                mMasks.forEachSetBit(size_t(tile), first, last, [&](uint32_t position) {
                    uint32_t lanes = 0;
                    for (int k = 0; k < binCount; ++k)
                        if (ranges[k].first <= position && position <= ranges[k].last)
                            lanes |= binLanes[k];
                    if (lanes != 0)
                        scratch.keys.push_back(uint64_t(mBins.sortedLight(position)) << 16 | lanes);
                });
            for (uint32_t light : unbounded)
                scratch.keys.push_back(uint64_t(light) << 16 | groupMask);
            std::sort(scratch.keys.begin() + std::ptrdiff_t(begin), scratch.keys.end());
            groups[groupCount++] = {groupMask, begin, scratch.keys.size(), binCount > 1};
        }
        // The lists, in storage that stays put until this packet is shaded (the next call on this
        // thread is for the next packet).
        scratch.lights.resize(scratch.keys.size());
        scratch.laneMasks.resize(scratch.keys.size());
        for (size_t i = 0; i < scratch.keys.size(); ++i) {
            scratch.lights[i] = uint32_t(scratch.keys[i] >> 16);
            scratch.laneMasks[i] = uint16_t(scratch.keys[i] & 0xFFFFu);
        }
        for (int g = 0; g < groupCount; ++g) {
            const Group& group = groups[g];
            const size_t count = group.end - group.begin;
            const std::span<const uint32_t> lights =
                std::span<const uint32_t>(scratch.lights).subspan(group.begin, count);
            if (group.perLane)
                lists.addTransient(
                    group.laneMask, lights,
                    std::span<const uint16_t>(scratch.laneMasks).subspan(group.begin, count));
            else
                lists.addTransient(group.laneMask, lights);
        }
    }

private:
    struct Scratch {
        std::vector<uint64_t> keys;
        std::vector<uint32_t> lights;
        std::vector<uint16_t> laneMasks;
    };
    const TileGrid& mGrid;
    const ZBins& mBins;
    const ZBinTileMasks& mMasks;
    mutable tbb::enumerable_thread_specific<Scratch> mScratch;
};

std::string metres(float value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.6g", double(value));
    return text;
}

class ZBinnedStage final : public ShadingStage {
public:
    explicit ZBinnedStage(const ZBinnedOptions& options) : mOptions(options) {}

    std::string name() const override { return "zbinned"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const gbuffer::CameraView& view = gb.view();
        result.resize(gb.width(), gb.height(), false);
        PassTimer assign(result, pass::kAssign);

        const TileGrid grid = TileGrid::make(gb.width(), gb.height(), mOptions.tileSizePixels);
        const std::vector<LightSphere> spheres = boundingSpheresView(*inputs.lights);
        // Depth bounds from the depth plane alone (bitwise computeTileSurfaceBounds' depth range,
        // without decoding normals and materials).
        const std::vector<TileSurfaceBounds> bounds =
            computeTileDepthBounds(gb.depthDecoder(), gb.depth(), grid, false);
        const TileEdgePlanes edges = TileEdgePlanes::make(view, grid);
        const std::vector<CandidateLight> candidates =
            candidateLights(view, grid, edges, spheres, true);
        // The bins span the covered samples' depths: the tiles' own bounds (min/max of the decoded
        // positions), so every tile's range lies inside them (ZBinTileMasks::build).
        float nearDepth = INFINITY, farDepth = -INFINITY;
        for (const TileSurfaceBounds& b : bounds)
            if (b.covered) {
                nearDepth = std::min(nearDepth, b.minDepthMetres);
                farDepth = std::max(farDepth, b.maxDepthMetres);
            }
        if (!(nearDepth <= farDepth))
            nearDepth = farDepth = 0.0f; // nothing covered: every bin empty, nothing to shade
        mBins.build(candidates, nearDepth, farDepth, mOptions.binCount, mOptions.spacing);
        mMasks.build(grid, edges, bounds, candidates, mBins);
        assign.stop();

        PassTimer shading(result, pass::kShading);
        accumulateLights(inputs, ZBinListSource(grid, mBins, mMasks), {}, result);
        shading.stop();

        if (mBlended.prepare(inputs))
            mBlended.shadeWithTileLists(gb.depth(), mOptions.tileSizePixels, true, result);

        result.parameters["tile"] = std::to_string(mOptions.tileSizePixels);
        result.parameters["bins"] = std::to_string(mOptions.binCount);
        result.parameters["spacing"] = mOptions.spacing == ZBinSpacing::Uniform ? "uniform" : "exp";
        result.parameters["lights_after_vfc"] = std::to_string(candidates.size());
        result.parameters["vfc_culled"] = std::to_string(spheres.size() - candidates.size());
        result.parameters["binned_lights"] = std::to_string(mBins.binnedCount());
        result.parameters["tile_light_pairs"] = std::to_string(mMasks.bitCount());
        result.parameters["mask_words"] = std::to_string(mMasks.wordCount());
        result.parameters["mask_bytes"] = std::to_string(mMasks.byteCount());
        result.parameters["bin_bytes"] = std::to_string(mBins.binBytes());
        result.parameters["sorted_bytes"] = std::to_string(mBins.sortedBytes());
        result.parameters["zbin_near_m"] = metres(nearDepth);
        result.parameters["zbin_far_m"] = metres(farDepth);
    }

private:
    ZBinnedOptions mOptions;
    ZBins mBins;          // storage reused across frames
    ZBinTileMasks mMasks; // likewise
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
};

const StageRegistrar kRegistrar(
    {.name = "zbinned",
     .description = "z-binning (Drobot 2017): depth-sorted lights, per-z-bin index ranges and "
                    "per-tile bit masks",
     .kind = StageKind::Exact,
     .options = {StageOption::integer("tile", 32, 4, 128, "tile size in pixels of the masks"),
                 StageOption::integer("bins", 1024, 1, kMaxZBinCount, "z-bins"),
                 StageOption::choice("spacing", {"uniform", "exp"},
                                     "z-bin boundaries between the G-buffer's nearest and "
                                     "farthest depth: linear or geometric")},
     .listOrder = 65},
    [](const StageOptions& table) {
        ZBinnedOptions options;
        options.tileSizePixels = table.integer("tile");
        options.binCount = table.integer("bins");
        options.spacing =
            table.text("spacing") == "uniform" ? ZBinSpacing::Uniform : ZBinSpacing::Exponential;
        return std::make_unique<ZBinnedStage>(options);
    });

} // namespace

} // namespace lighting
