// shadePacketScalar: the kernel's scalar path and the vector path's oracle. Each lane calls
// lighting/brdf/Brdf.h's evaluateLight<float> for each light with the lane's material model
// (Blinn-Phong or metallic-roughness), exactly as the per-pixel path does; the packet-level
// early-out counters come from earlyExit, which repeats evaluateLight's three rejection tests with
// the same float operations (so they take the same decisions), and apply the vector path's rule: a
// light is skipped when every active lane rejects it. shadePacketSplitScalar (SplitLightKernel.h)
// is the same loop around addSplitLight.
#include "lighting/kernel/LightKernel.h"

#include <cmath>
#include <optional>

#include "lighting/brdf/Brdf.h"
#include "lighting/brdf/SplitLighting.h"
#include "lighting/kernel/SplitLightKernel.h"

namespace lighting::kernel {

namespace {

enum class EarlyExit { None, Range, ConeOrFacing };

// Where evaluateLight returns zero before shading, for this point and light (both models share
// these tests: lightIncidence, then n.l).
EarlyExit earlyExit(const gbuffer::Surface& s, const LightInView<float>& light) {
    using scenes::LightType;
    if (light.type == LightType::Ambient)
        return EarlyExit::None;
    glm::vec3 toLight;
    if (light.type == LightType::Directional) {
        toLight = -light.directionView;
    } else {
        const glm::vec3 offset = light.positionView - s.positionView;
        const float distance2 = glm::dot(offset, offset);
        if (!(distance2 < light.rangeMetres * light.rangeMetres))
            return EarlyExit::Range;
        toLight = distance2 > 0.0f ? offset / std::sqrt(distance2) : s.normalView;
        if (light.type == LightType::Spot &&
            !(-glm::dot(toLight, light.directionView) > light.spotOuterCos))
            return EarlyExit::ConeOrFacing;
    }
    return glm::dot(s.normalView, toLight) > 0.0f ? EarlyExit::None : EarlyExit::ConeOrFacing;
}

// The shadow factor of light `index` at a lane: the lookup's visibility where the light passes the
// range, cone and facing tests (the lanes the vector path looks up), 1 elsewhere (the light adds
// +0 there, and +0 x 1 is +0 on both paths).
float shadowFactor(const KernelLights& lights, uint32_t index, const gbuffer::Surface& s,
                   EarlyExit exit) {
    const uint32_t shadow = lights.shadowOf(index);
    if (shadow == shadows::kNoShadow || !lights.shadows() || exit != EarlyExit::None)
        return 1.0f;
    return lights.shadows()->visibility(shadow, s.positionView, s.normalView);
}

// Lane `lane` of the packet as the per-pixel code's surface.
gbuffer::Surface surfaceOfLane(const ShadingPacket& packet, int lane) {
    gbuffer::Surface p;
    for (int c = 0; c < 3; ++c) {
        p.positionView[c] = packet.positionView[c][lane];
        p.normalView[c] = packet.normalView[c][lane];
        p.albedo[c] = packet.albedo[c][lane];
    }
    p.specularIntensity = packet.specularIntensity[lane];
    p.specularPower = packet.specularPower[lane];
    p.roughness = packet.roughness[lane];
    p.metallic = packet.metallic[lane];
    p.occlusion = packet.occlusion[lane];
    p.model = packet.metallicRoughnessMask >> lane & 1u ? scenes::MaterialModel::MetallicRoughness
                                                        : scenes::MaterialModel::BlinnPhong;
    return p;
}

// The packet-level early-out counter a light lands in, from where each active lane left it.
template <class Accumulator>
void countLight(bool anyShaded, bool anyPastRange, Accumulator& accumulator) {
    if (anyShaded)
        ++accumulator.lightsShaded;
    else if (anyPastRange)
        ++accumulator.lightsSkippedAtConeOrFacing;
    else
        ++accumulator.lightsSkippedAtRange;
}

} // namespace

void shadePacketScalar(const ShadingPacket& packet, uint32_t laneMask, const KernelLights& lights,
                       std::span<const uint32_t> lightIndices, PacketAccumulator& accumulator,
                       bool countContributing, std::span<const uint16_t> lightLaneMasks) {
    laneMask &= packet.laneMask;
    if (laneMask == 0)
        return;
    gbuffer::Surface points[kPacketLanes];
    glm::vec3 toViewer[kPacketLanes];
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        if (!(laneMask >> lane & 1u))
            continue;
        const gbuffer::Surface& p = points[lane] = surfaceOfLane(packet, lane);
        toViewer[lane] = glm::normalize(-p.positionView);
        if (lightLaneMasks.empty())
            accumulator.lightsEvaluated[lane] += uint32_t(lightIndices.size());
    }
    const std::vector<LightInView<float>>& source = lights.source();
    for (size_t i = 0; i < lightIndices.size(); ++i) {
        const LightInView<float>& light = source[lightIndices[i]];
        const uint32_t lightMask = lightLaneMasks.empty() ? laneMask : laneMask & lightLaneMasks[i];
        if (lightMask == 0)
            continue;
        bool anyShaded = false, anyPastRange = false;
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            if (!(lightMask >> lane & 1u))
                continue;
            if (!lightLaneMasks.empty())
                ++accumulator.lightsEvaluated[lane];
            const EarlyExit exit = earlyExit(points[lane], light);
            anyShaded |= exit == EarlyExit::None;
            anyPastRange |= exit != EarlyExit::Range;
            const glm::vec3 radiance = evaluateLight(points[lane], toViewer[lane], light);
            const float shadow = shadowFactor(lights, lightIndices[i], points[lane], exit);
            for (int c = 0; c < 3; ++c)
                accumulator.radiance[c][lane] += radiance[c] * shadow;
            if (countContributing)
                accumulator.lightsContributing[lane] += contributes(radiance) ? 1u : 0u;
        }
        countLight(anyShaded, anyPastRange, accumulator);
    }
}

void shadePacketSplitScalar(const ShadingPacket& packet, uint32_t laneMask,
                            const KernelLights& lights, std::span<const uint32_t> lightIndices,
                            SplitPacketAccumulator& accumulator) {
    laneMask &= packet.laneMask;
    if (laneMask == 0)
        return;
    // Per lane: its surface, the two Blinn-Phong evaluations of it, the direction to the viewer
    // and its running sums (continuing from the accumulator, so a split list adds in order).
    struct Lane {
        gbuffer::Surface point;
        SplitPoints points{point};
        glm::vec3 toViewer{0.0f};
        SplitLighting sum;
    };
    std::optional<Lane> lanes[kPacketLanes];
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        if (!(laneMask >> lane & 1u))
            continue;
        const gbuffer::Surface point = surfaceOfLane(packet, lane);
        Lane& l = lanes[lane].emplace(Lane{point, SplitPoints(point), glm::vec3(0.0f), {}});
        l.toViewer = glm::normalize(-point.positionView);
        for (int c = 0; c < 3; ++c) {
            l.sum.diffuse[c] = accumulator.diffuse[c][lane];
            l.sum.specular[c] = accumulator.specular[c][lane];
            l.sum.specularEdge[c] = accumulator.specularEdge[c][lane];
        }
        accumulator.lightsEvaluated[lane] += uint32_t(lightIndices.size());
    }
    const std::vector<LightInView<float>>& source = lights.source();
    for (uint32_t index : lightIndices) {
        const LightInView<float>& light = source[index];
        bool anyShaded = false, anyPastRange = false;
        for (int lane = 0; lane < kPacketLanes; ++lane) {
            if (!lanes[lane])
                continue;
            Lane& l = *lanes[lane];
            const EarlyExit exit = earlyExit(l.point, light);
            anyShaded |= exit == EarlyExit::None;
            anyPastRange |= exit != EarlyExit::Range;
            addSplitLight(l.point, l.points, l.toViewer, light, l.sum,
                          shadowFactor(lights, index, l.point, exit));
        }
        countLight(anyShaded, anyPastRange, accumulator);
    }
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        if (!lanes[lane])
            continue;
        const SplitLighting& sum = lanes[lane]->sum;
        for (int c = 0; c < 3; ++c) {
            accumulator.diffuse[c][lane] = sum.diffuse[c];
            accumulator.specular[c][lane] = sum.specular[c];
            accumulator.specularEdge[c][lane] = sum.specularEdge[c];
        }
    }
}

} // namespace lighting::kernel
