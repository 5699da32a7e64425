// `light-indexed`: light-indexed deferred lighting (Trebilco 2009; Ishmukhametov 2013, 2.3).
// Pass "index": the light volumes of LightVolumes.h (the same proxies and tests as `deferred`)
// are rasterized in ascending light order into a per-pixel light-index list of at most `max`
// entries; directional and ambient lights enter every covered pixel's list. Pass "shading": each
// pixel is shaded once over its list with accumulateLights (LightAccumulation.h; the G-buffer is
// decoded once per pixel, not once per light as in `deferred`), by 4x4 packets whose lanes are
// grouped by equal lists (neighbouring pixels usually share theirs).
//
// Overflow never drops a light: a pixel whose list would exceed `max` is marked and shaded with
// the light list of its 16x16 screen tile (buildTileLightLists in culling/TileFrusta.h, `tiled`'s
// builder without its options: ascending), built only when some pixel overflowed. Like
// Filament's froxel overflow it is conservative, but it costs a tile's lights, not every light.
// parameters["overflow_pixels"] counts such pixels.
//
// Memory: max x 4 bytes per pixel for the lists plus 2 bytes of count and overflow flag (16 lights
// at 1280x720: 59 MB). Lists are ascending because lights are drawn in ascending order and each
// draw visits a pixel once, so the image is bitwise equal to `brute`'s. Deterministic: each draw
// writes a pixel from one task only.
//
// Options (defaults first):
//   max=16           list capacity per pixel, 1..255
//   volume=sphere|rect, spot=cone|sphere, stencil=0|1, vfc=1|0   as for `deferred`
// Passes: "cull", "index", "shading".
#include "lighting/StageRegistry.h"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightVolumes.h"
#include "lighting/culling/TileFrusta.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PassNames.h"
#include "lighting/stages/VolumeStageOptions.h"

namespace lighting {

namespace {

// Marks an overflowed pixel in the count plane (counts never exceed 255).
constexpr uint16_t kOverflowed = 0xFFFF;
// Tile size of the overflow fallback's lists: `tiled`'s default.
constexpr int kOverflowTileSize = 16;

// A packet's lanes grouped by equal per-pixel lists (an overflowed pixel uses its tile's list),
// each group shaded under its lane mask with its ascending list: every lane walks exactly its own
// list, as the per-pixel loop did.
class PerPixelListSource final : public PacketListSource {
public:
    PerPixelListSource(int width, const uint16_t* counts, const uint32_t* lists, size_t capacity,
                       const TileGrid& overflowGrid, const LightIndexLists& overflowLists)
        : mWidth(width), mCounts(counts), mLists(lists), mCapacity(capacity),
          mOverflowGrid(overflowGrid), mOverflowLists(overflowLists) {}
    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        lists.addByContent(packet, [&](int lane) {
            const int x = packet.x0 + kernel::laneX(lane), y = packet.y0 + kernel::laneY(lane);
            const size_t pixel = size_t(y) * size_t(mWidth) + size_t(x);
            if (mCounts[pixel] == kOverflowed) {
                const size_t tile = size_t(y / kOverflowTileSize) * mOverflowGrid.tileCountX +
                                    size_t(x / kOverflowTileSize);
                return mOverflowLists[tile];
            }
            return std::span<const uint32_t>(mLists + pixel * mCapacity, mCounts[pixel]);
        });
    }

private:
    int mWidth;
    const uint16_t* mCounts;
    const uint32_t* mLists;
    size_t mCapacity;
    const TileGrid& mOverflowGrid;
    const LightIndexLists& mOverflowLists;
};

class LightIndexedStage final : public ShadingStage {
public:
    LightIndexedStage(int maxLights, const VolumeStageOptions& volume)
        : mMaxLights(maxLights), mVolume(volume) {}

    std::string name() const override { return "light-indexed"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        const size_t capacity = size_t(mMaxLights);
        result.resize(width, height, false);

        VolumeCull cull = cullLightVolumes(gb, *inputs.lights, mVolume, result);
        PassTimer index(result, pass::kIndex);
        mCounts.assign(gb.pixelCount(), 0);
        mLists.resize(gb.pixelCount() * capacity);
        uint16_t* counts = mCounts.data();
        uint32_t* lists = mLists.data();
        auto append = [&](size_t pixel, uint32_t light) {
            uint16_t& count = counts[pixel];
            if (count == kOverflowed)
                return;
            if (count == capacity) {
                count = kOverflowed;
                return;
            }
            lists[pixel * capacity + count++] = light;
        };
        cull.volumes.draw(cull.spheres, cull.drawn,
                          [&](uint32_t light, int, int, size_t pixel) { append(pixel, light); });
        index.stop();

        PassTimer shading(result, pass::kShading);
        const bool anyOverflow =
            std::find(mCounts.begin(), mCounts.end(), kOverflowed) != mCounts.end();
        const TileGrid overflowGrid = TileGrid::make(width, height, kOverflowTileSize);
        if (anyOverflow)
            buildTileLightLists(gb.view(), overflowGrid,
                                computeTileSurfaceBounds(gb, overflowGrid, {}), cull.spheres, {},
                                mOverflowLists);
        else
            mOverflowLists.assign(std::span<const std::vector<uint32_t>>());
        const PerPixelListSource source(width, counts, lists, capacity, overflowGrid,
                                        mOverflowLists);
        accumulateLights(inputs, source, {}, result);
        uint64_t overflowPixels = 0;
        for (uint16_t count : mCounts)
            overflowPixels += count == kOverflowed ? 1 : 0;
        shading.stop();
        // Blended surfaces: every light (the per-pixel lists are the opaque surface's).
        if (mBlended.prepare(inputs))
            mBlended.shadeWithEveryLight(gb.depth(), result);

        result.parameters["max"] = std::to_string(mMaxLights);
        recordVolumeParameters(mVolume, cull.culled(), cull.volumes.stats(), result.parameters);
        result.parameters["overflow_pixels"] = std::to_string(overflowPixels);
    }

private:
    int mMaxLights;
    VolumeStageOptions mVolume;
    // Kept between frames so steady-state frames do not allocate.
    std::vector<uint16_t> mCounts;  // entries used, or kOverflowed
    std::vector<uint32_t> mLists;   // capacity entries per pixel
    LightIndexLists mOverflowLists; // per 16x16 tile, when some pixel overflowed
    BlendedPass mBlended;           // blended surfaces after the opaque pass (BlendedPass.h)
};

std::vector<StageOption> lightIndexedOptionTable() {
    std::vector<StageOption> table = {StageOption::integer(
        "max", 16, 1, 255,
        "per-pixel light list capacity; a pixel beyond it uses its tile's list")};
    for (StageOption& option : volumeStageOptionTable())
        table.push_back(std::move(option));
    return table;
}

const StageRegistrar kRegistrar(
    {.name = "light-indexed",
     .description = "light-indexed deferred: volumes write per-pixel light lists, overflow "
                    "shades its tile's lights",
     .kind = StageKind::Exact,
     .options = lightIndexedOptionTable(),
     .listOrder = 40},
    [](const StageOptions& options) {
        const VolumeStageOptions volume = volumeStageOptions(options);
        return std::make_unique<LightIndexedStage>(options.integer("max"), volume);
    });

} // namespace

} // namespace lighting
