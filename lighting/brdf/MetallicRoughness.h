// The glTF 2.0 metallic-roughness BRDF, exactly as the specification's Appendix B defines it,
// and the radiance it reflects from one light. The second material model of DESIGN.md beside
// Brdf.h's Lambert + Blinn-Phong; templated on the scalar type so that the reference runs the same
// formula in double. Written as straight-line arithmetic (no table, no per-lane branch other than
// the light's support tests that Brdf.h has too) so that a SIMD kernel can evaluate it with masked
// lanes.
//
// Appendix B, with alpha = roughness^2, V the unit vector to the viewer, L to the light, N the
// shading normal and H = normalize(L + V):
//     D   = alpha^2 chi+(N.H) / (pi ((N.H)^2 (alpha^2 - 1) + 1)^2)             Trowbridge-Reitz/GGX
//     Vis = chi+(H.L) chi+(H.V) / (2 (|N.V| sqrt(alpha^2 + (1 - alpha^2)(N.L)^2)
//                                     + |N.L| sqrt(alpha^2 + (1 - alpha^2)(N.V)^2)))  Smith,
//                                     height-
//                                                                                     correlated
//     specular_brdf   = Vis D
//     fresnel_w       = (1 - |V.H|)^5                                          Schlick
//     dielectric_brdf = mix(baseColor / pi, specular_brdf, 0.04 + 0.96 fresnel_w)
//     metal_brdf      = (baseColor + (1 - baseColor) fresnel_w) specular_brdf
//     material        = mix(dielectric_brdf, metal_brdf, metallic)
// which expands to what is computed here (the same function, fewer operations):
//     f = (1 - F_dielectric) c_diff / pi + F D Vis,   c_diff = mix(baseColor, 0, metallic),
//     F = f0 + (1 - f0) fresnel_w,                    f0 = mix(0.04, baseColor, metallic),
//     F_dielectric = 0.04 + 0.96 fresnel_w.
// Note the diffuse weight: the spec mixes the diffuse lobe with the dielectric Fresnel only (the
// metal has none), so it is (1 - F_dielectric), not the (1 - F) some renderers use.
// Numerics, all mathematically neutral:
// - (N.H)^2 (alpha^2 - 1) + 1 is evaluated as |N x H|^2 + (N.H)^2 alpha^2 (Lagrange's identity
//   for unit vectors), which does not cancel in float when N.H is close to 1 and alpha is small.
// - roughness is clamped to [kMinRoughness, 1]: the spec allows 0, a perfect mirror whose D is a
//   Dirac that no point light can hit (0/0 in the formula at N.H = 1); metallic to [0, 1].
// - Vis's denominator is floored at kMinVisibilityDenominator, which only matters when both N.L
//   and N.V are below ~1e-17 (then f is huge but N.L is ~0, so the radiance stays finite).
// - N.V <= 0 happens on normal-mapped surfaces; the spec's absolute values keep f finite and
//   non-negative there. A light contributes only where N.L > 0, as in Brdf.h.
// Ambient lights stand for a uniform environment, whose exact response would need the BRDF's
// directional albedo (an integral, or a table); instead they reflect (0.96 c_diff + f0) times the
// occlusion, the BRDF's response at normal incidence for a smooth surface: a white dielectric or a
// white metal in a white ambient light reflects exactly what it receives.
// Point, spot and directional lights attenuate through lightIncidence (LightIncidence.h), the same
// arithmetic as Brdf.h, so their support, and exact culling, is that of the Blinn-Phong model.
// Conventions: view space, camera at the origin looking down -Z; unit normal and toViewer.
// Pure functions, thread-safe.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "lighting/brdf/LightInView.h"
#include "lighting/brdf/LightIncidence.h"

namespace lighting {

// Perceptual roughness floor: alpha = 4e-4, alpha^2 = 1.6e-7 keeps D's peak (1 / (pi alpha^2),
// ~2e6) and its square in the denominator well inside float's range.
inline constexpr double kMinRoughness = 0.02;
inline constexpr double kDielectricF0 = 0.04; // ior 1.5: ((1 - 1.5) / (1 + 1.5))^2
inline constexpr double kMinVisibilityDenominator = 1e-20;

// What a sample of a metallic-roughness material is, after its textures are applied.
template <class T> struct MetallicRoughnessSurface {
    Vec3<T> baseColor{T(1)}; // linear
    T metallic = T(0);
    T roughness = T(1); // perceptual; alpha = roughness^2
    T occlusion = T(1); // ambient only; 1 = unoccluded
};

// The per-sample quantities every light needs, computed once per sample.
template <class T> struct MetallicRoughnessLobes {
    Vec3<T> diffuseColor{T(0)}; // c_diff = baseColor (1 - metallic)
    Vec3<T> f0{T(0)};           // mix(0.04, baseColor, metallic)
    T alpha2 = T(1);            // alpha^2 = roughness^4
    T ambientWeight = T(0);     // occlusion, for ambient lights
};

template <class T>
inline MetallicRoughnessLobes<T> metallicRoughnessLobes(const MetallicRoughnessSurface<T>& s) {
    const T metallic = glm::clamp(s.metallic, T(0), T(1));
    const T roughness = glm::clamp(s.roughness, T(kMinRoughness), T(1));
    const T alpha = roughness * roughness;
    MetallicRoughnessLobes<T> lobes;
    lobes.diffuseColor = s.baseColor * (T(1) - metallic);
    lobes.f0 = Vec3<T>(T(kDielectricF0)) * (T(1) - metallic) + s.baseColor * metallic;
    lobes.alpha2 = alpha * alpha;
    lobes.ambientWeight = s.occlusion;
    return lobes;
}

// GGX / Trowbridge-Reitz D for unit n and h (see the file comment for the form).
template <class T> inline T ggxDistribution(T alpha2, const Vec3<T>& n, const Vec3<T>& h) {
    const T nDotH = glm::dot(n, h);
    const Vec3<T> nCrossH = glm::cross(n, h);
    const T k = glm::dot(nCrossH, nCrossH) + nDotH * nDotH * alpha2;
    return nDotH > T(0) ? alpha2 / (T(kPi) * k * k) : T(0);
}

// Smith height-correlated visibility Vis = G / (4 |N.L| |N.V|), without the chi+ factors (the
// caller's half vector makes H.L = H.V, tested once).
template <class T> inline T smithVisibility(T alpha2, T nDotL, T nDotV) {
    const T absL = std::abs(nDotL), absV = std::abs(nDotV);
    const T denominator = absV * std::sqrt(alpha2 + (T(1) - alpha2) * absL * absL) +
                          absL * std::sqrt(alpha2 + (T(1) - alpha2) * absV * absV);
    return T(0.5) / std::max(denominator, T(kMinVisibilityDenominator));
}

// Schlick's weight (1 - |V.H|)^5, by multiplications.
template <class T> inline T schlickWeight(T vDotH) {
    const T x = glm::clamp(T(1) - std::abs(vDotH), T(0), T(1));
    const T x2 = x * x;
    return x2 * x2 * x;
}

// The BRDF f(l, v) (per steradian, without the cosine), for unit n, l and v. Symmetric in l and v.
template <class T>
inline Vec3<T> metallicRoughnessBrdf(const MetallicRoughnessLobes<T>& lobes, const Vec3<T>& n,
                                     const Vec3<T>& l, const Vec3<T>& v) {
    // l = -v has no half vector; h = 0 then gives D = 0 and the Fresnel limit (weight 1), both
    // continuous with the neighbouring directions.
    const Vec3<T> sum = l + v;
    const T sumLength2 = glm::dot(sum, sum);
    const Vec3<T> h = sumLength2 > T(0) ? sum / std::sqrt(sumLength2) : Vec3<T>(T(0));
    const T vDotH = glm::dot(v, h);
    const T w = schlickWeight(vDotH);
    const Vec3<T> fresnel = lobes.f0 + (Vec3<T>(T(1)) - lobes.f0) * w;
    const T dielectricFresnel = T(kDielectricF0) + T(1.0 - kDielectricF0) * w;
    const T specular = vDotH > T(0)
                           ? ggxDistribution(lobes.alpha2, n, h) *
                                 smithVisibility(lobes.alpha2, glm::dot(n, l), glm::dot(n, v))
                           : T(0);
    return lobes.diffuseColor * ((T(1) - dielectricFresnel) * T(1.0 / kPi)) + fresnel * specular;
}

// Radiance towards the viewer from one light at one sample. Zero (exactly) where Brdf.h's
// evaluateLight is zero for the same light and point: at or beyond the range, outside a spot
// cone, or with the light at or below the tangent plane.
template <class T>
inline Vec3<T>
evaluateLightMetallicRoughness(const Vec3<T>& positionView, const Vec3<T>& normalView,
                               const MetallicRoughnessLobes<T>& lobes, const Vec3<T>& toViewer,
                               const LightInView<T>& light) {
    if (light.type == scenes::LightType::Ambient)
        return light.radiance * lobes.ambientWeight *
               (lobes.diffuseColor * T(1.0 - kDielectricF0) + lobes.f0);
    const Incidence<T> incidence = lightIncidence(positionView, normalView, light);
    if (!(incidence.attenuation > T(0)))
        return Vec3<T>(T(0));
    const T nDotL = glm::dot(normalView, incidence.toLight);
    if (!(nDotL > T(0)))
        return Vec3<T>(T(0));
    return light.radiance * (incidence.attenuation * nDotL) *
           metallicRoughnessBrdf(lobes, normalView, incidence.toLight, toViewer);
}

// The radiance of evaluateLightMetallicRoughness split the way light buffers store lighting
// (light pre-pass, inferred lighting), into sums that do not depend on the base colour or on
// metallic, so that a light buffer computed before the material is known can be completed by the
// material pass exactly:
//     radiance = c_diff * diffuse + f0 * specularF0 + specularEdge
// with c_diff = baseColor (1 - metallic) and f0 = mix(0.04, baseColor, metallic)
// (metallicRoughnessLobes). Schlick's F = f0 + (1 - f0) w = f0 (1 - w) + w splits the specular
// lobe D Vis into a part proportional to f0 and the Fresnel edge w D Vis, which is not; the
// diffuse weight (1 - F(0.04)) / pi does not involve f0. The sums depend on the normal, roughness,
// occlusion (ambient lights: (0.96 c_diff + f0) occlusion) and the lights only. Equal to
// evaluateLightMetallicRoughness up to rounding (the same factors, grouped differently).
template <class T> struct MetallicRoughnessSplit {
    Vec3<T> diffuse{T(0)};      // times c_diff
    Vec3<T> specularF0{T(0)};   // times f0
    Vec3<T> specularEdge{T(0)}; // added as is
};

template <class T>
inline MetallicRoughnessSplit<T>
splitLightMetallicRoughness(const Vec3<T>& positionView, const Vec3<T>& normalView, T roughness,
                            T occlusion, const Vec3<T>& toViewer, const LightInView<T>& light) {
    MetallicRoughnessSplit<T> split;
    if (light.type == scenes::LightType::Ambient) {
        split.diffuse = light.radiance * (occlusion * T(1.0 - kDielectricF0));
        split.specularF0 = light.radiance * occlusion;
        return split;
    }
    const Incidence<T> incidence = lightIncidence(positionView, normalView, light);
    if (!(incidence.attenuation > T(0)))
        return split;
    const T nDotL = glm::dot(normalView, incidence.toLight);
    if (!(nDotL > T(0)))
        return split;
    const T clamped = glm::clamp(roughness, T(kMinRoughness), T(1));
    const T alpha = clamped * clamped;
    const T alpha2 = alpha * alpha;
    const Vec3<T> sum = incidence.toLight + toViewer;
    const T sumLength2 = glm::dot(sum, sum);
    const Vec3<T> h = sumLength2 > T(0) ? sum / std::sqrt(sumLength2) : Vec3<T>(T(0));
    const T vDotH = glm::dot(toViewer, h);
    const T w = schlickWeight(vDotH);
    const T dielectricFresnel = T(kDielectricF0) + T(1.0 - kDielectricF0) * w;
    const T specular = vDotH > T(0)
                           ? ggxDistribution(alpha2, normalView, h) *
                                 smithVisibility(alpha2, nDotL, glm::dot(normalView, toViewer))
                           : T(0);
    const Vec3<T> incident = light.radiance * (incidence.attenuation * nDotL);
    split.diffuse = incident * ((T(1) - dielectricFresnel) * T(1.0 / kPi));
    split.specularF0 = incident * ((T(1) - w) * specular);
    split.specularEdge = incident * (w * specular);
    return split;
}

} // namespace lighting
