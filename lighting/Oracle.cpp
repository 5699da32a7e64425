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

namespace {

// Both oracles: contributing lights, and with `visibility` only those that reach the surface.
std::vector<uint32_t> countReaching(const StageInputs& inputs,
                                    const shadows::ExactShadowLookup* visibility) {
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
                auto count = [&](uint32_t light) {
                    if (!contributes(evaluateLight(point, toViewer, lights[light])))
                        return 0u;
                    if (!visibility || !visibility->casts(light))
                        return 1u;
                    return visibility->visibility(light, glm::dvec3(point.positionView),
                                                  glm::dvec3(point.normalView)) > 0.0
                               ? 1u
                               : 0u;
                };
                for (uint32_t light : grid.everywhere())
                    contributing += count(light);
                for (uint32_t light : grid.candidatesAt(point.positionView))
                    contributing += count(light);
                counts[size_t(y) * width + x] = contributing;
            }
        });
    }
    addBlended(inputs, counts);
    return counts;
}

} // namespace

std::vector<uint32_t> countContributingLights(const StageInputs& inputs) {
    return countReaching(inputs, nullptr);
}

std::vector<uint32_t> countVisibleLights(const StageInputs& inputs,
                                         const shadows::ExactShadowLookup& visibility) {
    return countReaching(inputs, &visibility);
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
