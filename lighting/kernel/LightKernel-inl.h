// shadePacketVector: the vector light loop of the shading kernel, once per compiled instruction
// set (included by VectorTargets.cpp through foreach_target.h). It evaluates the one lighting
// model of lighting/Brdf.h (evaluateLight: Lambert + normalised Blinn-Phong, windowed
// inverse-square falloff, spot smoothstep, directional and ambient lights) for the 16 lanes of a
// ShadingPacket and each light of a list, in list order.
//
// The packet's 16 lanes are kChunks = 16 / N hardware vectors of N lanes (AVX-512: 1 x 16,
// AVX2: 2 x 8, SSE4: 4 x 4). A light goes through three phases, each over every chunk, and the
// packet leaves it as soon as every active lane of all 16 has rejected it, as a GPU warp does:
//   1. range:  offset, distance^2 < range^2                   (all lanes out: skipped at range)
//   2. cone and facing: direction, attenuation, spot cone, n.l > 0
//                                                              (all lanes out: skipped later)
//   3. shading: halfway vector, n.h, pow, sum                  (at least one lane: shaded)
// Lanes that rejected the light, and lanes outside the lane mask, add exactly +0 (their radiance
// is selected to zero, whatever NaN or Inf their arithmetic produced), so a lane's sum depends on
// its own surface and the light list only, never on its neighbours.
//
// Floating point: every operation is the one evaluateLight performs in float, in its order (dot
// products (x + y) + z, exact IEEE division and square root, no reciprocal estimate, multiply and
// add kept apart: the project compiles with -ffp-contract=off, which also keeps the compiler from
// fusing Highway's Mul and Add), except pow (VectorPow-inl.h). So every decision (range, cone,
// n.l) and every factor but the specular lobe are bitwise the scalar path's, and the radiance
// differs from it only through pow. Quantities that depend only on the pixel (direction to the
// viewer, albedo / pi, the specular normalisation) are computed once per call with the operations
// evaluateLight repeats per light, so they too are bitwise the same. (Measured: fusing the dot
// products of the shading part and skipping the halfway vector's normalisation saved ~3% of a
// shaded light and made sharp lobes (powers of thousands) differ from the scalar path by up to
// 10^4 ulps; not worth losing the tight comparison.)

// Ordinary headers outside the per-target region, so they are compiled for the baseline only.
#include "lighting/kernel/VectorTargets.h"
#include "scenes/Scene.h"

#if defined(LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_
#undef LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_
#else
#define LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_
#endif

#include <hwy/highway.h>

#include "lighting/kernel/VectorPow-inl.h"

HWY_BEFORE_NAMESPACE();
namespace lighting::kernel::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using FloatTag = hn::ScalableTag<float>;
using IntTag = hn::RebindToSigned<FloatTag>;
using FloatVec = hn::Vec<FloatTag>;
using IntVec = hn::Vec<IntTag>;
using LaneMask = hn::Mask<FloatTag>;

constexpr size_t kLanesPerVector = hn::MaxLanes(FloatTag());
static_assert(kPacketLanes % kLanesPerVector == 0, "a packet is a whole number of vectors");
constexpr size_t kChunks = kPacketLanes / kLanesPerVector;

// glm::dot's order: (x * x' + y * y') + z * z'.
HWY_INLINE FloatVec dot3(FloatVec ax, FloatVec ay, FloatVec az, FloatVec bx, FloatVec by,
                         FloatVec bz) {
    return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}

// One chunk's surface, read once per call.
struct ChunkSurface {
    FloatVec normal[3];
    FloatVec toViewer[3];
    FloatVec diffuse[3];    // albedo * (1 / pi)
    FloatVec specularScale; // specularIntensity * (specularPower + 8) * (1 / (8 pi))
    FloatVec specularPower;
    LaneMask active;
};

// One chunk's light-dependent values between the phases.
struct ChunkLight {
    FloatVec offset[3];
    FloatVec distance2;
    FloatVec toLight[3];
    FloatVec attenuation;
    FloatVec nDotL;
    LaneMask pass;
};

struct ChunkSums {
    FloatVec radiance[3];
    IntVec contributing;
};

template <bool kCountContributing>
HWY_INLINE void accumulate(const FloatVec radiance[3], ChunkSums& sums) {
    const FloatTag d;
    const IntTag di;
    const FloatVec zero = hn::Zero(d);
    for (int k = 0; k < 3; ++k)
        sums.radiance[k] = hn::Add(sums.radiance[k], radiance[k]);
    if (!kCountContributing)
        return;
    const LaneMask contributes = hn::Or(
        hn::Or(hn::Ne(radiance[0], zero), hn::Ne(radiance[1], zero)), hn::Ne(radiance[2], zero));
    // An all-ones lane is -1: subtracting it counts one.
    sums.contributing =
        hn::Sub(sums.contributing, hn::VecFromMask(di, hn::RebindMask(di, contributes)));
}

// Phase 3 for one chunk: the halfway vector, the specular lobe and the radiance, with
// evaluateLight's operations except pow.
HWY_INLINE void shadedRadiance(const KernelLight& light, const ChunkSurface& s, const ChunkLight& l,
                               FloatVec radiance[3]) {
    const FloatTag d;
    const FloatVec one = hn::Set(d, 1.0f);
    FloatVec halfway[3];
    for (int k = 0; k < 3; ++k)
        halfway[k] = hn::Add(l.toLight[k], s.toViewer[k]);
    const FloatVec inverseLength = hn::Div(one, hn::Sqrt(dot3(halfway[0], halfway[1], halfway[2],
                                                              halfway[0], halfway[1], halfway[2])));
    for (int k = 0; k < 3; ++k)
        halfway[k] = hn::Mul(halfway[k], inverseLength);
    // evaluateLight clamps n.h at 0 before pow; powNonNegative treats every n.h that is not > 0
    // as 0 already (NaN too: a zero halfway vector, the light exactly opposite the viewer, where
    // evaluateLight returns NaN).
    const FloatVec nDotH =
        dot3(s.normal[0], s.normal[1], s.normal[2], halfway[0], halfway[1], halfway[2]);
    const FloatVec specular = hn::Mul(s.specularScale, powNonNegative(d, nDotH, s.specularPower));
    const FloatVec scale = hn::Mul(l.attenuation, l.nDotL);
    for (int k = 0; k < 3; ++k)
        radiance[k] =
            hn::IfThenElseZero(l.pass, hn::Mul(hn::Mul(hn::Set(d, light.radiance[k]), scale),
                                               hn::Add(s.diffuse[k], specular)));
}

template <bool kCountContributing>
HWY_INLINE void shadeAndAdd(const KernelLight& light, const ChunkSurface& s, const ChunkLight& l,
                            ChunkSums& sums) {
    FloatVec radiance[3];
    shadedRadiance(light, s, l, radiance);
    accumulate<kCountContributing>(radiance, sums);
}

// Phase 1 for one chunk; returns whether any lane is in range.
HWY_INLINE bool rangeChunk(const KernelLight& light, const ShadingPacket& packet, size_t chunk,
                           LaneMask active, ChunkLight& l) {
    const FloatTag d;
    const size_t first = chunk * kLanesPerVector;
    for (int k = 0; k < 3; ++k)
        l.offset[k] =
            hn::Sub(hn::Set(d, light.positionView[k]), hn::Load(d, packet.positionView[k] + first));
    l.distance2 =
        dot3(l.offset[0], l.offset[1], l.offset[2], l.offset[0], l.offset[1], l.offset[2]);
    l.pass = hn::And(active, hn::Lt(l.distance2, hn::Set(d, light.rangeSquared)));
    return !hn::AllFalse(d, l.pass);
}

// Phase 2 for one chunk of a point or spot light; returns whether any lane still passes.
HWY_INLINE bool coneAndFacingChunk(const KernelLight& light, bool spot, const ChunkSurface& s,
                                   ChunkLight& l) {
    const FloatTag d;
    const FloatVec zero = hn::Zero(d);
    const FloatVec one = hn::Set(d, 1.0f);
    // A light exactly on the surface has no direction; evaluateLight treats it as overhead.
    const LaneMask apart = hn::Gt(l.distance2, zero);
    const FloatVec distance = hn::Sqrt(l.distance2);
    for (int k = 0; k < 3; ++k)
        l.toLight[k] = hn::IfThenElse(apart, hn::Div(l.offset[k], distance), s.normal[k]);
    const FloatVec rangeSquared = hn::Set(d, light.rangeSquared);
    const FloatVec ratio2 = hn::Div(l.distance2, rangeSquared);
    const FloatVec window = hn::Sub(one, hn::Mul(ratio2, ratio2));
    l.attenuation = hn::Div(hn::Mul(window, window), hn::Add(l.distance2, one));
    if (spot) {
        const FloatVec cosAngle = hn::Neg(
            dot3(l.toLight[0], l.toLight[1], l.toLight[2], hn::Set(d, light.directionView[0]),
                 hn::Set(d, light.directionView[1]), hn::Set(d, light.directionView[2])));
        const FloatVec outer = hn::Set(d, light.spotOuterCos);
        l.pass = hn::And(l.pass, hn::Gt(cosAngle, outer));
        FloatVec t = one;
        if (light.spotWidth > 0.0f)
            t = hn::Min(
                hn::Max(hn::Div(hn::Sub(cosAngle, outer), hn::Set(d, light.spotWidth)), zero), one);
        const FloatVec smooth =
            hn::Mul(hn::Mul(t, t), hn::Sub(hn::Set(d, 3.0f), hn::Mul(hn::Set(d, 2.0f), t)));
        l.attenuation = hn::Mul(l.attenuation, smooth);
    }
    l.nDotL = dot3(s.normal[0], s.normal[1], s.normal[2], l.toLight[0], l.toLight[1], l.toLight[2]);
    l.pass = hn::And(l.pass, hn::Gt(l.nDotL, zero));
    return !hn::AllFalse(d, l.pass);
}

// Phase 2 for one chunk of a directional light (no range, no cone, unit attenuation).
HWY_INLINE bool facingChunk(const FloatVec toLight[3], const ChunkSurface& s, LaneMask active,
                            ChunkLight& l) {
    const FloatTag d;
    for (int k = 0; k < 3; ++k)
        l.toLight[k] = toLight[k];
    l.attenuation = hn::Set(d, 1.0f);
    l.nDotL = dot3(s.normal[0], s.normal[1], s.normal[2], toLight[0], toLight[1], toLight[2]);
    l.pass = hn::And(active, hn::Gt(l.nDotL, hn::Zero(d)));
    return !hn::AllFalse(d, l.pass);
}

// The lanes of `laneMask` (bit l = packet lane l) that fall in vector `chunk`.
HWY_INLINE LaneMask chunkMask(uint32_t laneMask, size_t chunk) {
    const FloatTag d;
    // Little-endian bytes as LoadMaskBits reads them.
    const uint32_t bits = laneMask >> (chunk * kLanesPerVector);
    const uint8_t bytes[8] = {uint8_t(bits), uint8_t(bits >> 8)};
    return hn::LoadMaskBits(d, bytes);
}

HWY_INLINE void loadSurface(const ShadingPacket& packet, uint32_t laneMask, size_t chunk,
                            ChunkSurface& s) {
    const FloatTag d;
    const size_t first = chunk * kLanesPerVector;
    const FloatVec one = hn::Set(d, 1.0f);
    FloatVec toViewer[3];
    for (int k = 0; k < 3; ++k) {
        s.normal[k] = hn::Load(d, packet.normalView[k] + first);
        toViewer[k] = hn::Neg(hn::Load(d, packet.positionView[k] + first));
        s.diffuse[k] = hn::Mul(hn::Load(d, packet.albedo[k] + first),
                               hn::Set(d, float(1.0 / 3.14159265358979323846)));
    }
    // glm::normalize: v * (1 / sqrt(dot(v, v))).
    const FloatVec inverseLength =
        hn::Div(one, hn::Sqrt(dot3(toViewer[0], toViewer[1], toViewer[2], toViewer[0], toViewer[1],
                                   toViewer[2])));
    for (int k = 0; k < 3; ++k)
        s.toViewer[k] = hn::Mul(toViewer[k], inverseLength);
    s.specularPower = hn::Load(d, packet.specularPower + first);
    s.specularScale = hn::Mul(hn::Mul(hn::Load(d, packet.specularIntensity + first),
                                      hn::Add(s.specularPower, hn::Set(d, 8.0f))),
                              hn::Set(d, float(1.0 / (8.0 * 3.14159265358979323846))));
    s.active = chunkMask(laneMask, chunk);
}

// kPerLightMasks: args.lightLaneMasks[i] further restricts light i to some lanes (the `ideal`
// stage's per-lane lists as one union list); each lane then counts only its own lights.
template <bool kCountContributing, bool kPerLightMasks> void shadeLights(const ShadeArgs& args) {
    const FloatTag d;
    const IntTag di;
    const ShadingPacket& packet = *args.packet;
    PacketAccumulator& accumulator = *args.accumulator;
    const uint32_t laneMask = args.laneMask & packet.laneMask;
    if (laneMask == 0)
        return;

    ChunkSurface surface[kChunks];
    ChunkSums sums[kChunks];
    for (size_t c = 0; c < kChunks; ++c) {
        loadSurface(packet, laneMask, c, surface[c]);
        // Sums continue from the accumulator, so a list split over calls adds in the same order.
        for (int k = 0; k < 3; ++k)
            sums[c].radiance[k] = hn::Load(d, accumulator.radiance[k] + c * kLanesPerVector);
        sums[c].contributing = hn::Zero(di);
    }
    IntVec evaluatedCount[kChunks];
    for (size_t c = 0; c < kChunks; ++c)
        evaluatedCount[c] = hn::Zero(di);

    // With one vector per packet (AVX-512), a light's shading is one long dependency chain (two
    // square roots, three divisions, Log, Exp: ~200 cycles) and the core overlaps too few of
    // them; so a light to shade waits for the next one and the two are shaded side by side,
    // then added in list order. Measured on Zen 5: 6% less time per shaded light with AVX-512
    // (median of 6 alternating runs, 105.6 against 112.3 cycles); with 2 or 4 vectors per
    // packet, which already have independent chains, pairing was slower.
    constexpr bool kPairLights = kChunks == 1;
    ChunkLight chunkLight[kChunks];
    ChunkLight pendingLight[kChunks];
    const KernelLight* pending = nullptr;
    for (size_t i = 0; i < args.count; ++i) {
        const KernelLight& light = args.lights[args.indices[i]];
        const auto type = scenes::LightType(light.type);
        LaneMask active[kChunks];
        if (kPerLightMasks) {
            const uint32_t lightMask = laneMask & args.lightLaneMasks[i];
            if (lightMask == 0)
                continue;
            for (size_t c = 0; c < kChunks; ++c) {
                active[c] = chunkMask(lightMask, c);
                // An all-ones lane is -1: subtracting it counts one.
                evaluatedCount[c] =
                    hn::Sub(evaluatedCount[c], hn::VecFromMask(di, hn::RebindMask(di, active[c])));
            }
        } else {
            for (size_t c = 0; c < kChunks; ++c)
                active[c] = surface[c].active;
        }
        if (type == scenes::LightType::Ambient) {
            if (pending) {
                for (size_t c = 0; c < kChunks; ++c)
                    shadeAndAdd<kCountContributing>(*pending, surface[c], pendingLight[c], sums[c]);
                pending = nullptr;
            }
            for (size_t c = 0; c < kChunks; ++c) {
                FloatVec radiance[3];
                for (int k = 0; k < 3; ++k)
                    radiance[k] = hn::IfThenElseZero(
                        active[c], hn::Mul(hn::Set(d, light.radiance[k]),
                                           hn::Load(d, packet.albedo[k] + c * kLanesPerVector)));
                accumulate<kCountContributing>(radiance, sums[c]);
            }
            ++accumulator.lightsShaded;
            continue;
        }
        bool any = false;
        if (type == scenes::LightType::Directional) {
            const FloatVec toLight[3] = {hn::Set(d, -light.directionView[0]),
                                         hn::Set(d, -light.directionView[1]),
                                         hn::Set(d, -light.directionView[2])};
            for (size_t c = 0; c < kChunks; ++c)
                any |= facingChunk(toLight, surface[c], active[c], chunkLight[c]);
        } else {
            for (size_t c = 0; c < kChunks; ++c)
                any |= rangeChunk(light, packet, c, active[c], chunkLight[c]);
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
        if (!kPairLights) {
            for (size_t c = 0; c < kChunks; ++c)
                shadeAndAdd<kCountContributing>(light, surface[c], chunkLight[c], sums[c]);
        } else if (!pending) {
            pending = &light;
            for (size_t c = 0; c < kChunks; ++c)
                pendingLight[c] = chunkLight[c];
        } else {
            for (size_t c = 0; c < kChunks; ++c) {
                FloatVec first[3], second[3];
                shadedRadiance(*pending, surface[c], pendingLight[c], first);
                shadedRadiance(light, surface[c], chunkLight[c], second);
                accumulate<kCountContributing>(first, sums[c]);
                accumulate<kCountContributing>(second, sums[c]);
            }
            pending = nullptr;
        }
    }
    if (pending)
        for (size_t c = 0; c < kChunks; ++c)
            shadeAndAdd<kCountContributing>(*pending, surface[c], pendingLight[c], sums[c]);

    for (size_t c = 0; c < kChunks; ++c) {
        const size_t first = c * kLanesPerVector;
        const LaneMask active = surface[c].active;
        // Inactive lanes only ever added +0; keeping their stored value exactly leaves them
        // untouched (a -0 stays -0).
        for (int k = 0; k < 3; ++k) {
            float* target = accumulator.radiance[k] + first;
            hn::Store(hn::IfThenElse(active, sums[c].radiance[k], hn::Load(d, target)), d, target);
        }
        int32_t* contributing = reinterpret_cast<int32_t*>(accumulator.lightsContributing + first);
        hn::Store(hn::Add(hn::Load(di, contributing), sums[c].contributing), di, contributing);
        // Every active lane walked the whole list, or with per-light masks its own lights.
        int32_t* evaluated = reinterpret_cast<int32_t*>(accumulator.lightsEvaluated + first);
        const IntVec walked = kPerLightMasks ? evaluatedCount[c]
                                             : hn::IfThenElseZero(hn::RebindMask(di, active),
                                                                  hn::Set(di, int32_t(args.count)));
        hn::Store(hn::Add(hn::Load(di, evaluated), walked), di, evaluated);
    }
}

void shadePacketVector(const ShadeArgs& args) {
    if (args.lightLaneMasks) {
        if (args.countContributing)
            shadeLights<true, true>(args);
        else
            shadeLights<false, true>(args);
    } else if (args.countContributing) {
        shadeLights<true, false>(args);
    } else {
        shadeLights<false, false>(args);
    }
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // include guard toggle
