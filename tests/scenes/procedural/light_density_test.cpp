// The light generator's constant-overlap mode (scenes/SceneRequest.h LightDensity): the expected
// number of lights whose sphere holds a point of the atrium's courtyard stays what it is at the
// reference count (kOverlapReferenceCount) as the count grows 8x and 64x, while with fixed radii
// it grows with the count; intensities fall as radii shrink, by the falloff's mean over the ball.
#include <gtest/gtest.h>

#include "scenes/procedural/LightGenerator.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

// Mean over a fixed grid of points in the courtyard of the lights whose range holds the point.
double meanOverlap(const scenes::Scene& scene) {
    double total = 0.0;
    int points = 0;
    for (float x = -5.0f; x <= 5.0f; x += 2.5f)
        for (float y = 1.0f; y <= 9.0f; y += 2.0f)
            for (float z = -15.0f; z <= 15.0f; z += 3.0f) {
                const glm::vec3 p(x, y, z);
                for (const scenes::Light& light : scene.lights)
                    if (light.type == scenes::LightType::Point &&
                        glm::length(light.positionWorld - p) < light.rangeMetres)
                        total += 1.0;
                ++points;
            }
    return total / points;
}

scenes::Scene atrium(int lights, scenes::LightDensity density) {
    scenes::SceneRequest request;
    request.lightCount = lights;
    request.seed = 7;
    request.lightDensity = density;
    return scenes::buildProceduralScene("atrium", request);
}

TEST(LightDensity, ConstantOverlapKeepsTheLightsReachingAPoint) {
    using scenes::LightDensity;
    const double reference = meanOverlap(atrium(1000, LightDensity::ConstantOverlap));
    ASSERT_GT(reference, 5.0);
    EXPECT_EQ(reference, meanOverlap(atrium(1000, LightDensity::FixedRadius)))
        << "at the reference count both modes are the same lights";
    for (int count : {8000, 64000}) {
        SCOPED_TRACE(count);
        const double constant = meanOverlap(atrium(count, LightDensity::ConstantOverlap));
        EXPECT_NEAR(constant / reference, 1.0, 0.15);
        const double fixed = meanOverlap(atrium(count, LightDensity::FixedRadius));
        EXPECT_NEAR(fixed / reference, count / 1000.0, 0.15 * count / 1000.0);
    }
}

TEST(LightDensity, IntensityFollowsTheMeanFalloff) {
    scenes::PointLightScatter scatter;
    scatter.minRangeMetres = 2.0f;
    scatter.maxRangeMetres = 4.0f;
    const scenes::PointLightScatter same =
        scenes::scatterForDensity(scatter, scenes::LightDensity::ConstantOverlap, 1000);
    EXPECT_EQ(same.minRangeMetres, 2.0f);
    EXPECT_EQ(same.maxIntensity, scatter.maxIntensity);
    const scenes::PointLightScatter dense =
        scenes::scatterForDensity(scatter, scenes::LightDensity::ConstantOverlap, 8000);
    EXPECT_NEAR(dense.minRangeMetres, 1.0f, 1e-6f); // (1000 / 8000)^(1/3) = 1/2
    EXPECT_NEAR(dense.maxRangeMetres, 2.0f, 1e-6f);
    const double expected = scenes::meanFalloffOverBall(3.0) / scenes::meanFalloffOverBall(1.5);
    EXPECT_NEAR(dense.maxIntensity / scatter.maxIntensity, expected, 1e-5);
    EXPECT_LT(expected, 1.0) << "smaller balls sit closer to their light";
    // A mean of a window in [0, 1] times 1 / (d^2 + 1) in (0, 1].
    EXPECT_GT(scenes::meanFalloffOverBall(1.0), 0.0);
    EXPECT_LT(scenes::meanFalloffOverBall(1.0), 1.0);
    EXPECT_THROW(scenes::parseLightDensity("dense"), scenes::SceneError);
}

} // namespace
