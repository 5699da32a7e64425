#include "lighting/kernel/ShadingPacket.h"

#include <algorithm>
#include <iterator>

namespace lighting::kernel {

void ShadingPacket::clear(int originX, int originY) {
    for (int c = 0; c < 3; ++c) {
        std::fill(std::begin(positionView[c]), std::end(positionView[c]), 0.0f);
        std::fill(std::begin(normalView[c]), std::end(normalView[c]), c == 2 ? 1.0f : 0.0f);
        std::fill(std::begin(albedo[c]), std::end(albedo[c]), 0.0f);
    }
    std::fill(std::begin(specularIntensity), std::end(specularIntensity), 0.0f);
    std::fill(std::begin(specularPower), std::end(specularPower), 1.0f);
    std::fill(std::begin(roughness), std::end(roughness), 1.0f);
    std::fill(std::begin(metallic), std::end(metallic), 0.0f);
    std::fill(std::begin(occlusion), std::end(occlusion), 1.0f);
    laneMask = 0;
    metallicRoughnessMask = 0;
    x0 = originX;
    y0 = originY;
}

void ShadingPacket::setLane(int lane, const glm::vec3& position, const glm::vec3& normal,
                            const glm::vec3& albedoLinear, float specularIntensityValue,
                            float specularPowerValue) {
    for (int c = 0; c < 3; ++c) {
        positionView[c][lane] = position[c];
        normalView[c][lane] = normal[c];
        albedo[c][lane] = albedoLinear[c];
    }
    specularIntensity[lane] = specularIntensityValue;
    specularPower[lane] = specularPowerValue;
    laneMask |= 1u << lane;
}

void ShadingPacket::setMetallicRoughness(int lane, float roughnessValue, float metallicValue,
                                         float occlusionValue) {
    roughness[lane] = roughnessValue;
    metallic[lane] = metallicValue;
    occlusion[lane] = occlusionValue;
    metallicRoughnessMask |= 1u << lane;
}

void PacketAccumulator::clear() {
    for (auto& plane : radiance)
        std::fill(std::begin(plane), std::end(plane), 0.0f);
    std::fill(std::begin(lightsEvaluated), std::end(lightsEvaluated), 0u);
    std::fill(std::begin(lightsContributing), std::end(lightsContributing), 0u);
    lightsSkippedAtRange = 0;
    lightsSkippedAtConeOrFacing = 0;
    lightsShaded = 0;
}

} // namespace lighting::kernel
