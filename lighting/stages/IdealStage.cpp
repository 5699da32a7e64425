// `ideal`: perfect culling, the ceiling of any exact culling method. At every pixel it shades
// exactly the lights that contribute there (non-zero radiance, the oracle's definition), in
// ascending light order, through the shared shading loop (accumulateLights, LightAccumulation.h)
// and so the same kernel and ISA as the other stages. Its image is therefore bitwise `brute`'s on
// the same ISA and its evaluated count equals the oracle at every pixel (culling efficiency 1).
//
// Per packet of 4x4 pixels the kernel gets the union of the 16 lanes' lists with a lane mask per
// light (PacketContributingLights.h): each lane sums only its own lights, and the packet pays one
// packet-wide evaluation per light of the union, never one kernel call per distinct list. That is
// the least a packet (or a SIMT warp) can pay with perfect per-pixel culling, so this stage's
// shading time is the ceiling of the vector kernel's exact stages, not only of scalar shading.
//
// The lists cost as much as `brute` to make (every light at every pixel, ContributingLights.h),
// so they are made OUTSIDE the timer: timingsMs holds only "shading" (decode + the contributing
// lights), and the list-building time (per-pixel lists and their packet unions) is recorded as
// the parameter untimed_list_build_ms (in stats.json's stage_parameters), not as a pass, so it is
// in neither timings_ms nor the total. What the stage measures is the shading a perfect culler
// would leave; any exact stage's shading pass can at best reach it, and its cull/assign pass comes
// on top.
//
// Options: none. Parameters: untimed_list_build_ms, contributing_pairs (= the oracle total),
// packet_light_pairs (packet-wide evaluations), and accumulateLights' isa, simt_warp and
// simt_lane_slots. Threads: lists as ContributingLights (deterministic), shading as
// accumulateLights (each pixel written by one task).
#include "lighting/StageRegistry.h"

#include "lighting/lists/ContributingLights.h"
#include "lighting/lists/PacketContributingLights.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

class IdealStage final : public ShadingStage {
public:
    std::string name() const override { return "ideal"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const std::vector<LightInView<float>>& lights = inputs.lights->lights;
        result.resize(gb.width(), gb.height(), false);

        const Stopwatch listBuild; // untimed: a figure of its own, in no pass
        mPixelLists.build(gb, lights);
        mPacketLists.build(mPixelLists, lights.size());
        const double listBuildMs = listBuild.milliseconds();

        PassTimer shading(result, pass::kShading);
        accumulateLights(inputs, mPacketLists, {}, result);
        shading.stop();
        // Blended surfaces: each fragment's contributing lights, found by testing every light at
        // the fragment (the lists above are the opaque surface's), inside the blend pass's time.
        if (mBlended.prepare(inputs))
            mBlended.shadeWithContributingLights(gb.depth(), result);
        result.parameters["untimed_list_build_ms"] = std::to_string(listBuildMs);
        result.parameters["contributing_pairs"] = std::to_string(mPixelLists.pairCount());
        result.parameters["packet_light_pairs"] = std::to_string(mPacketLists.pairCount());
    }

private:
    BlendedPass mBlended;                  // blended surfaces after the opaque pass (BlendedPass.h)
    ContributingLights mPixelLists;        // reused across calls
    PacketContributingLights mPacketLists; // reused across calls
};

const StageRegistrar kRegistrar(
    {.name = "ideal",
     .description = "perfect culling, the ceiling of exact culling: each pixel shades exactly its "
                    "contributing lights (lists made outside the timer)",
     .kind = StageKind::Exact,
     .options = {}, // none
     .listOrder = 20},
    [](const StageOptions&) { return std::make_unique<IdealStage>(); });

} // namespace

} // namespace lighting
