#include "lighting/Oracle.h"

#include <tbb/parallel_for.h>

#include "lighting/culling/LightBounds.h"
#include "lighting/lists/EveryLight.h"
#include "lighting/lists/LightGrid.h"
#include "lighting/passes/BlendedPass.h"

namespace lighting {

namespace {

void addBlended(const StageInputs& inputs, std::vector<uint32_t>& counts) {
    BlendedPass blended;
    if (blended.prepare(inputs))
        blended.addOracle(inputs.gbuffer->depth(), counts);
}

} // namespace

std::vector<uint32_t> countContributingLights(const StageInputs& inputs) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    const int width = gb.width(), height = gb.height();
    const std::vector<LightInView<float>>& lights = inputs.lights->lights;

    const auto box = surfaceBox<gbuffer::Surface>(
        width, height, [&gb](int x, int y, gbuffer::Surface& s) { return gb.surfaceAt(x, y, s); });
    std::vector<uint32_t> counts(size_t(width) * height, 0);
    if (box) { // some pixel is covered
        LightGrid grid;
        grid.build(boundingSpheresView(*inputs.lights), box->first, box->second);
        tbb::parallel_for(0, height, [&](int y) {
            for (int x = 0; x < width; ++x) {
                gbuffer::Surface point;
                if (!gb.surfaceAt(x, y, point))
                    continue;
                const glm::vec3 toViewer = glm::normalize(-point.positionView);
                uint32_t contributing = 0;
                for (uint32_t light : grid.everywhere())
                    contributing += contributes(evaluateLight(point, toViewer, lights[light]));
                for (uint32_t light : grid.candidatesAt(point.positionView))
                    contributing += contributes(evaluateLight(point, toViewer, lights[light]));
                counts[size_t(y) * width + x] = contributing;
            }
        });
    }
    addBlended(inputs, counts);
    return counts;
}

std::vector<uint32_t> countContributingLightsBrute(const StageInputs& inputs) {
    const gbuffer::GBuffer& gb = *inputs.gbuffer;
    StageResult scratch;
    shadeWithEveryLight(
        gb.width(), gb.height(), inputs.lights->lights,
        [&gb](int x, int y, gbuffer::Surface& s) { return gb.surfaceAt(x, y, s); }, scratch);
    addBlended(inputs, scratch.lightsOracle);
    return std::move(scratch.lightsOracle);
}

} // namespace lighting
