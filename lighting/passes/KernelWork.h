// KernelWork: what the shading kernel did over a frame, as every stage that calls it records it
// (accumulateLights, accumulateSplitLights, `deferred`, FragmentShading): the SIMT cost model's
// lane slots (lighting/README.md) and the packet-level counters of kernel::PacketAccumulator.
// Each task sums its own KernelWork; the stage adds them in a fixed order after its parallel loop
// (integers: the total does not depend on the thread count) and records them once per kernel
// pass. A frame can have two kernel passes (the opaque surfaces, then the blended ones,
// BlendedPass.h): the second record adds to the first, so the frame's figures are its whole
// work and simt_efficiency (the oracle, which counts blended fragments too, over the lane slots)
// compares like with like.
#pragma once

#include <cstdint>
#include <iterator>
#include <string>

#include "lighting/ShadingStage.h"
#include "lighting/kernel/KernelIsa.h"

namespace lighting {

struct KernelWork {
    uint64_t laneSlots = 0;             // SIMT lane slots: warp lanes x lights each warp paid
    uint64_t groups = 0;                // kernel calls (lane groups shaded)
    uint64_t skippedAtRange = 0;        // packet-wide light iterations by where they ended
    uint64_t skippedAtConeOrFacing = 0; // (PacketAccumulator's three counters)
    uint64_t shaded = 0;

    // Adds a packet's three early-out counters (kernel::PacketAccumulator's or
    // SplitPacketAccumulator's).
    template <class Accumulator> void addCounters(const Accumulator& accumulator) {
        skippedAtRange += accumulator.lightsSkippedAtRange;
        skippedAtConeOrFacing += accumulator.lightsSkippedAtConeOrFacing;
        shaded += accumulator.lightsShaded;
    }

    KernelWork& operator+=(const KernelWork& other) {
        laneSlots += other.laneSlots;
        groups += other.groups;
        skippedAtRange += other.skippedAtRange;
        skippedAtConeOrFacing += other.skippedAtConeOrFacing;
        shaded += other.shaded;
        return *this;
    }

    // Records "isa" (what ran), "simt_warp", "simt_lane_slots", "packet_groups" and the three
    // "packet_lights_*" counters; each counter adds to the value an earlier pass of the frame
    // recorded.
    void record(const kernel::KernelIsa& isa, int warpLanes, StageResult& result) const {
        result.parameters["isa"] = isa.name();
        result.parameters["simt_warp"] = std::to_string(warpLanes);
        const uint64_t values[] = {laneSlots, groups, skippedAtRange, skippedAtConeOrFacing,
                                   shaded};
        for (size_t k = 0; k < std::size(kCounterKeys); ++k)
            add(result, kCounterKeys[k], values[k]);
    }

    // The counters record() writes, in its order: additive over a frame's kernel passes.
    static constexpr const char* kCounterKeys[] = {
        "simt_lane_slots", "packet_groups", "packet_lights_skipped_at_range",
        "packet_lights_skipped_at_cone_or_facing", "packet_lights_shaded"};

    // Adds another run's recorded counters to `result`'s (a multisampled frame's layer runs and
    // background run, MultisampleShading.h: the frame's work is every run's). A counter `from`
    // does not have is skipped.
    static void addRecorded(const StageResult& from, StageResult& result) {
        for (const char* key : kCounterKeys) {
            const auto value = from.parameters.find(key);
            if (value != from.parameters.end())
                add(result, key, std::stoull(value->second));
        }
    }

private:
    static void add(StageResult& result, const std::string& key, uint64_t value) {
        const auto earlier = result.parameters.find(key);
        if (earlier != result.parameters.end())
            value += std::stoull(earlier->second);
        result.parameters[key] = std::to_string(value);
    }
};

} // namespace lighting
