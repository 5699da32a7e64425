// accumulateLights: the one "sum the lights, store the pixel" loop of the G-buffer stages (issue
// 14, section 1): brute, tiled, tiled-backface, clustered and light-indexed call it with their
// light lists instead of each copying a per-pixel loop. accumulateSplitLights (below) is its form
// for the light-buffer stages (light-prepass, inferred): the same packets, lists, paths and SIMT
// counters, with split diffuse / specular sums (kernel::shadePacketSplit). (`deferred`, which
// shades light by light over its volumes' pixels, calls the kernel itself and shares the path
// check, packetPathFits.)
//
// The frame is walked in SIMT warps (8x4 pixels, or 8x8), each made of 4x4-pixel packets. Per
// packet: decode the G-buffer (lighting/kernel/PacketDecoder.h), ask the stage's PacketListSource
// which light list each lane uses (lanes grouped by list: a mask per list), shade each group
// with the kernel (lighting/kernel/LightKernel.h, the StageInputs' KernelIsa), and store every
// covered lane's radiance and lights.evaluated (and, when asked, the oracle count). Each lane is
// summed over its own list in list order, so an ascending list gives bitwise the image `brute`
// gives with the same ISA whenever the culled lights contribute exactly zero.
//
// Two paths, chosen once per frame by packetPathFits in LightAccumulation.cpp (the one place that
// check lives):
// - packets: the G-buffer layout is one PacketDecoder reads (either material model, or both);
//   the kernel runs on the requested ISA (`scalar` = evaluateLight lane by lane, bitwise the
//   per-pixel loop; a vector target differs from it by a few ulps on Blinn-Phong lanes, through
//   pow, and not at all on metallic-roughness lanes, lighting/kernel/README.md);
// - per pixel: otherwise (layouts with normal codes, packed albedo, specular, roughness-metallic
//   or occlusion, world-space normals): GBuffer::surfaceAt and evaluateLight pixel by pixel, over
//   the same lists, in the same order.
//   result.parameters["isa"] then says "scalar" whatever was requested.
//
// SIMT cost model (issue 14, section 3; lighting/README.md): a warp pays one lane slot per lane
// (all of its warpLanes, covered or not) for every light that any of its lanes evaluates, i.e.
// warpLanes x |union of its lanes' lists|. The loop sums this into "simt_lane_slots"; the runner
// divides the oracle's evaluations by it (simt_efficiency, experiments/render/RunMetrics.h).
//
// Determinism: warps rows in parallel (TBB), each pixel written by one task, the per-row counters
// summed in row order after the loop: the result does not depend on the thread count.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "lighting/ShadingStage.h"
#include "lighting/culling/LightIndexLists.h"
#include "lighting/kernel/KernelIsa.h"
#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/PacketDecoder.h"
#include "lighting/kernel/ShadingPacket.h"
#include "lighting/kernel/SplitLightKernel.h"

namespace lighting {

namespace kernel {
struct GBufferPlanes; // PacketDecoder.h
} // namespace kernel

// The lists of one packet: groups of lanes, each with the light indices (ascending for exactness)
// its lanes are shaded with. A lane in no group gets no light (radiance 0, evaluated 0).
class PacketLightLists {
public:
    // Adds `laneMask`'s lanes (ignored when 0) with `lights`; a lane must be in one group only.
    void add(uint32_t laneMask, std::span<const uint32_t> lights) {
        if (laneMask != 0)
            mGroups[mCount++] = {laneMask, lights, {}, false};
    }
    // Per-lane lists as one union list: light lights[i] is evaluated on the lanes
    // laneMask & lightLaneMasks[i] only, so each lane sums its own sub-list in list order (the
    // kernel's per-light lane masks, LightKernel.h; `ideal`). Sizes must match.
    void add(uint32_t laneMask, std::span<const uint32_t> lights,
             std::span<const uint16_t> lightLaneMasks) {
        if (laneMask != 0)
            mGroups[mCount++] = {laneMask, lights, lightLaneMasks, false};
    }
    // As add(), for lists a source builds per packet in storage of its own that it rewrites for
    // its next packet (z-binned): valid until this packet is shaded, so the SIMT model counts them
    // at once instead of keeping the span for the rest of the warp (Group::scratch).
    void addTransient(uint32_t laneMask, std::span<const uint32_t> lights,
                      std::span<const uint16_t> lightLaneMasks = {}) {
        if (laneMask != 0)
            mGroups[mCount++] = {laneMask, lights, lightLaneMasks, true};
    }
    // Groups the covered lanes of `packet` by the key lane -> keyOf(lane), whose equal values
    // mean the same list listOf(key); for per-tile or per-cluster lists.
    template <class KeyOf, class ListOf>
    void addByKey(const kernel::ShadingPacket& packet, const KeyOf& keyOf, const ListOf& listOf) {
        uint32_t remaining = packet.laneMask;
        while (remaining != 0) {
            const int first = __builtin_ctz(remaining);
            const auto key = keyOf(first);
            uint32_t mask = 0;
            for (uint32_t lanes = remaining; lanes != 0; lanes &= lanes - 1) {
                const int lane = __builtin_ctz(lanes);
                if (lane == first || keyOf(lane) == key)
                    mask |= 1u << lane;
            }
            remaining &= ~mask;
            add(mask, listOf(key));
        }
    }

    // As addByKey, but a packet whose lanes fall under several keys gets ONE group: the union of
    // their lists (ascending lists give an ascending union) with per-light lane masks, so a light
    // in several of the lists costs one packet-wide evaluation instead of one per list, and each
    // lane still sums exactly its own list in its order (bitwise addByKey's result). The union
    // lives in this object's scratch storage until clear(): at most one such union per packet.
    // Lists must be ascending.
    template <class KeyOf, class ListOf>
    void addByKeyMerged(const kernel::ShadingPacket& packet, const KeyOf& keyOf,
                        const ListOf& listOf) {
        using Key = decltype(keyOf(0));
        Key keys[kernel::kPacketLanes];
        Key distinct[kernel::kPacketLanes];
        uint32_t masks[kernel::kPacketLanes];
        int count = 0;
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const int lane = __builtin_ctz(lanes);
            keys[lane] = keyOf(lane);
            int k = 0;
            while (k < count && !(distinct[k] == keys[lane]))
                ++k;
            if (k == count) {
                distinct[count] = keys[lane];
                masks[count++] = 0;
            }
            masks[k] |= 1u << lane;
        }
        if (count == 1) {
            add(masks[0], listOf(distinct[0]));
            return;
        }
        // k-way merge of the (ascending) lists; equal heads merge their lane masks.
        std::span<const uint32_t> heads[kernel::kPacketLanes];
        for (int k = 0; k < count; ++k)
            heads[k] = listOf(distinct[k]);
        if (!mScratchLights.empty())
            throw std::logic_error("PacketLightLists: one merged union per packet");
        const size_t begin = 0;
        if (count == 2) {
            // The common case (a packet across one tile edge or one slice boundary): a branch-free
            // two-way merge, the same union and masks as the general loop below.
            mergeTwo(heads[0], masks[0], heads[1], masks[1]);
            heads[0] = heads[1] = {};
        }
        for (;;) {
            uint32_t smallest = UINT32_MAX;
            for (int k = 0; k < count; ++k)
                if (!heads[k].empty() && heads[k].front() < smallest)
                    smallest = heads[k].front();
            if (smallest == UINT32_MAX)
                break;
            uint32_t mask = 0;
            for (int k = 0; k < count; ++k)
                if (!heads[k].empty() && heads[k].front() == smallest) {
                    mask |= masks[k];
                    heads[k] = heads[k].subspan(1);
                }
            mScratchLights.push_back(smallest);
            mScratchMasks.push_back(uint16_t(mask));
        }
        uint32_t all = 0;
        for (int k = 0; k < count; ++k)
            all |= masks[k];
        mGroups[mCount++] = {all, std::span<const uint32_t>(mScratchLights).subspan(begin),
                             std::span<const uint16_t>(mScratchMasks).subspan(begin), true};
    }

    // Groups the covered lanes of `packet` whose lists listOfLane(lane) hold the same indices
    // (per-pixel lists, e.g. light-indexed: neighbours often share one).
    template <class ListOfLane>
    void addByContent(const kernel::ShadingPacket& packet, const ListOfLane& listOfLane) {
        uint32_t remaining = packet.laneMask;
        while (remaining != 0) {
            const int first = __builtin_ctz(remaining);
            const std::span<const uint32_t> list = listOfLane(first);
            uint32_t mask = 1u << first;
            for (uint32_t lanes = remaining & (remaining - 1); lanes != 0; lanes &= lanes - 1) {
                const int lane = __builtin_ctz(lanes);
                const std::span<const uint32_t> other = listOfLane(lane);
                if (std::equal(list.begin(), list.end(), other.begin(), other.end()))
                    mask |= 1u << lane;
            }
            remaining &= ~mask;
            add(mask, list);
        }
    }

    struct Group {
        uint32_t laneMask = 0;
        std::span<const uint32_t> lights;
        std::span<const uint16_t> lightLaneMasks; // empty: every light on every lane of laneMask
        bool scratch = false; // `lights` lives in scratch storage (until clear() or the next
                              // packet): addByKeyMerged's union, addTransient's lists
        // Whether lane `lane` of the group evaluates light lights[i].
        bool evaluates(int lane, size_t i) const {
            return (laneMask >> lane & 1u) &&
                   (lightLaneMasks.empty() || (lightLaneMasks[i] >> lane & 1u));
        }
    };
    int size() const { return mCount; }
    const Group& operator[](int i) const { return mGroups[i]; }
    void clear() {
        mCount = 0;
        mScratchLights.clear();
        mScratchMasks.clear();
    }

private:
    // Appends the ascending union of a and b to the scratch lists, each light with the mask of
    // the lists holding it.
    void mergeTwo(std::span<const uint32_t> a, uint32_t maskA, std::span<const uint32_t> b,
                  uint32_t maskB) {
        const size_t total = a.size() + b.size();
        mScratchLights.resize(total);
        mScratchMasks.resize(total);
        uint32_t* lights = mScratchLights.data();
        uint16_t* masks = mScratchMasks.data();
        size_t i = 0, j = 0, n = 0;
        while (i < a.size() && j < b.size()) {
            const uint32_t x = a[i], y = b[j];
            const uint32_t smallest = std::min(x, y);
            lights[n] = smallest;
            masks[n] = uint16_t((x == smallest ? maskA : 0u) | (y == smallest ? maskB : 0u));
            ++n;
            i += x == smallest ? 1 : 0;
            j += y == smallest ? 1 : 0;
        }
        for (; i < a.size(); ++i, ++n) {
            lights[n] = a[i];
            masks[n] = uint16_t(maskA);
        }
        for (; j < b.size(); ++j, ++n) {
            lights[n] = b[j];
            masks[n] = uint16_t(maskB);
        }
        mScratchLights.resize(n);
        mScratchMasks.resize(n);
    }

    Group mGroups[kernel::kPacketLanes];
    int mCount = 0;
    // The merged union of addByKeyMerged and its lane masks (one per packet, so no span into them
    // is invalidated by a later push_back).
    std::vector<uint32_t> mScratchLights;
    std::vector<uint16_t> mScratchMasks;
};

// What a stage gives the loop: the lists of a packet (its x0, y0, laneMask and decoded
// view-space positions are set). Called once per
// packet from several threads at once: it must only read shared state.
class PacketListSource {
public:
    virtual ~PacketListSource() = default;
    virtual void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const = 0;
};

// Every light of the frame for every covered lane (`brute`).
class EveryLightSource final : public PacketListSource {
public:
    explicit EveryLightSource(size_t lightCount);
    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        lists.add(packet.laneMask, mIndices);
    }

private:
    std::vector<uint32_t> mIndices; // 0 .. n-1
};

struct AccumulationOptions {
    // Count the contributing lights into result.lightsOracle (the stage must have resized with
    // the oracle plane): `brute`, which evaluates every light anyway.
    bool countOracle = false;
};

// Shades every covered pixel of inputs.gbuffer with its lists and writes result.radiance (the light
// sum, plus the pixel's emission, GBuffer::emission, once, when the layout stores any),
// result.lightsEvaluated (and lightsOracle when asked); result must be resized already. Records
// the parameters "isa" (what ran), "simt_warp" and "simt_lane_slots", and on the packet path the
// packet-level work: "packet_groups" (kernel calls), "packet_lights_skipped_at_range",
// "packet_lights_skipped_at_cone_or_facing" and "packet_lights_shaded" (packet-wide light
// iterations by outcome, the kernel's cost drivers). Adds no timing: the stage times its own
// "shading" pass around the call.
void accumulateLights(const StageInputs& inputs, const PacketListSource& source,
                      const AccumulationOptions& options, StageResult& result);

// A packet's lanes grouped by square tile of `tileSize` (pixels, or samples on a lattice; tile
// (tx, ty) is number ty * tileCountX + tx), each group with its tile's list: the lists of the
// tiled stages (a packet spans several tiles when the tile size is not a multiple of 4).
class TileListSource final : public PacketListSource {
public:
    TileListSource(int tileSize, int tileCountX, const LightIndexLists& tileLights)
        : mTileSize(tileSize), mTileCountX(tileCountX), mTileLights(tileLights) {}
    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        lists.addByKey(
            packet,
            [&](int lane) {
                return ((packet.y0 + kernel::laneY(lane)) / mTileSize) * mTileCountX +
                       (packet.x0 + kernel::laneX(lane)) / mTileSize;
            },
            [&](int tile) { return mTileLights[size_t(tile)]; });
    }

private:
    int mTileSize;
    int mTileCountX;
    const LightIndexLists& mTileLights;
};

// Split lighting (lighting/brdf/SplitLighting.h) for the stages that accumulate light buffers,
// `light-prepass` and `inferred`: the one loop that lights their samples, in place of two
// per-pixel loops around splitLighting.
//
// Samples: a lattice over the G-buffer, sample (i, j) reading pixel
// (min(i scale + scale / 2, W - 1), min(j scale + scale / 2, H - 1)): scale 1 is every pixel
// (light-prepass), scale s inferred's L-buffer. Packets are 4x4 SAMPLES (packet.x0, y0 and the
// lanes' coordinates are sample coordinates, which the list source keys its tiles by); a packet of
// pixels (scale 1) is decoded by kernel::PacketDecoder, a strided one gathered lane by lane with
// GBuffer::surfaceAt (the same surfaces, bitwise). Then kernel::shadePacketSplit per lane group on
// inputs.isa, and the sink stores the lanes. A layout the packet decoder refuses is gathered
// pixel by pixel at scale 1 too (PacketPath), and shaded the same way. `--isa scalar` runs the
// kernel's scalar split path: addSplitLight lane by lane, bitwise splitLighting. Vector ISAs:
// diffuse and metallic-roughness sums bitwise, the Blinn-Phong specular sum within a few ulps (pow;
// kernel/SplitLightKernel.h). Fills lane `lane` of `packet` with surface `s`, either material
// model: how every loop that gathers its lanes (lattice samples, queued fragments, held surfaces)
// fills one.
inline void setLaneSurface(kernel::ShadingPacket& packet, int lane, const gbuffer::Surface& s) {
    packet.setLane(lane, s.positionView, s.normalView, s.albedo, s.specularIntensity,
                   s.specularPower);
    if (s.model == scenes::MaterialModel::MetallicRoughness)
        packet.setMetallicRoughness(lane, s.roughness, s.metallic, s.occlusion);
}

struct SplitLightingOptions {
    int scale = 1; // lattice spacing in pixels
    // Samples not to light (e.g. inferred's stippled samples), lowWidth x lowHeight, 1 = skip;
    // empty: none.
    std::span<const uint8_t> excludedSamples;
    // Surfaces to light instead of the G-buffer's (inferred's stippled blended samples,
    // InferredStipple.h): when set, sample index j lowWidth + i is lit iff this returns a surface
    // for it (gathered into the packets; never decoded).
    std::function<const gbuffer::Surface*(size_t sample)> sampleSurfaces;
};

// Where the loop puts a packet's sums. Called once per packet that has a lit lane, from several
// threads at once (each sample belongs to one packet, so each call writes its own samples): the
// lit lanes are packet.laneMask (sample (packet.x0 + laneX, packet.y0 + laneY)); their view-space
// position and normal are in the packet, their sums in `sums`.
class SplitLightSink {
public:
    virtual ~SplitLightSink() = default;
    virtual void store(const kernel::ShadingPacket& packet,
                       const kernel::SplitPacketAccumulator& sums) const = 0;
};

// A sink from a callable store(packet, sums) (a stage's lambda; one virtual call per packet).
template <class Store> class SplitLightSinkOf final : public SplitLightSink {
public:
    explicit SplitLightSinkOf(Store store) : mStore(std::move(store)) {}
    void store(const kernel::ShadingPacket& packet,
               const kernel::SplitPacketAccumulator& sums) const override {
        mStore(packet, sums);
    }

private:
    Store mStore;
};

// Lights every sample of the lattice that holds a surface with its lists and hands the sums to
// `sink`; writes result.lightsEvaluated at each lit sample's pixel (its list length; result must be
// resized) and the light trace there when tracing. Records "isa", "simt_warp" and
// "simt_lane_slots" (warps of 8x4 or 8x8 SAMPLES, the lanes a GPU would run the light pass with)
// and, on the packet path, the packet counters, as accumulateLights does. Group lists must not
// carry per-light lane masks. Adds no timing.
void accumulateSplitLights(const StageInputs& inputs, const SplitLightingOptions& options,
                           const PacketListSource& source, const SplitLightSink& sink,
                           StageResult& result);

// Whether the packet decoder reads the frame's G-buffer layout: the one check (PacketDecoder::
// supports), made by PacketPath for every caller; otherwise pixels are gathered with surfaceAt.
bool packetPathFits(const StageInputs& inputs);
// The G-buffer's own planes as a PacketDecoder reads them (no copy; valid while `gb` lives).
kernel::GBufferPlanes planesOf(const gbuffer::GBuffer& gb);

// A frame's shading path, set up once by every caller of the kernel (accumulateLights,
// accumulateSplitLights, `deferred`): the ISA that runs (the requested one, for every layout),
// the lights in the kernel's form, and how the G-buffer reaches the kernel's packets: a packet at
// a time by the PacketDecoder when the layout fits it (packetPathFits) and the caller decodes
// whole pixels (`decodePixels`), else lane by lane through GBuffer::surfaceAt (layouts with normal
// codes or packed channels, which the vector decoder does not read yet). Either way the surfaces
// are bitwise GBuffer::decode's and the shading is the kernel's, so a layout changes the decode
// cost and its own error, never the shading path. Valid while the inputs live.
struct PacketPath {
    explicit PacketPath(const StageInputs& inputs, bool decodePixels = true);

    // Fills `packet` with the 4x4 pixels at (x0, y0) (the decoder's rule for the lane mask: covered
    // pixels inside the image).
    void decode(int x0, int y0, kernel::ShadingPacket& packet) const;
    // Records "gbuffer_decode": "packet" (the vector decoder) or "per-pixel".
    void record(StageResult& result) const;

    const gbuffer::GBuffer& gbuffer;
    kernel::KernelIsa isa;
    std::optional<kernel::PacketDecoder> decoder;
    kernel::KernelLights lights;
};

} // namespace lighting
