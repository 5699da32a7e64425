// `reference`: every light at every pixel in double precision, from the exact surface (position
// and normal recomputed in double from the unrounded geometry, materials unencoded). Every other
// image is compared with it. The loop is shadeWithEveryLight (EveryLight.h), shared with `brute`.
#include "lighting/StageRegistry.h"

#include "lighting/lists/EveryLight.h"
#include "lighting/passes/BlendedPass.h"

namespace lighting {

namespace {

class ReferenceStage final : public ShadingStage {
public:
    std::string name() const override { return "reference"; }
    StageRequirements requirements() const override { return {{gbuffer::Channel::Depth}, true}; }
    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::ExactSurface& exact = *inputs.exact;
        auto surfaceAt = [&exact](int x, int y, gbuffer::BasicSurface<double>& s) {
            return exact.surfaceAt(x, y, s);
        };
        // Every light that can reach a surface, found by a light grid over the exact surfaces:
        // the sum is bitwise the full loop's (EveryLight.h), and 10^6 lights stay tractable.
        LightGrid grid;
        const auto box =
            surfaceBox<gbuffer::BasicSurface<double>>(exact.width, exact.height, surfaceAt);
        if (box)
            grid.build(boundingSpheresView(*inputs.lights), box->first, box->second);
        shadeWithEveryLight(exact.width, exact.height, inputs.lights->lightsExact, surfaceAt,
                            result, box ? &grid : nullptr, inputs.exactShadows);
        if (mBlended.prepare(inputs))
            mBlended.compositeExact(inputs.gbuffer->depth(), result);
    }

private:
    BlendedPass mBlended; // blended surfaces after the opaque pass (BlendedPass.h)
};

const StageRegistrar kRegistrar(
    {.name = "reference",
     .description = "every light at every pixel, double precision, exact surface",
     .kind = StageKind::Reference,
     .options = {}, // none
     .listOrder = 0,
     .msaaRefusal =
         "the reference of an anti-aliased frame is supersampled instead (--reference-spp)"},
    [](const StageOptions&) { return std::make_unique<ReferenceStage>(); });

} // namespace

} // namespace lighting
