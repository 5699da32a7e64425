#include "lighting/Oracle.h"

#include "lighting/lists/EveryLight.h"
#include "lighting/passes/BlendedPass.h"

namespace lighting {

std::vector<uint32_t> countContributingLights(const StageInputs& inputs) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    StageResult scratch;
    shadeWithEveryLight(
        gb.width(), gb.height(), inputs.lights->lights,
        [&gb](int x, int y, gbuffer::Surface& s) { return gb.surfaceAt(x, y, s); }, scratch);
    BlendedPass blended;
    if (blended.prepare(inputs))
        blended.addOracle(gb.depth(), scratch.lightsOracle);
    return std::move(scratch.lightsOracle);
}

} // namespace lighting
