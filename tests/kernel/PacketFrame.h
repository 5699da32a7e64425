// shadeFrameByPackets: a whole frame shaded brute-force (or with one list for every pixel) the way
// a stage will once it runs on the kernel: decode each 4x4 packet, shade it, write its covered
// lanes. Rows of packets in parallel (TBB, each pixel written by one task: the result does not
// depend on the thread count). For the kernel's tests and benchmarks.
#pragma once

#include <span>
#include <vector>

#include <tbb/parallel_for.h>

#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/PacketDecoder.h"

namespace kerneltest {

struct PacketFrameResult {
    std::vector<float> radiance[3];
    std::vector<uint32_t> lightsEvaluated;
    std::vector<uint32_t> lightsContributing;
    uint64_t lightsShaded = 0; // summed over packets
    uint64_t lightsSkippedAtRange = 0;
    uint64_t lightsSkippedAtConeOrFacing = 0;
};

inline PacketFrameResult shadeFrameByPackets(const lighting::kernel::PacketDecoder& decoder,
                                             const lighting::kernel::KernelIsa& isa,
                                             const lighting::kernel::KernelLights& lights,
                                             std::span<const uint32_t> indices) {
    using namespace lighting::kernel;
    const int width = decoder.tables().width, height = decoder.tables().height;
    const size_t n = size_t(width) * size_t(height);
    PacketFrameResult result;
    for (auto& plane : result.radiance)
        plane.assign(n, 0.0f);
    result.lightsEvaluated.assign(n, 0);
    result.lightsContributing.assign(n, 0);
    const int packetRows = (height + kPacketHeight - 1) / kPacketHeight;
    std::vector<PacketAccumulator> rowCounters(static_cast<size_t>(packetRows));
    tbb::parallel_for(0, packetRows, [&](int row) {
        ShadingPacket packet;
        PacketAccumulator accumulator;
        PacketAccumulator& counters = rowCounters[size_t(row)];
        counters.clear();
        for (int x0 = 0; x0 < width; x0 += kPacketWidth) {
            const int y0 = row * kPacketHeight;
            decoder.decode(isa, x0, y0, packet);
            accumulator.clear();
            shadePacket(isa, packet, kAllLanes, lights, indices, accumulator);
            counters.lightsShaded += accumulator.lightsShaded;
            counters.lightsSkippedAtRange += accumulator.lightsSkippedAtRange;
            counters.lightsSkippedAtConeOrFacing += accumulator.lightsSkippedAtConeOrFacing;
            for (int lane = 0; lane < kPacketLanes; ++lane) {
                if (!(packet.laneMask >> lane & 1u))
                    continue;
                const size_t pixel =
                    size_t(y0 + laneY(lane)) * size_t(width) + size_t(x0 + laneX(lane));
                for (int k = 0; k < 3; ++k)
                    result.radiance[k][pixel] = accumulator.radiance[k][lane];
                result.lightsEvaluated[pixel] = accumulator.lightsEvaluated[lane];
                result.lightsContributing[pixel] = accumulator.lightsContributing[lane];
            }
        }
    });
    for (const PacketAccumulator& counters : rowCounters) {
        result.lightsShaded += counters.lightsShaded;
        result.lightsSkippedAtRange += counters.lightsSkippedAtRange;
        result.lightsSkippedAtConeOrFacing += counters.lightsSkippedAtConeOrFacing;
    }
    return result;
}

} // namespace kerneltest
