// shadePacket: the one shading loop of issue 14. For a packet of 4x4 pixels and a list of light
// indices, evaluate lighting/brdf/Brdf.h's lighting model for every active lane and every light of
// the list, in list order, and add each lane's radiance and counts into a PacketAccumulator.
//
// Contract (both paths, every instruction set):
// - Lanes: those set in laneMask & packet.laneMask. Other lanes of the accumulator are untouched.
//   A caller can shade one packet in several calls with disjoint lane masks (e.g. lanes that fall
//   in different clusters, each with its cluster's list).
// - Order: each lane adds its lights one by one in list order, into the accumulator's running sum,
//   so a lane's result is bitwise independent of the other lanes of the packet and of how the list
//   is split over calls. Keep lists ascending and exact culling stays bitwise equal to brute force
//   (skipped lights add exactly +0).
// - Early out: a light is left after the range test, or after the spot-cone and n.l tests, only
//   when EVERY active lane rejects it (a GPU warp's rule); a light contributes at a lane only if it
//   passes all three, so no contributing light is ever skipped. The accumulator's per-packet
//   counters say how often each exit was taken (for the SIMT cost model).
// - Counts: lightsEvaluated[lane] += list length (every lane walks the list); when
//   countContributing, lightsContributing[lane] += lights with non-zero radiance there (the
//   oracle's definition; it costs ~5% of a shaded light, so stages that do not report the oracle
//   leave it off and lightsContributing untouched).
// - Lights: the indices must be valid for `lights`; duplicates are evaluated twice.
//
// Cost: see README.md for the measured figures. Thread-safe: it reads its inputs and writes only
// `accumulator`.
#pragma once

#include <cstdint>
#include <span>

#include "lighting/kernel/KernelIsa.h"
#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/ShadingPacket.h"

namespace lighting::kernel {

void shadePacket(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                 const KernelLights& lights, std::span<const uint32_t> lightIndices,
                 PacketAccumulator& accumulator, bool countContributing = true);

// Per-lane lists given as one list with a lane mask per light: light lightIndices[i] is evaluated
// on the lanes laneMask & packet.laneMask & lightLaneMasks[i] only (the other lanes add nothing
// and do not count it in lightsEvaluated; a light with no lane left is not counted in the early-
// out counters either). So each lane sums exactly its own sub-list, in list order: one packet-wide
// evaluation per light of the union of the lanes' lists, as a SIMT warp with per-lane lists pays.
// lightLaneMasks.size() must equal lightIndices.size().
void shadePacket(const KernelIsa& isa, const ShadingPacket& packet, uint32_t laneMask,
                 const KernelLights& lights, std::span<const uint32_t> lightIndices,
                 std::span<const uint16_t> lightLaneMasks, PacketAccumulator& accumulator,
                 bool countContributing = true);

// The scalar path, what shadePacket runs for KernelIsa::scalar(): evaluateLight (float) lane by
// lane, and the early-out counters from the same tests evaluateLight makes.
// lightLaneMasks: empty, or one lane mask per light as in the overload above.
void shadePacketScalar(const ShadingPacket& packet, uint32_t laneMask, const KernelLights& lights,
                       std::span<const uint32_t> lightIndices, PacketAccumulator& accumulator,
                       bool countContributing = true,
                       std::span<const uint16_t> lightLaneMasks = {});

} // namespace lighting::kernel
