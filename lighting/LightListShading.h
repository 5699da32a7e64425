// shadeWithLightList: the shading loop every culling stage ends in. At one pixel, evaluate the
// given lights (indices into the frame's light list, ascending) with the one BRDF, accumulate
// radiance and count evaluations. Keeping the indices ascending makes the sum bitwise equal to
// `brute`'s whenever the skipped lights contribute exactly zero (x + 0 == x in IEEE arithmetic),
// which is what exact culling guarantees.
#pragma once

#include <cstdint>
#include <span>

#include "lighting/Brdf.h"
#include "lighting/ShadingStage.h"

namespace lighting {

// Shades `point`, the surface at `pixel`, with `lightIndices`; writes result.radiance and
// result.lightsEvaluated at that pixel.
inline void shadeWithLightList(const gbuffer::Surface& point, size_t pixel,
                               const std::vector<LightInView<float>>& lights,
                               std::span<const uint32_t> lightIndices, StageResult& result) {
    const glm::vec3 toViewer = glm::normalize(-point.positionView);
    glm::vec3 sum(0.0f);
    for (uint32_t index : lightIndices)
        sum += evaluateLight(point, toViewer, lights[index]);
    result.radiance[0][pixel] = sum.x;
    result.radiance[1][pixel] = sum.y;
    result.radiance[2][pixel] = sum.z;
    result.lightsEvaluated[pixel] = uint32_t(lightIndices.size());
    result.traceLightList(pixel, lightIndices);
}

// Shades pixel (x, y) of the G-buffer with `lightIndices`. Background pixels are left alone (zero
// radiance, no evaluations).
inline void shadeWithLightList(const gbuffer::GBuffer& gb, int x, int y,
                               const std::vector<LightInView<float>>& lights,
                               std::span<const uint32_t> lightIndices, StageResult& result) {
    gbuffer::Surface point;
    if (gb.surfaceAt(x, y, point))
        shadeWithLightList(point, size_t(y) * gb.width() + x, lights, lightIndices, result);
}

// The lighting at one point split the way light buffers store it (light pre-pass, inferred
// lighting): `diffuse` is the diffuse term with albedo 1, `specular` the specular term with
// intensity 1, summed over `lightIndices`. Both come from the one BRDF; a light whose diffuse
// part is zero (beyond range, facing away) has zero specular too, so it is not evaluated twice.
struct SplitLighting {
    glm::vec3 diffuse{0.0f};
    glm::vec3 specular{0.0f};
};

inline SplitLighting splitLighting(const gbuffer::Surface& point,
                                   const std::vector<LightInView<float>>& lights,
                                   std::span<const uint32_t> lightIndices) {
    const glm::vec3 toViewer = glm::normalize(-point.positionView);
    gbuffer::Surface diffusePoint = point, specularPoint = point;
    diffusePoint.albedo = glm::vec3(1.0f);
    diffusePoint.specularIntensity = 0.0f;
    specularPoint.albedo = glm::vec3(0.0f);
    specularPoint.specularIntensity = 1.0f;
    SplitLighting sum;
    for (uint32_t index : lightIndices) {
        const glm::vec3 d = evaluateLight(diffusePoint, toViewer, lights[index]);
        sum.diffuse += d;
        if (contributes(d) && lights[index].type != scenes::LightType::Ambient)
            sum.specular += evaluateLight(specularPoint, toViewer, lights[index]);
    }
    return sum;
}

} // namespace lighting
