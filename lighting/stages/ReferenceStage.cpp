// `reference`: every light at every pixel in double precision, from the exact surface (position
// and normal recomputed in double from the unrounded geometry, materials unencoded). Every other
// image is compared with it.
#include "lighting/stages/Stages.h"

#include <chrono>

#include "lighting/EveryLight.h"
#include "lighting/PassNames.h"

namespace lighting {

namespace {

class ReferenceStage final : public ShadingStage {
public:
    std::string name() const override { return "reference"; }
    StageRequirements requirements() const override { return {{gbuffer::Channel::Depth}, true}; }
    void shade(const Frame& frame, StageResult& result) override {
        const gbuffer::ExactSurface& exact = *frame.exact;
        result.resize(exact.width, exact.height, true);
        const auto start = std::chrono::steady_clock::now();
        shadeWithEveryLight<double>(
            exact.width, exact.height, frame.lights->lightsExact,
            [&](int x, int y, ShadingPoint<double>& point) {
                const size_t pixel = size_t(y) * exact.width + x;
                if (!exact.covered(pixel))
                    return false;
                point = {exact.positionView[pixel], exact.normalView[pixel],
                         glm::dvec3(exact.albedo[pixel]), double(exact.specular[pixel].x),
                         double(exact.specular[pixel].y)};
                return true;
            },
            result);
        result.timingsMs.emplace_back(pass::kShading, std::chrono::duration<double, std::milli>(
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
