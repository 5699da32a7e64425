#include "lighting/Oracle.h"

#include "lighting/EveryLight.h"

namespace lighting {

std::vector<uint32_t> countContributingLights(const Frame& frame) {
    const gbuffer::GBuffer& gb = *frame.gbuffer;
    StageResult scratch;
    scratch.resize(gb.width(), gb.height(), true);
    shadeWithEveryLight<float>(
        gb.width(), gb.height(), frame.lights->lights,
        [&](int x, int y, ShadingPoint<float>& point) { return gbufferSurfaceAt(gb, x, y, point); },
        scratch);
    return std::move(scratch.lightsOracle);
}

} // namespace lighting
