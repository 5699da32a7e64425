// Material: what a surface is made of. Two material models (DESIGN.md), each with its own lighting
// function in lighting/: Lambert + normalised Blinn-Phong (Brdf.h), used by the procedural scenes
// and the seeds' reproductions, and the glTF 2.0 metallic-roughness model (MetallicRoughness.h:
// GGX, Smith height-correlated visibility, Schlick Fresnel), used by glTF models.
//
// Conventions:
// - Colours and factors are linear. Colour textures (base colour, emissive) are stored sRGB and
//   decoded to linear when sampled; data textures (metallic-roughness, normal, occlusion) are
//   stored and sampled as linear values (Texture::srgb says which).
// - A texture is an index into Scene::textures, -1 = none (the factor alone applies). The factor
//   multiplies the texture, as glTF defines: baseColor = baseColorFactor * texture,
//   metallic = metallicFactor * texture.B, roughness = roughnessFactor * texture.G,
//   emissive = emissiveFactor * emissiveStrength * texture.rgb,
//   occlusion = 1 + occlusionStrength * (texture.R - 1), normal = normalize((2 * texture.rgb - 1)
//   * (normalScale, normalScale, 1)) in the tangent frame (Mesh::tangents).
// - Which uv set a texture reads and how the uv is transformed first is its TextureMapping
//   (glTF texCoord and KHR_texture_transform).
// Plain data; reading is thread-safe.
#pragma once

#include <array>
#include <string>

#include <glm/glm.hpp>

namespace scenes {

enum class MaterialModel {
    BlinnPhong,        // Lambert + normalised Blinn-Phong: specularIntensity, specularPower
    MetallicRoughness, // glTF 2.0 Appendix B: metallic, roughness (+ their texture)
};

// "blinn-phong" or "metallic-roughness": the names used in files and on the command line.
const char* materialModelName(MaterialModel model);
// The inverse of materialModelName; throws std::invalid_argument naming the valid names.
MaterialModel parseMaterialModel(const std::string& name);

// glTF alphaMode. Opaque ignores alpha; Mask keeps a sample when alpha >= alphaCutoff and drops
// it otherwise; Blend composites the surface over what is behind it with its alpha.
enum class AlphaMode { Opaque, Mask, Blend };

// How a texture's uv is found (glTF texCoord and KHR_texture_transform): uv set `texCoord`,
// then uv' = offset + rotate(rotationRadians) * (scale * uv), the rotation turning the uvs
// counter-clockwise, i.e. u' = cos r * su + sin r * sv, v' = -sin r * su + cos r * sv (the
// extension's matrix; its example maps [0,1]^2 onto the image's lower-left quadrant).
struct TextureMapping {
    int texCoord = 0; // 0 = Mesh::uvs (TEXCOORD_0), 1 = Mesh::uvs1 (TEXCOORD_1)
    glm::vec2 offset{0.0f};
    float rotationRadians = 0.0f;
    glm::vec2 scale{1.0f};

    bool isIdentity() const {
        return offset == glm::vec2(0.0f) && rotationRadians == 0.0f && scale == glm::vec2(1.0f);
    }
    glm::vec2 apply(glm::vec2 uv) const;
};

struct Material {
    std::string name;
    MaterialModel model = MaterialModel::BlinnPhong;

    // -- Both models -------------------------------------------------------------------------
    glm::vec4 baseColorFactor{1.0f}; // linear RGBA (the diffuse albedo for Blinn-Phong)
    int baseColorTexture = -1;       // sRGB colour, alpha linear
    TextureMapping baseColorMapping;
    int normalTexture = -1; // tangent-space normal map, linear, +Y up in the image (glTF)
    TextureMapping normalMapping;
    float normalScale = 1.0f;  // scales the map's X and Y (glTF normalTexture.scale)
    int occlusionTexture = -1; // linear, red channel; darkens ambient (indirect) light only
    TextureMapping occlusionMapping;
    float occlusionStrength = 1.0f; // 0 = no occlusion, 1 = the texture's full effect
    glm::vec3 emissiveFactor{0.0f}; // linear radiance added once per pixel, not per light
    float emissiveStrength = 1.0f;  // KHR_materials_emissive_strength, >= 0
    int emissiveTexture = -1;       // sRGB colour
    TextureMapping emissiveMapping;
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f; // Mask only
    bool doubleSided = false; // back faces drawn, with the normal flipped

    // -- Blinn-Phong -------------------------------------------------------------------------
    float specularIntensity = 0.04f; // ks, unitless reflectance at normal incidence
    float specularPower = 32.0f;     // Blinn-Phong exponent

    // -- Metallic-roughness ------------------------------------------------------------------
    // For a Blinn-Phong material these are informative (procedural materials set roughness to
    // the inverse of the mapping below); for a metallic-roughness material the Blinn-Phong pair
    // above holds the approximation blinnPhongFromMetallicRoughness gives, used when a study
    // forces Blinn-Phong.
    float metallic = 0.0f;
    float roughness = 0.5f;            // perceptual roughness; the GGX alpha is roughness^2
    int metallicRoughnessTexture = -1; // linear: B = metallic, G = roughness
    TextureMapping metallicRoughnessMapping;

    // Every texture index with its mapping, for code that renumbers, checks or loads them.
    static constexpr size_t kTextureSlotCount = 5;
    std::array<int*, kTextureSlotCount> textureSlots() {
        return {&baseColorTexture, &normalTexture, &occlusionTexture, &emissiveTexture,
                &metallicRoughnessTexture};
    }
    std::array<const TextureMapping*, kTextureSlotCount> textureMappings() const {
        return {&baseColorMapping, &normalMapping, &occlusionMapping, &emissiveMapping,
                &metallicRoughnessMapping};
    }
    std::array<int, kTextureSlotCount> textureIndices() const {
        return {baseColorTexture, normalTexture, occlusionTexture, emissiveTexture,
                metallicRoughnessTexture};
    }
    // True when some texture reads TEXCOORD_1.
    bool usesSecondUvSet() const;
    // Emitted radiance before the emissive texture: emissiveFactor * emissiveStrength.
    glm::vec3 emission() const { return emissiveFactor * emissiveStrength; }
    // Whether the material emits at all (a texture alone, with a zero factor, emits nothing).
    bool emits() const { return emission() != glm::vec3(0.0f); }
};

// The Blinn-Phong pair that stands in for a metallic-roughness material when Blinn-Phong is the
// lighting model: metals reflect their whole colour at normal incidence and dielectrics about 4%,
// so ks = mix(0.04, 1, metallic) (a scalar approximation of the coloured F0); the exponent whose
// lobe matches a GGX lobe of the same roughness is 2 / roughness^4 - 2, clamped to [1, 2048]
// (1 is the broadest lobe that is still a lobe; beyond 2048 the highlight is narrower than a texel
// of any texture we load; roughness^4 is floored at 1e-4, a mirror for our purposes).
void setBlinnPhongFromMetallicRoughness(Material& material);

// Shades `material` with `model` (a study's --brdf): both parameter sets are always present
// (a Blinn-Phong material carries an informative roughness, a metallic-roughness one its
// Blinn-Phong stand-in), so forcing only switches which one the lighting function reads.
// Textures of the other model stay in the material but are not read.
inline void forceMaterialModel(Material& material, MaterialModel model) {
    material.model = model;
}

// The roughness whose Blinn-Phong exponent (above, before clamping) is specularPower:
// (2 / (specularPower + 2))^(1/4). Keeps a Blinn-Phong material's informative roughness truthful.
float roughnessForSpecularPower(float specularPower);

} // namespace scenes
