// `brute`: every light at every pixel, in float, from the G-buffer. The baseline every culling
// stage must match (up to summation order) and the source of the per-pixel oracle count.
#include "lighting/stages/Stages.h"

#include <chrono>

#include "lighting/EveryLight.h"
#include "lighting/PassNames.h"

namespace lighting {

namespace {

class BruteStage final : public ShadingStage {
public:
    std::string name() const override { return "brute"; }
    StageRequirements requirements() const override {
        return {{gbuffer::Channel::Depth, gbuffer::Channel::Normal, gbuffer::Channel::Albedo,
                 gbuffer::Channel::Specular},
                false};
    }
    void shade(const Frame& frame, StageResult& result) override {
        const gbuffer::GBuffer& gb = *frame.gbuffer;
        result.resize(gb.width(), gb.height(), true);
        const auto start = std::chrono::steady_clock::now();
        shadeWithEveryLight<float>(
            gb.width(), gb.height(), frame.lights->lights,
            [&](int x, int y, ShadingPoint<float>& point) {
                return gbufferSurfaceAt(gb, x, y, point);
            },
            result);
        result.timingsMs.emplace_back(pass::kShading, std::chrono::duration<double, std::milli>(
                                                          std::chrono::steady_clock::now() - start)
                                                          .count());
    }
};

} // namespace

std::unique_ptr<ShadingStage> makeBruteStage(const StageSpec& spec) {
    rejectUnknownOptions(spec, {});
    return std::make_unique<BruteStage>();
}

} // namespace lighting
