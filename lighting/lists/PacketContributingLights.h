// PacketContributingLights: ContributingLights regrouped by shading packet (4x4 pixels,
// lighting/kernel/ShadingPacket.h), the form the `ideal` stage gives the kernel. Per packet: the
// union of its lanes' contributing lights, ascending, and per light of the union the mask of the
// lanes it contributes to (bit l = lane l = pixel (x0 + l % 4, y0 + l / 4)). Shaded with the
// kernel's per-light lane masks (LightKernel.h) each lane sums exactly its own contributing lights
// in ascending order, while the packet pays one packet-wide evaluation per light of the union:
// perfect per-pixel culling as a SIMD packet (or a SIMT warp) can use it. It is the
// PacketListSource the `ideal` stage gives accumulateLights (LightAccumulation.h).
//
// Storage: one CSR over the packets (row-major, packetsX = ceil(width / 4) per row): offsets
// (packet count + 1), light indices and lane masks (4 + 2 bytes per (packet, light) pair).
// Cost: a merge of the 16 lanes' lists per packet, outside any timer of the stage.
// Threads: packet rows in parallel, each row's lists concatenated in row order, so the result
// never depends on the thread count. build() is not reentrant; the const queries are thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lighting/lists/ContributingLights.h"
#include "lighting/passes/LightAccumulation.h"

namespace lighting {

class PacketContributingLights final : public PacketListSource {
public:
    // Regroups `pixels` (lists of a width x height image) by packet; replaces the previous lists.
    // Throws std::length_error beyond 2^32 - 1 pairs.
    void build(const ContributingLights& pixels, size_t lightCount);

    // The packet whose lane 0 is pixel (x0, y0); x0 and y0 multiples of 4, inside the image.
    size_t packetOf(int x0, int y0) const { return size_t(y0 / 4) * mPacketsX + size_t(x0 / 4); }
    std::span<const uint32_t> lightsOf(size_t packet) const {
        return {mIndices.data() + mOffsets[packet], mIndices.data() + mOffsets[packet + 1]};
    }
    std::span<const uint16_t> laneMasksOf(size_t packet) const {
        return {mLaneMasks.data() + mOffsets[packet], mLaneMasks.data() + mOffsets[packet + 1]};
    }
    size_t pairCount() const { return mIndices.size(); }

    // The packet's union list with its per-light lane masks, as one group (the packet must lie in
    // the image of the last build()).
    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        const size_t index = packetOf(packet.x0, packet.y0);
        lists.add(packet.laneMask, lightsOf(index), laneMasksOf(index));
    }

private:
    size_t mPacketsX = 0;
    std::vector<uint32_t> mOffsets;
    std::vector<uint32_t> mIndices;
    std::vector<uint16_t> mLaneMasks;
    std::vector<std::vector<uint32_t>> mRowIndices; // scratch: one packet row's lists
    std::vector<std::vector<uint16_t>> mRowMasks;
};

} // namespace lighting
