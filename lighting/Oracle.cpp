#include "lighting/Oracle.h"

#include "lighting/EveryLight.h"

namespace lighting {

std::vector<uint32_t> countContributingLights(const StageInputs& inputs) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    StageResult scratch;
    scratch.resize(gb.width(), gb.height(), true);
    shadeWithEveryLight<float>(
        gb.width(), gb.height(), inputs.lights->lights,
        [&](int x, int y, gbuffer::Surface& point) { return gbufferSurfaceAt(gb, x, y, point); },
        scratch);
    return std::move(scratch.lightsOracle);
}

} // namespace lighting
