#include "lighting/passes/LightAccumulation.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "lighting/brdf/Brdf.h"
#include "lighting/brdf/SplitLighting.h"
#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/PacketDecoder.h"
#include "lighting/passes/KernelWork.h"
#include "lighting/passes/PackedFragments.h"

namespace lighting {

using kernel::kPacketHeight;
using kernel::kPacketLanes;
using kernel::kPacketWidth;

EveryLightSource::EveryLightSource(size_t lightCount) : mIndices(lightCount) {
    for (size_t i = 0; i < lightCount; ++i)
        mIndices[i] = uint32_t(i);
}

namespace {

constexpr int kWarpWidth = 8; // pixels; a warp is 8x4 (32 lanes) or 8x8 (64 lanes)

} // namespace

// The one check of which path a frame takes (see the header): the packet decoder must read the
// layout. The kernel shades both material models (Blinn-Phong and metallic-roughness).
bool packetPathFits(const StageInputs& inputs) {
    return kernel::PacketDecoder::supports(inputs.gbuffer->layout());
}

kernel::GBufferPlanes planesOf(const gbuffer::GBuffer& gb) {
    kernel::GBufferPlanes planes;
    planes.depth = gb.depth().data();
    for (int k = 0; k < 3; ++k) {
        planes.normal[k] = gb.normalPlane(k).empty() ? nullptr : gb.normalPlane(k).data();
        planes.albedo[k] = gb.albedoPlane(k).empty() ? nullptr : gb.albedoPlane(k).data();
    }
    for (int k = 0; k < 2; ++k)
        planes.specular[k] = gb.specularPlane(k).empty() ? nullptr : gb.specularPlane(k).data();
    for (int k = 0; k < 2; ++k)
        planes.roughnessMetallic[k] =
            gb.roughnessMetallicPlane(k).empty() ? nullptr : gb.roughnessMetallicPlane(k).data();
    planes.occlusion = gb.occlusionPlane().empty() ? nullptr : gb.occlusionPlane().data();
    planes.material = gb.materialPlane().empty() ? nullptr : gb.materialPlane().data();
    return planes;
}

PacketPath::PacketPath(const StageInputs& inputs, bool decodePixels)
    : gbuffer(*inputs.gbuffer), isa(inputs.isa), lights(inputs.lights->lights, inputs.shadows) {
    if (decodePixels && packetPathFits(inputs))
        decoder.emplace(gbuffer.layout(), gbuffer.view(), planesOf(gbuffer));
}

void PacketPath::decode(int x0, int y0, kernel::ShadingPacket& packet) const {
    // A packet without a covered pixel (most of an upper MSAA layer's, whose fragments lie at
    // complex pixels only) has nothing to decode: its lane mask is empty either way, and every
    // caller skips such a packet before reading a lane.
    const int columns = std::min(kPacketWidth, gbuffer.width() - x0);
    const int rows = std::min(kPacketHeight, gbuffer.height() - y0);
    bool anyCovered = false;
    for (int row = 0; row < rows && !anyCovered; ++row) {
        const size_t first = size_t(y0 + row) * size_t(gbuffer.width()) + size_t(x0);
        for (int column = 0; column < columns; ++column)
            anyCovered |= gbuffer.covered(first + size_t(column));
    }
    if (!anyCovered) {
        packet.laneMask = 0;
        packet.x0 = x0;
        packet.y0 = y0;
        return;
    }
    if (decoder) {
        decoder->decode(isa, x0, y0, packet);
        return;
    }
    // Row by row (lanes are row-major): a visibility buffer fetches each triangle once per row.
    packet.clear(x0, y0);
    const int count = std::min(kPacketWidth, gbuffer.width() - x0);
    for (int row = 0; row < kPacketHeight && y0 + row < gbuffer.height(); ++row)
        gbuffer.decodeRun(x0, count, y0 + row, [&](int x, const gbuffer::Surface& s) {
            setLaneSurface(packet, row * kPacketWidth + (x - x0), s);
        });
}

void PacketPath::record(StageResult& result) const {
    result.parameters["gbuffer_decode"] = decoder ? "packet" : "per-pixel";
}

namespace {

// Lights in the union of a warp's lists: the common case (one list for the whole warp) directly,
// otherwise by stamping each light index with the warp's number.
class WarpUnion {
public:
    explicit WarpUnion(size_t lightCount) : mStamp(lightCount, 0) {}
    void begin() {
        ++mWarp;
        mFirst = {};
        mHasFirst = false;
        mSingle = true;
        mCount = 0;
    }
    void add(std::span<const uint32_t> list) {
        if (mSingle) {
            if (!mHasFirst) {
                mFirst = list;
                mHasFirst = true;
                return;
            }
            if (list.data() == mFirst.data() && list.size() == mFirst.size())
                return;
            mSingle = false;
            stamp(mFirst);
        }
        stamp(list);
    }
    // A list whose storage does not outlive the packet (PacketLightLists' scratch): stamped now.
    void addTransient(std::span<const uint32_t> list) {
        if (mSingle) {
            mSingle = false;
            if (mHasFirst)
                stamp(mFirst);
        }
        stamp(list);
    }
    uint64_t count() const { return mSingle ? mFirst.size() : mCount; }

private:
    void stamp(std::span<const uint32_t> list) {
        for (uint32_t index : list)
            if (mStamp[index] != mWarp) {
                mStamp[index] = mWarp;
                ++mCount;
            }
    }
    std::vector<uint32_t> mStamp;
    uint32_t mWarp = 0;
    std::span<const uint32_t> mFirst;
    bool mHasFirst = false;
    bool mSingle = true;
    uint64_t mCount = 0;
};

// Shades each lane group of `lists` on the kernel into `accumulator` (cleared first): one call per
// group, with its per-light lane masks when it has them.
void shadeGroups(const kernel::KernelIsa& isa, const kernel::ShadingPacket& packet,
                 const PacketLightLists& lists, const kernel::KernelLights& lights,
                 bool countOracle, kernel::PacketAccumulator& accumulator) {
    accumulator.clear();
    for (int g = 0; g < lists.size(); ++g) {
        const PacketLightLists::Group& group = lists[g];
        if (group.lightLaneMasks.empty())
            kernel::shadePacket(isa, packet, group.laneMask, lights, group.lights, accumulator,
                                countOracle);
        else
            kernel::shadePacket(isa, packet, group.laneMask, lights, group.lights,
                                group.lightLaneMasks, accumulator, countOracle);
    }
}

// What one warp-row task of walkWarps keeps between packets.
template <class Accumulator> struct PacketScratch {
    kernel::ShadingPacket packet;
    Accumulator accumulator;
    PacketLightLists lists;
};

// The SIMT model's bill for a packet: the lists its lanes walked join the warp's union; true when
// it had a lane group (the warp then pays).
bool payLists(const PacketLightLists& lists, WarpUnion& warpUnion) {
    for (int g = 0; g < lists.size(); ++g) {
        if (lists[g].scratch)
            warpUnion.addTransient(lists[g].lights);
        else
            warpUnion.add(lists[g].lights);
    }
    return lists.size() > 0;
}

// The walk accumulateLights and accumulateSplitLights share: a grid of columns x rows units
// (pixels or lattice samples) in 4x4 packets and warps of 8 x (warpLanes / 8) units, warp rows in
// parallel (one task per row, with its own scratch), the packets of a warp in order.
// shade(scratch, x0, y0, warpUnion, work) shades the packet at (x0, y0), pays its lists
// (payLists) and adds its kernel counters to `work`, and returns whether the warp pays; a warp that
// pays costs warpLanes lane slots per light of its union. Returns the frame's work summed in row
// order (integers: the same for any thread count).
template <class Accumulator, class Shade>
KernelWork walkWarps(int columns, int rows, int warpLanes, size_t lightCount, const Shade& shade) {
    const int warpHeight = warpLanes / kWarpWidth;
    const int warpRows = (rows + warpHeight - 1) / warpHeight;
    std::vector<KernelWork> workPerRow(static_cast<size_t>(warpRows));
    // One union per thread, not per warp row: its stamps are lightCount words (4 MB at 10^6
    // lights, which 180 warp rows of a 1280x720 frame would each allocate and clear). A union's
    // state is reset by begin() and its warp stamp is unique per union, so which thread's union a
    // row uses changes nothing. `shade` runs no parallel work of its own, so a thread never takes
    // another row while its union is in use.
    tbb::enumerable_thread_specific<WarpUnion> unions(
        [lightCount] { return WarpUnion(lightCount); });
    tbb::parallel_for(0, warpRows, [&](int warpRow) {
        PacketScratch<Accumulator> scratch;
        WarpUnion& warpUnion = unions.local();
        KernelWork rowWork;
        for (int wx = 0; wx < columns; wx += kWarpWidth) {
            warpUnion.begin();
            bool pays = false;
            for (int y0 = warpRow * warpHeight; y0 < std::min(rows, (warpRow + 1) * warpHeight);
                 y0 += kPacketHeight)
                for (int x0 = wx; x0 < std::min(columns, wx + kWarpWidth); x0 += kPacketWidth)
                    pays |= shade(scratch, x0, y0, warpUnion, rowWork);
            if (pays)
                rowWork.laneSlots += uint64_t(warpLanes) * warpUnion.count();
        }
        workPerRow[size_t(warpRow)] = rowWork;
    });
    KernelWork work;
    for (const KernelWork& row : workPerRow)
        work += row;
    return work;
}

} // namespace

void accumulateLights(const StageInputs& inputs, const PacketListSource& source,
                      const AccumulationOptions& options, StageResult& result) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    const int width = gb.width(), height = gb.height();
    if (inputs.simtWarpLanes != 32 && inputs.simtWarpLanes != 64)
        throw std::invalid_argument("accumulateLights: simtWarpLanes must be 32 or 64, not " +
                                    std::to_string(inputs.simtWarpLanes));
    const std::vector<LightInView<float>>& lights = inputs.lights->lights;

    const bool emission = gb.hasEmission();
    const PacketPath path(inputs);
    const kernel::KernelIsa isa = path.isa;

    // Per warp: lane slots; per packet: packet-wide light iterations by outcome
    // (PacketAccumulator's counters; the vector kernel's cost is about proportional to them,
    // lighting/kernel/README.md) and kernel calls (one per group).
    const KernelWork work = walkWarps<kernel::PacketAccumulator>(
        width, height, inputs.simtWarpLanes, lights.size(),
        [&](PacketScratch<kernel::PacketAccumulator>& scratch, int x0, int y0, WarpUnion& warpUnion,
            KernelWork& rowWork) {
            kernel::ShadingPacket& packet = scratch.packet;
            kernel::PacketAccumulator& accumulator = scratch.accumulator;
            PacketLightLists& lists = scratch.lists;
            path.decode(x0, y0, packet);
            if (packet.laneMask == 0)
                return false;
            lists.clear();
            source.listsOf(packet, lists);
            shadeGroups(isa, packet, lists, path.lights, options.countOracle, accumulator);
            rowWork.groups += uint64_t(lists.size());
            rowWork.addCounters(accumulator);
            // The test-only light trace (StageResult::traceLights): each lane summed exactly its
            // group's list (with per-light masks, its lights of it).
            if (result.tracing())
                for (int g = 0; g < lists.size(); ++g)
                    for (uint32_t lanes = lists[g].laneMask & packet.laneMask; lanes != 0;
                         lanes &= lanes - 1) {
                        const int lane = __builtin_ctz(lanes);
                        std::vector<uint32_t> own;
                        for (size_t i = 0; i < lists[g].lights.size(); ++i)
                            if (lists[g].evaluates(lane, i))
                                own.push_back(lists[g].lights[i]);
                        result.traceLightList(size_t(y0 + kernel::laneY(lane)) * size_t(width) +
                                                  size_t(x0 + kernel::laneX(lane)),
                                              own);
                    }
            for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
                const int lane = __builtin_ctz(lanes);
                const size_t pixel = size_t(y0 + kernel::laneY(lane)) * size_t(width) +
                                     size_t(x0 + kernel::laneX(lane));
                for (int c = 0; c < 3; ++c)
                    result.radiance[c][pixel] = accumulator.radiance[c][lane];
                if (emission) {
                    const glm::vec3 emitted = gb.emission(pixel);
                    for (int c = 0; c < 3; ++c)
                        result.radiance[c][pixel] += emitted[c];
                }
                result.lightsEvaluated[pixel] = accumulator.lightsEvaluated[lane];
                if (options.countOracle)
                    result.lightsOracle[pixel] = accumulator.lightsContributing[lane];
            }
            return payLists(lists, warpUnion);
        });
    work.record(isa, inputs.simtWarpLanes, result);
    path.record(result);
}

} // namespace lighting

namespace lighting {

namespace {

// The lanes of the 4x4 samples at (i0, j0) that options.excludedSamples marks.
uint32_t excludedLanes(std::span<const uint8_t> excluded, int sampleWidth, int sampleHeight, int i0,
                       int j0) {
    uint32_t lanes = 0;
    if (excluded.empty())
        return 0;
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        const int i = i0 + kernel::laneX(lane), j = j0 + kernel::laneY(lane);
        if (i < sampleWidth && j < sampleHeight && excluded[size_t(j) * sampleWidth + i] != 0)
            lanes |= 1u << lane;
    }
    return lanes;
}

// The 4x4 samples at (i0, j0) of the lattice, lane by lane through GBuffer::surfaceAt.
void gatherSamples(const gbuffer::GBuffer& gb, int scale, int sampleWidth, int sampleHeight,
                   uint32_t excluded, int i0, int j0, kernel::ShadingPacket& packet) {
    packet.clear(i0, j0);
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        const int i = i0 + kernel::laneX(lane), j = j0 + kernel::laneY(lane);
        if (i >= sampleWidth || j >= sampleHeight || (excluded >> lane & 1u))
            continue;
        const int x = std::min(i * scale + scale / 2, gb.width() - 1);
        const int y = std::min(j * scale + scale / 2, gb.height() - 1);
        gbuffer::Surface s;
        if (gb.surfaceAt(x, y, s))
            setLaneSurface(packet, lane, s);
    }
}

// The same for surfaces the caller holds per sample (SplitLightingOptions::sampleSurfaces).
void gatherOwnSamples(const std::function<const gbuffer::Surface*(size_t)>& surfaceOf,
                      int sampleWidth, int sampleHeight, uint32_t excluded, int i0, int j0,
                      kernel::ShadingPacket& packet) {
    packet.clear(i0, j0);
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        const int i = i0 + kernel::laneX(lane), j = j0 + kernel::laneY(lane);
        if (i >= sampleWidth || j >= sampleHeight || (excluded >> lane & 1u))
            continue;
        const gbuffer::Surface* held = surfaceOf(size_t(j) * size_t(sampleWidth) + size_t(i));
        if (held != nullptr)
            setLaneSurface(packet, lane, *held);
    }
}

} // namespace

void accumulateSplitLights(const StageInputs& inputs, const SplitLightingOptions& options,
                           const PacketListSource& source, const SplitLightSink& sink,
                           StageResult& result) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    const int width = gb.width(), height = gb.height();
    const int scale = options.scale;
    if (scale < 1)
        throw std::invalid_argument("accumulateSplitLights: scale must be at least 1");
    const int sampleWidth = (width + scale - 1) / scale,
              sampleHeight = (height + scale - 1) / scale;
    if (!options.excludedSamples.empty() &&
        options.excludedSamples.size() != size_t(sampleWidth) * size_t(sampleHeight))
        throw std::invalid_argument("accumulateSplitLights: one excluded flag per sample expected");
    if (inputs.simtWarpLanes != 32 && inputs.simtWarpLanes != 64)
        throw std::invalid_argument("accumulateSplitLights: simtWarpLanes must be 32 or 64, not " +
                                    std::to_string(inputs.simtWarpLanes));
    const std::vector<LightInView<float>>& lights = inputs.lights->lights;

    // Whole pixels (scale 1) are decoded a packet at a time; lattice samples and the caller's
    // own surfaces are gathered.
    const PacketPath path(inputs, scale == 1 && !options.sampleSurfaces);
    const kernel::KernelIsa isa = path.isa;
    auto pixelOf = [&](int i, int j) {
        return size_t(std::min(j * scale + scale / 2, height - 1)) * size_t(width) +
               size_t(std::min(i * scale + scale / 2, width - 1));
    };

    const KernelWork work = walkWarps<kernel::SplitPacketAccumulator>(
        sampleWidth, sampleHeight, inputs.simtWarpLanes, lights.size(),
        [&](PacketScratch<kernel::SplitPacketAccumulator>& scratch, int i0, int j0,
            WarpUnion& warpUnion, KernelWork& rowWork) {
            kernel::ShadingPacket& packet = scratch.packet;
            kernel::SplitPacketAccumulator& sums = scratch.accumulator;
            PacketLightLists& lists = scratch.lists;
            const uint32_t excluded =
                excludedLanes(options.excludedSamples, sampleWidth, sampleHeight, i0, j0);
            if (options.sampleSurfaces) {
                gatherOwnSamples(options.sampleSurfaces, sampleWidth, sampleHeight, excluded, i0,
                                 j0, packet);
            } else if (scale == 1) {
                path.decode(i0, j0, packet);
                packet.laneMask &= ~excluded;
            } else {
                gatherSamples(gb, scale, sampleWidth, sampleHeight, excluded, i0, j0, packet);
            }
            if (packet.laneMask == 0)
                return false;
            lists.clear();
            source.listsOf(packet, lists);
            sums.clear();
            rowWork.groups += uint64_t(lists.size());
            for (int g = 0; g < lists.size(); ++g) {
                const PacketLightLists::Group& group = lists[g];
                if (!group.lightLaneMasks.empty())
                    throw std::logic_error(
                        "accumulateSplitLights: per-light lane masks are not supported");
                kernel::shadePacketSplit(isa, packet, group.laneMask, path.lights, group.lights,
                                         sums);
                for (uint32_t lanes = group.laneMask & packet.laneMask; lanes != 0;
                     lanes &= lanes - 1) {
                    const int lane = __builtin_ctz(lanes);
                    const size_t pixel =
                        pixelOf(i0 + kernel::laneX(lane), j0 + kernel::laneY(lane));
                    result.lightsEvaluated[pixel] = sums.lightsEvaluated[lane];
                    result.traceLightList(pixel, group.lights);
                }
            }
            rowWork.addCounters(sums);
            sink.store(packet, sums);
            return payLists(lists, warpUnion);
        });
    work.record(isa, inputs.simtWarpLanes, result);
    path.record(result);
}

namespace {

// A 4x4 block of one layer as the vector decoder gave it (accumulatePackedFragments).
struct DecodedBlock {
    int x = -1, y = -1; // in blocks; -1: none yet
    kernel::ShadingPacket packet;
};

// Lane `from` of `source` into lane `to` of `packet` (the surface, its material model), as if
// `packet` had decoded it.
void copyLane(const kernel::ShadingPacket& source, int from, kernel::ShadingPacket& packet,
              int to) {
    for (int c = 0; c < 3; ++c) {
        packet.positionView[c][to] = source.positionView[c][from];
        packet.normalView[c][to] = source.normalView[c][from];
        packet.albedo[c][to] = source.albedo[c][from];
    }
    packet.specularIntensity[to] = source.specularIntensity[from];
    packet.specularPower[to] = source.specularPower[from];
    packet.roughness[to] = source.roughness[from];
    packet.metallic[to] = source.metallic[from];
    packet.occlusion[to] = source.occlusion[from];
    const uint32_t bit = 1u << to;
    packet.metallicRoughnessMask =
        (packet.metallicRoughnessMask & ~bit) | ((source.metallicRoughnessMask >> from & 1u) << to);
    packet.laneMask |= bit;
}

} // namespace

void accumulatePackedFragments(const PackedFragmentRun& run, const FragmentListSource& source,
                               StageResult& result) {
    const StageInputs& frame = *run.frame;
    const PackedFragments& fragments = *run.fragments;
    if (frame.simtWarpLanes != 32 && frame.simtWarpLanes != 64)
        throw std::invalid_argument(
            "accumulatePackedFragments: simtWarpLanes must be 32 or 64, not " +
            std::to_string(frame.simtWarpLanes));
    const PacketPath path(frame, false); // the kernel's lights and ISA; lanes are gathered
    const kernel::KernelIsa isa = path.isa;
    // A lane's surface: from its layer's 4x4 block decoded by the vector decoder (the per-layer
    // runs' decode, bitwise GBuffer::decode), kept while the packets' lanes come from it, at a
    // block's cost instead of a scalar decode per lane (perf on atrium at 4x: GBuffer::decode and
    // its inverse projection were 10% of the frame's CPU time). GBuffer::decode per lane for a
    // layout the decoder does not read.
    std::vector<std::unique_ptr<kernel::PacketDecoder>> decoders(run.layerGBuffers.size());
    if (packetPathFits(frame))
        for (size_t k = 0; k < decoders.size(); ++k)
            decoders[k] = std::make_unique<kernel::PacketDecoder>(run.layerGBuffers[k]->layout(),
                                                                  run.layerGBuffers[k]->view(),
                                                                  planesOf(*run.layerGBuffers[k]));
    const int layerCount = int(run.layerGBuffers.size());
    const bool emission = frame.gbuffer->hasEmission();
    const size_t count = fragments.size();
    const size_t warpLanes = size_t(frame.simtWarpLanes);
    const size_t warps = (count + warpLanes - 1) / warpLanes;
    std::vector<KernelWork> workPerWarp(warps);
    tbb::enumerable_thread_specific<WarpUnion> unions(
        [&] { return WarpUnion(frame.lights->lights.size()); });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, warps), [&](const auto& range) {
        PacketScratch<kernel::PacketAccumulator> scratch;
        kernel::ShadingPacket& packet = scratch.packet;
        kernel::PacketAccumulator& accumulator = scratch.accumulator;
        PacketLightLists& lists = scratch.lists;
        WarpUnion& warpUnion = unions.local();
        // Decoded blocks, per layer the four block columns of a 16-pixel screen block (the
        // shading order's unit, PackedFragments::kBlockPixels): a block is decoded once for all
        // the rows of fragments it holds.
        constexpr int kColumns = PackedFragments::kBlockPixels / kPacketWidth;
        std::vector<DecodedBlock> blocks(decoders[0] ? size_t(layerCount * kColumns) : 0);
        for (size_t warp = range.begin(); warp != range.end(); ++warp) {
            KernelWork& work = workPerWarp[warp];
            warpUnion.begin();
            bool pays = false;
            for (size_t first = warp * warpLanes; first < std::min(count, (warp + 1) * warpLanes);
                 first += kPacketLanes) {
                const int lanes = int(std::min<size_t>(kPacketLanes, count - first));
                std::span<const uint32_t> laneLists[kPacketLanes];
                size_t laneFragment[kPacketLanes];
                packet.clear();
                for (int lane = 0; lane < lanes; ++lane) {
                    const size_t fragment = fragments.inShadingOrder(first + size_t(lane));
                    laneFragment[lane] = fragment;
                    const int x = fragments.x(fragment), y = fragments.y(fragment);
                    const int layer = fragments.layer(fragment);
                    if (!blocks.empty()) {
                        const int bx = x / kPacketWidth, by = y / kPacketHeight;
                        DecodedBlock& block = blocks[size_t(layer * kColumns + bx % kColumns)];
                        if (block.x != bx || block.y != by) {
                            decoders[size_t(layer)]->decode(isa, bx * kPacketWidth,
                                                            by * kPacketHeight, block.packet);
                            block.x = bx;
                            block.y = by;
                        }
                        copyLane(block.packet,
                                 (y % kPacketHeight) * kPacketWidth + x % kPacketWidth, packet,
                                 lane);
                        laneLists[lane] = source.listOf(x, y,
                                                        glm::vec3(packet.positionView[0][lane],
                                                                  packet.positionView[1][lane],
                                                                  packet.positionView[2][lane]));
                        continue;
                    }
                    const gbuffer::Surface s = run.gbufferOf(fragment).decode(x, y);
                    setLaneSurface(packet, lane, s);
                    laneLists[lane] = source.listOf(x, y, s.positionView);
                }
                // Lanes grouped by list (the same list is the same storage): one kernel call over
                // the union of the packet's lists, each lane masked to its own.
                lists.clear();
                // (Storage and length: an empty list may start where another one does.)
                using ListKey = std::pair<const uint32_t*, size_t>;
                auto keyOf = [&](int lane) {
                    return ListKey(laneLists[lane].data(), laneLists[lane].size());
                };
                lists.addByKeyMerged(packet, keyOf, [&](const ListKey& key) {
                    int lane = 0;
                    while (keyOf(lane) != key)
                        ++lane;
                    return laneLists[lane];
                });
                shadeGroups(isa, packet, lists, path.lights, false, accumulator);
                work.groups += uint64_t(lists.size());
                work.addCounters(accumulator);
                for (int lane = 0; lane < lanes; ++lane) {
                    const size_t fragment = laneFragment[lane];
                    for (int c = 0; c < 3; ++c)
                        result.radiance[c][fragment] = accumulator.radiance[c][lane];
                    if (emission) {
                        const glm::vec3 emitted =
                            run.gbufferOf(fragment).emission(fragments.pixel(fragment));
                        for (int c = 0; c < 3; ++c)
                            result.radiance[c][fragment] += emitted[c];
                    }
                    result.lightsEvaluated[fragment] = accumulator.lightsEvaluated[lane];
                    result.traceLightList(fragment, laneLists[lane]);
                }
                pays |= payLists(lists, warpUnion);
            }
            if (pays)
                work.laneSlots += uint64_t(warpLanes) * warpUnion.count();
        }
    });
    KernelWork work;
    for (const KernelWork& warp : workPerWarp)
        work += warp;
    work.record(isa, frame.simtWarpLanes, result);
}

} // namespace lighting
