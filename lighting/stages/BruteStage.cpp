// `brute`: every light at every pixel, in float, from the G-buffer. The baseline every culling
// stage must match (up to summation order) and the source of the per-pixel oracle count. The
// loop is shadeWithEveryLight (EveryLight.h), shared with `reference` and the oracle.
#include "lighting/stages/Stages.h"

#include "lighting/EveryLight.h"

namespace lighting {

namespace {

class BruteStage final : public ShadingStage {
public:
    std::string name() const override { return "brute"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }
    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        shadeWithEveryLight(
            gb.width(), gb.height(), inputs.lights->lights,
            [&gb](int x, int y, gbuffer::Surface& s) { return gb.surfaceAt(x, y, s); }, result);
    }
};

} // namespace

std::unique_ptr<ShadingStage> makeBruteStage(const StageSpec& spec) {
    rejectUnknownOptions(spec, {});
    return std::make_unique<BruteStage>();
}

} // namespace lighting
