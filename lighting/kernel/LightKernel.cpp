#include "lighting/kernel/LightKernel.h"

#include "lighting/kernel/VectorTargets.h"

namespace lighting::kernel {

void shadePacket(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                 const KernelLights& lights, std::span<const uint32_t> lightIndices,
                 PacketAccumulator& accumulator, bool countContributing) {
    if (isa.isScalar()) {
        shadePacketScalar(packet, laneMask, lights, lightIndices, accumulator, countContributing);
        return;
    }
    isa.vector()->shade(ShadeArgs{&packet, laneMask, lights.records(), lightIndices.data(),
                                  lightIndices.size(), &accumulator, countContributing});
}

} // namespace lighting::kernel
