// `ideal`: perfect culling, the ceiling of any exact culling method. At every pixel it shades
// exactly the lights that contribute there (non-zero radiance, the oracle's definition), in
// ascending light order, through the shared shading loop (shadeWithLightList). Its image is
// therefore bitwise `brute`'s and its evaluated count equals the oracle at every pixel (culling
// efficiency 1).
//
// The lists cost as much as `brute` to make (every light at every pixel, ContributingLights.h),
// so they are made OUTSIDE the timer: timingsMs holds only "shading" (decode + the contributing
// lights), and the list-building time is recorded as the parameter untimed_list_build_ms (in
// stats.json's stage_parameters), not as a pass, so it is in neither timings_ms nor the total.
// What the stage measures is the shading a perfect culler would leave; any exact stage's shading
// pass can at best reach it, and its cull/assign pass comes on top.
//
// Options: none. Parameters: untimed_list_build_ms, contributing_pairs (= the oracle total).
// Threads: lists as ContributingLights (deterministic), shading rows in parallel, each pixel
// written by one task.
#include "lighting/stages/Stages.h"

#include <chrono>

#include <tbb/parallel_for.h>

#include "lighting/BlendedPass.h"
#include "lighting/ContributingLights.h"
#include "lighting/LightListShading.h"
#include "lighting/PassNames.h"

namespace lighting {

namespace {

class IdealStage final : public ShadingStage {
public:
    std::string name() const override { return "ideal"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        const std::vector<LightInView<float>>& lights = inputs.lights->lights;
        result.resize(width, height, false);

        auto start = std::chrono::steady_clock::now();
        mLists.build(gb, lights);
        const double listBuildMs = millisecondsSince(start);

        start = std::chrono::steady_clock::now();
        tbb::parallel_for(0, height, [&](int y) {
            for (int x = 0; x < width; ++x)
                shadeWithLightList(gb, x, y, lights, mLists.lightsOf(size_t(y) * width + x),
                                   result);
        });
        result.timingsMs.emplace_back(pass::kShading, millisecondsSince(start));
        // Blended surfaces: each fragment's contributing lights, found by testing every light at
        // the fragment (the lists above are the opaque surface's), inside the blend pass's time.
        if (mBlended.prepare(inputs))
            mBlended.shade(
                gb.depth(),
                [&](int, int, const gbuffer::Surface& point, uint32_t) {
                    return mBlended.contributingLights(point);
                },
                result);
        result.parameters["untimed_list_build_ms"] = std::to_string(listBuildMs);
        result.parameters["contributing_pairs"] = std::to_string(mLists.pairCount());
    }

private:
    BlendedPass mBlended;      // blended surfaces after the opaque pass (BlendedPass.h)
    ContributingLights mLists; // reused across calls
};

} // namespace

std::unique_ptr<ShadingStage> makeIdealStage(const StageSpec& spec) {
    rejectUnknownOptions(spec, {});
    return std::make_unique<IdealStage>();
}

} // namespace lighting
