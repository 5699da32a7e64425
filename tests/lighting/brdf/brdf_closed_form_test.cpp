// Lambert + Blinn-Phong (lighting/brdf/Brdf.h) against closed forms computed independently of it,
// so that a wrong formula cannot hide behind the reference, which shares it: the specular peak and
// the directional albedo of the normalised lobe (its (n + 8) / (8 pi) normalisation integrated by
// quadrature), the Lambert albedo, the spot smoothstep at chosen angles and the distance window at
// chosen distances. Also: lightIncidence (LightIncidence.h), which the metallic-roughness model
// uses, attenuates bit for bit as evaluateLight does, and both models have the same support.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/glm.hpp>

#include "lighting/brdf/Brdf.h"
#include "lighting/brdf/LightIncidence.h"
#include "lighting/brdf/MetallicRoughness.h"

namespace {

using lighting::evaluateLight;
using lighting::LightInView;
using scenes::LightType;

constexpr double kPi = 3.14159265358979323846;

gbuffer::BasicSurface<double> pointFacingUp(double albedo, double specularIntensity, double power) {
    gbuffer::BasicSurface<double> p;
    p.positionView = {0, 0, -3};
    p.normalView = {0, 0, 1};
    p.albedo = glm::dvec3(albedo);
    p.specularIntensity = specularIntensity;
    p.specularPower = power;
    return p;
}

LightInView<double> sunFrom(const glm::dvec3& toLight) {
    LightInView<double> sun;
    sun.type = LightType::Directional;
    sun.directionView = -toLight;
    sun.radiance = glm::dvec3(1.0);
    return sun;
}

// Directional albedo of the specular lobe seen along the normal, for f = (n + 8) / (8 pi)
// (n.h)^n: with v = n the half vector's polar angle is half the light's, and
// E(n) = (n + 8) / 4 * integral over theta in [0, pi/2] of cos^n(theta/2) cos(theta) sin(theta)
//      = (n + 8) [2 / (n + 4) - 1 / (n + 2) + 2^(-(n+2)/2) 2 / ((n + 2)(n + 4))].
double blinnPhongAlbedoClosedForm(double n) {
    return (n + 8) *
           (2 / (n + 4) - 1 / (n + 2) + std::pow(2.0, -(n + 2) / 2) * 2 / ((n + 2) * (n + 4)));
}

// The same albedo by quadrature over the light's polar angle (the lobe is symmetric about n when
// v = n), midpoint rule, evaluateLight giving f * cos.
double integratedAlbedo(const gbuffer::BasicSurface<double>& p, int cells = 20000) {
    const glm::dvec3 toViewer = p.normalView;
    double sum = 0;
    for (int i = 0; i < cells; ++i) {
        const double theta = (i + 0.5) * (kPi / 2) / cells;
        const glm::dvec3 toLight(std::sin(theta), 0, std::cos(theta));
        sum += evaluateLight(p, toViewer, sunFrom(toLight)).x * std::sin(theta);
    }
    return sum * (kPi / 2) / cells * 2 * kPi;
}

TEST(BlinnPhongClosedForm, SpecularPeakIsTheNormalisation) {
    // Light and viewer both along the normal: n.h = 1, n.l = 1, so the radiance is
    // ks (n + 8) / (8 pi) for a unit sun.
    for (double power : {1.0, 8.0, 32.0, 128.0, 1000.0}) {
        const auto p = pointFacingUp(0.0, 0.5, power);
        const glm::dvec3 radiance = evaluateLight(p, p.normalView, sunFrom(p.normalView));
        EXPECT_NEAR(radiance.x, 0.5 * (power + 8) / (8 * kPi), 1e-12) << "power " << power;
    }
}

TEST(BlinnPhongClosedForm, SpecularAlbedoMatchesTheNormalisation) {
    for (double power : {1.0, 4.0, 16.0, 32.0, 100.0, 256.0}) {
        const double integrated = integratedAlbedo(pointFacingUp(0.0, 1.0, power));
        EXPECT_NEAR(integrated, blinnPhongAlbedoClosedForm(power), 1e-6) << "power " << power;
    }
    // (n + 8) / (8 pi) approximates the normalisation: the albedo seen head-on stays less than
    // 7% above 1 (1.024 at n = 1, 1.067 at n = 16, about 1 + 2/n for large n).
    for (double power : {1.0, 4.0, 16.0, 256.0, 2048.0}) {
        EXPECT_GT(blinnPhongAlbedoClosedForm(power), 1.0) << power;
        EXPECT_LT(blinnPhongAlbedoClosedForm(power), 1.07) << power;
    }
}

TEST(BlinnPhongClosedForm, LambertAlbedoIsTheAlbedo) {
    EXPECT_NEAR(integratedAlbedo(pointFacingUp(0.7, 0.0, 1.0)), 0.7, 1e-8);
}

TEST(BlinnPhongClosedForm, DistanceWindowAtChosenDistances) {
    // Range 2 m, light on the normal at distance d, matte albedo 1: radiance =
    // (1 - (d/2)^4)^2 / (d^2 + 1) / pi.
    struct Distance {
        double metres, attenuation;
    };
    for (const Distance& d : {Distance{0.5, (255.0 / 256) * (255.0 / 256) / 1.25},
                              Distance{1.0, (15.0 / 16) * (15.0 / 16) / 2.0},
                              Distance{1.5, (175.0 / 256) * (175.0 / 256) / 3.25},
                              Distance{1.9, std::pow(1 - std::pow(0.95, 4), 2) / 4.61},
                              Distance{2.0, 0.0}, Distance{3.0, 0.0}}) {
        const auto p = pointFacingUp(1.0, 0.0, 1.0);
        LightInView<double> light;
        light.type = LightType::Point;
        light.positionView = p.positionView + glm::dvec3(0, 0, d.metres);
        light.radiance = glm::dvec3(1.0);
        light.rangeMetres = 2.0;
        EXPECT_NEAR(evaluateLight(p, p.normalView, light).x, d.attenuation / kPi, 1e-15)
            << d.metres << " m";
    }
}

TEST(BlinnPhongClosedForm, SpotSmoothstepAtChosenAngles) {
    // Inner 20 degrees, outer 30: at the angle whose cosine is cos30 + t (cos20 - cos30) the
    // factor is 3t^2 - 2t^3. The surface faces the light, 1 m away, so only the cone varies.
    const double innerCos = std::cos(20 * kPi / 180), outerCos = std::cos(30 * kPi / 180);
    struct Angle {
        double cosine, factor;
    };
    for (const Angle& a :
         {Angle{1.0, 1.0}, Angle{std::cos(10 * kPi / 180), 1.0}, Angle{innerCos, 1.0},
          Angle{outerCos + 0.75 * (innerCos - outerCos), 0.84375},
          Angle{outerCos + 0.5 * (innerCos - outerCos), 0.5},
          Angle{outerCos + 0.25 * (innerCos - outerCos), 0.15625}, Angle{outerCos, 0.0},
          Angle{std::cos(40 * kPi / 180), 0.0}}) {
        LightInView<double> spot;
        spot.type = LightType::Spot;
        spot.positionView = {0, 0, 0};
        spot.directionView = {0, 0, -1};
        spot.radiance = glm::dvec3(1.0);
        spot.rangeMetres = 4.0;
        spot.spotInnerCos = innerCos;
        spot.spotOuterCos = outerCos;
        const double sine = std::sqrt(1 - a.cosine * a.cosine);
        gbuffer::BasicSurface<double> p = pointFacingUp(1.0, 0.0, 1.0);
        p.positionView = {sine, 0, -a.cosine};
        p.normalView = -p.positionView;                               // facing the light: n.l = 1
        const double window = std::pow(1 - std::pow(0.25, 4), 2) / 2; // d = 1, r = 4
        EXPECT_NEAR(evaluateLight(p, glm::dvec3(0, 0, 1), spot).x, window * a.factor / kPi, 1e-12)
            << "cos " << a.cosine;
    }
}

// ---- one attenuation for both models ----------------------------------------------------------

TEST(LightIncidence, AttenuatesBitForBitAsEvaluateLightAndBothModelsShareTheSupport) {
    std::mt19937 random(5);
    std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f), unit(0.0f, 1.0f);
    int contributing = 0;
    for (int i = 0; i < 20000; ++i) {
        gbuffer::Surface p;
        p.positionView = {coordinate(random), coordinate(random), coordinate(random) - 4.0f};
        p.normalView = glm::normalize(glm::vec3(coordinate(random), coordinate(random), 1.0f));
        p.albedo = glm::vec3(1.0f);
        p.specularIntensity = 0.0f;
        LightInView<float> light;
        light.type = i % 3 == 0   ? LightType::Spot
                     : i % 3 == 1 ? LightType::Point
                                  : LightType::Directional;
        light.positionView = {coordinate(random), coordinate(random), coordinate(random) - 4.0f};
        light.directionView =
            glm::normalize(glm::vec3(coordinate(random), -1.0f, coordinate(random)));
        light.radiance = glm::vec3(1.0f, 0.5f, 0.25f);
        light.rangeMetres = 0.5f + 4.0f * unit(random);
        light.spotOuterCos = 0.5f + 0.4f * unit(random);
        light.spotInnerCos = light.spotOuterCos + (1.0f - light.spotOuterCos) * unit(random);
        const glm::vec3 toViewer = glm::normalize(-p.positionView);

        const glm::vec3 blinnPhong = evaluateLight(p, toViewer, light);
        const lighting::Incidence<float> incidence =
            lighting::lightIncidence(p.positionView, p.normalView, light);
        const float nDotL = glm::dot(p.normalView, incidence.toLight);
        const glm::vec3 recomposed =
            nDotL > 0.0f ? light.radiance * (incidence.attenuation * nDotL) *
                               (p.albedo * float(1.0 / lighting::kPi) + glm::vec3(0.0f))
                         : glm::vec3(0.0f);
        ASSERT_EQ(blinnPhong, recomposed) << "sample " << i;

        lighting::MetallicRoughnessSurface<float> surface;
        surface.baseColor = glm::vec3(0.5f);
        surface.metallic = unit(random);
        surface.roughness = unit(random);
        const glm::vec3 metallicRoughness = lighting::evaluateLightMetallicRoughness(
            p.positionView, p.normalView, lighting::metallicRoughnessLobes(surface), toViewer,
            light);
        ASSERT_EQ(lighting::contributes(blinnPhong), lighting::contributes(metallicRoughness))
            << "sample " << i;
        contributing += lighting::contributes(blinnPhong);
    }
    EXPECT_GT(contributing, 2000); // the cases are not all trivially zero
}

} // namespace
