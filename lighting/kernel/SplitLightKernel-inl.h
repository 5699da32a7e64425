// shadeSplitVector: the vector loop of shadePacketSplit (SplitLightKernel.h), once per compiled
// instruction set (included by VectorTargets.cpp after LightKernel-inl.h, whose per-chunk phases
// it reuses: loadSurface, rangeChunk, coneAndFacingChunk, facingChunk, blinnPhongLobe, ggxTerms).
//
// Per light the three phases of LightKernel-inl.h with its early-out rule and counters; phase 3
// adds addSplitLight's terms (lighting/brdf/SplitLighting.h) instead of one radiance, with its
// float operations in its order:
// - Blinn-Phong lanes: diffuse = (radiance x (att n.l)) x (1 / pi). evaluateLight with albedo 1
//   and intensity 0 computes (radiance x (att n.l)) x (1 x (1 / pi) + 0 x lobe); 1 x (1 / pi) and
//   the + 0 are exact (the lobe is finite: pow of n.h <= 1), so this is its value bitwise and pow
//   is not needed for it. specular = (radiance x (att n.l)) x ((power + 8) / (8 pi) x pow), the
//   evaluation with albedo 0 and intensity 1 (0 x (1 / pi) + lobe is the lobe), selected to 0
//   where the lane's diffuse part is zero in every channel (addSplitLight evaluates it only where
//   contributes(diffuse)); ambient lights add their radiance x 1 to diffuse only.
// - metallic-roughness lanes: splitLightMetallicRoughness: incident = radiance x (att n.l);
//   diffuse = incident x ((1 - F_dielectric) / pi), specular (the f0 part) =
//   incident x ((1 - w) D Vis), specularEdge = incident x (w D Vis); ambient: diffuse =
//   radiance x (occlusion x 0.96), specular = radiance x occlusion.
// Rejected lanes (not passing, or attenuation not > 0, as both scalar functions return zero
// there) add exactly +0. So diffuse and every metallic-roughness sum are bitwise the scalar path's
// and the Blinn-Phong specular differs only through pow. Lights are not shaded in pairs as
// shadePacket does on AVX-512 (a 6% gain there): kept simple until measured worth it here.

// Ordinary headers outside the per-target region, so they are compiled for the baseline only.
#include "lighting/brdf/MetallicRoughness.h"
#include "lighting/kernel/VectorTargets.h"
#include "scenes/Scene.h"

#if defined(LIGHTING_KERNEL_SPLIT_LIGHT_KERNEL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef LIGHTING_KERNEL_SPLIT_LIGHT_KERNEL_INL_H_
#undef LIGHTING_KERNEL_SPLIT_LIGHT_KERNEL_INL_H_
#else
#define LIGHTING_KERNEL_SPLIT_LIGHT_KERNEL_INL_H_
#endif

#include <hwy/highway.h>

#include "lighting/kernel/LightKernel-inl.h"

HWY_BEFORE_NAMESPACE();
namespace lighting::kernel::HWY_NAMESPACE {

// One chunk's running split sums.
struct ChunkSplitSums {
    FloatVec diffuse[3];
    FloatVec specular[3];
    FloatVec specularEdge[3];
};

HWY_INLINE void addSplit(const FloatVec diffuse[3], const FloatVec specular[3],
                         const FloatVec specularEdge[3], ChunkSplitSums& sums) {
    for (int k = 0; k < 3; ++k) {
        sums.diffuse[k] = hn::Add(sums.diffuse[k], diffuse[k]);
        sums.specular[k] = hn::Add(sums.specular[k], specular[k]);
        sums.specularEdge[k] = hn::Add(sums.specularEdge[k], specularEdge[k]);
    }
}

// Phase 3 of a point, spot or directional light for one chunk: the lane's own model's terms.
// unitSpecularScale: (power + 8) / (8 pi), the Blinn-Phong normalisation with intensity 1.
template <Models kModels>
HWY_INLINE void splitShaded(const ShadeSplitArgs& args, const KernelLight& light, size_t chunk,
                            const ChunkSurface& s, FloatVec unitSpecularScale, const ChunkLight& l,
                            ChunkSplitSums& sums) {
    const FloatTag d;
    const FloatVec zero = hn::Zero(d);
    const FloatVec scale = hn::Mul(l.attenuation, l.nDotL);
    const LaneMask pass = hn::And(l.pass, hn::Gt(l.attenuation, zero));
    FloatVec incident[3];
    for (int k = 0; k < 3; ++k)
        incident[k] = hn::Mul(hn::Set(d, light.radiance[k]), scale);
    FloatVec diffuse[3], specular[3], specularEdge[3];
    if constexpr (kModels != Models::MetallicRoughness) {
        const FloatVec lobe = hn::Mul(unitSpecularScale, blinnPhongLobe(s, l));
        const FloatVec inversePi = hn::Set(d, kInversePiFloat);
        for (int k = 0; k < 3; ++k)
            diffuse[k] = hn::IfThenElseZero(pass, hn::Mul(incident[k], inversePi));
        const LaneMask contributes = hn::Or(
            hn::Or(hn::Ne(diffuse[0], zero), hn::Ne(diffuse[1], zero)), hn::Ne(diffuse[2], zero));
        for (int k = 0; k < 3; ++k) {
            specular[k] = hn::IfThenElseZero(contributes, hn::Mul(incident[k], lobe));
            specularEdge[k] = zero;
        }
    }
    if constexpr (kModels != Models::BlinnPhong) {
        const GgxTerms terms = ggxTerms(s, l);
        const FloatVec one = hn::Set(d, 1.0f);
        const FloatVec f0Part = hn::Mul(hn::Sub(one, terms.w), terms.specular);
        const FloatVec edgePart = hn::Mul(terms.w, terms.specular);
        for (int k = 0; k < 3; ++k) {
            const FloatVec mrDiffuse =
                hn::IfThenElseZero(pass, hn::Mul(incident[k], terms.diffuseWeight));
            const FloatVec mrSpecular = hn::IfThenElseZero(pass, hn::Mul(incident[k], f0Part));
            const FloatVec mrEdge = hn::IfThenElseZero(pass, hn::Mul(incident[k], edgePart));
            if constexpr (kModels == Models::Mixed) {
                diffuse[k] = hn::IfThenElse(s.metallicRoughness, mrDiffuse, diffuse[k]);
                specular[k] = hn::IfThenElse(s.metallicRoughness, mrSpecular, specular[k]);
                specularEdge[k] = hn::IfThenElse(s.metallicRoughness, mrEdge, specularEdge[k]);
            } else {
                diffuse[k] = mrDiffuse;
                specular[k] = mrSpecular;
                specularEdge[k] = mrEdge;
            }
        }
    }
    // A shadowed light: all three terms times the shadow factor (addSplitLight's order: the
    // Blinn-Phong specular was decided by the unshadowed diffuse above).
    if (light.shadow != shadows::kNoShadow && args.shadows) {
        const FloatVec visibility = chunkVisibility(*args.shadows, args.shadowView, light.shadow,
                                                    *args.packet, chunk, l.pass);
        for (int k = 0; k < 3; ++k) {
            diffuse[k] = hn::Mul(diffuse[k], visibility);
            specular[k] = hn::Mul(specular[k], visibility);
            specularEdge[k] = hn::Mul(specularEdge[k], visibility);
        }
    }
    addSplit(diffuse, specular, specularEdge, sums);
}

// An ambient light for one chunk: Blinn-Phong diffuse += radiance (x albedo 1);
// metallic-roughness diffuse += radiance x (occlusion x 0.96), specular += radiance x occlusion.
template <Models kModels>
HWY_INLINE void splitAmbient(const KernelLight& light, const ChunkSurface& s, LaneMask active,
                             ChunkSplitSums& sums) {
    const FloatTag d;
    const FloatVec zero = hn::Zero(d);
    FloatVec diffuse[3], specular[3], specularEdge[3];
    for (int k = 0; k < 3; ++k) {
        const FloatVec lightRadiance = hn::Set(d, light.radiance[k]);
        FloatVec diffuseValue = lightRadiance, specularValue = zero;
        if constexpr (kModels != Models::BlinnPhong) {
            const FloatVec mrDiffuse =
                hn::Mul(lightRadiance, hn::Mul(s.occlusion, hn::Set(d, kDielectricWeightFloat)));
            const FloatVec mrSpecular = hn::Mul(lightRadiance, s.occlusion);
            diffuseValue = kModels == Models::Mixed
                               ? hn::IfThenElse(s.metallicRoughness, mrDiffuse, diffuseValue)
                               : mrDiffuse;
            specularValue = kModels == Models::Mixed
                                ? hn::IfThenElseZero(s.metallicRoughness, mrSpecular)
                                : mrSpecular;
        }
        diffuse[k] = hn::IfThenElseZero(active, diffuseValue);
        specular[k] = hn::IfThenElseZero(active, specularValue);
        specularEdge[k] = zero;
    }
    addSplit(diffuse, specular, specularEdge, sums);
}

template <Models kModels> void shadeSplitLights(const ShadeSplitArgs& args) {
    const FloatTag d;
    const IntTag di;
    const ShadingPacket& packet = *args.packet;
    SplitPacketAccumulator& accumulator = *args.accumulator;
    const uint32_t laneMask = args.laneMask & packet.laneMask;
    if (laneMask == 0)
        return;

    ChunkSurface surface[kChunks];
    FloatVec unitSpecularScale[kChunks];
    ChunkSplitSums sums[kChunks];
    for (size_t c = 0; c < kChunks; ++c) {
        loadSurface<kModels>(packet, laneMask, c, surface[c]);
        // Brdf.h's intensity x (power + 8) x (1 / (8 pi)) with intensity 1 (1 x y is y).
        if constexpr (kModels != Models::MetallicRoughness)
            unitSpecularScale[c] = hn::Mul(hn::Add(surface[c].specularPower, hn::Set(d, 8.0f)),
                                           hn::Set(d, float(1.0 / (8.0 * 3.14159265358979323846))));
        else
            unitSpecularScale[c] = hn::Zero(d);
        const size_t first = c * kLanesPerVector;
        // Sums continue from the accumulator, so a list split over calls adds in the same order.
        for (int k = 0; k < 3; ++k) {
            sums[c].diffuse[k] = hn::Load(d, accumulator.diffuse[k] + first);
            sums[c].specular[k] = hn::Load(d, accumulator.specular[k] + first);
            sums[c].specularEdge[k] = hn::Load(d, accumulator.specularEdge[k] + first);
        }
    }

    ChunkLight chunkLight[kChunks];
    for (size_t i = 0; i < args.count; ++i) {
        const KernelLight& light = args.lights[args.indices[i]];
        const auto type = scenes::LightType(light.type);
        if (type == scenes::LightType::Ambient) {
            for (size_t c = 0; c < kChunks; ++c)
                splitAmbient<kModels>(light, surface[c], surface[c].active, sums[c]);
            ++accumulator.lightsShaded;
            continue;
        }
        bool any = false;
        if (type == scenes::LightType::Directional) {
            const FloatVec toLight[3] = {hn::Set(d, -light.directionView[0]),
                                         hn::Set(d, -light.directionView[1]),
                                         hn::Set(d, -light.directionView[2])};
            for (size_t c = 0; c < kChunks; ++c)
                any |= facingChunk(toLight, surface[c], surface[c].active, chunkLight[c]);
        } else {
            for (size_t c = 0; c < kChunks; ++c)
                any |= rangeChunk(light, packet, c, surface[c].active, chunkLight[c]);
            if (!any) {
                ++accumulator.lightsSkippedAtRange;
                continue;
            }
            any = false;
            const bool spot = type == scenes::LightType::Spot;
            for (size_t c = 0; c < kChunks; ++c)
                any |= coneAndFacingChunk(light, spot, surface[c], chunkLight[c]);
        }
        if (!any) {
            ++accumulator.lightsSkippedAtConeOrFacing;
            continue;
        }
        ++accumulator.lightsShaded;
        for (size_t c = 0; c < kChunks; ++c)
            splitShaded<kModels>(args, light, c, surface[c], unitSpecularScale[c], chunkLight[c],
                                 sums[c]);
    }

    for (size_t c = 0; c < kChunks; ++c) {
        const size_t first = c * kLanesPerVector;
        const LaneMask active = surface[c].active;
        // Inactive lanes only ever added +0; keeping their stored value leaves them untouched.
        for (int k = 0; k < 3; ++k) {
            float* diffuse = accumulator.diffuse[k] + first;
            float* specular = accumulator.specular[k] + first;
            float* specularEdge = accumulator.specularEdge[k] + first;
            hn::Store(hn::IfThenElse(active, sums[c].diffuse[k], hn::Load(d, diffuse)), d, diffuse);
            hn::Store(hn::IfThenElse(active, sums[c].specular[k], hn::Load(d, specular)), d,
                      specular);
            hn::Store(hn::IfThenElse(active, sums[c].specularEdge[k], hn::Load(d, specularEdge)), d,
                      specularEdge);
        }
        int32_t* evaluated = reinterpret_cast<int32_t*>(accumulator.lightsEvaluated + first);
        const IntVec walked =
            hn::IfThenElseZero(hn::RebindMask(di, active), hn::Set(di, int32_t(args.count)));
        hn::Store(hn::Add(hn::Load(di, evaluated), walked), di, evaluated);
    }
}

void shadeSplitVector(const ShadeSplitArgs& args) {
    withLaneModels(*args.packet, args.laneMask,
                   [&](auto models) HWY_ATTR { shadeSplitLights<decltype(models)::value>(args); });
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // include guard toggle
