// LightListShading: the per-pixel pieces shared by the stages that do not end in one light sum per
// pixel on the kernel: addEmission (deferred's light volumes, which accumulate light by light) and
// the split lighting of the light buffers (light-prepass, inferred). The per-pixel "sum the lights,
// store the pixel" loop it once held is gone: the G-buffer stages end in accumulateLights
// (LightAccumulation.h), the forward stages in FragmentShading (FragmentShading.h), both on the
// shared light kernel.
#pragma once

#include <cstdint>
#include <span>

#include <tbb/parallel_for.h>

#include "lighting/Brdf.h"
#include "lighting/ShadingStage.h"

namespace lighting {

// Adds every covered pixel's emission (GBuffer::emission) to result.radiance, for the stages that
// accumulate light by light (deferred's volumes): once, after the last light, so the sum is the
// light sum plus the emission as in every other stage. Nothing to do when no material emits.
inline void addEmission(const gbuffer::GBuffer& gb, StageResult& result) {
    if (!gb.hasEmission())
        return;
    const int width = gb.width();
    tbb::parallel_for(0, gb.height(), [&](int y) {
        for (int x = 0; x < width; ++x) {
            const size_t pixel = size_t(y) * width + x;
            if (!gb.covered(pixel))
                continue;
            const glm::vec3 emitted = gb.emission(pixel);
            for (int c = 0; c < 3; ++c)
                result.radiance[c][pixel] += emitted[c];
        }
    });
}

// The lighting at one point split the way light buffers store it (light pre-pass, inferred
// lighting), summed over `lightIndices`, in terms that do not depend on the material's colour,
// which the material pass supplies (combineSplitLighting):
// - Blinn-Phong: `diffuse` is the diffuse term with albedo 1, `specular` the specular term with
//   intensity 1, both from the one BRDF (evaluateLight); a light whose diffuse part is zero
//   (beyond range, facing away) has zero specular too, so it is not evaluated twice.
// - metallic-roughness: `diffuse` times c_diff, `specular` times f0, plus `specularEdge`
//   (splitLightMetallicRoughness, MetallicRoughness.h): exact, since the model is linear in the
//   base colour once roughness (in the G-buffer) is known.
struct SplitLighting {
    glm::vec3 diffuse{0.0f};
    glm::vec3 specular{0.0f};
    glm::vec3 specularEdge{0.0f}; // metallic-roughness only (Fresnel edge); zero for Blinn-Phong
};

inline SplitLighting splitLighting(const gbuffer::Surface& point,
                                   const std::vector<LightInView<float>>& lights,
                                   std::span<const uint32_t> lightIndices) {
    const glm::vec3 toViewer = glm::normalize(-point.positionView);
    if (point.model == scenes::MaterialModel::MetallicRoughness) {
        SplitLighting sum;
        for (uint32_t index : lightIndices) {
            const MetallicRoughnessSplit<float> split =
                splitLightMetallicRoughness(point.positionView, point.normalView, point.roughness,
                                            point.occlusion, toViewer, lights[index]);
            sum.diffuse += split.diffuse;
            sum.specular += split.specularF0;
            sum.specularEdge += split.specularEdge;
        }
        return sum;
    }
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

// The material pass's half of a split light buffer: the radiance of `material` (the surface the
// material pass resolved) lit by `diffuse`, `specular` and `specularEdge` (SplitLighting's terms,
// possibly filtered or made monochrome by the stage). Blinn-Phong: albedo diffuse + intensity
// specular; metallic-roughness: c_diff diffuse + f0 specular + specularEdge. The emission is the
// caller's to add.
inline glm::vec3 combineSplitLighting(const gbuffer::Surface& material, const glm::vec3& diffuse,
                                      const glm::vec3& specular, const glm::vec3& specularEdge) {
    if (material.model == scenes::MaterialModel::MetallicRoughness) {
        const MetallicRoughnessLobes<float> lobes =
            metallicRoughnessLobes(MetallicRoughnessSurface<float>{
                material.albedo, material.metallic, material.roughness, material.occlusion});
        return lobes.diffuseColor * diffuse + lobes.f0 * specular + specularEdge;
    }
    return material.albedo * diffuse + material.specularIntensity * specular;
}

} // namespace lighting
