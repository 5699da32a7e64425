// The glTF metallic-roughness BRDF (lighting/brdf/MetallicRoughness.h) against values computed
// independently of it: the spec's Appendix B "full code" written out here in double in its own
// form (D with (N.H)^2 (alpha^2 - 1) + 1, G / (4 |N.L| |N.V|), the mix() of dielectric and metal
// lobes), closed forms (roughness 1 makes D = 1/pi), white-furnace integrals of the GGX + Smith
// lobe by deterministic quadrature, reciprocity, and the limits (roughness 0 and 1, metallic 0 and
// 1, grazing angles, N.V <= 0) giving finite non-negative values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "lighting/brdf/MetallicRoughness.h"

namespace {

using lighting::LightInView;
using lighting::MetallicRoughnessLobes;
using lighting::MetallicRoughnessSurface;
using scenes::LightType;

constexpr double kPi = 3.14159265358979323846;

// ---- an independent evaluation of Appendix B --------------------------------------------------

double mix(double a, double b, double t) {
    return a * (1 - t) + b * t;
}
double heaviside(double x) {
    return x > 0 ? 1.0 : 0.0;
}

// The spec's "full code", per colour channel, straight from its formulas.
glm::dvec3 specBrdf(const glm::dvec3& baseColor, double metallic, double roughness,
                    const glm::dvec3& n, const glm::dvec3& l, const glm::dvec3& v) {
    const glm::dvec3 h = glm::normalize(l + v);
    const double nl = glm::dot(n, l), nv = glm::dot(n, v), nh = glm::dot(n, h);
    const double hl = glm::dot(h, l), hv = glm::dot(h, v), vh = glm::dot(v, h);
    const double alpha = roughness * roughness, a2 = alpha * alpha;
    const double d = a2 * heaviside(nh) / (kPi * std::pow(nh * nh * (a2 - 1) + 1, 2));
    const double g = 2 * std::abs(nl) * std::abs(nv) * heaviside(hl) * heaviside(hv) /
                     (std::abs(nv) * std::sqrt(a2 + (1 - a2) * nl * nl) +
                      std::abs(nl) * std::sqrt(a2 + (1 - a2) * nv * nv));
    const double specular = d * g / (4 * std::abs(nv) * std::abs(nl));
    const double fresnelW = std::pow(1 - std::abs(vh), 5);
    glm::dvec3 material;
    for (int c = 0; c < 3; ++c) {
        const double diffuse = baseColor[c] / kPi;
        const double dielectric = mix(diffuse, specular, 0.04 + (1 - 0.04) * fresnelW);
        const double metal = (baseColor[c] + (1 - baseColor[c]) * fresnelW) * specular;
        material[c] = mix(dielectric, metal, metallic);
    }
    return material;
}

template <class T>
MetallicRoughnessLobes<T> lobes(const glm::dvec3& baseColor, double metallic, double roughness,
                                double occlusion = 1.0) {
    MetallicRoughnessSurface<T> surface;
    surface.baseColor = lighting::Vec3<T>(baseColor);
    surface.metallic = T(metallic);
    surface.roughness = T(roughness);
    surface.occlusion = T(occlusion);
    return lighting::metallicRoughnessLobes(surface);
}

glm::dvec3 direction(double thetaRadians, double phiRadians) {
    return {std::sin(thetaRadians) * std::cos(phiRadians),
            std::sin(thetaRadians) * std::sin(phiRadians), std::cos(thetaRadians)};
}

void expectRelative(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance,
                    const std::string& what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(actual[c], expected[c], tolerance * std::abs(expected[c]) + 1e-300)
            << what << " channel " << c;
}

// ---- values ---------------------------------------------------------------------------------

struct Case {
    glm::dvec3 baseColor;
    double metallic, roughness;
    double thetaL, phiL, thetaV, phiV; // degrees, around n = +Z
};

const std::vector<Case> kCases = {
    {{0.8, 0.6, 0.2}, 0.0, 0.5, 30, 0, 45, 180},   // dielectric, near the mirror direction
    {{0.8, 0.6, 0.2}, 1.0, 0.5, 30, 0, 45, 180},   // metal, same geometry
    {{0.9, 0.9, 0.9}, 0.3, 0.25, 10, 40, 60, 200}, // partly metallic, off the mirror direction
    {{0.1, 0.5, 0.9}, 0.7, 0.9, 70, 10, 20, 100},  // rough
    {{0.5, 0.5, 0.5}, 0.0, 0.1, 40, 0, 40, 180},   // smooth, exactly at the mirror direction
    {{0.5, 0.2, 0.1}, 0.5, 0.6, 85, 30, 80, 250},  // both grazing
    {{0.3, 0.3, 0.3}, 0.0, 0.4, 20, 0, 100, 0},    // n.v < 0 (a normal-mapped normal)
};

TEST(MetallicRoughness, MatchesAnIndependentEvaluationOfTheSpec) {
    const glm::dvec3 n(0, 0, 1);
    for (const Case& c : kCases) {
        const double r = kPi / 180;
        const glm::dvec3 l = direction(c.thetaL * r, c.phiL * r);
        const glm::dvec3 v = direction(c.thetaV * r, c.phiV * r);
        const glm::dvec3 expected = specBrdf(c.baseColor, c.metallic, c.roughness, n, l, v);
        const std::string what = "case metallic " + std::to_string(c.metallic) + " roughness " +
                                 std::to_string(c.roughness) + " thetaV " +
                                 std::to_string(c.thetaV);
        const glm::dvec3 inDouble = lighting::metallicRoughnessBrdf(
            lobes<double>(c.baseColor, c.metallic, c.roughness), n, l, v);
        // 1e-10: the spec's form (N.H)^2 (alpha^2 - 1) + 1 itself loses digits where N.H is
        // close to 1 (the mirror case at roughness 0.1 is off by 4e-12 relative).
        expectRelative(inDouble, expected, 1e-10, what + " (double)");
        const glm::dvec3 inFloat(
            lighting::metallicRoughnessBrdf(lobes<float>(c.baseColor, c.metallic, c.roughness),
                                            glm::vec3(n), glm::vec3(l), glm::vec3(v)));
        expectRelative(inFloat, expected, 2e-5, what + " (float)");
        for (int k = 0; k < 3; ++k)
            EXPECT_GT(expected[k], 0.0) << what; // every case has both lobes non-zero
    }
}

TEST(MetallicRoughness, ClosedFormAtRoughnessOneAndNormalIncidence) {
    // roughness 1: alpha = 1, D = 1/pi everywhere, Vis = 1 / (2 (N.L + N.V)) = 1/4 at l = v = n;
    // fresnel_w = 0, so F = f0 and the diffuse weight is 1 - 0.04.
    const glm::dvec3 n(0, 0, 1);
    const glm::dvec3 baseColor(0.5, 0.25, 1.0);
    for (double metallic : {0.0, 0.4, 1.0}) {
        const glm::dvec3 f0 = (1 - metallic) * glm::dvec3(0.04) + metallic * baseColor;
        const glm::dvec3 expected =
            (1 - 0.04) * (1 - metallic) * baseColor / kPi + f0 * (1 / kPi) * 0.25;
        expectRelative(
            lighting::metallicRoughnessBrdf(lobes<double>(baseColor, metallic, 1.0), n, n, n),
            expected, 1e-14, "metallic " + std::to_string(metallic));
    }
}

TEST(MetallicRoughness, Reciprocity) {
    std::mt19937_64 random(17);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const glm::dvec3 n(0, 0, 1);
    for (int i = 0; i < 2000; ++i) {
        // l above the surface; v anywhere but straight below (n.v < 0 included).
        const glm::dvec3 l = direction(std::acos(unit(random)), 2 * kPi * unit(random));
        const glm::dvec3 v =
            direction(std::acos(1.999 * unit(random) - 0.999), 2 * kPi * unit(random));
        const glm::dvec3 baseColor(unit(random), unit(random), unit(random));
        const auto m = lobes<double>(baseColor, unit(random), unit(random));
        const glm::dvec3 forward = lighting::metallicRoughnessBrdf(m, n, l, v);
        const glm::dvec3 backward = lighting::metallicRoughnessBrdf(m, n, v, l);
        expectRelative(backward, forward, 1e-12, "sample " + std::to_string(i));
    }
}

// ---- limits ---------------------------------------------------------------------------------

template <class T> void expectFiniteNonNegativeEverywhere() {
    using V = lighting::Vec3<T>;
    const V position(T(0), T(0), T(-3));
    const std::vector<double> angles = {0, 1e-4, 30, 60, 89, 89.999, 90, 90.001, 100, 179.9, 180};
    for (double roughness : {0.0, 1e-6, lighting::kMinRoughness, 0.05, 0.5, 1.0})
        for (double metallic : {0.0, 0.5, 1.0})
            for (double normalTilt : angles) // tilted normals put v below them (n.v <= 0)
                for (double lightAngle : angles) {
                    const double r = kPi / 180;
                    const V n = V(direction(normalTilt * r, 0.3));
                    const auto m = lobes<T>(glm::dvec3(1.0, 0.5, 0.0), metallic, roughness);
                    LightInView<T> sun;
                    sun.type = LightType::Directional;
                    sun.directionView = -V(direction(lightAngle * r, kPi));
                    sun.radiance = V(T(1));
                    const V toViewer(T(0), T(0), T(1));
                    const V radiance =
                        lighting::evaluateLightMetallicRoughness(position, n, m, toViewer, sun);
                    // The mirror configuration at the smallest roughness is the largest value.
                    const V mirror =
                        lighting::metallicRoughnessBrdf(m, toViewer, toViewer, toViewer);
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_TRUE(std::isfinite(radiance[c]) && radiance[c] >= T(0))
                            << "roughness " << roughness << " metallic " << metallic << " tilt "
                            << normalTilt << " light " << lightAngle << ": " << radiance[c];
                        ASSERT_TRUE(std::isfinite(mirror[c]) && mirror[c] >= T(0));
                    }
                }
}

TEST(MetallicRoughness, LimitsGiveFiniteNonNegativeValuesInFloat) {
    expectFiniteNonNegativeEverywhere<float>();
}

TEST(MetallicRoughness, LimitsGiveFiniteNonNegativeValuesInDouble) {
    expectFiniteNonNegativeEverywhere<double>();
}

TEST(MetallicRoughness, LightOppositeTheViewerAndTinyCosines) {
    const glm::vec3 n(0, 0, 1);
    const auto m = lobes<float>(glm::dvec3(0.7), 0.2, 0.0);
    // l = -v: no half vector.
    const glm::vec3 l = glm::normalize(glm::vec3(0.3f, 0, 1)), v = -l;
    const glm::vec3 opposite = lighting::metallicRoughnessBrdf(m, n, l, v);
    EXPECT_TRUE(std::isfinite(opposite.x) && opposite.x >= 0.0f);
    // Cosines near the smallest floats.
    for (float tiny : {1e-20f, 1e-38f, 1e-44f}) {
        const glm::vec3 grazing = glm::normalize(glm::vec3(1, 0, tiny));
        for (const glm::vec3& f : {lighting::metallicRoughnessBrdf(m, n, grazing, grazing),
                                   lighting::metallicRoughnessBrdf(m, n, grazing, n)})
            for (int c = 0; c < 3; ++c)
                EXPECT_TRUE(std::isfinite(f[c]) && f[c] >= 0.0f) << tiny;
    }
}

TEST(MetallicRoughness, MetallicAndRoughnessAreClampedToTheirRanges) {
    const glm::dvec3 n(0, 0, 1), l = direction(0.5, 0), v = direction(0.4, kPi);
    const glm::dvec3 bc(0.6, 0.5, 0.4);
    EXPECT_EQ(lighting::metallicRoughnessBrdf(lobes<double>(bc, 1.5, 2.0), n, l, v),
              lighting::metallicRoughnessBrdf(lobes<double>(bc, 1.0, 1.0), n, l, v));
    EXPECT_EQ(
        lighting::metallicRoughnessBrdf(lobes<double>(bc, -1.0, 0.0), n, l, v),
        lighting::metallicRoughnessBrdf(lobes<double>(bc, 0.0, lighting::kMinRoughness), n, l, v));
}

// ---- white furnace --------------------------------------------------------------------------

// Directional albedo of the specular lobe alone, E(v) = integral of D Vis (N.L) over the
// hemisphere of l, with F = 1 (a white metal: f0 = 1, no diffuse), by a midpoint rule over the
// half vector h. Cells are bounded by polar angles theta_k = atan(alpha sqrt(u_k / (1 - u_k)))
// at uniform u_k, which crowds them where D peaks; each cell's solid angle is exact
// ((cos theta_k - cos theta_k+1) dphi) and dw_l = 4 (v.h) dw_h. The BRDF is the function under
// test; the quadrature knows nothing of it.
double specularAlbedo(double roughness, double cosThetaV, int thetaCells = 3000,
                      int phiCells = 360) {
    const auto m = lobes<double>(glm::dvec3(1.0), 1.0, roughness);
    const double alpha = roughness * roughness;
    const glm::dvec3 n(0, 0, 1);
    const glm::dvec3 v(std::sqrt(1 - cosThetaV * cosThetaV), 0, cosThetaV);
    auto thetaAt = [&](int k) {
        if (k == thetaCells)
            return kPi / 2;
        const double u = double(k) / thetaCells;
        return std::atan(alpha * std::sqrt(u / (1 - u)));
    };
    double sum = 0;
    for (int k = 0; k < thetaCells; ++k) {
        const double theta0 = thetaAt(k), theta1 = thetaAt(k + 1);
        const double thetaMid = 0.5 * (theta0 + theta1);
        const double cellSolidAngle = (std::cos(theta0) - std::cos(theta1)) * 2 * kPi / phiCells;
        for (int j = 0; j < phiCells; ++j) {
            const glm::dvec3 h = direction(thetaMid, (j + 0.5) * 2 * kPi / phiCells);
            const double vDotH = glm::dot(v, h);
            if (vDotH <= 0)
                continue;
            const glm::dvec3 l = 2 * vDotH * h - v;
            const double nDotL = glm::dot(n, l);
            if (nDotL <= 0)
                continue;
            sum +=
                lighting::metallicRoughnessBrdf(m, n, l, v).x * nDotL * 4 * vDotH * cellSolidAngle;
        }
    }
    return sum;
}

TEST(MetallicRoughness, WhiteFurnaceSpecularLobeNeverGainsEnergy) {
    // The quadrature's own error, measured at roughness 1 against the closed form below, is
    // under 1e-4; 1e-3 leaves room for the sharper lobes.
    constexpr double kQuadratureTolerance = 1e-3;
    const std::vector<double> cosines = {1.0, 0.8, 0.5, 0.2, 0.05};
    for (double roughness : {0.05, 0.1, 0.25, 0.5, 0.75, 1.0}) {
        std::printf("roughness %.2f: E(n.v) =", roughness);
        for (double mu : cosines) {
            const double albedo = specularAlbedo(roughness, mu);
            std::printf(" %.4f (%.2f)", albedo, mu);
            EXPECT_LE(albedo, 1.0 + kQuadratureTolerance)
                << "roughness " << roughness << " n.v " << mu;
            EXPECT_GT(albedo, 0.0);
        }
        std::printf("\n");
    }
    // Single scattering only: a smooth lobe seen head-on keeps almost all its energy...
    EXPECT_GT(specularAlbedo(0.05, 1.0), 0.99);
    // ...a rough one loses much (light that would hit the microsurface twice is dropped). At
    // roughness 1, D = 1/pi and Vis = 1 / (2 (N.L + N.V)), so E(mu) = integral over mu_l of
    // mu_l / (mu_l + mu) = 1 - mu ln((1 + mu) / mu): 1 - ln 2 = 0.307 head-on.
    for (double mu : cosines) {
        const double closedForm = 1 - mu * std::log((1 + mu) / mu);
        EXPECT_NEAR(specularAlbedo(1.0, mu), closedForm, 1e-4) << "n.v " << mu;
    }
    // The loss grows with roughness at normal incidence.
    double previous = 2.0;
    for (double roughness : {0.05, 0.25, 0.5, 0.75, 1.0}) {
        const double albedo = specularAlbedo(roughness, 1.0);
        EXPECT_LT(albedo, previous) << roughness;
        previous = albedo;
    }
}

TEST(MetallicRoughness, DiffuseLobeOfABlackDielectricIsLambertTimesOneMinusFresnel) {
    // Only the diffuse part: a dielectric with base colour c has f = (1 - F_dielectric) c / pi +
    // 0.04-ish specular; subtracting a metal-free, diffuse-free evaluation isolates it.
    const glm::dvec3 n(0, 0, 1), l = direction(0.7, 0.2), v = direction(0.3, 2.0);
    const glm::dvec3 c(0.5, 0.3, 0.1);
    const glm::dvec3 withDiffuse =
        lighting::metallicRoughnessBrdf(lobes<double>(c, 0, 0.5), n, l, v);
    const glm::dvec3 without =
        lighting::metallicRoughnessBrdf(lobes<double>(glm::dvec3(0), 0, 0.5), n, l, v);
    const double w = std::pow(1 - glm::dot(v, glm::normalize(l + v)), 5);
    expectRelative(withDiffuse - without, (1 - (0.04 + 0.96 * w)) * c / kPi, 1e-12, "diffuse");
}

// ---- lights ---------------------------------------------------------------------------------

TEST(MetallicRoughness, PointLightRadianceIsAttenuationTimesCosineTimesBrdf) {
    // A point light 1 m from the sample along its normal, range 2 m: attenuation
    // (1 - 1/16)^2 / 2, n.l = 1.
    const glm::dvec3 position(0, 0, -4), n = glm::normalize(glm::dvec3(0, 1, 1));
    LightInView<double> light;
    light.type = LightType::Point;
    light.positionView = position + n;
    light.rangeMetres = 2;
    light.radiance = glm::dvec3(2.0, 1.0, 0.5);
    const glm::dvec3 toViewer = glm::normalize(-position);
    const auto m = lobes<double>(glm::dvec3(0.6, 0.6, 0.6), 0.25, 0.4);
    const glm::dvec3 expected = light.radiance * (225.0 / 256.0 / 2.0) *
                                specBrdf(glm::dvec3(0.6), 0.25, 0.4, n, n, toViewer);
    expectRelative(lighting::evaluateLightMetallicRoughness(position, n, m, toViewer, light),
                   expected, 1e-12, "point light");
}

TEST(MetallicRoughness, AmbientReflectsWhiteExactlyForWhiteDielectricsAndMetals) {
    LightInView<double> ambient;
    ambient.type = LightType::Ambient;
    ambient.radiance = glm::dvec3(0.3);
    const glm::dvec3 p(0, 0, -1), n(0, 0, 1), v(0, 0, 1);
    for (double metallic : {0.0, 1.0})
        expectRelative(lighting::evaluateLightMetallicRoughness(
                           p, n, lobes<double>(glm::dvec3(1), metallic, 0.5), v, ambient),
                       glm::dvec3(0.3), 1e-15, "metallic " + std::to_string(metallic));
    // Occlusion scales ambient light only.
    expectRelative(lighting::evaluateLightMetallicRoughness(
                       p, n, lobes<double>(glm::dvec3(1), 0.0, 0.5, 0.25), v, ambient),
                   glm::dvec3(0.075), 1e-15, "occluded");
}

} // namespace
