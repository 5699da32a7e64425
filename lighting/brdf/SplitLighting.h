// Split lighting: the lighting at one point split the way light buffers store it (light pre-pass,
// inferred lighting), into sums that do not depend on the material's colour, which the material
// pass supplies (combineSplitLighting):
// - Blinn-Phong: `diffuse` is the diffuse term with albedo 1, `specular` the specular term with
//   intensity 1, both from the one BRDF (evaluateLight); a light whose diffuse part is zero
//   (beyond range, facing away) has zero specular too, so it is not evaluated twice.
// - metallic-roughness: `diffuse` times c_diff, `specular` times f0, plus `specularEdge`
//   (splitLightMetallicRoughness, MetallicRoughness.h): exact, since the model is linear in the
//   base colour once roughness (in the G-buffer) is known.
//
// addSplitLight is the one per-light definition, in float: splitLighting (a pixel's list) and the
// kernel's scalar split path (lighting/kernel/SplitLightKernel.h, lane by lane) both call it, and
// the kernel's vector split path performs its float operations in its order (only Blinn-Phong's
// pow differs). Header-only and free of stage types so that lighting/kernel can use it.
// Conventions: view space, camera at the origin looking down -Z. Pure functions, thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "lighting/brdf/Brdf.h"
#include "lighting/brdf/LightInView.h"
#include "lighting/brdf/MetallicRoughness.h"

namespace lighting {

struct SplitLighting {
    glm::vec3 diffuse{0.0f};
    glm::vec3 specular{0.0f};
    glm::vec3 specularEdge{0.0f}; // metallic-roughness only (Fresnel edge); zero for Blinn-Phong
};

// The two Blinn-Phong evaluations of a point: albedo 1 and specular intensity 0 (the diffuse
// part), albedo 0 and intensity 1 (the specular part). Built once per point.
struct SplitPoints {
    gbuffer::Surface diffuse;
    gbuffer::Surface specular;
    explicit SplitPoints(const gbuffer::Surface& point) : diffuse(point), specular(point) {
        diffuse.albedo = glm::vec3(1.0f);
        diffuse.specularIntensity = 0.0f;
        specular.albedo = glm::vec3(0.0f);
        specular.specularIntensity = 1.0f;
    }
};

// Adds one light's split lighting at `point` (whose Blinn-Phong evaluations are `points`) to `sum`,
// each term times `shadow` (the light's shadow factor there, lighting/shadows; 1 = unshadowed,
// and x 1 is exact). Whether Blinn-Phong's specular is evaluated is decided by the unshadowed
// diffuse term.
inline void addSplitLight(const gbuffer::Surface& point, const SplitPoints& points,
                          const glm::vec3& toViewer, const LightInView<float>& light,
                          SplitLighting& sum, float shadow = 1.0f) {
    if (point.model == scenes::MaterialModel::MetallicRoughness) {
        const MetallicRoughnessSplit<float> split =
            splitLightMetallicRoughness(point.positionView, point.normalView, point.roughness,
                                        point.occlusion, toViewer, light);
        sum.diffuse += split.diffuse * shadow;
        sum.specular += split.specularF0 * shadow;
        sum.specularEdge += split.specularEdge * shadow;
        return;
    }
    const glm::vec3 d = evaluateLight(points.diffuse, toViewer, light);
    sum.diffuse += d * shadow;
    if (contributes(d) && light.type != scenes::LightType::Ambient)
        sum.specular += evaluateLight(points.specular, toViewer, light) * shadow;
}

// The split lighting of `point` summed over `lightIndices`, in list order.
inline SplitLighting splitLighting(const gbuffer::Surface& point,
                                   const std::vector<LightInView<float>>& lights,
                                   std::span<const uint32_t> lightIndices) {
    const glm::vec3 toViewer = glm::normalize(-point.positionView);
    const SplitPoints points(point);
    SplitLighting sum;
    for (uint32_t index : lightIndices)
        addSplitLight(point, points, toViewer, lights[index], sum);
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
