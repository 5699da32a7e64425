// Inputs for the kernel tests: random packets and lights (seeded, so every run sees the same
// cases), the double-precision reference of one lane, and ULP distances. View space as everywhere
// (camera at the origin looking down -Z).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "lighting/brdf/Brdf.h"
#include "lighting/kernel/KernelIsa.h"
#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/ShadingPacket.h"

namespace kerneltest {

using lighting::LightInView;
using lighting::kernel::kPacketLanes;
using lighting::kernel::ShadingPacket;
using scenes::LightType;

struct Surface {
    glm::vec3 position{0.0f, 0.0f, -5.0f};
    glm::vec3 normal{0.0f, 0.0f, 1.0f};
    glm::vec3 albedo{0.5f};
    float specularIntensity = 0.2f;
    float specularPower = 16.0f;
    // The glTF metallic-roughness model instead of Blinn-Phong (albedo is then the base colour).
    bool metallicRoughness = false;
    float roughness = 1.0f;
    float metallic = 0.0f;
    float occlusion = 1.0f;
};

template <class T> gbuffer::BasicSurface<T> basicSurfaceOf(const Surface& s) {
    gbuffer::BasicSurface<T> p;
    p.positionView = glm::vec<3, T>(s.position);
    p.normalView = glm::vec<3, T>(s.normal);
    p.albedo = glm::vec<3, T>(s.albedo);
    p.specularIntensity = T(s.specularIntensity);
    p.specularPower = T(s.specularPower);
    p.roughness = T(s.roughness);
    p.metallic = T(s.metallic);
    p.occlusion = T(s.occlusion);
    p.model = s.metallicRoughness ? scenes::MaterialModel::MetallicRoughness
                                  : scenes::MaterialModel::BlinnPhong;
    return p;
}

inline gbuffer::Surface pointOf(const Surface& s) {
    return basicSurfaceOf<float>(s);
}

inline void setLane(ShadingPacket& packet, int lane, const Surface& s) {
    packet.setLane(lane, s.position, s.normal, s.albedo, s.specularIntensity, s.specularPower);
    if (s.metallicRoughness)
        packet.setMetallicRoughness(lane, s.roughness, s.metallic, s.occlusion);
}

// A packet whose inactive lanes hold NaN, so a kernel that lets them leak is caught.
inline ShadingPacket poisonedPacket() {
    ShadingPacket packet;
    packet.clear();
    const float nan = std::nanf("");
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        for (int c = 0; c < 3; ++c) {
            packet.positionView[c][lane] = nan;
            packet.normalView[c][lane] = nan;
            packet.albedo[c][lane] = nan;
        }
        packet.specularIntensity[lane] = nan;
        packet.specularPower[lane] = nan;
        packet.roughness[lane] = nan;
        packet.metallic[lane] = nan;
        packet.occlusion[lane] = nan;
    }
    return packet;
}

class RandomScene {
public:
    explicit RandomScene(uint32_t seed) : mRandom(seed) {}

    float uniform(float lo, float hi) {
        return std::uniform_real_distribution<float>(lo, hi)(mRandom);
    }
    bool chance(float p) { return uniform(0.0f, 1.0f) < p; }

    glm::vec3 unitVector() {
        for (;;) {
            const glm::vec3 v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
            const float length2 = glm::dot(v, v);
            if (length2 > 1e-4f && length2 <= 1.0f)
                return v / std::sqrt(length2);
        }
    }

    // A surface point in front of the camera, mostly facing it, with a material of the range
    // the scenes use (specular powers 1..8192, sometimes 0).
    Surface surface() {
        Surface s;
        s.position = {uniform(-6, 6), uniform(-4, 4), uniform(-25, -0.5f)};
        s.normal = unitVector();
        if (glm::dot(s.normal, -s.position) < 0.0f && chance(0.8f))
            s.normal = -s.normal;
        s.albedo = {uniform(0.01f, 1), uniform(0.01f, 1), uniform(0.01f, 1)};
        s.specularIntensity = chance(0.1f) ? 0.0f : uniform(0, 1);
        s.specularPower = chance(0.05f) ? 0.0f : std::exp2(uniform(0, 13));
        return s;
    }

    // Makes `s` a metallic-roughness surface of the range glTF materials use: roughness over
    // [0, 1] (sometimes exactly 0, the mirror the BRDF clamps, or 1), metallic over [0, 1]
    // (often exactly 0 or 1), occlusion over [0, 1].
    void makeMetallicRoughness(Surface& s) {
        s.metallicRoughness = true;
        s.roughness = chance(0.05f) ? 0.0f : chance(0.05f) ? 1.0f : uniform(0, 1);
        const float m = uniform(0, 1);
        s.metallic = m < 0.3f ? 0.0f : m < 0.5f ? 1.0f : uniform(0, 1);
        s.occlusion = chance(0.5f) ? 1.0f : uniform(0, 1);
    }

    // A light near `target`: mostly points, some spots (some with a zero-width cone edge),
    // a few directional and ambient lights.
    LightInView<float> lightNear(const glm::vec3& target) {
        LightInView<float> light;
        light.radiance = {uniform(0, 3), uniform(0, 3), uniform(0, 3)};
        const float kind = uniform(0, 1);
        if (kind < 0.02f) {
            light.type = LightType::Ambient;
            light.radiance *= 0.05f;
            return light;
        }
        if (kind < 0.07f) {
            light.type = LightType::Directional;
            light.directionView = unitVector();
            return light;
        }
        light.type = kind < 0.25f ? LightType::Spot : LightType::Point;
        light.positionView = target + unitVector() * uniform(0, 6);
        light.rangeMetres = uniform(0.5f, 8);
        if (light.type == LightType::Spot) {
            light.directionView = glm::normalize(target - light.positionView + unitVector());
            light.spotOuterCos = uniform(0.3f, 0.95f);
            light.spotInnerCos = chance(0.2f)
                                     ? light.spotOuterCos
                                     : std::min(1.0f, light.spotOuterCos + uniform(0, 0.1f));
        }
        return light;
    }

    std::mt19937& engine() { return mRandom; }

private:
    std::mt19937 mRandom;
};

// The double-precision sum of `lights[indices]` at a lane's surface, from the same float inputs.
inline glm::dvec3 referenceSum(const Surface& s, const std::vector<LightInView<float>>& lights,
                               const std::vector<uint32_t>& indices) {
    const gbuffer::BasicSurface<double> p = basicSurfaceOf<double>(s);
    const glm::dvec3 toViewer = glm::normalize(-p.positionView);
    glm::dvec3 sum(0.0);
    for (uint32_t index : indices) {
        const LightInView<float>& l = lights[index];
        LightInView<double> light{l.type,
                                  glm::dvec3(l.positionView),
                                  glm::dvec3(l.directionView),
                                  glm::dvec3(l.radiance),
                                  double(l.rangeMetres),
                                  double(l.spotInnerCos),
                                  double(l.spotOuterCos)};
        sum += lighting::evaluateLight(p, toViewer, light);
    }
    return sum;
}

// Distance in units in the last place between two finite floats of the same sign (or zeros).
// A random packet and light list: 16 lanes around one point (a 4x4 block of a surface) or
// scattered, ~15% background; `lightCount` lights, the first `nearCount` near the block and the
// rest anywhere; a random ascending list of ~70% of them. models: 0 Blinn-Phong, 1
// metallic-roughness, 2 mixed (each lane either, at random).
struct PacketCase {
    ShadingPacket packet = poisonedPacket();
    Surface surfaces[kPacketLanes];
    std::vector<LightInView<float>> lights;
    std::vector<uint32_t> indices;
};

inline PacketCase randomPacketCase(RandomScene& random, int models, int lightCount, int nearCount) {
    PacketCase c;
    const bool coherent = random.chance(0.5f);
    const Surface centre = random.surface();
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        Surface s = random.surface();
        if (coherent) {
            s.position = centre.position + 0.05f * random.unitVector();
            s.normal = glm::normalize(centre.normal + 0.1f * random.unitVector());
        }
        if (models == 1 || (models == 2 && random.chance(0.5f)))
            random.makeMetallicRoughness(s);
        c.surfaces[lane] = s;
        if (!random.chance(0.15f))
            setLane(c.packet, lane, s);
    }
    for (int i = 0; i < lightCount; ++i)
        c.lights.push_back(
            random.lightNear(i < nearCount ? centre.position : random.surface().position));
    for (uint32_t i = 0; i < c.lights.size(); ++i)
        if (random.chance(0.7f))
            c.indices.push_back(i);
    return c;
}

inline int64_t ulpDistance(float a, float b) {
    int32_t ia, ib;
    std::memcpy(&ia, &a, 4);
    std::memcpy(&ib, &b, 4);
    // Map to a monotonic integer line (negative floats reversed).
    const int64_t la = ia < 0 ? int64_t(INT32_MIN) - ia : ia;
    const int64_t lb = ib < 0 ? int64_t(INT32_MIN) - ib : ib;
    return la > lb ? la - lb : lb - la;
}

inline std::vector<lighting::kernel::KernelIsa> vectorIsas() {
    std::vector<lighting::kernel::KernelIsa> isas;
    for (const auto& isa : lighting::kernel::KernelIsa::available())
        if (!isa.isScalar())
            isas.push_back(isa);
    return isas;
}

} // namespace kerneltest
