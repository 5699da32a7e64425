// FragmentShading: rasterized fragments shaded on the shared light kernel
// (lighting/kernel/LightKernel.h), in 16-lane fragment packets instead of one scalar
// evaluateLight loop per fragment: the forward stages' opaque fragments (`forward`,
// `forward-multipass`, `tiled-forward`) and every stage's blended fragments (BlendedPass.h).
//
// Why: a forward stage shades what the rasterizer emits, in submission order, not 4x4 blocks
// decoded from a G-buffer, so accumulateLights (LightAccumulation.h) does not fit. But the
// kernel's lanes are independent (each lane sums its own list in list order, bitwise
// independently of the other lanes), so a lane can hold any surface: here a packet's lanes are
// CONSECUTIVE FRAGMENTS of one raster tile, each with the surface the caller gives for it
// (ForwardGeometry::surfaceAt, BlendedPass's blended surface).
//
// How: the draw's fragment function decides what the stage decides today (visible or not, which
// surface, which list) and calls add() instead of shading. Fragments are queued per raster tile
// (the rasterizer's kTileSize x kTileSize screen tiles, raster/Rasterizer.h: a tile is drawn by one
// task at a time, in submission order) into a batch of `inputs.simtWarpLanes` (32 or 64)
// fragments, i.e. 2 or 4 packets. A full batch is shaded at once; flush() shades every tile's
// partial batch after the draw. Per packet: lanes grouped by list (PacketLightLists::
// addByKeyMerged: one kernel call over the union of the lanes' lists, each lane masked to its
// own list), shadePacket on inputs.isa, then the results applied lane by lane IN FRAGMENT ORDER
// with the stage's semantics (FragmentApply):
// - Replace (`forward`, `tiled-forward`): the pixel's radiance becomes the fragment's light sum
//   plus its emission; lightsEvaluated ADDS the list length (a forward pass without pre-pass
//   shades every fragment that passes the depth test: overdraw is real cost and stays counted
//   and shaded, a later fragment of the same pixel, even in the same packet, replaces it);
// - Add (`forward-multipass`): the fragment's light sum is added to the pixel's radiance, its
//   evaluations to lightsEvaluated (one additive pass per light; the stage adds the emission);
// - Over (blended fragments): the fragment's light sum plus its emission is composited over the
//   pixel with its alpha, radiance = alpha (sum + emitted) + (1 - alpha) radiance, the same
//   float expression BlendedPass's scalar loop had; lightsEvaluated adds the list length and,
//   when the stage counts the oracle itself (result.lightsOracle non-empty: `brute`),
//   lightsOracle adds the lane's contributing lights (the kernel's count).
// The light trace follows: Replace assigns the lane's list, Add appends its lights, Over appends
// a blended fragment (StageResult::traceBlendedFragment).
//
// Multisampling (begin() with a SampleRadiance: the forward stages' hardware-style MSAA, and the
// blended pass of every multisampled frame): the fragment is still shaded once, and its result is
// applied as above to each sample of its coverage mask (raster::Fragment::coverage, queued with
// it) in the per-sample colour buffer instead of the pixel (a buffer filled on demand first takes
// the pixel's radiance from the StageResult, SampleRadiance::over); lightsEvaluated still
// adds once per fragment, the opaque trace goes to the buffer's per-sample lists
// (SampleRadiance.h), blended fragments are traced per pixel.
//
// Exactness: a lane's sum is the kernel's sum over its own list in list order from 0, the same
// sequence of float operations `brute` runs on the same ISA at the same surface (bitwise the
// G-buffer's, ForwardGeometry.h); `--isa scalar` is evaluateLight lane by lane, bitwise the
// per-fragment loops these stages had before. An Add pass of one light adds (0 + r) = r.
//
// SIMT cost model (lighting/README.md): a warp is one batch, i.e. simtWarpLanes consecutive
// fragments of one raster tile in submission order (of one draw: batches never span draws), as a
// GPU packs the fragments of a draw into warps in rasterization order. It pays warpLanes lane
// slots (idle lanes of a tile's last, partial batch included) for every light of the union of its
// fragments' lists. Recorded with the packet counters (as accumulateLights does) by end().
//
// Memory: per raster tile one batch of at most 64 queued fragments (~130 bytes each: the surface
// is queued, so that the caller's surface, not a recomputed one, is shaded) plus its union
// scratch and copied lists (at most the batch's list lengths); atrium at 1280x720 has 60 tiles:
// ~0.5 MB.
//
// Determinism: a tile's batches are cut from its own fragment stream (submission order, the same
// for any thread count), shaded by the task that draws the tile (full batches) or by flush() (one
// task per tile); every pixel belongs to one tile. Counters are summed in tile order. So images,
// counts and parameters do not depend on the thread count.
//
// Thread safety: add() may be called concurrently for fragments of different raster tiles (the
// rasterizer's contract); begin(), flush() and end() from the stage's thread, between draws.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "gbuffer/Surface.h"
#include "lighting/ShadingStage.h"
#include "lighting/passes/SampleRadiance.h"
#include "raster/Rasterizer.h"

namespace lighting {

namespace kernel {
class KernelLights;
}

enum class FragmentApply {
    Replace, // the fragment's light sum + emission replaces the pixel's radiance
    Add,     // the fragment's light sum is added to the pixel's radiance
    Over,    // the fragment's light sum + emission is composited over the pixel with its alpha
};

class FragmentShading {
public:
    FragmentShading();
    ~FragmentShading();
    FragmentShading(const FragmentShading&) = delete;
    FragmentShading& operator=(const FragmentShading&) = delete;

    // Starts a pass: the kernel's lights from inputs.lights, inputs.isa, the warp size
    // (inputs.simtWarpLanes, 32 or 64), one batch per raster tile of the view. `result` (resized
    // already) receives the fragments and must outlive end(). With `samples` (multisampled
    // frames: reset to the view and inputs.samples) fragments are applied to their covered
    // samples there instead of to result.radiance (see the file comment).
    void begin(const StageInputs& inputs, FragmentApply apply, StageResult& result,
               SampleRadiance* samples = nullptr);
    // Queues a fragment of scene triangle `triangle` with surface `surface` (and, for Over, its
    // alpha) to be shaded with `lights` (ascending for exactness; must stay valid until the next
    // flush()), a list `listKey` identifies within the draw (equal keys = the same list: an
    // object, a tile, a light). Shades the fragment's tile batch when it is full. Called from the
    // draw's fragment function.
    void add(const raster::Fragment& fragment, uint32_t triangle, const gbuffer::Surface& surface,
             uint64_t listKey, std::span<const uint32_t> lights, float alpha = 1.0f);
    // As add(), for a list that is the fragment's own and may go away when this returns (a
    // thread_local scratch list): copied into the tile's batch, never grouped with another.
    void addCopyingList(const raster::Fragment& fragment, uint32_t triangle,
                        const gbuffer::Surface& surface, std::span<const uint32_t> lights,
                        float alpha = 1.0f);
    // For FragmentApply::Add: whether `positionView` is certainly beyond the range of `light`
    // (a point or spot light; false for the others), with a margin so that the kernel's range
    // test rejects it on every ISA. A light then adds exactly zero there.
    bool beyondRange(uint32_t light, const glm::vec3& positionView) const;
    // Queues a fragment every light of whose list is beyondRange there (FragmentApply::Add only):
    // it takes its lane of the warp and counts its evaluations like any fragment, but is neither
    // given a surface nor shaded (its sums are zero), and the packet counters are those of
    // shading it (its lights are rejected at range by all its lanes). What makes a light pass of
    // `forward-multipass` cheap where most of the illumination set lies outside the light's range.
    void addBeyondRange(const raster::Fragment& fragment, uint32_t triangle, uint64_t listKey,
                        std::span<const uint32_t> lights);
    // Shades every tile's queued fragments; after each draw, before its lists go away.
    void flush();
    // Ends the pass: records "isa", "simt_warp", "simt_lane_slots", "packet_groups" and the
    // packet_lights_* counters (LightAccumulation.h) in result.parameters, added to those an
    // earlier kernel pass of the frame recorded (KernelWork::record).
    void end();
    // Fragments queued since begin() (add, addCopyingList and addBeyondRange), all flushed.
    uint64_t fragmentCount() const;

private:
    struct TileBatch;
    TileBatch& tileOf(const raster::Fragment& fragment);
    void shadeBatch(TileBatch& batch);

    StageResult* mResult = nullptr;
    SampleRadiance* mSamples = nullptr; // multisampled: the per-sample colour, else null
    FragmentApply mApply = FragmentApply::Replace;
    bool mCountOracle = false;
    kernel::KernelIsa mIsa = kernel::KernelIsa::scalar();
    int mWarpLanes = 32;
    int mWidth = 0;
    int mTilesX = 0;
    std::unique_ptr<kernel::KernelLights> mLights;
    std::vector<TileBatch> mTiles;
};

} // namespace lighting
