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
// nearest and farthest covered depth, the masks over each covered tile's window of bins.
// Shading ("shading" pass): accumulateLights (LightAccumulation.h) by 4x4 packets, lanes grouped by
// tile. lists=packet: one list per group, the tile's bits inside the hull of the ranges of the bins
// from its nearest to its farthest lane (Drobot's wave-uniform range: every lane walks it).
// lists=pixel: each lane exactly its own bin's bits (per-light lane masks; lights.evaluated is then
// the per-pixel candidate count, as in `clustered`). The kernel sums in ascending light index
// (ShadingStage.h) and the bits come in depth order, so each thread keeps its current tile's bits
// sorted by light index with their sorted positions (built once per thread and tile visit), and a
// list is a filter of it by range: the image is bitwise `brute`'s on the same ISA. This gathering
// is the stage's lookup cost, the z-binned counterpart of reading a cluster's list, and is timed in
// the shading pass, as it runs in the shader on a GPU.
//
// Options (defaults first):
//   tile=32          tile size in pixels (4..128): 920 tiles at 1280x720, which keeps the masks
//                    small at 10^6 lights (see lighting/culling/README.md for the measured bytes)
//   bins=1024        z-bins (1..65536)
//   spacing=uniform|exp  bin boundaries linear in view depth (Drobot's) or geometric, between the
//                    G-buffer's nearest and farthest covered depth
//   lists=packet|pixel   (above)
// Parameters: the options, lights_after_vfc, vfc_culled, binned_lights (bounded lights overlapping
// the depth range), tile_light_pairs (mask bits set), mask_words, mask_bytes, bin_bytes,
// sorted_bytes, zbin_near_m, zbin_far_m.
// MSAA: through the fragment layers, as `tiled` (MultisampleShading.h): each layer gets its own
// bins and masks from its own depth. Blended surfaces: the near-to-opaque tile lists of the tiled
// stages (BlendedPass::shadeWithTileLists), as `tiled`.
// Threads: the builds are deterministic (ZBins.h); each pixel is written by one task; per-packet
// scratch is per thread (a thread shades one packet at a time, so a list stays put until its
// packet is shaded).
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
    bool perPixelLists = false;
};

// The lists of a packet from the bins and the masks (see the file comment).
class ZBinListSource final : public PacketListSource {
public:
    // perPixel: each lane exactly its own bin's candidates (per-light lane masks); otherwise one
    // list per packet and tile over the hull of the ranges of its lanes' bins (every lane walks
    // it, as a GPU wave walks Drobot's wave-uniform range).
    ZBinListSource(const TileGrid& grid, const ZBins& bins, const ZBinTileMasks& masks,
                   bool perPixel)
        : mGrid(grid), mBins(bins), mMasks(masks), mPerPixel(perPixel) {}

    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        Scratch& scratch = mScratch.local();
        // Lane bins: the nearest and the farthest lane's by search; when they differ and lists
        // are per pixel, each lane's is the nearest's plus the boundaries in between its depth
        // reaches (binOfDepth's own comparisons, as `clustered` finds slices).
        float nearest = INFINITY, farthest = -INFINITY;
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const float depth = -packet.positionView[2][__builtin_ctz(lanes)];
            nearest = std::min(nearest, depth);
            farthest = std::max(farthest, depth);
        }
        const int nearBin = mBins.binOfDepth(nearest), farBin = mBins.binOfDepth(farthest);
        const int firstTileX = packet.x0 / mGrid.tileSizePixels;
        const int firstTileY = packet.y0 / mGrid.tileSizePixels;
        const int lastX = std::min(packet.x0 + kernel::kPacketWidth, mGrid.widthPixels) - 1;
        const int lastY = std::min(packet.y0 + kernel::kPacketHeight, mGrid.heightPixels) - 1;
        if ((nearBin == farBin || !mPerPixel) && lastX / mGrid.tileSizePixels == firstTileX &&
            lastY / mGrid.tileSizePixels == firstTileY) {
            // One tile and one list (most packets): reused while the thread's next packets have
            // the same tile and range.
            const size_t tile = size_t(firstTileY) * size_t(mGrid.tileCountX) + size_t(firstTileX);
            const ZBins::Range range = mBins.rangeOfBins(nearBin, farBin);
            if (!(scratch.single && scratch.singleTile == tile &&
                  scratch.singleRange.first == range.first &&
                  scratch.singleRange.last == range.last)) {
                scratch.lights.clear();
                const TileLights& tileLights = lightsOfTile(scratch, tile);
                for (size_t j = 0; j < tileLights.lights.size(); ++j)
                    if (inRange(tileLights.positions[j], range))
                        scratch.lights.push_back(tileLights.lights[j]);
                scratch.single = true;
                scratch.singleTile = tile;
                scratch.singleRange = range;
            }
            lists.addTransient(packet.laneMask, scratch.lights);
            return;
        }
        scratch.single = false;
        scratch.lights.clear();
        scratch.laneMasks.clear();
        int tileOfLane[kernel::kPacketLanes];
        int binOfLane[kernel::kPacketLanes];
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const int lane = __builtin_ctz(lanes);
            const int x = packet.x0 + kernel::laneX(lane), y = packet.y0 + kernel::laneY(lane);
            tileOfLane[lane] =
                (y / mGrid.tileSizePixels) * mGrid.tileCountX + x / mGrid.tileSizePixels;
            const float depth = -packet.positionView[2][lane];
            int bin = nearBin;
            for (int k = nearBin + 1; k <= farBin; ++k)
                bin += mBins.boundary(k) <= depth ? 1 : 0;
            binOfLane[lane] = bin;
        }
        struct Group {
            uint32_t laneMask;
            size_t begin, end;
            bool perLane; // lanes in several bins: per-light lane masks
        };
        Group groups[kernel::kPacketLanes];
        int groupCount = 0;
        for (uint32_t remaining = packet.laneMask; remaining != 0;) {
            const int tile = tileOfLane[__builtin_ctz(remaining)];
            uint32_t groupMask = 0;
            // The group's distinct bins and the lanes in each.
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
            const TileLights& tileLights = lightsOfTile(scratch, size_t(tile));
            const size_t begin = scratch.lights.size();
            const bool perLane = mPerPixel && binCount > 1;
            if (!perLane) {
                // One list for the group: its one bin, or the hull of the bins from its nearest
                // to its farthest.
                const auto [lowBin, highBin] = std::minmax_element(bins, bins + binCount);
                const ZBins::Range range = mBins.rangeOfBins(*lowBin, *highBin);
                for (size_t j = 0; j < tileLights.lights.size(); ++j)
                    if (inRange(tileLights.positions[j], range))
                        scratch.lights.push_back(tileLights.lights[j]);
            } else {
                ZBins::Range ranges[kernel::kPacketLanes];
                for (int k = 0; k < binCount; ++k)
                    ranges[k] = mBins.range(bins[k]);
                for (size_t j = 0; j < tileLights.lights.size(); ++j) {
                    uint32_t lanes = 0;
                    for (int k = 0; k < binCount; ++k)
                        if (inRange(tileLights.positions[j], ranges[k]))
                            lanes |= binLanes[k];
                    if (lanes != 0) {
                        scratch.lights.push_back(tileLights.lights[j]);
                        scratch.laneMasks.push_back(uint16_t(lanes));
                    }
                }
            }
            groups[groupCount++] = {groupMask, begin, scratch.lights.size(), perLane};
            if (!perLane) // keep laneMasks aligned with lights
                scratch.laneMasks.resize(scratch.lights.size(), uint16_t(groupMask));
        }
        // The lists, in storage that stays put until this packet is shaded (the next call on this
        // thread is for the next packet).
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
    // A tile's lights in ascending light index, each with its sorted position (UINT32_MAX for the
    // unbounded lights, which every range takes): the tile's mask bits over its whole window,
    // sorted once per thread and tile, so that a packet's list is a filter by range that is
    // already in the order the kernel sums in.
    struct TileLights {
        size_t tile = SIZE_MAX;
        std::vector<uint32_t> lights;
        std::vector<uint32_t> positions;
    };
    struct Scratch {
        TileLights tileLights;
        std::vector<uint64_t> keys;
        std::vector<uint32_t> lights;
        std::vector<uint16_t> laneMasks;
        // `lights` holds the one list of a one-tile packet with this tile and range.
        bool single = false;
        size_t singleTile = 0;
        ZBins::Range singleRange;
    };

    static bool inRange(uint32_t position, ZBins::Range range) {
        return position == UINT32_MAX || (range.first <= position && position <= range.last);
    }

    const TileLights& lightsOfTile(Scratch& scratch, size_t tile) const {
        TileLights& t = scratch.tileLights;
        if (t.tile == tile)
            return t;
        scratch.keys.clear();
        mMasks.forEachSetBit(tile, 0, UINT32_MAX, [&](uint32_t position) {
            scratch.keys.push_back(uint64_t(mBins.sortedLight(position)) << 32 | position);
        });
        for (uint32_t light : mBins.unboundedLights())
            scratch.keys.push_back(uint64_t(light) << 32 | UINT32_MAX);
        std::sort(scratch.keys.begin(), scratch.keys.end());
        t.lights.resize(scratch.keys.size());
        t.positions.resize(scratch.keys.size());
        for (size_t i = 0; i < scratch.keys.size(); ++i) {
            t.lights[i] = uint32_t(scratch.keys[i] >> 32);
            t.positions[i] = uint32_t(scratch.keys[i]);
        }
        t.tile = tile;
        return t;
    }

    const TileGrid& mGrid;
    const ZBins& mBins;
    const ZBinTileMasks& mMasks;
    bool mPerPixel;
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
        accumulateLights(inputs, ZBinListSource(grid, mBins, mMasks, mOptions.perPixelLists), {},
                         result);
        shading.stop();

        if (mBlended.prepare(inputs))
            mBlended.shadeWithTileLists(gb.depth(), mOptions.tileSizePixels, true, result);

        result.parameters["tile"] = std::to_string(mOptions.tileSizePixels);
        result.parameters["bins"] = std::to_string(mOptions.binCount);
        result.parameters["spacing"] = mOptions.spacing == ZBinSpacing::Uniform ? "uniform" : "exp";
        result.parameters["lists"] = mOptions.perPixelLists ? "pixel" : "packet";
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
                                     "farthest depth: linear or geometric"),
                 StageOption::choice("lists", {"packet", "pixel"},
                                     "packet: one list per packet and tile over the hull of its "
                                     "lanes' bin ranges (Drobot's wave-uniform ranges); pixel: "
                                     "each pixel exactly its own bin's lights (lane masks)")},
     .listOrder = 65},
    [](const StageOptions& table) {
        ZBinnedOptions options;
        options.tileSizePixels = table.integer("tile");
        options.binCount = table.integer("bins");
        options.spacing =
            table.text("spacing") == "uniform" ? ZBinSpacing::Uniform : ZBinSpacing::Exponential;
        options.perPixelLists = table.text("lists") == "pixel";
        return std::make_unique<ZBinnedStage>(options);
    });

} // namespace

} // namespace lighting
