// Light volumes (`deferred`, `light-indexed`): option variants and hard cases against `brute`
// (image within 1e-5 of peak, evaluated >= oracle at every pixel), the proxies' conservativeness
// (sphere and spot cone), thread-count independence, and that volumes (and cones) actually cull.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <random>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferLayout.h"
#include "gbuffer/GBufferPass.h"
#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/culling/LightVolumes.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

constexpr int kWidth = 256;
constexpr int kHeight = 144;

// A prepared frame plus the oracle and brute's image for its current lights.
struct TestScene : lighting::PreparedScene {
    std::vector<uint32_t> oracle;
    lighting::StageResult brute;

    // Renders the G-buffer of `scene`; setLights() replaces the lights and re-runs the oracles.
    explicit TestScene(scenes::Scene s,
                       gbuffer::DepthConvention depth = gbuffer::DepthConvention::Reversed)
        : lighting::PreparedScene(std::move(s), kWidth, kHeight, false, depth) {
        setLights(scene.lights);
    }
    void setLights(const std::vector<scenes::Light>& sceneLights) {
        lighting::PreparedScene::setLights(sceneLights);
        oracle = lighting::countContributingLights(inputs);
        lighting::makeStage("brute")->shade(inputs, brute);
    }
    glm::vec3 worldFromView(const glm::vec3& p) const {
        return glm::vec3(glm::inverse(view.viewFromWorld) * glm::vec4(p, 1.0f));
    }
    glm::vec3 worldDirectionFromView(const glm::vec3& d) const {
        return glm::transpose(view.viewFromWorldNormal) * d;
    }
};

scenes::Scene proceduralScene(const char* name, int lightCount,
                              std::map<std::string, std::string> options = {}) {
    scenes::SceneRequest request;
    request.lightCount = lightCount;
    request.seed = 7;
    request.options = std::move(options);
    return scenes::buildProceduralScene(name, request);
}

// Shades with `stage` and checks the image against brute and the counts against the oracle.
void expectMatchesBrute(const TestScene& f, const std::string& stage, const std::string& where) {
    lighting::StageResult result;
    lighting::makeStage(stage)->shade(f.inputs, result);
    float peak = 0.0f;
    for (int ch = 0; ch < 3; ++ch)
        for (float v : f.brute.radiance[ch])
            peak = std::max(peak, v);
    int imageFailures = 0, dropped = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        for (int ch = 0; ch < 3; ++ch) {
            const float difference =
                std::abs(result.radiance[ch][pixel] - f.brute.radiance[ch][pixel]);
            if (!(difference <= 1e-5f * peak) && imageFailures++ < 3)
                ADD_FAILURE() << stage << " " << where << ": pixel (" << pixel % kWidth << ", "
                              << pixel / kWidth << ") differs by " << difference << " (peak "
                              << peak << ")";
        }
        if (result.lightsEvaluated[pixel] < f.oracle[pixel] && dropped++ < 3)
            ADD_FAILURE() << stage << " " << where << ": pixel (" << pixel % kWidth << ", "
                          << pixel / kWidth << ") evaluated " << result.lightsEvaluated[pixel]
                          << " < oracle " << f.oracle[pixel];
    }
    EXPECT_EQ(imageFailures, 0) << stage << " " << where;
    EXPECT_EQ(dropped, 0) << stage << " " << where;
}

const std::vector<std::string> kVariants = {
    "deferred",
    "deferred:volume=rect",
    "deferred:stencil=1",
    "deferred:spot=sphere",
    "deferred:vfc=0",
    "deferred:volume=rect,vfc=0",
    "light-indexed",
    "light-indexed:max=1",
    "light-indexed:stencil=1,max=4",
    "light-indexed:volume=rect",
};

TEST(LightVolumes, OptionVariantsMatchBrute) {
    struct Case {
        const char* scene;
        int lights;
        std::map<std::string, std::string> options;
    };
    const Case cases[] = {
        {"atrium", 300, {}}, {"wall", 400, {{"behind", "200"}}}, {"spheres", 200, {}}};
    for (const Case& c : cases) {
        const TestScene f(proceduralScene(c.scene, c.lights, c.options));
        for (const std::string& stage : kVariants)
            expectMatchesBrute(f, stage, c.scene);
    }
}

TEST(LightVolumes, LightIndexedOverflowIsReportedAndConservative) {
    const TestScene f(proceduralScene("atrium", 300));
    lighting::StageResult result;
    lighting::makeStage("light-indexed:max=1")->shade(f.inputs, result);
    ASSERT_TRUE(result.parameters.count("overflow_pixels"));
    EXPECT_GT(std::stoull(result.parameters.at("overflow_pixels")), 0u);
    // Overflowed pixels are shaded with their 16x16 tile's conservative list: more than the
    // one-entry capacity, far fewer than every light (exactness: OptionVariantsMatchBrute).
    const uint32_t most =
        *std::max_element(result.lightsEvaluated.begin(), result.lightsEvaluated.end());
    EXPECT_GT(most, 1u);
    EXPECT_LT(most, uint32_t(f.lights.size()) / 2);
}

TEST(LightVolumes, ProxyCircumscribesTheUnitSphereAndIsClosed) {
    const lighting::ProxyMesh& proxy = lighting::unitProxySphere();
    ASSERT_EQ(proxy.positions.size(), 42u);
    ASSERT_EQ(proxy.indices.size(), 80u * 3);
    std::map<std::pair<uint32_t, uint32_t>, int> directedEdges;
    std::vector<glm::vec4> planes; // outward unit normal, distance from the origin
    for (size_t t = 0; t < proxy.indices.size(); t += 3) {
        const uint32_t i[3] = {proxy.indices[t], proxy.indices[t + 1], proxy.indices[t + 2]};
        const glm::dvec3 a(proxy.positions[i[0]]), b(proxy.positions[i[1]]),
            c(proxy.positions[i[2]]);
        const glm::dvec3 normal = glm::normalize(glm::cross(b - a, c - a));
        const double distance = glm::dot(normal, a);
        EXPECT_GE(distance, 1.0) << "face " << t / 3 << " cuts into the unit sphere";
        EXPECT_GT(glm::dot(normal, a + b + c), 0.0)
            << "face " << t / 3 << " is not counter-clockwise outside";
        planes.emplace_back(glm::vec3(normal), float(distance));
        for (int e = 0; e < 3; ++e)
            ++directedEdges[{i[e], i[(e + 1) % 3]}];
    }
    // Closed and consistently wound: every directed edge once, and its reverse once.
    for (const auto& [edge, count] : directedEdges) {
        EXPECT_EQ(count, 1);
        EXPECT_EQ(directedEdges.count({edge.second, edge.first}), 1u);
    }
    for (const glm::vec3& p : proxy.positions)
        EXPECT_LE(glm::length(p), proxy.circumradius);
    // Random points of the unit sphere are inside every face plane.
    std::mt19937 random(1);
    std::normal_distribution<float> gaussian;
    for (int s = 0; s < 20000; ++s) {
        const glm::vec3 p =
            glm::normalize(glm::vec3(gaussian(random), gaussian(random), gaussian(random)));
        for (const glm::vec4& plane : planes)
            ASSERT_LE(glm::dot(glm::vec3(plane), p), plane.w);
    }
}

// Adds hard lights to `f`'s scene in view space: camera inside a volume, a volume crossing the
// near plane, range zero, a volume covering the whole screen and crossing the far plane, lights
// behind the camera, and lights just touching (or just reaching through) visible surfaces.
std::vector<scenes::Light> hardLights(const TestScene& f) {
    std::vector<scenes::Light> lights = f.scene.lights;
    auto point = [&](glm::vec3 positionView, float range, glm::vec3 color = glm::vec3(1.0f)) {
        scenes::Light light;
        light.type = scenes::LightType::Point;
        light.positionWorld = f.worldFromView(positionView);
        light.rangeMetres = range;
        light.color = color;
        light.intensity = 2.0f;
        lights.push_back(light);
    };
    const float nearMetres = f.view.nearMetres;
    point({0.0f, 0.0f, -0.5f}, 4.0f);                     // camera inside the volume
    point({0.2f, 0.1f, -nearMetres}, 1.5f);               // centred on the near plane
    point({-0.3f, 0.0f, 0.05f}, 0.8f);                    // just behind the eye, reaching in front
    point({0.0f, 0.0f, 3.0f}, 2.0f);                      // wholly behind the camera
    point({0.0f, 0.0f, 1.0f}, 50.0f);                     // behind, covering everything in view
    point({0.0f, 0.0f, -20.0f}, 2.0f * f.view.farMetres); // whole screen, beyond the far plane
    // Surfaces: range zero on a surface, and spheres barely touching or reaching through it.
    int placed = 0;
    for (int y = 5; y < kHeight; y += 23)
        for (int x = 7; x < kWidth; x += 31) {
            const size_t pixel = size_t(y) * kWidth + x;
            if (!f.gbuffer->covered(pixel))
                continue;
            const gbuffer::Surface s = f.gbuffer->decode(x, y);
            const float distance = glm::length(s.positionView);
            const float range = 0.02f * distance + 0.05f;
            switch (placed++ % 4) {
            case 0:
                point(s.positionView, 0.0f);
                break;
            case 1:
                point(s.positionView + s.normalView * (range * 0.999f), range);
                break;
            case 2:
                point(s.positionView - s.normalView * (range * 0.999f), range);
                break;
            default: {
                // Grazing: along the surface, slightly above it.
                const glm::vec3 along =
                    glm::normalize(glm::cross(s.normalView, glm::vec3(0.0f, 1.0f, 0.3f)));
                point(s.positionView + along * (range * 0.9f) + s.normalView * (range * 0.05f),
                      range);
            }
            }
        }
    // A spot light inside the camera's volume, pointing forward.
    scenes::Light spot;
    spot.type = scenes::LightType::Spot;
    spot.positionWorld = f.worldFromView({0.1f, -0.1f, -0.3f});
    spot.directionWorld = f.worldDirectionFromView({0.0f, 0.0f, -1.0f});
    spot.rangeMetres = 30.0f;
    lights.push_back(spot);
    return lights;
}

TEST(LightVolumes, HardCasesMatchBrute) {
    for (const char* sceneName : {"atrium", "spheres", "wall"}) {
        TestScene f(proceduralScene(sceneName, 20));
        f.setLights(hardLights(f));
        for (const std::string& stage : kVariants)
            expectMatchesBrute(f, stage, std::string("hard ") + sceneName);
    }
}

TEST(LightVolumes, StandardDepthMatchesBrute) {
    TestScene f(proceduralScene("atrium", 200), gbuffer::DepthConvention::Standard);
    ASSERT_FALSE(f.view.reversedZ());
    f.setLights(hardLights(f));
    for (const std::string& stage : kVariants)
        expectMatchesBrute(f, stage, "standard depth");
}

TEST(LightVolumes, SameResultForOneAndTwoThreads) {
    const TestScene f(proceduralScene("atrium", 300));
    for (const char* stage : {"deferred", "deferred:stencil=1", "light-indexed:max=2"}) {
        lighting::StageResult one, two;
        tbb::task_arena(1).execute([&] { lighting::makeStage(stage)->shade(f.inputs, one); });
        tbb::task_arena(2).execute([&] { lighting::makeStage(stage)->shade(f.inputs, two); });
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_EQ(one.radiance[ch], two.radiance[ch]) << stage;
        EXPECT_EQ(one.lightsEvaluated, two.lightsEvaluated) << stage;
    }
}

TEST(LightVolumes, DeferredCullsOnAtrium) {
    const TestScene f(proceduralScene("atrium", 300));
    for (const char* stage : {"deferred", "deferred:stencil=1", "light-indexed"}) {
        lighting::StageResult result;
        lighting::makeStage(stage)->shade(f.inputs, result);
        uint64_t evaluated = 0, brute = 0;
        for (uint32_t n : result.lightsEvaluated)
            evaluated += n;
        for (uint32_t n : f.brute.lightsEvaluated)
            brute += n;
        EXPECT_LT(evaluated * 4, brute)
            << stage << " evaluated " << evaluated << " of brute's " << brute;
    }
}

// The cone proxy: closed, wound counter-clockwise outside, and every point of the lit region
// (distance < range, angle < outer) is at least the margin inside every face plane; lights the
// pyramid does not suit get none.
TEST(LightVolumes, ConeProxyCircumscribesTheLitRegionAndIsClosed) {
    const std::vector<uint32_t>& indices = lighting::coneProxyIndices();
    ASSERT_EQ(indices.size(), size_t(2 * lighting::kConeProxySides - 2) * 3);
    std::map<std::pair<uint32_t, uint32_t>, int> directedEdges;
    for (size_t t = 0; t < indices.size(); t += 3)
        for (int e = 0; e < 3; ++e)
            ++directedEdges[{indices[t + e], indices[t + (e + 1) % 3]}];
    for (const auto& [edge, count] : directedEdges) {
        EXPECT_EQ(count, 1);
        EXPECT_EQ(directedEdges.count({edge.second, edge.first}), 1u);
    }
    std::mt19937 random(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::normal_distribution<float> gaussian;
    const float halfAnglesDegrees[] = {0.05f, 0.5f, 5.0f, 30.0f, 45.0f, 60.0f, 75.0f, 79.0f};
    for (int s = 0; s < 64; ++s) {
        lighting::LightSphere light;
        light.spot = true;
        light.positionView = {gaussian(random) * 10.0f, gaussian(random) * 10.0f,
                              gaussian(random) * 10.0f};
        light.axisView =
            glm::normalize(glm::vec3(gaussian(random), gaussian(random), gaussian(random)));
        const float halfAngle = glm::radians(halfAnglesDegrees[s % std::size(halfAnglesDegrees)]);
        light.spotOuterCos = std::cos(halfAngle);
        light.rangeMetres = 0.01f + 20.0f * unit(random);
        const float margin = s % 2 ? 0.0f : 0.01f * light.rangeMetres;
        const std::optional<lighting::ConeProxy> cone = lighting::coneProxy(light, margin);
        ASSERT_TRUE(cone.has_value()) << "cone " << s;
        const glm::dvec3 interior =
            (glm::dvec3(cone->positionsView[0]) + glm::dvec3(cone->positionsView[1]) +
             glm::dvec3(cone->positionsView[1 + lighting::kConeProxySides / 2])) /
            3.0;
        std::vector<glm::dvec4> planes; // outward unit normal, offset
        for (size_t t = 0; t < indices.size(); t += 3) {
            const glm::dvec3 a(cone->positionsView[indices[t]]),
                b(cone->positionsView[indices[t + 1]]), c(cone->positionsView[indices[t + 2]]);
            const glm::dvec3 normal = glm::normalize(glm::cross(b - a, c - a));
            ASSERT_GT(glm::dot(normal, a - interior), 0.0)
                << "cone " << s << " face " << t / 3 << " inward";
            planes.emplace_back(normal, glm::dot(normal, a));
        }
        // Lit points, biased to the rim, the tip and the cap where the proxy is tightest.
        for (int p = 0; p < 4000; ++p) {
            const glm::dvec3 axis = glm::normalize(glm::dvec3(light.axisView));
            const glm::dvec3 side = glm::normalize(
                glm::cross(axis, glm::dvec3(gaussian(random), gaussian(random), gaussian(random))));
            const double angle = halfAngle * (p % 3 ? 0.99999 : double(unit(random)));
            const double distance =
                light.rangeMetres * (p % 5 ? 0.99999 : std::pow(double(unit(random)), 3.0));
            const glm::dvec3 point = glm::dvec3(light.positionView) +
                                     distance * (std::cos(angle) * axis + std::sin(angle) * side);
            for (const glm::dvec4& plane : planes)
                ASSERT_LE(glm::dot(glm::dvec3(plane), point), plane.w - margin * 0.999)
                    << "cone " << s << ": lit point outside a face (half-angle "
                    << glm::degrees(halfAngle) << ")";
        }
        // The pyramid is tight: its volume within 25% of the grown cone's for non-tiny cones.
        if (halfAngle > glm::radians(1.0f) && margin == 0.0f && light.rangeMetres > 1.0f) {
            const double r = light.rangeMetres, tanT = std::tan(double(halfAngle));
            EXPECT_LT(cone->volume, 1.25 * 3.14159265 * r * r * r * tanT * tanT / 3.0)
                << "cone " << s;
        }
    }
    lighting::LightSphere wide;
    wide.spot = true;
    wide.rangeMetres = 1.0f;
    wide.spotOuterCos = std::cos(glm::radians(80.5f));
    EXPECT_FALSE(lighting::coneProxy(wide, 0.0f).has_value());
    wide.spot = false;
    wide.spotOuterCos = 0.9f;
    EXPECT_FALSE(lighting::coneProxy(wide, 0.0f).has_value());
}

// Hard spot lights in view space: the camera inside a cone, apexes just in front of, on and just
// behind the near plane, a spot pointing at the camera, narrow (0.5 to 5 degrees) and wide
// (75 degrees) cones into the scene, and surfaces grazed by the cone's edge just inside and just
// outside, or touched by the rim at the range.
std::vector<scenes::Light> hardSpots(const TestScene& f) {
    std::vector<scenes::Light> lights = f.scene.lights;
    auto spot = [&](glm::vec3 positionView, glm::vec3 axisView, float range, float outerDegrees) {
        scenes::Light light;
        light.type = scenes::LightType::Spot;
        light.positionWorld = f.worldFromView(positionView);
        light.directionWorld = f.worldDirectionFromView(glm::normalize(axisView));
        light.rangeMetres = range;
        light.spotOuterCos = std::cos(glm::radians(outerDegrees));
        light.spotInnerCos = std::cos(glm::radians(0.7f * outerDegrees));
        light.intensity = 2.0f;
        lights.push_back(light);
    };
    const float nearZ = -f.view.nearMetres;
    // Camera inside: apex behind the eye (30 degrees), and a wide cone (75) around the eye.
    spot({0.0f, 0.0f, 2.0f}, {0.0f, 0.0f, -1.0f}, 40.0f, 30.0f);
    spot({0.2f, -0.1f, 0.5f}, {0.1f, 0.0f, -1.0f}, 25.0f, 75.0f);
    // Apex just in front of the near plane (forward and aside), just behind it, and on it.
    spot({0.1f, 0.05f, nearZ - 1e-3f}, {0.0f, 0.0f, -1.0f}, 30.0f, 40.0f);
    spot({0.3f, 0.0f, nearZ - 1e-3f}, {1.0f, 0.0f, -0.2f}, 20.0f, 20.0f);
    spot({-0.1f, 0.0f, nearZ + 1e-3f}, {0.1f, -0.2f, -1.0f}, 30.0f, 20.0f);
    spot({0.0f, 0.1f, nearZ}, {-0.2f, -0.1f, -1.0f}, 30.0f, 10.0f);
    // Pointing at the camera: reaching past it, and stopping just short of the near plane.
    spot({0.0f, 0.0f, -8.0f}, {0.0f, 0.0f, 1.0f}, 12.0f, 20.0f);
    spot({0.5f, 0.0f, -3.0f}, {-0.1f, 0.0f, 1.0f}, 3.0f + nearZ - 1e-3f, 45.0f);
    // Narrow (5 and 0.5 degrees) and wide (75) cones into the scene, one past the far plane.
    spot({0.0f, 1.0f, -2.0f}, {0.0f, -0.3f, -1.0f}, 60.0f, 5.0f);
    spot({-1.0f, 0.5f, -2.0f}, {0.1f, -0.2f, -1.0f}, 60.0f, 0.5f);
    spot({1.0f, 1.5f, -4.0f}, {-0.1f, -0.5f, -1.0f}, 40.0f, 75.0f);
    spot({0.0f, 0.0f, -20.0f}, {0.0f, 0.0f, -1.0f}, 2.0f * f.view.farMetres, 15.0f);
    int placed = 0;
    const float angles[] = {5.0f, 30.0f, 55.0f, 75.0f, 45.0f};
    for (int y = 9; y < kHeight; y += 19)
        for (int x = 11; x < kWidth; x += 27) {
            const size_t pixel = size_t(y) * kWidth + x;
            if (!f.gbuffer->covered(pixel))
                continue;
            const gbuffer::Surface s = f.gbuffer->decode(x, y);
            const float range = 0.05f * glm::length(s.positionView) + 0.2f;
            const glm::vec3 n = s.normalView;
            const glm::vec3 t = glm::normalize(glm::cross(n, glm::vec3(0.3f, 1.0f, 0.2f)));
            const float theta = glm::radians(angles[placed % std::size(angles)]);
            const int kind = placed++ % 4;
            if (kind < 3) {
                // Grazing: the cone's lower edge runs along the surface, dipping into it by
                // 0.01 rad (kind 0), parallel (1), or rising away (2), from just above it.
                const float dip = 0.01f * float(kind - 1);
                const glm::vec3 axis = std::cos(theta + dip) * t + std::sin(theta + dip) * n;
                spot(s.positionView - t * (0.5f * range) + n * (0.002f * range), axis, range,
                     glm::degrees(theta));
            } else {
                // The rim: the surface point at 0.999 of the range and of the half-angle.
                const float angle = 0.999f * theta;
                spot(s.positionView + n * (0.999f * range),
                     -n * std::cos(angle) + t * std::sin(angle), range, glm::degrees(theta));
            }
        }
    return lights;
}

const std::vector<std::string> kSpotVariants = {
    "deferred",
    "deferred:stencil=1",
    "deferred:spot=sphere",
    "deferred:stencil=1,vfc=0",
    "light-indexed",
    "light-indexed:stencil=1,max=4",
};

TEST(LightVolumes, HardSpotsMatchBrute) {
    for (const gbuffer::DepthConvention depth :
         {gbuffer::DepthConvention::Reversed, gbuffer::DepthConvention::Standard})
        for (const char* sceneName : {"atrium", "spheres", "wall"}) {
            TestScene f(proceduralScene(sceneName, 20), depth);
            f.setLights(hardSpots(f));
            const std::string where =
                std::string("hard spots ") + sceneName +
                (depth == gbuffer::DepthConvention::Standard ? " standard" : " reversed");
            for (const std::string& stage : kSpotVariants)
                expectMatchesBrute(f, stage, where);
            // The cone path is the one under test.
            lighting::StageResult result;
            lighting::makeStage("deferred:stencil=1")->shade(f.inputs, result);
            EXPECT_GT(std::stoull(result.parameters.at("cone_proxies")), 20u) << where;
        }
}

// Narrow spots on atrium: the cone proxy evaluates markedly fewer lights than the sphere proxy,
// and the images agree (both are checked against brute above).
TEST(LightVolumes, ConeProxiesCullMoreThanSpheresForNarrowSpots) {
    scenes::Scene scene = proceduralScene("atrium", 300);
    int index = 0;
    for (scenes::Light& light : scene.lights) {
        if (light.type != scenes::LightType::Point)
            continue;
        const float a = 2.399963f * float(index);
        light.type = scenes::LightType::Spot;
        light.directionWorld = glm::normalize(glm::vec3(std::cos(a), -0.5f, std::sin(a)));
        const float outer = glm::radians(5.0f + 25.0f * float(index % 6) / 5.0f); // 5..30 degrees
        light.spotOuterCos = std::cos(outer);
        light.spotInnerCos = std::cos(0.8f * outer);
        light.rangeMetres *= 2.0f;
        ++index;
    }
    const TestScene f(std::move(scene));
    for (const char* stencil : {"0", "1"}) {
        uint64_t evaluated[2] = {0, 0};
        const char* proxies[2] = {"cone", "sphere"};
        for (int k = 0; k < 2; ++k) {
            lighting::StageResult result;
            lighting::makeStage(std::string("deferred:stencil=") + stencil + ",spot=" + proxies[k])
                ->shade(f.inputs, result);
            EXPECT_EQ(result.parameters.at("spot"), proxies[k]);
            for (uint32_t n : result.lightsEvaluated)
                evaluated[k] += n;
            if (k == 0)
                EXPECT_GT(std::stoull(result.parameters.at("cone_proxies")), 200u);
            else
                EXPECT_EQ(result.parameters.at("cone_proxies"), "0");
        }
        uint64_t oracle = 0;
        for (uint32_t n : f.oracle)
            oracle += n;
        std::printf("narrow spots, stencil=%s: evaluated cone %llu, sphere %llu, oracle %llu\n",
                    stencil, (unsigned long long)evaluated[0], (unsigned long long)evaluated[1],
                    (unsigned long long)oracle);
        EXPECT_LT(double(evaluated[0]), 0.7 * double(evaluated[1])) << "stencil=" << stencil;
    }
}

TEST(LightVolumes, SpotOptionIsForSphereVolumesOnly) {
    EXPECT_THROW(lighting::makeStage("deferred:volume=rect,spot=cone"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("deferred:spot=pyramid"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("light-indexed:volume=rect,spot=sphere"),
                 lighting::StageError);
}

TEST(LightVolumes, FrustumCullingAndScreenRectAreConservative) {
    const TestScene f(proceduralScene("atrium", 8));
    lighting::LightVolumeRasterizer volumes(*f.gbuffer, lighting::VolumeShape::Rect, false,
                                            lighting::SpotProxy::Cone);
    std::mt19937 random(5);
    std::uniform_real_distribution<float> coordinate(-30.0f, 30.0f), radius(0.01f, 10.0f);
    int visibleCount = 0;
    for (int s = 0; s < 800; ++s) {
        lighting::LightSphere sphere;
        sphere.centreView = {coordinate(random), coordinate(random), coordinate(random) - 20.0f};
        sphere.radius = radius(random);
        // Brute force: any pixel-centre ray point within [near, far] inside the sphere.
        const lighting::LightVolumeRasterizer::PixelRect rect = volumes.screenRect(sphere);
        bool anyInside = false;
        for (int y = 0; y < kHeight; y += 1)
            for (int x = 0; x < kWidth; x += 1) {
                const glm::vec2 ndc = f.view.ndcOfPixel(x, y);
                const glm::vec4 h = f.view.viewFromClip * glm::vec4(ndc, 0.5f, 1.0f);
                const glm::vec3 ray = glm::normalize(glm::vec3(h) / h.w);
                // Closest approach of the ray to the centre, clamped to the view depth range.
                float t = glm::dot(sphere.centreView, ray);
                const float tNear = f.view.nearMetres / -ray.z, tFar = f.view.farMetres / -ray.z;
                t = std::clamp(t, tNear, tFar);
                if (glm::length(ray * t - sphere.centreView) < sphere.radius) {
                    anyInside = true;
                    ASSERT_TRUE(x >= rect.minX && x <= rect.maxX && y >= rect.minY &&
                                y <= rect.maxY)
                        << "pixel (" << x << ", " << y << ") outside the rectangle of sphere " << s;
                }
            }
        if (anyInside) {
            ++visibleCount;
            ASSERT_TRUE(lighting::ViewFrustum(f.view).mayTouch(sphere))
                << "sphere " << s << " culled but visible";
        }
    }
    EXPECT_GT(visibleCount, 30);
}

} // namespace

// ---------------------------------------------------------------------------------------------
// `deferred` on the shared light kernel (DeferredStage.cpp): each light's volume pixels shaded a
// 4x4 packet at a time on the requested ISA, one light per kernel call.

namespace deferredkernel {

using lighting::kernel::KernelIsa;

// 203x117: packets and SIMT warps cut by the right and bottom edges, a partial raster tile.
constexpr int kOddWidth = 203;
constexpr int kOddHeight = 117;

const lighting::PreparedScene& oddAtrium() {
    static const std::unique_ptr<lighting::PreparedScene> frame = [] {
        scenes::Scene scene = proceduralScene("atrium", 150);
        // A few spots, so the cone proxies and the kernel's cone test are in the frame too.
        for (size_t i = 0; i < scene.lights.size(); i += 5)
            if (scene.lights[i].type == scenes::LightType::Point) {
                const float a = 2.4f * float(i);
                scene.lights[i].type = scenes::LightType::Spot;
                scene.lights[i].directionWorld =
                    glm::normalize(glm::vec3(std::cos(a), -0.6f, std::sin(a)));
                scene.lights[i].spotOuterCos = std::cos(glm::radians(35.0f));
                scene.lights[i].spotInnerCos = std::cos(glm::radians(25.0f));
                scene.lights[i].rangeMetres *= 1.5f;
            }
        return std::make_unique<lighting::PreparedScene>(std::move(scene), kOddWidth, kOddHeight);
    }();
    return *frame;
}

lighting::StageResult shadeOn(const std::string& stage, lighting::StageInputs inputs,
                              const KernelIsa& isa, int threads, int warpLanes = 32,
                              bool traced = false) {
    inputs.isa = isa;
    inputs.simtWarpLanes = warpLanes;
    lighting::StageResult result;
    result.traceLights = traced;
    tbb::task_arena(threads).execute([&] { lighting::makeStage(stage)->shade(inputs, result); });
    return result;
}

bool sameImage(const lighting::StageResult& a, const lighting::StageResult& b) {
    for (int c = 0; c < 3; ++c)
        if (a.radiance[c].size() != b.radiance[c].size() ||
            std::memcmp(a.radiance[c].data(), b.radiance[c].data(),
                        a.radiance[c].size() * sizeof(float)) != 0)
            return false;
    return true;
}

const char* const kDeferredVariants[] = {"deferred",           "deferred:volume=rect",
                                         "deferred:stencil=1", "deferred:spot=sphere",
                                         "deferred:vfc=0",     "deferred:volume=rect,vfc=0"};

} // namespace deferredkernel

// Every option variant, on the scalar path and the widest vector target: the ISA that ran is
// recorded, the image is bitwise brute's on the same ISA, the counts do not depend on the ISA,
// and 1 and 7 threads give bitwise the same image, counts and kernel/SIMT counters.
TEST(LightVolumes, DeferredOnTheKernelIsBitwiseBruteOnEveryIsa) {
    using namespace deferredkernel;
    const lighting::PreparedScene& frame = oddAtrium();
    for (const KernelIsa& isa : {KernelIsa::scalar(), KernelIsa::best()}) {
        const lighting::StageResult brute = shadeOn("brute", frame.inputs, isa, 2);
        ASSERT_EQ(brute.parameters.at("isa"), isa.name());
        for (const char* stage : kDeferredVariants) {
            const lighting::StageResult one = shadeOn(stage, frame.inputs, isa, 1);
            EXPECT_EQ(one.parameters.at("isa"), isa.name()) << stage;
            EXPECT_TRUE(sameImage(one, brute)) << stage << " on " << isa.name();
            const lighting::StageResult scalar =
                shadeOn(stage, frame.inputs, KernelIsa::scalar(), 2);
            EXPECT_EQ(one.lightsEvaluated, scalar.lightsEvaluated) << stage << " " << isa.name();
            const lighting::StageResult seven = shadeOn(stage, frame.inputs, isa, 7);
            EXPECT_TRUE(sameImage(one, seven)) << stage << " " << isa.name() << " 1 vs 7 threads";
            EXPECT_EQ(one.lightsEvaluated, seven.lightsEvaluated) << stage;
            EXPECT_EQ(one.parameters, seven.parameters) << stage;
        }
    }
}

// A layout the packet decoder refuses (octahedral normal codes) is gathered pixel by pixel and
// shaded on the kernel, as accumulateLights does: it says the ISA asked for and
// gbuffer_decode=per-pixel, and the image is brute's bitwise.
TEST(LightVolumes, DeferredGathersLayoutsThePacketDecoderRefuses) {
    using namespace deferredkernel;
    gbuffer::GBufferLayout layout = gbuffer::GBufferLayout::reference();
    layout.normals = gbuffer::NormalCodecSpec::parse("octahedral:16");
    layout.name = "octahedral-test";
    const lighting::PreparedScene frame(proceduralScene("atrium", 100), 96, 64, false, layout);
    const lighting::StageResult brute = shadeOn("brute", frame.inputs, KernelIsa::best(), 2);
    ASSERT_EQ(brute.parameters.at("isa"), KernelIsa::best().name());
    for (const char* stage : {"deferred", "deferred:stencil=1"}) {
        const lighting::StageResult result = shadeOn(stage, frame.inputs, KernelIsa::best(), 2);
        EXPECT_EQ(result.parameters.at("isa"), KernelIsa::best().name()) << stage;
        EXPECT_EQ(result.parameters.at("gbuffer_decode"), "per-pixel") << stage;
        EXPECT_GT(std::stoull(result.parameters.at("packet_groups")), 0u) << stage;
        EXPECT_TRUE(sameImage(result, brute)) << stage;
    }
}

// The SIMT model for deferred: a warp pays warpLanes slots for each light whose volume holds any
// of its pixels, i.e. for each light in the union of its pixels' traced lights (the same rule as
// accumulateLights'); recomputed here from the light trace for 8x4 and 8x8 warps, and below
// brute's (every light in every warp with a covered pixel).
TEST(LightVolumes, DeferredSimtLaneSlotsAreTheWarpsInEachVolume) {
    using namespace deferredkernel;
    const lighting::PreparedScene& frame = oddAtrium();
    for (int warpLanes : {32, 64})
        for (const char* stage : {"deferred", "deferred:volume=rect", "deferred:stencil=1"}) {
            const lighting::StageResult result =
                shadeOn(stage, frame.inputs, KernelIsa::best(), 2, warpLanes, true);
            const int warpHeight = warpLanes / 8;
            uint64_t expected = 0;
            std::vector<uint32_t> lights;
            for (int wy = 0; wy < kOddHeight; wy += warpHeight)
                for (int wx = 0; wx < kOddWidth; wx += 8) {
                    lights.clear();
                    for (int y = wy; y < std::min(kOddHeight, wy + warpHeight); ++y)
                        for (int x = wx; x < std::min(kOddWidth, wx + 8); ++x) {
                            const auto& trace = result.lightTrace[size_t(y) * kOddWidth + x];
                            lights.insert(lights.end(), trace.begin(), trace.end());
                        }
                    std::sort(lights.begin(), lights.end());
                    expected +=
                        uint64_t(warpLanes) *
                        uint64_t(std::unique(lights.begin(), lights.end()) - lights.begin());
                }
            EXPECT_EQ(std::stoull(result.parameters.at("simt_lane_slots")), expected)
                << stage << " warp " << warpLanes;
            EXPECT_EQ(result.parameters.at("simt_warp"), std::to_string(warpLanes));
            const lighting::StageResult brute =
                shadeOn("brute", frame.inputs, KernelIsa::best(), 2, warpLanes);
            EXPECT_LT(expected, std::stoull(brute.parameters.at("simt_lane_slots"))) << stage;
        }
}
