// TriangleCorners: how the surface of a triangle at a pixel centre is computed, inline because the
// G-buffer resolve runs it at every pixel (VisibilityPass::RowSurfaces is its one user; read
// VisibilityPass.h first).
//
// A triangle's corners (clip-space x, y, w, view-space normals, uvs, material) are loaded once;
// along a pixel row the perspective-correct barycentric weights are affine in the pixel's NDC x
// (RowWeights), so a run of pixels showing the same triangle costs three multiply-adds per pixel
// plus the normal's normalisation. Homogeneous: valid for triangles crossing the near plane.
// Extending the surface means loading the new per-vertex or per-material data in load() and
// interpolating it in updateSurfaceAt(). Textures (base colour, metallic-roughness, normal) are
// read with their own uv set and KHR_texture_transform (scenes::TextureMapping); normal maps
// through NormalMapping.h, the formula the reference shares.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "gbuffer/visibility/NormalMapping.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "raster/Rasterizer.h"
#include "scenes/Scene.h"

namespace gbuffer {

// What the resolve reads of one material, decided once per frame (VisibilityPass::transform) so
// that a scene that does not use a feature does not pay for it: per triangle, load() copies only
// the vertex data the material's textures read, and per pixel one flag (textured) skips every
// texture branch of a material that has none. A texture the material model ignores (the
// metallic-roughness and occlusion textures of a Blinn-Phong material, a normal map without
// tangents) is null here, so nothing downstream tests the model again.
struct MaterialSampling {
    Surface constant; // the parts of the surface that do not vary over a triangle
    const scenes::Material* material = nullptr;
    const scenes::Texture* baseColorTexture = nullptr;         // null when untextured
    const scenes::Texture* metallicRoughnessTexture = nullptr; // null when absent or Blinn-Phong
    const scenes::Texture* normalTexture = nullptr;            // null when absent or no tangents
    const scenes::Texture* occlusionTexture = nullptr;         // null when absent or Blinn-Phong
    const scenes::Texture* emissiveTexture = nullptr;          // null when absent or no emission
    bool textured = false;                                     // one of the five is present
    bool secondUvSet = false; // textured and the geometry has TEXCOORD_1

    // One entry per scene material. Cost O(materials).
    static std::vector<MaterialSampling> of(const scenes::Scene& scene,
                                            const SceneGeometry& geometry) {
        std::vector<MaterialSampling> table(scene.materials.size());
        auto texture = [&](bool read, int index) {
            return read && index >= 0 ? &scene.textures[size_t(index)] : nullptr;
        };
        for (size_t i = 0; i < table.size(); ++i) {
            const scenes::Material& m = scene.materials[i];
            const bool metallicRoughness = m.model == scenes::MaterialModel::MetallicRoughness;
            MaterialSampling& entry = table[i];
            entry.material = &m;
            entry.baseColorTexture = texture(true, m.baseColorTexture);
            entry.metallicRoughnessTexture = texture(metallicRoughness, m.metallicRoughnessTexture);
            entry.normalTexture = texture(!geometry.tangentWorld.empty(), m.normalTexture);
            entry.occlusionTexture = texture(metallicRoughness, m.occlusionTexture);
            entry.emissiveTexture = texture(m.emits(), m.emissiveTexture);
            entry.textured = entry.baseColorTexture || entry.metallicRoughnessTexture ||
                             entry.normalTexture || entry.occlusionTexture || entry.emissiveTexture;
            entry.secondUvSet = entry.textured && !geometry.uv1.empty();
            Surface& s = entry.constant;
            s.material = uint32_t(i);
            s.albedo = glm::vec3(m.baseColorFactor);
            s.specularIntensity = m.specularIntensity;
            s.specularPower = m.specularPower;
            s.model = m.model;
            s.roughness = m.roughness;
            s.metallic = m.metallic;
            s.emissive = m.emission();
        }
        return table;
    }
};

struct TriangleCorners {
    // Clip-space x, y and w of the three vertices (z is not needed: depth comes from the
    // rasterizer).
    glm::vec3 clipX, clipY, clipW;
    glm::vec3 normalView[3];
    // Flat triangles (the three normals bitwise equal: floors, walls) have one normal direction;
    // it is normalised here once, and per pixel only the sign of the weight sum is needed.
    bool flat;
    bool flatNormalIsZero;    // flat with zero-length normals: the (0, 0, +-1) fallback
    bool textured;            // sampling->textured, kept here for the per-pixel test
    glm::vec3 flatNormalView; // unit, valid when flat and not zero
    glm::vec2 uv[3];          // loaded only for textured materials
    glm::vec2 uv1[3];         // loaded only when a texture reads TEXCOORD_1
    glm::vec4 tangentView[3]; // loaded only with a normal texture (w = bitangent sign)
    const MaterialSampling* sampling;

    // `materials` is MaterialSampling::of(scene, geometry).
    static TriangleCorners load(const SceneGeometry& geometry,
                                std::span<const MaterialSampling> materials,
                                std::span<const glm::vec4> clipPositions,
                                std::span<const glm::vec3> normalsView,
                                std::span<const glm::vec4> tangentsView, uint32_t triangle) {
        const uint32_t* index = geometry.indices.data() + 3 * size_t(triangle);
        TriangleCorners corners;
        corners.sampling = &materials[geometry.triangleMaterial[triangle]];
        const MaterialSampling& sampling = *corners.sampling;
        corners.textured = sampling.textured;
        for (int i = 0; i < 3; ++i) {
            const glm::vec4& clip = clipPositions[index[i]];
            corners.clipX[i] = clip.x;
            corners.clipY[i] = clip.y;
            corners.clipW[i] = clip.w;
            corners.normalView[i] = normalsView[index[i]];
        }
        if (sampling.textured)
            for (int i = 0; i < 3; ++i) {
                corners.uv[i] = geometry.uv[index[i]];
                corners.uv1[i] = sampling.secondUvSet ? geometry.uv1[index[i]] : corners.uv[i];
            }
        if (sampling.normalTexture)
            for (int i = 0; i < 3; ++i)
                corners.tangentView[i] = tangentsView[index[i]];
        corners.flat = corners.normalView[0] == corners.normalView[1] &&
                       corners.normalView[0] == corners.normalView[2];
        const float length2 = glm::dot(corners.normalView[0], corners.normalView[0]);
        corners.flatNormalIsZero = !(length2 > 0.0f);
        corners.flatNormalView = corners.flatNormalIsZero
                                     ? glm::vec3(0.0f)
                                     : corners.normalView[0] * (1.0f / std::sqrt(length2));
        return corners;
    }
};

// Perspective-correct barycentrics along one pixel row. The point sum(b_i c_i) of the triangle
// with clip-space vertices c_i projects onto the pixel centre (ndcX, ndcY) when
// sum b_i (x_i - ndcX w_i) = 0 and sum b_i (y_i - ndcY w_i) = 0, so b is the cross product of
// those two rows, up to scale (the barycentrics are b / sum b). The second row is fixed along a
// pixel row, so b = cross(x, rowY) - ndcX cross(w, rowY) is affine in ndcX: two cross products per
// run of pixels, then three multiply-adds per pixel.
struct RowWeights {
    glm::vec3 constant;
    glm::vec3 slope;

    static RowWeights of(const TriangleCorners& corners, float ndcY) {
        const glm::vec3 rowY = corners.clipY - ndcY * corners.clipW;
        return {glm::cross(corners.clipX, rowY), glm::cross(corners.clipW, rowY)};
    }
};

// The parts of a triangle's surface that do not vary over it: material index and model, albedo
// factor (the whole albedo when untextured), specular, roughness and metallic factors, emission
// factor (made once per material by MaterialSampling::of). Normal, textured albedo and the other
// textures come per pixel from updateSurfaceAt. positionView stays zero: it comes from depth
// (DepthDecoder).
inline const Surface& triangleSurface(const TriangleCorners& corners) {
    return corners.sampling->constant;
}

// The texture lookups of updateSurfaceAt at barycentric weights `weights` (summing to 1).
inline void updateTexturedSurfaceAt(Surface& surface, const TriangleCorners& corners,
                                    const glm::vec3& weights, bool backFace) {
    const MaterialSampling& sampling = *corners.sampling;
    const scenes::Material& material = *sampling.material;
    const glm::vec2 uv0 = raster::interpolate(corners.uv[0], corners.uv[1], corners.uv[2], weights);
    const glm::vec2 uv1 =
        raster::interpolate(corners.uv1[0], corners.uv1[1], corners.uv1[2], weights);
    auto uvOf = [&](const scenes::TextureMapping& mapping) {
        return mapping.apply(mapping.texCoord == 1 ? uv1 : uv0);
    };
    if (sampling.baseColorTexture)
        surface.albedo =
            glm::vec3(material.baseColorFactor) *
            glm::vec3(sampling.baseColorTexture->sample(uvOf(material.baseColorMapping)));
    if (sampling.metallicRoughnessTexture) {
        const glm::vec4 texel =
            sampling.metallicRoughnessTexture->sample(uvOf(material.metallicRoughnessMapping));
        surface.roughness = material.roughness * texel.g;
        surface.metallic = material.metallic * texel.b;
    }
    if (sampling.occlusionTexture) {
        const float r = sampling.occlusionTexture->sample(uvOf(material.occlusionMapping)).r;
        surface.occlusion = 1.0f + material.occlusionStrength * (r - 1.0f);
    }
    if (sampling.emissiveTexture)
        surface.emissive =
            sampling.constant.emissive *
            glm::vec3(sampling.emissiveTexture->sample(uvOf(material.emissiveMapping)));
    if (sampling.normalTexture) {
        const glm::vec4 tangent = raster::interpolate(
            corners.tangentView[0], corners.tangentView[1], corners.tangentView[2], weights);
        const glm::vec4 texel = sampling.normalTexture->sample(uvOf(material.normalMapping));
        surface.normalView =
            normalMapped(surface.normalView, backFace, glm::vec3(tangent),
                         tangent.w < 0.0f ? -1.0f : 1.0f, glm::vec3(texel), material.normalScale);
    }
}

// Sets the pixel-varying parts of `surface` (from triangleSurface of the same corners) at the
// pixel centre ndcX of the row `row` describes: the interpolated, normalised view-space normal
// (negated when the back face is visible: two-sided draws light the visible side; then normal
// mapped), the albedo times the base colour texture, roughness and metallic times the
// metallic-roughness texture's G and B, the occlusion texture's R (with occlusionStrength).
[[gnu::always_inline]] inline void updateSurfaceAt(Surface& surface, const TriangleCorners& corners,
                                                   const RowWeights& row, bool backFace,
                                                   float ndcX) {
    // Unnormalised weights: the normal is renormalised anyway, so only the sign of the scale
    // matters there, and the division stays off the per-pixel path unless a texture needs the
    // true weights. sum = 0 (pixel ray parallel to the plane) gives equal weights.
    glm::vec3 b = row.constant - ndcX * row.slope;
    float sum = b.x + b.y + b.z;
    if (sum == 0.0f) {
        b = glm::vec3(1.0f);
        sum = 3.0f;
    }
    // Two-sided draws light the visible side; a negative weight sum flips the interpolated sum.
    const float sign = (sum < 0.0f) != backFace ? -1.0f : 1.0f;
    // Zero-length normals (degenerate input) face the viewer.
    const glm::vec3 zeroNormalFallback(0.0f, 0.0f, backFace ? -1.0f : 1.0f);
    if (corners.flat) {
        surface.normalView =
            corners.flatNormalIsZero ? zeroNormalFallback : corners.flatNormalView * sign;
    } else {
        const glm::vec3 normal = raster::interpolate(corners.normalView[0], corners.normalView[1],
                                                     corners.normalView[2], b);
        const float length2 = glm::dot(normal, normal);
        surface.normalView =
            length2 > 0.0f ? normal * (sign / std::sqrt(length2)) : zeroNormalFallback;
    }
    if (corners.textured)
        updateTexturedSurfaceAt(surface, corners, b * (1.0f / sum), backFace);
}

} // namespace gbuffer
