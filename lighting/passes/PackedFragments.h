// PackedFragments: the other fragments of a multisampled frame's complex pixels (the fragment
// layers above 0, gbuffer/msaa/FragmentLayers.h) packed into one list, and how a stage shades them
// in ONE run with full SIMD packets (Lauritzen 2010: the complex samples gathered so that lanes
// stay full), instead of one run per layer over screen-sized G-buffers that are mostly empty.
//
// Why: an upper layer's fragments lie at complex pixels only, so a per-layer run
// (MultisampleShading without this) walks every 4x4 packet of the screen to find them, shades the
// few it finds in packets with one or two live lanes, and pays the stage's whole-screen work (tile
// bounds and lists, cluster assignment, result planes) once per layer. Measured on atrium 1280x720,
// 256 lights, 4x with discontinuity detection (2.7% of the pixels hold a second fragment): the
// three upper runs cost 6.5 ms (clustered) and 9 ms (tiled), against about 0.35 ms for their
// fragments at layer 0's cost per pixel.
//
// The list: row-major, each complex pixel's fragments in layer order (what FragmentLayers keeps in
// upperColumns: the order the resolve walks). Packets take the fragments in screen-block order
// (PackedFragments::inShadingOrder), so that a packet's lanes are neighbouring pixels, mostly
// under one tile's or cluster's list. Each lane's surface is GBuffer::decode of its layer's
// G-buffer at its pixel (bitwise what the per-layer run's packet decoder gives), its list the
// stage's (FragmentListSource). The run writes a StageResult of width = the fragment count and
// height 1: radiance (the light sum plus the fragment's emission) and lightsEvaluated per fragment,
// the light trace per fragment when tracing, the stage's passes and the kernel's counters.
//
// Exactness: each lane sums exactly its own list in list order, as in accumulateLights, so a
// stage that is exact per layer is exact here, and bitwise the per-layer run's radiance at every
// fragment for the same ISA (lists may differ: the tiles' bounds now span every layer's fragments
// in the tile, the clusters are layer 0's grid; the culled lights contribute exactly zero).
// Deterministic: warps in list order in parallel, counters summed in warp order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/GBuffer.h"
#include "gbuffer/msaa/FragmentLayers.h"
#include "lighting/ShadingStage.h"

namespace lighting {

class PackedFragments {
public:
    // Packs every fragment of the layers above 0 (none when there is one layer). Storage is kept
    // between builds.
    void build(const gbuffer::FragmentLayers& layers);

    size_t size() const { return mPixels.size(); }
    // Fragment i: its pixel (y width + x) and layer (>= 1).
    uint32_t pixel(size_t i) const { return mPixels[i]; }
    // Its column and row.
    int x(size_t i) const { return int(mPixels[i] % uint32_t(mWidth)); }
    int y(size_t i) const { return int(mPixels[i] / uint32_t(mWidth)); }
    int layer(size_t i) const { return mLayers[i]; }
    // The fragments of row y are [rowFirst(y), rowFirst(y + 1)).
    size_t rowFirst(int y) const { return mRowFirst[size_t(y)]; }
    int width() const { return mWidth; }
    // The order packets take them in: screen blocks of kBlockPixels squared, the blocks row by
    // row, each block's fragments in list order. Consecutive fragments of a row lie at edges far
    // apart, in other tiles and clusters, and a packet of them walks the union of their lists;
    // a block's are neighbours, mostly under one list (measured: the row order cost the packed
    // run about twice its block order's time on atrium).
    static constexpr int kBlockPixels = 16;
    uint32_t inShadingOrder(size_t j) const { return mOrder[j]; }

private:
    std::vector<uint32_t> mOrder;
    std::vector<uint32_t> mPixels;
    std::vector<uint8_t> mLayers;
    std::vector<size_t> mRowFirst; // height + 1 entries
    int mWidth = 0;
};

// One packed run's inputs: the frame (layer 0's inputs, fragmentLayers set; shade() has run on
// them), each layer's G-buffer (index k; the same view and layout as layer 0's), the fragments.
struct PackedFragmentRun {
    const StageInputs* frame = nullptr;
    std::vector<const gbuffer::GBuffer*> layerGBuffers;
    const PackedFragments* fragments = nullptr;

    const gbuffer::GBuffer& gbufferOf(size_t fragment) const {
        return *layerGBuffers[size_t(fragments->layer(fragment))];
    }
};

// A stage that can shade a frame's packed fragments (tiled, clustered): MultisampleShading asks
// for this interface and calls shadeFragments right after shade() on layer 0, instead of running
// the stage once per upper layer. It returns false, having done nothing, when its configuration
// does not support it (the caller then runs the layers one by one).
class PackedFragmentShading {
public:
    virtual ~PackedFragmentShading() = default;
    // Resizes `result` to run.fragments->size() x 1 and fills it (see the file comment), with the
    // stage's passes timed as in shade() (they add to the frame's).
    virtual bool shadeFragments(const PackedFragmentRun& run, StageResult& result) = 0;
};

// The light list of a fragment at pixel (x, y) with view-space position `positionView` (decoded):
// a tile's or a cluster's, ascending. Called concurrently: must only read shared state; the list
// must live until the run ends.
class FragmentListSource {
public:
    virtual ~FragmentListSource() = default;
    virtual std::span<const uint32_t> listOf(int x, int y, const glm::vec3& positionView) const = 0;
};

// Shades every fragment of the run with its list on the kernel (run.frame->isa), in packets of 16
// consecutive fragments, warps of run.frame->simtWarpLanes; fills `result` (resized already):
// radiance, lightsEvaluated, the trace when tracing, and records "isa", "simt_warp" and the
// kernel counters (KernelWork::record; a warp pays its lanes for the union of its lists).
void accumulatePackedFragments(const PackedFragmentRun& run, const FragmentListSource& source,
                               StageResult& result);

} // namespace lighting
