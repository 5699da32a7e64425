// `brute`: every light at every pixel, in float, from the G-buffer. The baseline every culling
// stage must match (bitwise, for the same ISA, when its lists are ascending) and the source of
// the per-pixel oracle count. The loop is accumulateLights (LightAccumulation.h) with every light
// as the list of every packet, on the kernel's ISA (`--isa`); pass "shading".
#include "lighting/StageRegistry.h"

#include <optional>

#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

class BruteStage final : public ShadingStage {
public:
    std::string name() const override { return "brute"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }
    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        result.resize(gb.width(), gb.height(), true);
        PassTimer shading(result, pass::kShading);
        if (!mEveryLight || mLightCount != inputs.lights->size()) {
            mLightCount = inputs.lights->size();
            mEveryLight.emplace(mLightCount);
        }
        accumulateLights(inputs, *mEveryLight, {.countOracle = true}, result);
        shading.stop();
        if (mBlended.prepare(inputs))
            mBlended.shadeWithEveryLight(gb.depth(), result);
    }

private:
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
    size_t mLightCount = 0;
    std::optional<EveryLightSource> mEveryLight; // the list 0..n-1, kept across frames
};

const StageRegistrar
    kRegistrar({.name = "brute",
                .description = "every light at every pixel, float, from the G-buffer",
                .kind = StageKind::Exact,
                .options = {}, // none
                .listOrder = 10},
               [](const StageOptions&) { return std::make_unique<BruteStage>(); });

} // namespace

} // namespace lighting
