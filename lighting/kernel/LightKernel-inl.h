// shadePacketVector: the vector light loop of the shading kernel, once per compiled instruction
// set (included by VectorTargets.cpp through foreach_target.h). It evaluates lighting/brdf/Brdf.h's
// evaluateLight (windowed inverse-square falloff, spot smoothstep, directional and ambient lights)
// with each lane's material model, Lambert + normalised Blinn-Phong (Brdf.h) or glTF
// metallic-roughness (MetallicRoughness.h: GGX, Smith height-correlated visibility, Schlick), for
// the 16 lanes of a ShadingPacket and each light of a list, in list order.
//
// Models: the packet's metallicRoughnessMask says which lanes use metallic-roughness. A call whose
// active lanes all use one model runs that model's loop only (a Blinn-Phong scene runs exactly the
// loop it ran before the second model existed); a call with both computes both shadings for the
// packet and selects per lane. Phases 1 and 2 are the same for both models (lightIncidence).
//
// The packet's 16 lanes are kChunks = 16 / N hardware vectors of N lanes (AVX-512: 1 x 16,
// AVX2: 2 x 8, SSE4: 4 x 4). A light goes through three phases, each over every chunk, and the
// packet leaves it as soon as every active lane of all 16 has rejected it, as a GPU warp does:
//   1. range:  offset, distance^2 < range^2                   (all lanes out: skipped at range)
//   2. cone and facing: direction, attenuation, spot cone, n.l > 0
//                                                              (all lanes out: skipped later)
//   3. shading: halfway vector, n.h, pow, sum (Blinn-Phong); halfway vector, Schlick's weight,
//      GGX D, Smith Vis, Fresnel, sum (metallic-roughness)   (at least one lane: shaded)
// Lanes that rejected the light, and lanes outside the lane mask, add exactly +0 (their radiance
// is selected to zero, whatever NaN or Inf their arithmetic produced), so a lane's sum depends on
// its own surface and the light list only, never on its neighbours.
//
// Floating point: every operation is the one evaluateLight performs in float, in its order (dot
// products (x + y) + z, exact IEEE division and square root, no reciprocal estimate, multiply and
// add kept apart: the project compiles with -ffp-contract=off, which also keeps the compiler from
// fusing Highway's Mul and Add), except pow (VectorPow-inl.h). So every decision (range, cone,
// n.l) and every factor but the specular lobe are bitwise the scalar path's, and the radiance
// differs from it only through pow. The metallic-roughness model has no pow ((1 - |V.H|)^5 is
// multiplications, as MetallicRoughness.h computes it), so its radiance is bitwise the scalar
// path's. Quantities that depend only on the pixel (direction to the viewer, albedo / pi, the
// specular normalisation; c_diff, f0, alpha^2, the |N.V| half of Vis's denominator) are computed
// once per call with the operations evaluateLight repeats per light, so they too are bitwise the
// same. (Measured: fusing the dot
// products of the shading part and skipping the halfway vector's normalisation saved ~3% of a
// shaded light and made sharp lobes (powers of thousands) differ from the scalar path by up to
// 10^4 ulps; not worth losing the tight comparison.)

// Ordinary headers outside the per-target region, so they are compiled for the baseline only.
#include "lighting/brdf/MetallicRoughness.h"
#include "lighting/kernel/VectorTargets.h"
#include "lighting/shadows/ShadowLookup.h"
#include "scenes/Scene.h"

#include <type_traits>

#if defined(LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_
#undef LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_
#else
#define LIGHTING_KERNEL_LIGHT_KERNEL_INL_H_
#endif

#include <hwy/highway.h>

#include "lighting/kernel/VectorPow-inl.h"
#include "lighting/kernel/VectorShadows-inl.h"

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

// Which material models a call's active lanes use (ShadingPacket::metallicRoughnessMask).
enum class Models { BlinnPhong, MetallicRoughness, Mixed };

// Runs `shade` with the narrowest instantiation that covers the call's lanes (one model alone
// skips the other's arithmetic and the per-lane select); the radiance and split kernels dispatch
// here alike. `shade` takes a std::integral_constant<Models, M>.
template <class Shade>
HWY_INLINE void withLaneModels(const ShadingPacket& packet, uint32_t laneMask, Shade&& shade) {
    const uint32_t lanes = laneMask & packet.laneMask;
    const uint32_t metallicRoughness = lanes & packet.metallicRoughnessMask;
    if (metallicRoughness == 0)
        shade(std::integral_constant<Models, Models::BlinnPhong>());
    else if (metallicRoughness == lanes)
        shade(std::integral_constant<Models, Models::MetallicRoughness>());
    else
        shade(std::integral_constant<Models, Models::Mixed>());
}

// The float constants of MetallicRoughness.h as its float instantiation rounds them.
constexpr float kDielectricF0Float = float(kDielectricF0);
constexpr float kDielectricWeightFloat = float(1.0 - kDielectricF0);
constexpr float kMinRoughnessFloat = float(kMinRoughness);
constexpr float kMinVisibilityDenominatorFloat = float(kMinVisibilityDenominator);
constexpr float kPiFloat = float(kPi);
constexpr float kInversePiFloat = float(1.0 / kPi);

// One chunk's surface, read once per call. The rows of a model no lane uses are not filled.
struct ChunkSurface {
    FloatVec normal[3];
    FloatVec toViewer[3];
    // Blinn-Phong
    FloatVec diffuse[3];    // albedo * (1 / pi)
    FloatVec specularScale; // specularIntensity * (specularPower + 8) * (1 / (8 pi))
    FloatVec specularPower;
    // Metallic-roughness: metallicRoughnessLobes, and the per-pixel parts of the BRDF.
    FloatVec diffuseColor[3]; // c_diff = baseColor (1 - metallic)
    FloatVec f0[3];           // 0.04 (1 - metallic) + baseColor metallic
    FloatVec ambientColor[3]; // c_diff 0.96 + f0 (the ambient response)
    FloatVec occlusion;
    FloatVec alpha2;
    FloatVec oneMinusAlpha2;
    FloatVec absNDotV;
    FloatVec viewTerm; // sqrt(alpha^2 + (1 - alpha^2) |N.V| |N.V|), Vis's second square root
    LaneMask metallicRoughness;
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

// Adds one light's radiance; counts the lanes where it is non-zero. `counted` is what the count
// reads: the radiance itself, or for a shadowed light its radiance before the shadow (the oracle's
// definition of contributes ignores occlusion, so shadows change the image, never the counts).
template <bool kCountContributing>
HWY_INLINE void accumulate(const FloatVec radiance[3], ChunkSums& sums,
                           const FloatVec* counted = nullptr) {
    const FloatTag d;
    const IntTag di;
    const FloatVec zero = hn::Zero(d);
    for (int k = 0; k < 3; ++k)
        sums.radiance[k] = hn::Add(sums.radiance[k], radiance[k]);
    if (!kCountContributing)
        return;
    if (counted)
        radiance = counted;
    const LaneMask contributes = hn::Or(
        hn::Or(hn::Ne(radiance[0], zero), hn::Ne(radiance[1], zero)), hn::Ne(radiance[2], zero));
    // An all-ones lane is -1: subtracting it counts one.
    sums.contributing =
        hn::Sub(sums.contributing, hn::VecFromMask(di, hn::RebindMask(di, contributes)));
}

// Phase 3 for one chunk, Blinn-Phong: the halfway vector and pow(n.h, power), with
// evaluateLightBlinnPhong's operations except pow (shared with the split kernel).
HWY_INLINE FloatVec blinnPhongLobe(const ChunkSurface& s, const ChunkLight& l) {
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
    return powNonNegative(d, nDotH, s.specularPower);
}

// Phase 3 for one chunk, Blinn-Phong: the specular lobe and the radiance.
HWY_INLINE void blinnPhongRadiance(const KernelLight& light, const ChunkSurface& s,
                                   const ChunkLight& l, FloatVec radiance[3]) {
    const FloatTag d;
    const FloatVec specular = hn::Mul(s.specularScale, blinnPhongLobe(s, l));
    const FloatVec scale = hn::Mul(l.attenuation, l.nDotL);
    for (int k = 0; k < 3; ++k)
        radiance[k] =
            hn::IfThenElseZero(l.pass, hn::Mul(hn::Mul(hn::Set(d, light.radiance[k]), scale),
                                               hn::Add(s.diffuse[k], specular)));
}

// The light-dependent factors of the metallic-roughness BRDF for one chunk:
// evaluateLightMetallicRoughness's operations after lightIncidence, in its order
// (metallicRoughnessBrdf, ggxDistribution, smithVisibility, schlickWeight), with its branches as
// selections. Shared with the split kernel (splitLightMetallicRoughness computes the same terms).
struct GgxTerms {
    FloatVec w;             // Schlick's weight (1 - |V.H|)^5
    FloatVec diffuseWeight; // (1 - F_dielectric) / pi
    FloatVec specular;      // D Vis, 0 unless V.H > 0
};

HWY_INLINE GgxTerms ggxTerms(const ChunkSurface& s, const ChunkLight& l) {
    const FloatTag d;
    const FloatVec zero = hn::Zero(d);
    const FloatVec one = hn::Set(d, 1.0f);
    // h = normalize(l + v), or 0 when l = -v.
    FloatVec sum[3], h[3];
    for (int k = 0; k < 3; ++k)
        sum[k] = hn::Add(l.toLight[k], s.toViewer[k]);
    const FloatVec sumLength2 = dot3(sum[0], sum[1], sum[2], sum[0], sum[1], sum[2]);
    const LaneMask hasHalfway = hn::Gt(sumLength2, zero);
    const FloatVec sumLength = hn::Sqrt(sumLength2);
    for (int k = 0; k < 3; ++k)
        h[k] = hn::IfThenElseZero(hasHalfway, hn::Div(sum[k], sumLength));
    const FloatVec vDotH = dot3(s.toViewer[0], s.toViewer[1], s.toViewer[2], h[0], h[1], h[2]);
    // schlickWeight: x = clamp(1 - |V.H|, 0, 1), x^5 as (x^2 x^2) x.
    const FloatVec x = hn::Min(hn::Max(hn::Sub(one, hn::Abs(vDotH)), zero), one);
    const FloatVec x2 = hn::Mul(x, x);
    GgxTerms terms;
    terms.w = hn::Mul(hn::Mul(x2, x2), x);
    const FloatVec dielectricFresnel = hn::Add(
        hn::Set(d, kDielectricF0Float), hn::Mul(hn::Set(d, kDielectricWeightFloat), terms.w));
    // ggxDistribution: k = |N x H|^2 + (N.H)^2 alpha^2 (glm::cross's operand order).
    const FloatVec nDotH = dot3(s.normal[0], s.normal[1], s.normal[2], h[0], h[1], h[2]);
    const FloatVec cross[3] = {hn::Sub(hn::Mul(s.normal[1], h[2]), hn::Mul(h[1], s.normal[2])),
                               hn::Sub(hn::Mul(s.normal[2], h[0]), hn::Mul(h[2], s.normal[0])),
                               hn::Sub(hn::Mul(s.normal[0], h[1]), hn::Mul(h[0], s.normal[1]))};
    const FloatVec kTerm = hn::Add(dot3(cross[0], cross[1], cross[2], cross[0], cross[1], cross[2]),
                                   hn::Mul(hn::Mul(nDotH, nDotH), s.alpha2));
    const FloatVec distribution =
        hn::IfThenElseZero(hn::Gt(nDotH, zero),
                           hn::Div(s.alpha2, hn::Mul(hn::Mul(hn::Set(d, kPiFloat), kTerm), kTerm)));
    // smithVisibility: |N.V| sqrt(a2 + (1 - a2) |N.L|^2) + |N.L| sqrt(a2 + (1 - a2) |N.V|^2).
    const FloatVec absNDotL = hn::Abs(l.nDotL);
    const FloatVec lightTerm =
        hn::Sqrt(hn::Add(s.alpha2, hn::Mul(hn::Mul(s.oneMinusAlpha2, absNDotL), absNDotL)));
    const FloatVec denominator =
        hn::Add(hn::Mul(s.absNDotV, lightTerm), hn::Mul(absNDotL, s.viewTerm));
    const FloatVec visibility =
        hn::Div(hn::Set(d, 0.5f), hn::Max(denominator, hn::Set(d, kMinVisibilityDenominatorFloat)));
    terms.specular = hn::IfThenElseZero(hn::Gt(vDotH, zero), hn::Mul(distribution, visibility));
    terms.diffuseWeight = hn::Mul(hn::Sub(one, dielectricFresnel), hn::Set(d, kInversePiFloat));
    return terms;
}

// Phase 3 for one chunk, metallic-roughness: the BRDF from ggxTerms and the radiance.
// evaluateLightMetallicRoughness returns 0 where the attenuation is not > 0 (it can underflow
// inside the range); that is selected here too.
HWY_INLINE void metallicRoughnessRadiance(const KernelLight& light, const ChunkSurface& s,
                                          const ChunkLight& l, FloatVec radiance[3]) {
    const FloatTag d;
    const FloatVec zero = hn::Zero(d);
    const FloatVec one = hn::Set(d, 1.0f);
    const GgxTerms terms = ggxTerms(s, l);
    const FloatVec scale = hn::Mul(l.attenuation, l.nDotL);
    const LaneMask pass = hn::And(l.pass, hn::Gt(l.attenuation, zero));
    for (int k = 0; k < 3; ++k) {
        const FloatVec fresnel = hn::Add(s.f0[k], hn::Mul(hn::Sub(one, s.f0[k]), terms.w));
        const FloatVec brdf = hn::Add(hn::Mul(s.diffuseColor[k], terms.diffuseWeight),
                                      hn::Mul(fresnel, terms.specular));
        radiance[k] =
            hn::IfThenElseZero(pass, hn::Mul(hn::Mul(hn::Set(d, light.radiance[k]), scale), brdf));
    }
}

// Phase 3 with the call's models: a lane's radiance is its own model's.
template <Models kModels>
HWY_INLINE void shadedRadiance(const KernelLight& light, const ChunkSurface& s, const ChunkLight& l,
                               FloatVec radiance[3]) {
    if constexpr (kModels == Models::BlinnPhong) {
        blinnPhongRadiance(light, s, l, radiance);
    } else if constexpr (kModels == Models::MetallicRoughness) {
        metallicRoughnessRadiance(light, s, l, radiance);
    } else {
        FloatVec blinnPhong[3];
        blinnPhongRadiance(light, s, l, blinnPhong);
        metallicRoughnessRadiance(light, s, l, radiance);
        for (int k = 0; k < 3; ++k)
            radiance[k] = hn::IfThenElse(s.metallicRoughness, radiance[k], blinnPhong[k]);
    }
}

// An ambient light with the call's models: Blinn-Phong reflects radiance x albedo,
// metallic-roughness (radiance x occlusion) x (c_diff 0.96 + f0).
template <Models kModels>
HWY_INLINE void ambientRadiance(const KernelLight& light, const ShadingPacket& packet, size_t chunk,
                                const ChunkSurface& s, LaneMask active, FloatVec radiance[3]) {
    const FloatTag d;
    for (int k = 0; k < 3; ++k) {
        const FloatVec lightRadiance = hn::Set(d, light.radiance[k]);
        FloatVec value;
        if constexpr (kModels != Models::MetallicRoughness)
            value = hn::Mul(lightRadiance, hn::Load(d, packet.albedo[k] + chunk * kLanesPerVector));
        if constexpr (kModels != Models::BlinnPhong) {
            const FloatVec metallicRoughness =
                hn::Mul(hn::Mul(lightRadiance, s.occlusion), s.ambientColor[k]);
            value = kModels == Models::Mixed
                        ? hn::IfThenElse(s.metallicRoughness, metallicRoughness, value)
                        : metallicRoughness;
        }
        radiance[k] = hn::IfThenElseZero(active, value);
    }
}

// The vector lookup (VectorShadows-inl.h) for the lanes of chunk `chunk` whose bit is set in
// `lanes` (bit 0 = the chunk's first lane); 1 at the others. Bitwise ShadowMaps::visibility.
HWY_INLINE FloatVec vectorChunkVisibility(const shadows::ShadowMapsView& view, uint32_t shadow,
                                          const ShadingPacket& packet, size_t chunk,
                                          uint32_t lanes) {
    const FloatTag d;
    static_assert(kLanesPerVector % kShadowLanes == 0, "a float vector is whole double vectors");
    HWY_ALIGN float visibility[kLanesPerVector];
    constexpr uint32_t kHalfBits = (1u << kShadowLanes) - 1u;
    for (size_t h = 0; h < kLanesPerVector; h += kShadowLanes)
        hn::StoreU(shadowVisibilityLanes(view, shadow, packet, chunk * kLanesPerVector + h,
                                         lanes >> h & kHalfBits),
                   ShadowFloatTag(), visibility + h);
    return hn::Load(d, visibility);
}

// The shadow factor of a shadowed light for one chunk: the lookup's visibility at the lanes of
// `pass` (those whose radiance may be non-zero), 1 at the others (their radiance is +0 already).
// With the lookup's plain-data view (ShadowMaps), the vector lookup, bitwise the scalar one;
// without (a test's analytic lookup) or for a shadow the view marks scalarOnly (dual-paraboloid
// faces, per-light settings), the scalar lookup lane by lane with the packet's float
// position and normal: the very calls the scalar path makes. Either way the factor is bitwise the
// same on every path.
HWY_INLINE FloatVec chunkVisibility(const shadows::ShadowLookup& lookup,
                                    const shadows::ShadowMapsView* view, uint32_t shadow,
                                    const ShadingPacket& packet, size_t chunk, LaneMask pass) {
    const FloatTag d;
    uint8_t bits[8] = {};
    hn::StoreMaskBits(d, pass, bits);
    const uint32_t lanes = uint32_t(bits[0]) | uint32_t(bits[1]) << 8;
    if (view && (shadow >= view->shadowCount || !view->shadows[shadow].scalarOnly))
        return vectorChunkVisibility(*view, shadow, packet, chunk, lanes);
    HWY_ALIGN float visibility[kLanesPerVector];
    for (size_t i = 0; i < kLanesPerVector; ++i) {
        const size_t lane = chunk * kLanesPerVector + i;
        visibility[i] = lanes >> i & 1u ? lookup.visibility(shadow,
                                                            glm::vec3(packet.positionView[0][lane],
                                                                      packet.positionView[1][lane],
                                                                      packet.positionView[2][lane]),
                                                            glm::vec3(packet.normalView[0][lane],
                                                                      packet.normalView[1][lane],
                                                                      packet.normalView[2][lane]))
                                        : 1.0f;
    }
    return hn::Load(d, visibility);
}

// Adds a shaded light's radiance for one chunk, times its shadow factor when it casts a shadow.
template <bool kCountContributing>
HWY_INLINE void addShaded(const ShadeArgs& args, const KernelLight& light, size_t chunk,
                          const ChunkLight& l, const FloatVec radiance[3], ChunkSums& sums) {
    if (light.shadow == shadows::kNoShadow || !args.shadows) {
        accumulate<kCountContributing>(radiance, sums);
        return;
    }
    const FloatVec visibility =
        chunkVisibility(*args.shadows, args.shadowView, light.shadow, *args.packet, chunk, l.pass);
    FloatVec shadowed[3];
    for (int k = 0; k < 3; ++k)
        shadowed[k] = hn::Mul(radiance[k], visibility);
    accumulate<kCountContributing>(shadowed, sums, radiance);
}

template <bool kCountContributing, Models kModels>
HWY_INLINE void shadeAndAdd(const ShadeArgs& args, const KernelLight& light, size_t chunk,
                            const ChunkSurface& s, const ChunkLight& l, ChunkSums& sums) {
    FloatVec radiance[3];
    shadedRadiance<kModels>(light, s, l, radiance);
    addShaded<kCountContributing>(args, light, chunk, l, radiance, sums);
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

template <Models kModels>
HWY_INLINE void loadSurface(const ShadingPacket& packet, uint32_t laneMask, size_t chunk,
                            ChunkSurface& s) {
    const FloatTag d;
    const size_t first = chunk * kLanesPerVector;
    const FloatVec one = hn::Set(d, 1.0f);
    FloatVec toViewer[3];
    for (int k = 0; k < 3; ++k) {
        s.normal[k] = hn::Load(d, packet.normalView[k] + first);
        toViewer[k] = hn::Neg(hn::Load(d, packet.positionView[k] + first));
        if constexpr (kModels != Models::MetallicRoughness)
            s.diffuse[k] = hn::Mul(hn::Load(d, packet.albedo[k] + first),
                                   hn::Set(d, float(1.0 / 3.14159265358979323846)));
    }
    // glm::normalize: v * (1 / sqrt(dot(v, v))).
    const FloatVec inverseLength =
        hn::Div(one, hn::Sqrt(dot3(toViewer[0], toViewer[1], toViewer[2], toViewer[0], toViewer[1],
                                   toViewer[2])));
    for (int k = 0; k < 3; ++k)
        s.toViewer[k] = hn::Mul(toViewer[k], inverseLength);
    if constexpr (kModels != Models::MetallicRoughness) {
        s.specularPower = hn::Load(d, packet.specularPower + first);
        s.specularScale = hn::Mul(hn::Mul(hn::Load(d, packet.specularIntensity + first),
                                          hn::Add(s.specularPower, hn::Set(d, 8.0f))),
                                  hn::Set(d, float(1.0 / (8.0 * 3.14159265358979323846))));
    }
    if constexpr (kModels != Models::BlinnPhong) {
        // metallicRoughnessLobes: metallic clamped to [0, 1], roughness to [kMinRoughness, 1]
        // (glm::clamp: min(max(x, lo), hi)).
        const FloatVec zero = hn::Zero(d);
        const FloatVec metallic = hn::Min(hn::Max(hn::Load(d, packet.metallic + first), zero), one);
        const FloatVec roughness = hn::Min(
            hn::Max(hn::Load(d, packet.roughness + first), hn::Set(d, kMinRoughnessFloat)), one);
        const FloatVec alpha = hn::Mul(roughness, roughness);
        s.alpha2 = hn::Mul(alpha, alpha);
        s.oneMinusAlpha2 = hn::Sub(one, s.alpha2);
        const FloatVec oneMinusMetallic = hn::Sub(one, metallic);
        for (int k = 0; k < 3; ++k) {
            const FloatVec baseColor = hn::Load(d, packet.albedo[k] + first);
            s.diffuseColor[k] = hn::Mul(baseColor, oneMinusMetallic);
            s.f0[k] = hn::Add(hn::Mul(hn::Set(d, kDielectricF0Float), oneMinusMetallic),
                              hn::Mul(baseColor, metallic));
            s.ambientColor[k] =
                hn::Add(hn::Mul(s.diffuseColor[k], hn::Set(d, kDielectricWeightFloat)), s.f0[k]);
        }
        s.occlusion = hn::Load(d, packet.occlusion + first);
        s.absNDotV = hn::Abs(dot3(s.normal[0], s.normal[1], s.normal[2], s.toViewer[0],
                                  s.toViewer[1], s.toViewer[2]));
        s.viewTerm =
            hn::Sqrt(hn::Add(s.alpha2, hn::Mul(hn::Mul(s.oneMinusAlpha2, s.absNDotV), s.absNDotV)));
        s.metallicRoughness = chunkMask(packet.metallicRoughnessMask, chunk);
    }
    s.active = chunkMask(laneMask, chunk);
}

// kPerLightMasks: args.lightLaneMasks[i] further restricts light i to some lanes (the `ideal`
// stage's per-lane lists as one union list); each lane then counts only its own lights.
// kModels: which models the active lanes use (shadePacketVector decides it per call).
template <bool kCountContributing, bool kPerLightMasks, Models kModels>
void shadeLights(const ShadeArgs& args) {
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
        loadSurface<kModels>(packet, laneMask, c, surface[c]);
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
                    shadeAndAdd<kCountContributing, kModels>(args, *pending, c, surface[c],
                                                             pendingLight[c], sums[c]);
                pending = nullptr;
            }
            for (size_t c = 0; c < kChunks; ++c) {
                FloatVec radiance[3];
                ambientRadiance<kModels>(light, packet, c, surface[c], active[c], radiance);
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
                shadeAndAdd<kCountContributing, kModels>(args, light, c, surface[c], chunkLight[c],
                                                         sums[c]);
        } else if (!pending) {
            pending = &light;
            for (size_t c = 0; c < kChunks; ++c)
                pendingLight[c] = chunkLight[c];
        } else {
            for (size_t c = 0; c < kChunks; ++c) {
                FloatVec first[3], second[3];
                shadedRadiance<kModels>(*pending, surface[c], pendingLight[c], first);
                shadedRadiance<kModels>(light, surface[c], chunkLight[c], second);
                addShaded<kCountContributing>(args, *pending, c, pendingLight[c], first, sums[c]);
                addShaded<kCountContributing>(args, light, c, chunkLight[c], second, sums[c]);
            }
            pending = nullptr;
        }
    }
    if (pending)
        for (size_t c = 0; c < kChunks; ++c)
            shadeAndAdd<kCountContributing, kModels>(args, *pending, c, surface[c], pendingLight[c],
                                                     sums[c]);

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

template <Models kModels> void shadeWithModels(const ShadeArgs& args) {
    if (args.lightLaneMasks) {
        if (args.countContributing)
            shadeLights<true, true, kModels>(args);
        else
            shadeLights<false, true, kModels>(args);
    } else if (args.countContributing) {
        shadeLights<true, false, kModels>(args);
    } else {
        shadeLights<false, false, kModels>(args);
    }
}

// VectorFunctions::shadowVisibility: the vector lookup for every lane of a packet.
void shadowVisibilityVector(const ShadowVisibilityArgs& args) {
    const FloatTag d;
    const uint32_t laneMask = args.laneMask & ((1u << kPacketLanes) - 1u);
    for (size_t c = 0; c < kChunks; ++c)
        hn::StoreU(vectorChunkVisibility(*args.view, args.shadow, *args.packet, c,
                                         laneMask >> (c * kLanesPerVector)),
                   d, args.visibility + c * kLanesPerVector);
}

void shadePacketVector(const ShadeArgs& args) {
    withLaneModels(*args.packet, args.laneMask,
                   [&](auto models) HWY_ATTR { shadeWithModels<decltype(models)::value>(args); });
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // include guard toggle
