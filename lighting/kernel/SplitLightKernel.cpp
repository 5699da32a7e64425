#include "lighting/kernel/SplitLightKernel.h"

#include <algorithm>
#include <iterator>

#include "lighting/kernel/VectorTargets.h"

namespace lighting::kernel {

void SplitPacketAccumulator::clear() {
    for (auto* sums : {&diffuse, &specular, &specularEdge})
        for (auto& plane : *sums)
            std::fill(std::begin(plane), std::end(plane), 0.0f);
    std::fill(std::begin(lightsEvaluated), std::end(lightsEvaluated), 0u);
    lightsSkippedAtRange = 0;
    lightsSkippedAtConeOrFacing = 0;
    lightsShaded = 0;
}

void shadePacketSplit(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                      const KernelLights& lights, std::span<const uint32_t> lightIndices,
                      SplitPacketAccumulator& accumulator) {
    if (isa.isScalar()) {
        shadePacketSplitScalar(packet, laneMask, lights, lightIndices, accumulator);
        return;
    }
    isa.vector()->shadeSplit(ShadeSplitArgs{&packet, laneMask, lights.records(),
                                            lightIndices.data(), lightIndices.size(), &accumulator,
                                            lights.shadows(), lights.shadowView()});
}

} // namespace lighting::kernel
