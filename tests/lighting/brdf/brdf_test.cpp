// The one BRDF: finite support (exactly zero at and beyond the range), closed-form values,
// the float and double instantiations agreeing, and the one entry (evaluateLight) dispatching on
// the surface's material model to the model's own function.
#include <gtest/gtest.h>

#include <cmath>

#include "lighting/brdf/Brdf.h"

namespace {

using lighting::evaluateLight;
using lighting::LightInView;
using scenes::LightType;

template <class T> gbuffer::BasicSurface<T> matteFloorPoint() {
    gbuffer::BasicSurface<T> p;
    p.positionView = {T(0), T(0), T(-5)};
    p.normalView = {T(0), T(1), T(0)};
    p.albedo = {T(0.5), T(0.5), T(0.5)};
    p.specularIntensity = T(0);
    p.specularPower = T(1);
    return p;
}

template <class T> LightInView<T> pointLightAbove(T height, T range) {
    LightInView<T> light;
    light.type = LightType::Point;
    light.positionView = {T(0), height, T(-5)};
    light.radiance = {T(1), T(1), T(1)};
    light.rangeMetres = range;
    return light;
}

TEST(Brdf, PointLightClosedForm) {
    // Light 1 m straight above a matte floor (albedo 0.5), range 2 m:
    // window = (1 - (1/2)^4)^2, attenuation = window / (1 + 1), n.l = 1, diffuse = 0.5 / pi.
    const auto p = matteFloorPoint<double>();
    const glm::dvec3 toViewer = glm::normalize(-p.positionView);
    const glm::dvec3 radiance = evaluateLight(p, toViewer, pointLightAbove(1.0, 2.0));
    const double window = std::pow(1.0 - std::pow(0.5, 4), 2);
    const double expected = window / 2.0 * 0.5 / lighting::kPi;
    EXPECT_NEAR(radiance.x, expected, 1e-15);
    EXPECT_EQ(radiance.x, radiance.y);
}

TEST(Brdf, ExactlyZeroAtAndBeyondRange) {
    for (double range : {0.0, 0.5, 1.0}) { // light 1 m away: at, and beyond, the range
        const auto p = matteFloorPoint<double>();
        const glm::dvec3 radiance =
            evaluateLight(p, glm::dvec3(0, 0, 1), pointLightAbove(1.0, range));
        EXPECT_EQ(radiance, glm::dvec3(0.0)) << "range " << range;
        EXPECT_FALSE(lighting::contributes(radiance));
    }
    const auto pf = matteFloorPoint<float>();
    EXPECT_EQ(evaluateLight(pf, glm::vec3(0, 0, 1), pointLightAbove(1.0f, 1.0f)), glm::vec3(0.0f));
    EXPECT_EQ(evaluateLight(pf, glm::vec3(0, 0, 1), pointLightAbove(1e30f, 1.0f)), glm::vec3(0.0f));
    // Just inside the range the light still contributes (the window is positive).
    EXPECT_TRUE(lighting::contributes(evaluateLight(matteFloorPoint<double>(), glm::dvec3(0, 0, 1),
                                                    pointLightAbove(1.0, 1.0 + 1e-9))));
}

TEST(Brdf, ZeroWhenFacingAway) {
    const auto p = matteFloorPoint<double>();
    EXPECT_EQ(evaluateLight(p, glm::dvec3(0, 0, 1), pointLightAbove(-1.0, 10.0)), glm::dvec3(0.0));
    // Grazing: exactly in the tangent plane.
    LightInView<double> grazing = pointLightAbove(0.0, 10.0);
    grazing.positionView.x = 2.0;
    EXPECT_EQ(evaluateLight(p, glm::dvec3(0, 0, 1), grazing), glm::dvec3(0.0));
}

TEST(Brdf, SpotConeAndDirectionalAndAmbient) {
    const auto p = matteFloorPoint<double>();
    LightInView<double> spot = pointLightAbove(1.0, 5.0);
    spot.type = LightType::Spot;
    spot.directionView = {0, -1, 0};
    spot.spotInnerCos = std::cos(0.2);
    spot.spotOuterCos = std::cos(0.3);
    EXPECT_TRUE(lighting::contributes(evaluateLight(p, glm::dvec3(0, 0, 1), spot)));
    spot.directionView = glm::normalize(glm::dvec3(1, -1, 0)); // 45 degrees off: outside
    EXPECT_EQ(evaluateLight(p, glm::dvec3(0, 0, 1), spot), glm::dvec3(0.0));

    LightInView<double> sun;
    sun.type = LightType::Directional;
    sun.directionView = {0, -1, 0};
    sun.radiance = glm::dvec3(lighting::kPi);
    EXPECT_NEAR(evaluateLight(p, glm::dvec3(0, 1, 0), sun).x, 0.5, 1e-15);

    LightInView<double> ambient;
    ambient.type = LightType::Ambient;
    ambient.radiance = glm::dvec3(0.2);
    EXPECT_NEAR(evaluateLight(p, glm::dvec3(0, 0, 1), ambient).x, 0.1, 1e-15);
}

TEST(Brdf, FloatMatchesDouble) {
    // Same formula in both precisions: relative agreement to float rounding.
    gbuffer::BasicSurface<double> pd = matteFloorPoint<double>();
    pd.specularIntensity = 0.5;
    pd.specularPower = 64.0;
    gbuffer::Surface pf;
    pf.positionView = glm::vec3(pd.positionView);
    pf.normalView = glm::vec3(pd.normalView);
    pf.albedo = glm::vec3(pd.albedo);
    pf.specularIntensity = 0.5f;
    pf.specularPower = 64.0f;
    for (int i = 0; i < 100; ++i) {
        const double a = i * 0.0628;
        LightInView<double> ld = pointLightAbove(0.3 + 0.01 * i, 3.0);
        ld.positionView.x = std::cos(a);
        ld.positionView.z = -5.0 + std::sin(a);
        LightInView<float> lf;
        lf.positionView = glm::vec3(ld.positionView);
        lf.radiance = glm::vec3(ld.radiance);
        lf.rangeMetres = 3.0f;
        const glm::dvec3 toViewer = glm::normalize(-pd.positionView);
        const double expected = evaluateLight(pd, toViewer, ld).x;
        const double actual = evaluateLight(pf, glm::vec3(toViewer), lf).x;
        EXPECT_NEAR(actual, expected, 1e-5 * std::abs(expected) + 1e-9) << i;
    }
}

// evaluateLight is the Blinn-Phong function on Blinn-Phong surfaces and the metallic-roughness
// function on metallic-roughness ones (bitwise: the same call), and the two models differ.
TEST(Brdf, TheOneEntryDispatchesOnTheMaterialModel) {
    gbuffer::BasicSurface<double> s = matteFloorPoint<double>();
    s.specularIntensity = 0.5;
    s.specularPower = 40.0;
    s.roughness = 0.4;
    s.metallic = 0.3;
    s.occlusion = 0.7;
    const lighting::Vec3<double> toViewer = glm::normalize(glm::dvec3(0.3, 0.8, 0.2));
    std::vector<LightInView<double>> lights(3, pointLightAbove<double>(2.0, 6.0));
    lights[1].positionView = {1.0, 1.5, -4.0};
    lights[2].type = LightType::Ambient;
    lights[2].radiance = {0.2, 0.3, 0.4};
    for (const LightInView<double>& light : lights) {
        s.model = scenes::MaterialModel::BlinnPhong;
        const lighting::Vec3<double> blinnPhong = evaluateLight(s, toViewer, light);
        EXPECT_EQ(blinnPhong, lighting::evaluateLightBlinnPhong(s, toViewer, light));
        s.model = scenes::MaterialModel::MetallicRoughness;
        const lighting::Vec3<double> metallicRoughness = evaluateLight(s, toViewer, light);
        const lighting::MetallicRoughnessSurface<double> m{s.albedo, s.metallic, s.roughness,
                                                           s.occlusion};
        EXPECT_EQ(metallicRoughness, lighting::evaluateLightMetallicRoughness(
                                         s.positionView, s.normalView,
                                         lighting::metallicRoughnessLobes(m), toViewer, light));
        EXPECT_NE(blinnPhong, metallicRoughness);
        EXPECT_TRUE(lighting::contributes(metallicRoughness));
    }
}

} // namespace
