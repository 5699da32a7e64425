#include "lighting/Oracle.h"

#include <limits>

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

    // The box of the visible surfaces: per row, then over rows in order (min and max do not
    // depend on the order anyway).
    constexpr float kInf = std::numeric_limits<float>::infinity();
    std::vector<glm::vec3> rowMin(size_t(height), glm::vec3{kInf});
    std::vector<glm::vec3> rowMax(size_t(height), glm::vec3{-kInf});
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            gbuffer::Surface point;
            if (!gb.surfaceAt(x, y, point))
                continue;
            rowMin[size_t(y)] = glm::min(rowMin[size_t(y)], point.positionView);
            rowMax[size_t(y)] = glm::max(rowMax[size_t(y)], point.positionView);
        }
    });
    glm::vec3 boxMin(kInf), boxMax(-kInf);
    for (int y = 0; y < height; ++y) {
        boxMin = glm::min(boxMin, rowMin[size_t(y)]);
        boxMax = glm::max(boxMax, rowMax[size_t(y)]);
    }
    std::vector<uint32_t> counts(size_t(width) * height, 0);
    if (boxMin.x <= boxMax.x) { // some pixel is covered
        LightGrid grid;
        grid.build(boundingSpheresView(*inputs.lights), boxMin, boxMax);
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
