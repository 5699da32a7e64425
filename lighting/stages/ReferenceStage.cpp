// `reference`: every light at every pixel in double precision, from the exact surface (position
// and normal recomputed in double from the unrounded geometry, materials unencoded). Every other
// image is compared with it.
#include "lighting/stages/Stages.h"

#include <chrono>

#include "lighting/EveryLight.h"

namespace lighting {

namespace {

class ReferenceStage final : public ShadingStage {
public:
    std::string name() const override { return "reference"; }
    StageRequirements requirements() const override { return {{gbuffer::Channel::Depth}, true}; }
    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::ExactSurface& exact = *inputs.exact;
        result.resize(exact.width, exact.height, true);
        const auto start = std::chrono::steady_clock::now();
        shadeWithEveryLight<double>(
            exact.width, exact.height, inputs.lights->lightsExact,
            [&](int x, int y, gbuffer::BasicSurface<double>& point) {
                const size_t pixel = size_t(y) * exact.width + x;
                if (!exact.covered(pixel))
                    return false;
                point = exact.surface(pixel);
                return true;
            },
            result);
        result.timingsMs.emplace_back("shading", std::chrono::duration<double, std::milli>(
                                                     std::chrono::steady_clock::now() - start)
                                                     .count());
    }
};

} // namespace

std::unique_ptr<ShadingStage> makeReferenceStage(const StageSpec& spec) {
    rejectUnknownOptions(spec, {});
    return std::make_unique<ReferenceStage>();
}

} // namespace lighting
