// Tests of the JSON scene format (scenes/README.md): objects placed by transforms, cameras,
// explicit lights and the light generator, checked against the same scenes built directly
// (loadGltf, buildProceduralScene, scatterPointLights); and strictness: unknown keys, wrong
// types and bad values are SceneErrors naming the file and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scenes/SceneLoader.h"
#include "scenes/Viewpoints.h"
#include "scenes/procedural/LightGenerator.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using scenes::Scene;
using scenes::SceneError;

const fs::path kSuzanne = fs::path(TESTBED_GLTF_DIR) / "Suzanne" / "Suzanne.gltf";

// A fresh directory per test, named after it: a rerun replaces the previous run's files (left
// in place as evidence when a test fails) instead of accumulating them.
fs::path testDirectory() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path directory =
        fs::path(::testing::TempDir()) /
        (std::string("json_scene_test.") + test->test_suite_name() + "." + test->name());
    fs::remove_all(directory);
    fs::create_directories(directory);
    return directory;
}

fs::path writeScene(const json& document, const std::string& name = "scene.json") {
    const fs::path path = testDirectory() / name;
    std::ofstream(path) << document.dump(2);
    return path;
}

Scene loadJson(const json& document, const scenes::SceneRequest& request = {}) {
    return scenes::loadJsonScene(writeScene(document), request);
}

// Loading must throw one SceneError naming the file and containing every one of `details`.
void expectJsonError(const json& document, std::initializer_list<std::string> details,
                     const scenes::SceneRequest& request = {}) {
    const fs::path path = writeScene(document, "broken.json");
    try {
        scenes::loadJsonScene(path, request);
        ADD_FAILURE() << "no SceneError for " << document.dump();
    } catch (const SceneError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find(path.string()), std::string::npos) << message;
        for (const std::string& detail : details)
            EXPECT_NE(message.find(detail), std::string::npos)
                << "'" << message << "' does not mention '" << detail << "'";
    }
}

void expectNear(const glm::vec3& actual, const glm::vec3& expected, float tolerance = 1e-5f) {
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

scenes::Aabb instanceBounds(const Scene& scene, const scenes::Instance& instance) {
    scenes::Aabb bounds;
    for (const glm::vec3& p : scene.meshes[instance.mesh].positions)
        bounds.extend(glm::vec3(instance.worldFromObject * glm::vec4(p, 1.0f)));
    return bounds;
}

// The smallest complete scene: one procedural object.
json spheresOnly() {
    return {{"objects", {{{"procedural", "spheres"}}}}};
}

TEST(JsonScene, PlacesSuzanneAndSpheresWithCameraAndLights) {
    const json document = {
        {"name", "showcase"},
        {"camera",
         {{"position", {0, 2, 10}},
          {"target", {0, 1, 0}},
          {"fovYDegrees", 50},
          {"near", 0.05},
          {"far", 200}}},
        {"objects",
         {{{"gltf", kSuzanne.string()}, {"transform", {{"translate", {0, 1, 0}}, {"scale", 0.5}}}},
          {{"procedural", "spheres"},
           {"options", {{"segments", 16}}},
           {"transform", {{"rotateDegrees", {0, 90, 0}}}}}}},
        {"lights",
         {{{"type", "point"},
           {"position", {1, 2, 3}},
           {"range", 4},
           {"color", {1, 0.5, 0.25}},
           {"intensity", 2}},
          {{"type", "spot"},
           {"position", {0, 5, 0}},
           {"direction", {0, -2, 0}},
           {"range", 8},
           {"innerConeDegrees", 20},
           {"outerConeDegrees", 30}},
          {{"type", "directional"}, {"direction", {0, -1, -1}}},
          {{"type", "ambient"}, {"intensity", 0.1}}}}};
    const Scene scene = loadJson(document);

    scenes::SceneRequest sphereRequest;
    sphereRequest.options["segments"] = "16";
    const Scene spheres = scenes::buildProceduralScene("spheres", sphereRequest);
    const Scene suzanne = scenes::loadGltf(kSuzanne);
    EXPECT_EQ(scene.name, "showcase");
    EXPECT_EQ(scene.triangleCount(), suzanne.triangleCount() + spheres.triangleCount());
    EXPECT_EQ(scene.instances.size(), suzanne.instances.size() + spheres.instances.size());
    EXPECT_EQ(scene.textures.size(), suzanne.textures.size() + spheres.textures.size());

    // Suzanne comes first: scaled by 0.5 about her origin, then lifted by 1.
    const scenes::Aabb original = instanceBounds(suzanne, suzanne.instances[0]);
    const scenes::Aabb placed = instanceBounds(scene, scene.instances[0]);
    expectNear(placed.min, 0.5f * original.min + glm::vec3(0, 1, 0));
    expectNear(placed.max, 0.5f * original.max + glm::vec3(0, 1, 0));
    // The spheres turned 90 degrees about +Y: an object-space +X lands on world -Z.
    const glm::mat4& turned = scene.instances[suzanne.instances.size()].worldFromObject;
    expectNear(glm::vec3(turned * glm::vec4(1, 0, 0, 0)), {0, 0, -1});
    // Materials of the second object are rebased past the first object's.
    const scenes::Mesh& firstSphereMesh = scene.meshes[suzanne.meshes.size()];
    EXPECT_EQ(firstSphereMesh.material, suzanne.materials.size() + spheres.meshes[0].material);

    ASSERT_EQ(scene.cameras.size(), 1u);
    const scenes::Camera& camera = scene.cameras[0];
    expectNear(camera.positionWorld, {0, 2, 10});
    expectNear(camera.forwardWorld, glm::normalize(glm::vec3(0, -1, -10)));
    EXPECT_FLOAT_EQ(camera.verticalFovRadians, glm::radians(50.0f));
    EXPECT_FLOAT_EQ(camera.nearMetres, 0.05f);
    EXPECT_FLOAT_EQ(camera.farMetres, 200.0f);

    ASSERT_EQ(scene.lights.size(), 4u); // spheres adds no lights with its default options
    const scenes::Light& point = scene.lights[0];
    EXPECT_EQ(point.type, scenes::LightType::Point);
    expectNear(point.positionWorld, {1, 2, 3});
    expectNear(point.color, {1, 0.5f, 0.25f});
    EXPECT_FLOAT_EQ(point.intensity, 2.0f);
    EXPECT_FLOAT_EQ(point.rangeMetres, 4.0f);
    const scenes::Light& spot = scene.lights[1];
    EXPECT_EQ(spot.type, scenes::LightType::Spot);
    expectNear(spot.directionWorld, {0, -1, 0});
    EXPECT_FLOAT_EQ(spot.spotInnerCos, std::cos(glm::radians(20.0f)));
    EXPECT_FLOAT_EQ(spot.spotOuterCos, std::cos(glm::radians(30.0f)));
    EXPECT_EQ(scene.lights[2].type, scenes::LightType::Directional);
    expectNear(scene.lights[2].directionWorld, glm::normalize(glm::vec3(0, -1, -1)));
    EXPECT_EQ(scene.lights[3].type, scenes::LightType::Ambient);
    EXPECT_FLOAT_EQ(scene.lights[3].intensity, 0.1f);
}

// "castsShadows" (issue 29): read per light, false when absent, an error on an ambient light
// (which never casts) and when not a boolean.
TEST(JsonScene, CastsShadowsIsReadPerLight) {
    json document = spheresOnly();
    document["lights"] = {
        {{"type", "point"}, {"position", {0, 1, 0}}, {"range", 2}, {"castsShadows", true}},
        {{"type", "directional"}, {"direction", {0, -1, 0}}},
        {{"type", "directional"}, {"direction", {0, -1, 0}}, {"castsShadows", false}}};
    const Scene scene = loadJson(document);
    ASSERT_EQ(scene.lights.size(), 3u);
    EXPECT_TRUE(scene.lights[0].castsShadows);
    EXPECT_FALSE(scene.lights[1].castsShadows);
    EXPECT_FALSE(scene.lights[2].castsShadows);

    json ambient = spheresOnly();
    ambient["lights"] = {{{"type", "ambient"}, {"castsShadows", true}}};
    expectJsonError(ambient, {"lights[0]", "unknown key 'castsShadows'"});
    json notBoolean = spheresOnly();
    notBoolean["lights"] = {
        {{"type", "point"}, {"position", {0, 1, 0}}, {"range", 2}, {"castsShadows", 1}}};
    expectJsonError(notBoolean, {"lights[0].castsShadows", "true or false"});
}

// A light's "shadow" (issue 29, per-light settings): every key read, absent keys left to the
// global settings; the CLI's ranges and names; an error without "castsShadows": true, on an
// ambient light, for an unknown key and for each malformed value, naming the field.
TEST(JsonScene, LightShadowSettingsAreReadPerLight) {
    auto point = [](json shadow, json casts = true) {
        json light = {{"type", "point"}, {"position", {0, 1, 0}}, {"range", 2}};
        if (!casts.is_null())
            light["castsShadows"] = casts;
        light["shadow"] = std::move(shadow);
        return light;
    };
    json document = spheresOnly();
    document["lights"] = {
        point({{"mapSize", 256}, {"bias", {0.01, 2.5}}, {"filter", "pcf5"}, {"normalOffset", 1}}),
        point({{"filter", "none"}}),
        {{"type", "directional"}, {"direction", {0, -1, 0}}, {"castsShadows", true}}};
    const Scene scene = loadJson(document);
    ASSERT_EQ(scene.lights.size(), 3u);
    const scenes::LightShadow& first = scene.lights[0].shadow;
    EXPECT_EQ(first.mapSize, 256);
    EXPECT_EQ(first.biasConstant, 0.01f);
    EXPECT_EQ(first.biasSlope, 2.5f);
    EXPECT_EQ(first.filter, scenes::ShadowFilter::Pcf5);
    EXPECT_EQ(first.normalOffset, 1.0f);
    const scenes::LightShadow& second = scene.lights[1].shadow;
    EXPECT_EQ(second.filter, scenes::ShadowFilter::None);
    EXPECT_FALSE(second.mapSize || second.biasConstant || second.biasSlope || second.normalOffset);
    EXPECT_FALSE(scene.lights[2].shadow.any());

    auto expectLightError = [&](const json& light, std::initializer_list<std::string> details) {
        json bad = spheresOnly();
        // json::array, not {light}: a braced list of one json is a copy under clang and an
        // array of one under GCC (CWG 2137), so the test would check different documents.
        bad["lights"] = json::array({light});
        expectJsonError(bad, details);
    };
    expectLightError(point({{"filter", "pcf3"}}, nullptr), {"lights[0].shadow", "castsShadows"});
    expectLightError(point({{"filter", "pcf3"}}, false), {"lights[0].shadow", "castsShadows"});
    expectLightError({{"type", "ambient"}, {"shadow", {{"filter", "pcf3"}}}},
                     {"lights[0]", "unknown key 'shadow'"});
    expectLightError(point({{"size", 256}}), {"lights[0].shadow", "unknown key 'size'"});
    expectLightError(point({{"mapSize", 8}}), {"lights[0].shadow.mapSize", "[16, 8192]"});
    expectLightError(point({{"mapSize", 100000}}), {"lights[0].shadow.mapSize", "[16, 8192]"});
    expectLightError(point({{"mapSize", 512.5}}), {"lights[0].shadow.mapSize", "integer"});
    expectLightError(point({{"bias", 0.01}}), {"lights[0].shadow.bias", "[constant, slope]"});
    expectLightError(point({{"bias", {0.01, -1}}}), {"lights[0].shadow.bias[1]", "[0, 100]"});
    expectLightError(point({{"filter", "pcf7"}}), {"lights[0].shadow.filter", "'pcf7'", "poisson"});
    expectLightError(point({{"normalOffset", "1"}}), {"lights[0].shadow.normalOffset", "number"});
    expectLightError(point("pcf3"), {"lights[0].shadow", "expected an object"});
}

TEST(JsonScene, RelativeGltfPathAndDefaultCamera) {
    const fs::path directory = testDirectory();
    const json document = {
        {"objects",
         {{{"gltf", fs::relative(kSuzanne, directory).string()},
           {"transform", {{"axisAngle", {{"axis", {0, 0, 1}}, {"degrees", 90}}}}}}}}};
    const fs::path path = directory / "relative.json";
    std::ofstream(path) << document.dump();
    const Scene scene = scenes::loadJsonScene(path, {});
    EXPECT_EQ(scene.name, "relative");
    EXPECT_EQ(scene.triangleCount(), 3936u);
    expectNear(glm::vec3(scene.instances[0].worldFromObject * glm::vec4(1, 0, 0, 0)), {0, 1, 0});
    // No camera in the file and no procedural object: a camera framing the bounds.
    ASSERT_EQ(scene.cameras.size(), 1u);
    EXPECT_EQ(scene.cameras[0].name, "default");
    EXPECT_TRUE(scene.lights.empty());
}

TEST(JsonScene, ModelPlacedTwiceIsStoredOnce) {
    const json document = {
        {"objects",
         {{{"gltf", kSuzanne.string()}},
          {{"gltf", kSuzanne.string()}, {"transform", {{"translate", {3, 0, 0}}}}}}}};
    const Scene scene = loadJson(document);
    const Scene suzanne = scenes::loadGltf(kSuzanne);
    EXPECT_EQ(scene.meshes.size(), suzanne.meshes.size());
    EXPECT_EQ(scene.textures.size(), suzanne.textures.size());
    ASSERT_EQ(scene.instances.size(), 2 * suzanne.instances.size());
    EXPECT_EQ(scene.triangleCount(), 2 * suzanne.triangleCount());
    expectNear(glm::vec3(scene.instances[1].worldFromObject[3]), {3, 0, 0});
}

TEST(JsonScene, ProceduralCameraMovesWithItsObject) {
    json document = spheresOnly();
    document["objects"][0]["transform"] = {{"translate", {10, 0, 0}}};
    const Scene scene = loadJson(document);
    const Scene spheres = scenes::buildProceduralScene("spheres", {});
    ASSERT_EQ(scene.cameras.size(), 1u);
    expectNear(scene.cameras[0].positionWorld,
               spheres.cameras[0].positionWorld + glm::vec3(10, 0, 0));
    expectNear(scene.cameras[0].forwardWorld, spheres.cameras[0].forwardWorld);
}

TEST(JsonScene, ProceduralOptionsReachTheBuilderAndItsLightsAreKept) {
    json document = spheresOnly();
    document["objects"][0]["options"] = {{"sun", true}, {"ambient", 1}};
    scenes::SceneRequest request;
    request.options = {{"sun", "1"}, {"ambient", "1"}};
    const Scene built = scenes::buildProceduralScene("spheres", request);
    const Scene scene = loadJson(document);
    ASSERT_EQ(scene.lights.size(), built.lights.size());
    EXPECT_FALSE(scene.lights.empty());
}

TEST(JsonScene, LightGeneratorMatchesScatterPointLights) {
    json document = spheresOnly();
    document["lightGenerator"] = {
        {"count", 5},      {"seed", 3},    {"regionMin", {-1, 0, -1}}, {"regionMax", {1, 2, 1}},
        {"minRange", 0.5}, {"maxRange", 1}};
    const Scene scene = loadJson(document);

    Scene expected = scenes::buildProceduralScene("spheres", {});
    scenes::PointLightScatter scatter = scenes::defaultScatterFor(expected);
    scatter.region = scenes::Aabb{{-1, 0, -1}, {1, 2, 1}};
    scatter.minRangeMetres = 0.5f;
    scatter.maxRangeMetres = 1.0f;
    scenes::scatterPointLights(expected, scatter, 5, 3);
    ASSERT_EQ(scene.lights.size(), 5u);
    for (size_t i = 0; i < 5; ++i) {
        expectNear(scene.lights[i].positionWorld, expected.lights[i].positionWorld, 0.0f);
        EXPECT_EQ(scene.lights[i].rangeMetres, expected.lights[i].rangeMetres);
    }

    // The request's count and seed, when it asks for lights, replace the file's.
    scenes::SceneRequest request;
    request.lightCount = 7;
    request.seed = 9;
    const Scene overridden = loadJson(document, request);
    Scene expectedOverride = scenes::buildProceduralScene("spheres", {});
    scenes::scatterPointLights(expectedOverride, scatter, 7, 9);
    ASSERT_EQ(overridden.lights.size(), 7u);
    expectNear(overridden.lights[6].positionWorld, expectedOverride.lights[6].positionWorld, 0.0f);
}

TEST(JsonScene, RequestLightsWithoutGeneratorUseTheDefaultScatter) {
    scenes::SceneRequest request;
    request.lightCount = 4;
    EXPECT_EQ(loadJson(spheresOnly(), request).lights.size(), 4u);
}

TEST(JsonScene, LoadSceneDispatchesJsonFiles) {
    const Scene scene = scenes::loadScene(writeScene(spheresOnly()).string(), {});
    EXPECT_EQ(scene.name, "scene");
    EXPECT_GT(scene.triangleCount(), 0u);
}

// ---- errors ---------------------------------------------------------------------------------

TEST(JsonSceneErrors, UnknownKeysAreNamed) {
    json top = spheresOnly();
    top["colour"] = "red";
    expectJsonError(top, {"unknown key 'colour'"});

    json camera = spheresOnly();
    camera["camera"] = {{"position", {0, 0, 5}}, {"forward", {0, 0, -1}}, {"fov", 40}};
    expectJsonError(camera, {"camera", "unknown key 'fov'"});

    json transform = spheresOnly();
    transform["objects"][0]["transform"] = {{"translation", {1, 0, 0}}};
    expectJsonError(transform, {"objects[0].transform", "unknown key 'translation'"});

    json light = spheresOnly();
    light["lights"] = {{{"type", "directional"}, {"direction", {0, -1, 0}}, {"range", 3}}};
    expectJsonError(light, {"lights[0]", "unknown key 'range'"});

    json generator = spheresOnly();
    generator["lightGenerator"] = {{"count", 3}, {"radius", 2}};
    expectJsonError(generator, {"lightGenerator", "unknown key 'radius'"});
}

TEST(JsonSceneErrors, WrongTypesNameTheFieldAndTheExpectation) {
    json position = spheresOnly();
    position["camera"] = {{"position", "up"}, {"forward", {0, 0, -1}}};
    expectJsonError(position, {"camera.position", "array of 3 numbers"});

    json name = spheresOnly();
    name["name"] = 5;
    expectJsonError(name, {"name", "expected a string"});

    json component = spheresOnly();
    component["lights"] = {{{"type", "point"}, {"position", {0, "one", 0}}, {"range", 1}}};
    expectJsonError(component, {"lights[0].position[1]", "expected a number"});

    json count = spheresOnly();
    count["lightGenerator"] = {{"count", 2.5}};
    expectJsonError(count, {"lightGenerator.count", "non-negative integer"});

    expectJsonError({{"objects", {{{"procedural", "spheres"}, {"options", {{"segments", {1}}}}}}}},
                    {"objects[0].options.segments", "string, number or boolean"});
}

TEST(JsonSceneErrors, BadValues) {
    json range = spheresOnly();
    range["lights"] = {{{"type", "point"}, {"position", {0, 1, 0}}, {"range", -1}}};
    expectJsonError(range, {"lights[0].range", "positive"});

    json spot = spheresOnly();
    spot["lights"] = {{{"type", "spot"}, {"position", {0, 1, 0}}, {"range", 2}}};
    expectJsonError(spot, {"lights[0]", "needs 'direction'"});

    json cone = spheresOnly();
    cone["lights"] = {{{"type", "spot"},
                       {"position", {0, 1, 0}},
                       {"direction", {0, -1, 0}},
                       {"range", 2},
                       {"innerConeDegrees", 40},
                       {"outerConeDegrees", 30}}};
    expectJsonError(cone, {"innerConeDegrees <= outerConeDegrees"});

    json type = spheresOnly();
    type["lights"] = {{{"type", "area"}}};
    expectJsonError(type, {"lights[0].type", "unknown light type 'area'"});

    json scale = spheresOnly();
    scale["objects"][0]["transform"] = {{"scale", {1, -1, 1}}};
    expectJsonError(scale, {"objects[0].transform.scale", "positive"});

    json bothRotations = spheresOnly();
    bothRotations["objects"][0]["transform"] = {
        {"rotateDegrees", {0, 0, 0}}, {"axisAngle", {{"axis", {0, 1, 0}}, {"degrees", 5}}}};
    expectJsonError(bothRotations, {"not both"});

    json camera = spheresOnly();
    camera["camera"] = {{"position", {0, 0, 5}}, {"target", {0, 0, 0}}, {"forward", {0, 0, -1}}};
    expectJsonError(camera, {"camera", "exactly one of 'target' and 'forward'"});

    json nearFar = spheresOnly();
    nearFar["camera"] = {{"position", {0, 0, 5}}, {"forward", {0, 0, -1}}, {"near", 2}, {"far", 1}};
    expectJsonError(nearFar, {"'far' must exceed 'near'"});
}

// ---- materials ------------------------------------------------------------------------------

const scenes::Material& materialNamed(const Scene& scene, const std::string& name) {
    for (const scenes::Material& material : scene.materials)
        if (material.name == name)
            return material;
    throw std::runtime_error("no material " + name);
}

TEST(JsonScene, MaterialsDefaultToTheirSourcesModel) {
    json document = spheresOnly();
    document["objects"].push_back({{"gltf", kSuzanne.string()}});
    const Scene scene = loadJson(document);
    EXPECT_EQ(materialNamed(scene, "sphere-gold").model, scenes::MaterialModel::BlinnPhong);
    EXPECT_EQ(materialNamed(scene, "Suzanne").model, scenes::MaterialModel::MetallicRoughness);
}

TEST(JsonScene, MaterialEntriesSetModelMetallicRoughnessAndEmissive) {
    json document = spheresOnly();
    document["materials"] = {
        {{"name", "*"}, {"emissive", {0.5, 0.25, 0}}},
        {{"name", "sphere-gold"},
         {"model", "metallic-roughness"},
         {"baseColor", {1.0, 0.8, 0.3}},
         {"metallic", 1},
         {"roughness", 0.5},
         {"emissiveStrength", 4}},
        {{"name", "sphere-chrome"}, {"specularPower", 30}, {"specularIntensity", 1}}};
    const Scene reference = scenes::buildProceduralScene("spheres", {});
    const Scene scene = loadJson(document);
    for (const scenes::Material& material : scene.materials)
        expectNear(material.emissiveFactor, {0.5f, 0.25f, 0.0f});
    const scenes::Material& gold = materialNamed(scene, "sphere-gold");
    EXPECT_EQ(gold.model, scenes::MaterialModel::MetallicRoughness);
    EXPECT_EQ(gold.baseColorFactor, glm::vec4(1.0f, 0.8f, 0.3f, 1.0f));
    EXPECT_EQ(gold.metallic, 1.0f);
    EXPECT_EQ(gold.roughness, 0.5f);
    EXPECT_EQ(gold.emissiveStrength, 4.0f);
    // The Blinn-Phong approximation follows: ks = mix(0.04, 1, 1), power = 2 / 0.5^4 - 2.
    EXPECT_FLOAT_EQ(gold.specularIntensity, 1.0f);
    EXPECT_FLOAT_EQ(gold.specularPower, 30.0f);
    const scenes::Material& chrome = materialNamed(scene, "sphere-chrome");
    EXPECT_EQ(chrome.model, scenes::MaterialModel::BlinnPhong);
    EXPECT_EQ(chrome.specularPower, 30.0f);
    EXPECT_EQ(chrome.specularIntensity, 1.0f);
    EXPECT_FLOAT_EQ(chrome.roughness, 0.5f); // (2 / 32)^(1/4)
    // Untouched materials keep their values.
    const scenes::Material& white = materialNamed(scene, "sphere-matte-white");
    EXPECT_EQ(white.specularPower, materialNamed(reference, "sphere-matte-white").specularPower);
    EXPECT_EQ(white.model, scenes::MaterialModel::BlinnPhong);
}

TEST(JsonScene, MaterialEntriesSetAlphaModeAndCutoff) {
    json document = spheresOnly();
    document["materials"] = {
        {{"name", "sphere-gold"}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.25}},
        {{"name", "sphere-chrome"}, {"alphaMode", "BLEND"}, {"baseColor", {1, 1, 1, 0.4}}}};
    const Scene scene = loadJson(document);
    const scenes::Material& gold = materialNamed(scene, "sphere-gold");
    EXPECT_EQ(gold.alphaMode, scenes::AlphaMode::Mask);
    EXPECT_EQ(gold.alphaCutoff, 0.25f);
    const scenes::Material& chrome = materialNamed(scene, "sphere-chrome");
    EXPECT_EQ(chrome.alphaMode, scenes::AlphaMode::Blend);
    EXPECT_EQ(chrome.alphaCutoff, 0.5f); // glTF's default
    EXPECT_EQ(chrome.baseColorFactor.a, 0.4f);
    EXPECT_EQ(materialNamed(scene, "sphere-matte-white").alphaMode, scenes::AlphaMode::Opaque);
}

TEST(JsonSceneErrors, BadMaterialEntries) {
    auto with = [](json entry) {
        json document = spheresOnly();
        document["materials"] = json::array({entry}); // not {entry}: clang copies the element
        return document;
    };
    expectJsonError(
        with({{"name", "unobtainium"}}),
        {"materials[0].name", "no material named 'unobtainium'", "sphere-gold", "sphere-chrome"});
    expectJsonError(with({{"model", "phong"}, {"name", "sphere-gold"}}),
                    {"materials[0].model", "'phong'", "metallic-roughness"});
    expectJsonError(with({{"name", "sphere-gold"}, {"metallic", 0.5}}),
                    {"materials[0].metallic", "'sphere-gold'", "blinn-phong"});
    expectJsonError(
        with({{"name", "sphere-gold"}, {"model", "metallic-roughness"}, {"specularPower", 8}}),
        {"materials[0].specularPower", "metallic-roughness"});
    expectJsonError(
        with({{"name", "sphere-gold"}, {"model", "metallic-roughness"}, {"roughness", 2}}),
        {"materials[0].roughness", "[0, 1]"});
    expectJsonError(with({{"name", "sphere-gold"}, {"emissive", {1, -1, 0}}}),
                    {"materials[0].emissive", "negative"});
    expectJsonError(with({{"name", "sphere-gold"}, {"shininess", 3}}),
                    {"materials[0]", "unknown key 'shininess'"});
    expectJsonError(with({{"model", "blinn-phong"}}), {"materials[0]", "missing key 'name'"});
    expectJsonError(with({{"name", "sphere-gold"}, {"alphaMode", "CUTOUT"}}),
                    {"materials[0].alphaMode", "'CUTOUT'", "MASK"});
    expectJsonError(with({{"name", "sphere-gold"}, {"alphaCutoff", -1}}),
                    {"materials[0].alphaCutoff", "negative"});
}

TEST(JsonSceneErrors, BadObjects) {
    expectJsonError({{"objects", json::array()}}, {"objects", "non-empty"});
    expectJsonError({{"name", "no objects"}}, {"missing key 'objects'"});
    expectJsonError({{"objects", {{{"procedural", "spheres"}, {"gltf", kSuzanne.string()}}}}},
                    {"objects[0]", "exactly one of 'gltf' and 'procedural'"});
    expectJsonError({{"objects", {{{"procedural", "pyramids"}}}}},
                    {"objects[0].procedural", "pyramids", "atrium"});
    expectJsonError({{"objects", {{{"procedural", "spheres"}, {"options", {{"segments", 2}}}}}}},
                    {"objects[0]", "segments"});
    expectJsonError({{"objects", {{{"gltf", "missing/model.gltf"}}}}},
                    {"objects[0].gltf", "model.gltf: file not found"});
}

TEST(JsonSceneErrors, BadFiles) {
    const fs::path path = testDirectory() / "truncated.json";
    std::ofstream(path) << "{\"objects\": [";
    try {
        scenes::loadJsonScene(path, {});
        ADD_FAILURE() << "no SceneError";
    } catch (const SceneError& error) {
        EXPECT_NE(std::string(error.what()).find(path.string() + ": invalid JSON"),
                  std::string::npos)
            << error.what();
    }
    expectJsonError(json::array(), {"expected an object"});

    scenes::SceneRequest request;
    request.options["segments"] = "8";
    expectJsonError(spheresOnly(), {"option 'segments'"}, request);
}

TEST(JsonScene, CamerasListAndCameraPathBecomeNamedViews) {
    json document = spheresOnly();
    document["cameras"] = {{{"name", "near"}, {"position", {0, 1, 4}}, {"target", {0, 0, 0}}},
                           {{"position", {4, 1, 0}}, {"target", {0, 0, 0}}},
                           {{"name", "near"}, {"position", {0, 5, 1}}, {"target", {0, 0, 0}}}};
    document["cameraPath"] = {
        {"name", "orbit"},
        {"frames", 5},
        {"keys",
         {{{"position", {0, 1, 8}}, {"target", {0, 0, 0}}, {"fovYDegrees", 40}},
          {{"position", {8, 1, 0}}, {"target", {0, 0, 0}}, {"fovYDegrees", 80}}}}};
    const Scene scene = loadJson(document);
    const std::vector<std::string> expected = {"near",    "camera 1", "near (2)", "orbit/0",
                                               "orbit/1", "orbit/2",  "orbit/3",  "orbit/4"};
    EXPECT_EQ(scenes::viewNames(scene), expected);
    // The path starts and ends on its keys and interpolates in between.
    expectNear(scene.cameras[3].positionWorld, {0, 1, 8});
    expectNear(scene.cameras[7].positionWorld, {8, 1, 0});
    expectNear(scene.cameras[5].positionWorld, {4, 1, 4});
    EXPECT_NEAR(glm::degrees(scene.cameras[5].verticalFovRadians), 60.0f, 1e-4f);
    EXPECT_NEAR(glm::length(scene.cameras[5].forwardWorld), 1.0f, 1e-6f);
}

TEST(JsonScene, BadCameraPathsAreRefusedNamingTheKey) {
    json document = spheresOnly();
    document["cameraPath"] = {{"frames", 1},
                              {"keys",
                               {{{"position", {0, 1, 8}}, {"target", {0, 0, 0}}},
                                {{"position", {8, 1, 0}}, {"target", {0, 0, 0}}}}}};
    expectJsonError(document, {"cameraPath.frames", "[2, 10000]"});
    document["cameraPath"]["frames"] = 3;
    document["cameraPath"]["keys"] = {{{"position", {0, 1, 8}}, {"target", {0, 0, 0}}}};
    expectJsonError(document, {"cameraPath.keys", "at least 2"});
    document["cameraPath"]["keys"] = {{{"position", {0, 0, 8}}, {"target", {0, 0, 0}}},
                                      {{"position", {0, 0, -8}}, {"target", {0, 0, 0}}}};
    expectJsonError(document, {"cameraPath", "opposite directions"});
    document.erase("cameraPath");
    document["cameras"] = json::array();
    expectJsonError(document, {"cameras", "non-empty array"});
}

} // namespace
