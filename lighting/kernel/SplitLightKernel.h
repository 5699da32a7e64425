// shadePacketSplit: the shading kernel's second output form, for the stages that accumulate light
// buffers (light-prepass, inferred): for a packet and a light list it sums, per lane, the split
// lighting of lighting/brdf/SplitLighting.h (addSplitLight) instead of one radiance:
//   Blinn-Phong lanes: diffuse = the BRDF with albedo 1 and specular intensity 0, specular = the
//     BRDF with albedo 0 and intensity 1, added only where the light's diffuse part is non-zero
//     and the light is not ambient; specularEdge stays 0;
//   metallic-roughness lanes: splitLightMetallicRoughness's diffuse (times c_diff later),
//     specularF0 (times f0) and specularEdge.
// Why a kernel entry and not two shadePacket calls with made-up materials: the Blinn-Phong part
// could be had that way (albedo 1 / intensity 0, then albedo 0 / intensity 1), at twice the
// range, direction and attenuation work per light, but the metallic-roughness part cannot: no
// base colour and metallic make shadePacket's F = f0 + (1 - f0) w vanish beside c_diff = 1, so
// its diffuse and f0 sums are not any material's radiance. One pass over the list computes
// phases 1 and 2 once per light for all three sums.
//
// Contract: as shadePacket's (LightKernel.h) for lanes, order, early out and counts: lanes of
// laneMask & packet.laneMask; each lane adds light by light in list order into the accumulator's
// running sums (a list may be split over calls, lanes over calls with disjoint masks, bitwise the
// same); a light is left only when every active lane rejects it; lightsEvaluated[lane] += list
// length; the three packet counters are those shadePacket gives for the same packet and list.
// No contributing-light count (the split stages report none).
// Floating point: the scalar path is addSplitLight lane by lane (bitwise splitLighting); the
// vector path performs its operations in its order, so its diffuse sums and every
// metallic-roughness sum are bitwise the scalar path's, and the Blinn-Phong specular sum differs
// only through pow (a few ulps, as shadePacket; tests/kernel/split_kernel_test.cpp).
// Cost: one evaluation per light of the list (the specular part shares phases 1 and 2 with the
// diffuse one); thread-safe, it writes only `accumulator`.
#pragma once

#include <cstdint>
#include <span>

#include "lighting/kernel/KernelIsa.h"
#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/ShadingPacket.h"

namespace lighting::kernel {

// What shadePacketSplit adds into, per lane (linear RGB, summed in light order) and per packet.
// Memory: 576 bytes of sums, 64 of counts.
struct alignas(64) SplitPacketAccumulator {
    float diffuse[3][kPacketLanes];
    float specular[3][kPacketLanes];     // Blinn-Phong: times intensity; metallic-roughness: f0
    float specularEdge[3][kPacketLanes]; // metallic-roughness only
    uint32_t lightsEvaluated[kPacketLanes];
    // As PacketAccumulator's (the SIMT cost model's split of the packet's light iterations).
    uint64_t lightsSkippedAtRange = 0;
    uint64_t lightsSkippedAtConeOrFacing = 0;
    uint64_t lightsShaded = 0;

    void clear();
};

void shadePacketSplit(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                      const KernelLights& lights, std::span<const uint32_t> lightIndices,
                      SplitPacketAccumulator& accumulator);

// The scalar path, what shadePacketSplit runs for KernelIsa::scalar(): addSplitLight lane by
// lane, the counters from the tests evaluateLight makes (as shadePacketScalar).
void shadePacketSplitScalar(const ShadingPacket& packet, uint32_t laneMask,
                            const KernelLights& lights, std::span<const uint32_t> lightIndices,
                            SplitPacketAccumulator& accumulator);

} // namespace lighting::kernel
