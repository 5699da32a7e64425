#include "lighting/kernel/LightKernel.h"

#include <stdexcept>

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
                                  lightIndices.size(), &accumulator, countContributing, nullptr,
                                  lights.shadows(), lights.shadowView()});
}

} // namespace lighting::kernel

namespace lighting::kernel {

void shadePacket(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                 const KernelLights& lights, std::span<const uint32_t> lightIndices,
                 std::span<const uint16_t> lightLaneMasks, PacketAccumulator& accumulator,
                 bool countContributing) {
    if (lightLaneMasks.size() != lightIndices.size())
        throw std::invalid_argument("shadePacket: one lane mask per light expected");
    if (isa.isScalar()) {
        shadePacketScalar(packet, laneMask, lights, lightIndices, accumulator, countContributing,
                          lightLaneMasks);
        return;
    }
    isa.vector()->shade(ShadeArgs{&packet, laneMask, lights.records(), lightIndices.data(),
                                  lightIndices.size(), &accumulator, countContributing,
                                  lightLaneMasks.data(), lights.shadows(), lights.shadowView()});
}

} // namespace lighting::kernel
