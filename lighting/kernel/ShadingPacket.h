// ShadingPacket and PacketAccumulator: the unit of work of the shading kernel (LightKernel.h), a
// 4x4 block of pixels in structure-of-arrays form, and what the kernel sums into per lane.
//
// Conventions:
// - A packet always has kPacketLanes = 16 lanes, whatever the instruction set: lane l is pixel
//   (x0 + l % 4, y0 + l / 4), rows top to bottom as in the image. The dispatched target processes
//   the 16 lanes as 1 (AVX-512), 2 (AVX2) or 4 (SSE4, NEON) hardware vectors, but every decision
//   the kernel takes (skip a light, count it) is taken over all 16 lanes, so counts never depend
//   on the instruction set.
// - View space as everywhere (right-handed, camera at the origin looking down -Z); normals unit.
// - laneMask bit l is set when lane l holds a surface (covered, inside the image). Lanes whose bit
//   is clear may hold anything, NaN included (the vector decoder reconstructs background pixels
//   like any other); the kernel computes them and selects their results away.
// - Arrays are 64-byte aligned so a 16-lane float row is one aligned AVX-512 load.
// - Material model per lane: bit l of metallicRoughnessMask set = lane l uses the glTF
//   metallic-roughness model (lighting/brdf/MetallicRoughness.h): albedo is its base colour and the
//   roughness, metallic and occlusion rows are read; clear = Lambert + Blinn-Phong, which reads
//   albedo and the specular rows. The rows of the other model are ignored (any value).
// Memory: 1024 bytes of surface per packet (16 rows of 16 floats), 320 bytes of accumulator.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace lighting::kernel {

inline constexpr int kPacketWidth = 4;
inline constexpr int kPacketHeight = 4;
inline constexpr int kPacketLanes = kPacketWidth * kPacketHeight;
inline constexpr uint32_t kAllLanes = (1u << kPacketLanes) - 1u;

constexpr int laneX(int lane) {
    return lane % kPacketWidth;
}
constexpr int laneY(int lane) {
    return lane / kPacketWidth;
}

struct alignas(64) ShadingPacket {
    float positionView[3][kPacketLanes];
    float normalView[3][kPacketLanes];
    float albedo[3][kPacketLanes];
    float specularIntensity[kPacketLanes];
    float specularPower[kPacketLanes];
    float roughness[kPacketLanes]; // metallic-roughness: perceptual, unclamped (the BRDF clamps)
    float metallic[kPacketLanes];
    float occlusion[kPacketLanes]; // ambient occlusion, 1 = none
    uint32_t laneMask = 0;
    uint32_t metallicRoughnessMask = 0; // lanes of the metallic-roughness model
    int x0 = 0;                         // pixel of lane 0
    int y0 = 0;

    // Every lane to the background values (gbuffer::Surface's defaults), laneMask and
    // metallicRoughnessMask to 0.
    void clear(int originX = 0, int originY = 0);
    // Fills lane `lane` and sets its bit in laneMask (used by tests and scalar decoders); the lane
    // keeps its model (Blinn-Phong after clear()).
    void setLane(int lane, const glm::vec3& position, const glm::vec3& normal,
                 const glm::vec3& albedoLinear, float specularIntensityValue,
                 float specularPowerValue);
    // Makes lane `lane` a metallic-roughness lane with these parameters (albedo is then its base
    // colour).
    void setMetallicRoughness(int lane, float roughnessValue, float metallicValue,
                              float occlusionValue);
};

// What the kernel adds into, per lane and per packet. The kernel only ever adds, so a caller may
// split a light list over several calls (the sum is the same: each lane adds light by light in
// the order given). Lanes outside the call's lane mask are never touched.
struct alignas(64) PacketAccumulator {
    float radiance[3][kPacketLanes]; // linear RGB, summed in light order
    // Per lane: lights of the list the lane was shaded with (the stage's lights.evaluated; every
    // light of the list counts, whether the packet skipped it or not, as on a GPU where each
    // lane walks the list).
    uint32_t lightsEvaluated[kPacketLanes];
    // Per lane: lights whose radiance there is non-zero (the oracle's definition of contributes).
    uint32_t lightsContributing[kPacketLanes];
    // Per packet, for the SIMT cost model (issue 14, section 3): lights of the list every active
    // lane rejected at the range test (a warp pays a cheap test), lights every active lane
    // rejected later at the spot cone or n.l test (a warp pays the distance, normalisation and
    // attenuation), and lights at least one lane shaded (a warp pays the whole evaluation).
    // Each light of a call with a non-empty lane mask lands in exactly one of the three.
    uint64_t lightsSkippedAtRange = 0;
    uint64_t lightsSkippedAtConeOrFacing = 0;
    uint64_t lightsShaded = 0;

    void clear();
};

} // namespace lighting::kernel
