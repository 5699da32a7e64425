#include "scenes/materials/Material.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace scenes {

namespace {

// See setBlinnPhongFromMetallicRoughness.
constexpr float kMinSpecularPower = 1.0f;
constexpr float kMaxSpecularPower = 2048.0f;
constexpr float kMinRoughness4 = 1e-4f;

} // namespace

const char* materialModelName(MaterialModel model) {
    return model == MaterialModel::BlinnPhong ? "blinn-phong" : "metallic-roughness";
}

MaterialModel parseMaterialModel(const std::string& name) {
    for (MaterialModel model : {MaterialModel::BlinnPhong, MaterialModel::MetallicRoughness})
        if (name == materialModelName(model))
            return model;
    throw std::invalid_argument("unknown material model '" + name +
                                "'; valid: blinn-phong, metallic-roughness");
}

glm::vec2 TextureMapping::apply(glm::vec2 uv) const {
    if (isIdentity())
        return uv;
    const glm::vec2 scaled = scale * uv;
    const float c = std::cos(rotationRadians), s = std::sin(rotationRadians);
    return offset + glm::vec2(c * scaled.x + s * scaled.y, -s * scaled.x + c * scaled.y);
}

bool Material::usesSecondUvSet() const {
    const std::array<int, kTextureSlotCount> indices = textureIndices();
    const std::array<const TextureMapping*, kTextureSlotCount> mappings = textureMappings();
    for (size_t slot = 0; slot < kTextureSlotCount; ++slot)
        if (indices[slot] >= 0 && mappings[slot]->texCoord == 1)
            return true;
    return false;
}

void setBlinnPhongFromMetallicRoughness(Material& material) {
    material.specularIntensity = glm::mix(0.04f, 1.0f, material.metallic);
    const float roughness2 = material.roughness * material.roughness;
    const float roughness4 = std::max(roughness2 * roughness2, kMinRoughness4);
    material.specularPower =
        std::clamp(2.0f / roughness4 - 2.0f, kMinSpecularPower, kMaxSpecularPower);
}

float roughnessForSpecularPower(float specularPower) {
    return std::pow(2.0f / (specularPower + 2.0f), 0.25f);
}

} // namespace scenes
