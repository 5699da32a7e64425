// MaterialAlpha: a triangle's base colour alpha at a point of it, the one alpha every alpha test
// reads: the G-buffer's (AlphaCoverage.h, at a pixel centre) and the shadow casters' (maps and
// rays alike, lighting/shadows/CasterMaterials.h, at a texel centre or a ray's hit).
// alpha = baseColorFactor.a * the base colour texture's alpha (linear, bilinear, wrapping:
// scenes::sampleAlpha, bitwise Texture::sample's alpha) at the uv the weights give (the material's
// texCoord set, then its KHR_texture_transform). The loaders read no vertex colours, so there is no
// vertex-colour alpha. Pure and thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/SceneGeometry.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"
#include "scenes/materials/TextureAlpha.h"

namespace gbuffer {

// The uv `material`'s base colour texture reads on `triangle` at `weights` of its three corners
// (index order, summing to 1): its texCoord set, before the texture transform.
inline glm::vec2 baseColorUv(const scenes::Material& material, const SceneGeometry& geometry,
                             uint32_t triangle, const glm::vec3& weights) {
    const uint32_t* index = geometry.indices.data() + 3 * size_t(triangle);
    const bool second = material.baseColorMapping.texCoord == 1 && !geometry.uv1.empty();
    const std::vector<glm::vec2>& uvs = second ? geometry.uv1 : geometry.uv;
    return raster::interpolate(uvs[index[0]], uvs[index[1]], uvs[index[2]], weights);
}

// `material`'s base colour alpha at `uv` (as baseColorUv gives it).
inline float baseColorAlphaAtUv(const scenes::Scene& scene, const scenes::Material& material,
                                glm::vec2 uv) {
    if (material.baseColorTexture < 0)
        return material.baseColorFactor.a;
    return material.baseColorFactor.a *
           scenes::sampleAlpha(scene.textures[size_t(material.baseColorTexture)],
                               material.baseColorMapping.apply(uv));
}

// `triangle`'s base colour alpha at `weights` of its three corners.
inline float baseColorAlpha(const scenes::Scene& scene, const SceneGeometry& geometry,
                            uint32_t triangle, const glm::vec3& weights) {
    const scenes::Material& material = scene.materials[geometry.triangleMaterial[triangle]];
    if (material.baseColorTexture < 0)
        return material.baseColorFactor.a;
    return baseColorAlphaAtUv(scene, material, baseColorUv(material, geometry, triangle, weights));
}

} // namespace gbuffer
