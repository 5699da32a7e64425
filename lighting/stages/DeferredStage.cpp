// `deferred`: traditional deferred shading with light volumes (Ishmukhametov 2013, 1.3 and 3.5;
// Thaler 2011). Lights are processed one after another in ascending light order; each bounded
// light's volume is rasterized over the G-buffer (LightVolumes.h), and the pixels it covers
// decode the G-buffer surface, evaluate that light and ADD it to the pixel. Decoding the G-buffer
// once per light per pixel is the honest bandwidth cost of this technique (a GPU reads the
// G-buffer again in every light volume's pixel shader). Directional and ambient lights are
// full-screen quads at their place in the light order. Emission is added once per pixel after the
// last light (addEmission, LightListShading.h), inside "shading".
//
// Shading on the kernel (issue 14, "every stage uses the kernel"): the volume draw's fragment
// function does not shade pixel by pixel; it gathers the current light's covered pixels of its
// raster tile as a lane mask per 4x4 packet (TileBatch). When the light drawn in that tile
// changes (and for each tile's last light after the draw), every touched packet is decoded by the
// kernel's PacketDecoder on the StageInputs' ISA and shaded with that ONE light under that lane
// mask (kernel::shadePacket), its lanes starting from the pixels' running sums, which are stored
// back with lightsEvaluated + 1 and the light trace (traceAddedLight), as the per-pixel loop did.
// So the technique keeps its character: one light at a time, the G-buffer read (a packet at a
// time) once per light, one rasterizer draw in light order. Decoding a packet once and walking
// per-lane light lists instead (as `ideal` and `light-indexed` do) would need every light's
// coverage of a packet gathered before shading it, i.e. per-pixel light lists built by the volume
// draw and one shading pass over them: that is light-indexed deferred (LightIndexedStage.cpp),
// not this technique, so it is not offered as an option here.
//
// Exactness: every pixel receives its lights in ascending index order, one kernel call per light
// adding into its running sum, and skipped lights contribute exactly zero, so the image is bitwise
// equal to `brute`'s on the same ISA (a lane's value of a light does not depend on the other lanes
// of its packet, LightKernel.h). `--isa scalar` is evaluateLight lane by lane: bitwise the
// per-pixel loop this stage had before. A layout the packet decoder does not read (the check of
// accumulateLights, packetPathFits) is gathered pixel by pixel with GBuffer::surfaceAt
// (PacketPath::decode) and shaded on the kernel all the same.
//
// Threads: all volumes go through one rasterizer draw in light order (LightVolumes.h: the
// rasterizer keeps submission order per tile), parallel over tiles; a tile's batch is touched only
// by the task rasterizing that tile, then by one task per tile for the final flush. Packets and
// SIMT warps never straddle a tile (raster::kTileSize is a multiple of 8), so a pixel is written by
// one task only and the result does not depend on the thread count.
//
// SIMT cost model (lighting/README.md): a warp (8x4 or 8x8 pixels) pays a light, warpLanes lane
// slots, when any of its pixels is in that light's volume (passes the volume's tests), i.e. when
// any of its lanes would run that light's pixel shader; counted per light flush of a tile.
//
// Options (defaults first):
//   volume=sphere|rect  sphere: back faces of a circumscribing proxy (icosphere), depth test
//                       "surface not behind the back face"; rect: the sphere's screen rectangle
//   spot=cone|sphere    volume=sphere only: cone draws a spot light's pyramid proxy when it is
//                       smaller than its sphere proxy (LightVolumes.h); sphere always the sphere
//   stencil=0|1         1: also require the surface not in front of the volume's front face
//                       (two draws per light, a per-pixel mark)
//   vfc=1|0             CPU view-frustum culling of light spheres before any rasterizer set-up
// Every volume ends with the depth-bounds test (surface view depth within centre +- radius, and
// within the pyramid's depth range for cones).
// Passes: "cull" (view-frustum culling), "shading" (volume rasterization and shading, interleaved).
// Parameters: the volume options and statistics (recordVolumeParameters), isa, simt_warp,
// simt_lane_slots, and on the packet path packet_groups (kernel calls: one per light and touched
// packet) and the kernel's packet_lights_* counters, as accumulateLights records them.
#include "lighting/StageRegistry.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightVolumes.h"
#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/PacketDecoder.h"
#include "lighting/lists/LightListShading.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/KernelWork.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PassNames.h"
#include "lighting/stages/VolumeStageOptions.h"

namespace lighting {

namespace {

using kernel::kPacketHeight;
using kernel::kPacketLanes;
using kernel::kPacketWidth;

constexpr int kWarpWidth = 8; // pixels; a SIMT warp is 8x4 (32 lanes) or 8x8 (64 lanes)
constexpr int kTilePackets = raster::kTileSize / kPacketWidth; // packets along a tile's side
static_assert(raster::kTileSize % kWarpWidth == 0 && raster::kTileSize % 8 == 0,
              "packets and warps must not straddle a raster tile");
static_assert(kPacketWidth == kPacketHeight, "tiles hold square packet grids");
// Warps of a tile, the most there can be (8x4 warps).
constexpr int kTileWarps = (raster::kTileSize / kWarpWidth) * (raster::kTileSize / 4);
constexpr uint32_t kNoLight = UINT32_MAX;

// One raster tile's pixels of the light being drawn there: a lane mask per packet of the tile,
// the packets touched (first-touch order), and the tile's SIMT and kernel counters. Used by the
// one task rasterizing the tile at a time (LightVolumeRasterizer::tileOf).
struct alignas(64) TileBatch {
    uint32_t light = kNoLight;
    std::array<uint16_t, kTilePackets * kTilePackets> masks{}; // 0 outside the current light
    std::vector<uint16_t> touched;                             // packets with a non-zero mask
    std::array<uint32_t, kTileWarps> warpFlush{}; // per warp: the last flush that paid it
    uint32_t flushes = 0;
    KernelWork work; // SIMT lane slots and kernel counters
};

class DeferredStage final : public ShadingStage {
public:
    explicit DeferredStage(const VolumeStageOptions& volume) : mVolume(volume) {}

    std::string name() const override { return "deferred"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        if (inputs.simtWarpLanes != 32 && inputs.simtWarpLanes != 64)
            throw std::invalid_argument("deferred: simtWarpLanes must be 32 or 64, not " +
                                        std::to_string(inputs.simtWarpLanes));
        const int warpLanes = inputs.simtWarpLanes;
        const int warpPacketRows = warpLanes / kWarpWidth / kPacketHeight; // 1 or 2
        result.resize(width, height, false);

        VolumeCull cull = cullLightVolumes(gb, *inputs.lights, mVolume, result);
        PassTimer shading(result, pass::kShading);
        const PacketPath path(inputs);
        const kernel::KernelIsa isa = path.isa;
        const int tileCount = cull.volumes.tileCount();
        const int tilesX = (width + raster::kTileSize - 1) / raster::kTileSize;
        mBatches.resize(size_t(tileCount));
        for (TileBatch& batch : mBatches) {
            batch.light = kNoLight;
            batch.touched.clear();
            batch.work = {};
        }
        float* radiance[3] = {result.radiance[0].data(), result.radiance[1].data(),
                              result.radiance[2].data()};
        uint32_t* evaluated = result.lightsEvaluated.data();

        // Shades the batch's light at its touched packets and empties it. Called by the task that
        // owns the tile.
        auto flush = [&](TileBatch& batch, int tile) {
            if (batch.touched.empty())
                return;
            const uint32_t light = batch.light;
            const int tileX0 = (tile % tilesX) * raster::kTileSize;
            const int tileY0 = (tile / tilesX) * raster::kTileSize;
            ++batch.flushes;
            kernel::ShadingPacket packet;
            kernel::PacketAccumulator accumulator;
            for (const uint16_t index : batch.touched) {
                const uint32_t mask = batch.masks[index];
                batch.masks[index] = 0;
                const int packetX = index % kTilePackets, packetY = index / kTilePackets;
                // SIMT: the packet's warp pays this light once (warpLanes slots).
                const int warp = (packetY / warpPacketRows) * (kTilePackets / 2) + packetX / 2;
                if (batch.warpFlush[size_t(warp)] != batch.flushes) {
                    batch.warpFlush[size_t(warp)] = batch.flushes;
                    batch.work.laneSlots += uint64_t(warpLanes);
                }
                const int x0 = tileX0 + packetX * kPacketWidth;
                const int y0 = tileY0 + packetY * kPacketHeight;
                path.decode(x0, y0, packet);
                const uint32_t lanes = mask & packet.laneMask;
                if (lanes == 0)
                    continue;
                accumulator.clear();
                for (uint32_t rest = lanes; rest != 0; rest &= rest - 1) {
                    const int lane = __builtin_ctz(rest);
                    const size_t pixel = size_t(y0 + kernel::laneY(lane)) * size_t(width) +
                                         size_t(x0 + kernel::laneX(lane));
                    for (int c = 0; c < 3; ++c)
                        accumulator.radiance[c][lane] = radiance[c][pixel];
                }
                kernel::shadePacket(isa, packet, lanes, path.lights,
                                    std::span<const uint32_t>(&light, 1), accumulator,
                                    /*countContributing=*/false);
                for (uint32_t rest = lanes; rest != 0; rest &= rest - 1) {
                    const int lane = __builtin_ctz(rest);
                    const size_t pixel = size_t(y0 + kernel::laneY(lane)) * size_t(width) +
                                         size_t(x0 + kernel::laneX(lane));
                    for (int c = 0; c < 3; ++c)
                        radiance[c][pixel] = accumulator.radiance[c][lane];
                    evaluated[pixel] += accumulator.lightsEvaluated[lane];
                    result.traceAddedLight(pixel, light);
                }
                ++batch.work.groups;
                batch.work.addCounters(accumulator);
            }
            batch.touched.clear();
        };

        cull.volumes.draw(cull.spheres, cull.drawn, [&](uint32_t light, int x, int y, size_t) {
            const int tile = cull.volumes.tileOf(x, y);
            TileBatch& batch = mBatches[size_t(tile)];
            if (batch.light != light) {
                flush(batch, tile);
                batch.light = light;
            }
            const int localX = x % raster::kTileSize;
            const int localY = y % raster::kTileSize;
            const int index = (localY / kPacketHeight) * kTilePackets + localX / kPacketWidth;
            const int lane = (localY % kPacketHeight) * kPacketWidth + localX % kPacketWidth;
            uint16_t& mask = batch.masks[size_t(index)];
            if (mask == 0)
                batch.touched.push_back(uint16_t(index));
            mask = uint16_t(mask | (1u << lane));
        });
        // Each tile's last light.
        tbb::parallel_for(0, tileCount, [&](int tile) { flush(mBatches[size_t(tile)], tile); });
        addEmission(gb, result);
        shading.stop();
        // Blended surfaces: every light (light volumes are tested against the opaque depth).
        if (mBlended.prepare(inputs))
            mBlended.shadeWithEveryLight(gb.depth(), result);

        recordVolumeParameters(mVolume, cull.culled(), cull.volumes.stats(), result.parameters);
        KernelWork work;
        for (const TileBatch& batch : mBatches)
            work += batch.work;
        work.record(isa, warpLanes, result);
        path.record(result);
    }

private:
    VolumeStageOptions mVolume;
    BlendedPass mBlended;            // blended surfaces after the opaque pass (BlendedPass.h)
    std::vector<TileBatch> mBatches; // one per raster tile, reused across calls
};

const StageRegistrar kRegistrar(
    {.name = "deferred",
     .description = "traditional deferred: one light volume per light, shaded and added per "
                    "fragment",
     .kind = StageKind::Exact,
     .options = volumeStageOptionTable(),
     .listOrder = 30},
    [](const StageOptions& options) {
        return std::make_unique<DeferredStage>(volumeStageOptions(options));
    });

} // namespace

} // namespace lighting
