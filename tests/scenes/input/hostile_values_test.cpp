// Hostile values for the scene loaders (issue 32, classes 1 and 2): numbers finite as doubles but
// not as floats, transforms that overflow only once composed, derived quantities (colour x
// intensity, placed bounds) past float's range or the documented limits, and degenerate
// cameras. Every case must end in one SceneError that names the file and the field (or load, for
// the camera basis the glTF loader rebuilds with a warning), never in a scene that renders black.
//
// Two corpora: the hand-made one in tests/scenes/input/hostile-values/ (listed with the expected
// messages in its cases.txt), and generated ones here: every numeric field of a JSON scene and of
// a glTF file crossed with values just past float's range, and chains of node scales whose
// product overflows or passes the coordinate limit.
#include <cfloat>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scenes/SceneChecks.h"
#include "scenes/SceneLoader.h"
#include "scenes/input/FloatRange.h"
#include "scenes/input/Limits.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using scenes::SceneError;

const fs::path kCorpus =
    fs::path(TESTBED_SOURCE_DIR) / "tests" / "scenes" / "input" / "hostile-values";

fs::path testDirectory() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path directory =
        fs::path(::testing::TempDir()) /
        (std::string("hostile_values_test.") + test->test_suite_name() + "." + test->name());
    fs::remove_all(directory);
    fs::create_directories(directory);
    return directory;
}

struct LoadResult {
    bool loaded = false;
    std::string error;                 // the SceneError's message when not loaded
    std::vector<std::string> warnings; // Scene::warnings when loaded
};

LoadResult load(const fs::path& path) {
    LoadResult result;
    try {
        const scenes::Scene scene = scenes::loadScene(path.string(), scenes::SceneRequest{});
        result.loaded = true;
        result.warnings = scene.warnings;
    } catch (const SceneError& error) {
        result.error = error.what();
    }
    return result;
}

// One SceneError, one line, starting with the file's path, containing every fragment.
void expectError(const fs::path& path, const std::vector<std::string>& fragments) {
    const LoadResult result = load(path);
    ASSERT_FALSE(result.loaded) << path << " loaded; expected an error containing "
                                << fragments.front();
    EXPECT_EQ(result.error.rfind(path.string() + ": ", 0), 0u) << result.error;
    EXPECT_EQ(result.error.find('\n'), std::string::npos) << result.error;
    // Named once: a check inside a loader's catch-and-rethrow would prefix the file twice.
    EXPECT_EQ(result.error.find(path.string(), 1), std::string::npos) << result.error;
    for (const std::string& fragment : fragments)
        EXPECT_NE(result.error.find(fragment), std::string::npos)
            << "'" << fragment << "' not in: " << result.error;
}

std::string trim(const std::string& text) {
    const size_t first = text.find_first_not_of(' ');
    const size_t last = text.find_last_not_of(' ');
    return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

// A triangle (0,0,0), (1,0,0), (0,1,0) in an embedded buffer: nodes, cameras, lights and
// materials are the caller's.
json triangleGltf() {
    return json::parse(R"({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}]})");
}

fs::path write(const fs::path& path, const json& document) {
    std::ofstream(path) << document.dump(1);
    return path;
}

TEST(FloatRange, RefusesWhatFloatCannotHold) {
    EXPECT_EQ(scenes::floatRangeProblem(0.0), "");
    EXPECT_EQ(scenes::floatRangeProblem(-1.5), "");
    EXPECT_EQ(scenes::floatRangeProblem(double(FLT_MAX)), "");
    EXPECT_EQ(scenes::floatRangeProblem(-double(FLT_MAX)), "");
    EXPECT_EQ(scenes::floatRangeProblem(1e-300), ""); // rounds to 0, as a float store does
    EXPECT_EQ(scenes::floatRangeProblem(1e39),
              "1e+39 is beyond float's range (largest 3.40282e+38)");
    EXPECT_EQ(scenes::floatRangeProblem(-1e39),
              "-1e+39 is beyond float's range (largest 3.40282e+38)");
    EXPECT_NE(scenes::floatRangeProblem(std::nextafter(double(FLT_MAX), 1e300)), "");
    EXPECT_EQ(scenes::floatRangeProblem(std::numeric_limits<double>::infinity()), "is infinite");
    EXPECT_EQ(scenes::floatRangeProblem(std::nan("")), "is NaN");
}

TEST(SceneChecks, DerivedQuantitiesInFloat) {
    EXPECT_EQ(scenes::radianceProblem(glm::vec3(1e15f), 1e15f), "");
    EXPECT_NE(scenes::radianceProblem(glm::vec3(1e20f, 0.0f, 0.0f), 1e20f), "");
    EXPECT_NE(scenes::radianceProblem(glm::vec3(1e16f), 1e15f), ""); // finite, past kMaxRadiance
    glm::mat4 huge(1.0f);
    huge[0][0] = 1e20f;
    EXPECT_EQ(scenes::transformProblem(huge), "");
    EXPECT_NE(scenes::transformProblem(huge * huge), ""); // 1e40: infinite in float
    scenes::Aabb unit;
    unit.extend(glm::vec3(0.0f));
    unit.extend(glm::vec3(1.0f));
    EXPECT_NE(scenes::placedBoundsProblem(unit, huge), ""); // x reaches 1e20 m
    huge[0][0] = 1e15f;
    EXPECT_EQ(scenes::placedBoundsProblem(unit, huge), "");
    EXPECT_EQ(scenes::lengthProblem(1e15f), "");
    EXPECT_NE(scenes::lengthProblem(2e15f), "");
}

TEST(SceneChecks, CamerasNeedABasisAndAFiniteViewFarFromTheOrigin) {
    scenes::Camera camera;
    EXPECT_EQ(scenes::cameraProblem(camera), "");
    camera.upWorld = camera.forwardWorld;
    EXPECT_NE(scenes::cameraProblem(camera).find("up is parallel"), std::string::npos);
    // lookAt(eye, eye + forward) loses forward at 1e14 m even in double, and in float from
    // ~1e7 m: the view matrix is built from the basis and stays exact.
    camera = scenes::Camera{};
    camera.positionWorld = glm::vec3(1e14f, -3e14f, 1e14f);
    EXPECT_EQ(scenes::cameraProblem(camera), "");
    const glm::dmat4 view = camera.viewFromWorldExact();
    const glm::dvec4 ahead =
        view * glm::dvec4(glm::dvec3(camera.positionWorld) + glm::dvec3(0.0, 0.0, -1e6), 1.0);
    EXPECT_NEAR(ahead.z, -1e6, 1.0);
    EXPECT_NEAR(ahead.x, 0.0, 1.0);
}

// The hand-made corpus: every file of cases.txt with its expected message (or warning).
TEST(HostileValues, HandMadeCorpus) {
    std::ifstream cases(kCorpus / "cases.txt");
    ASSERT_TRUE(cases) << kCorpus / "cases.txt";
    std::string line;
    int count = 0;
    while (std::getline(cases, line)) {
        if (line.empty() || line[0] == '#')
            continue;
        std::vector<std::string> parts;
        std::stringstream fields(line);
        for (std::string part; std::getline(fields, part, '|');)
            parts.push_back(trim(part));
        ASSERT_GE(parts.size(), 2u) << line;
        const fs::path file = kCorpus / parts[0];
        ASSERT_TRUE(fs::is_regular_file(file)) << file;
        SCOPED_TRACE(parts[0]);
        ++count;
        const auto start = std::chrono::steady_clock::now();
        if (parts[1] == "OK") {
            const LoadResult result = load(file);
            ASSERT_TRUE(result.loaded) << result.error;
            bool warned = false;
            for (const std::string& warning : result.warnings)
                warned = warned || warning.find(parts.at(2)) != std::string::npos;
            EXPECT_TRUE(warned) << "no warning containing '" << parts.at(2) << "'";
        } else {
            expectError(file, std::vector<std::string>(parts.begin() + 1, parts.end()));
        }
        // A hang detector, not a timing: each case is a few kilobytes.
        EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
    }
    EXPECT_GE(count, 15);
}

// Values past float's range in every numeric field of a JSON scene: each is refused with the
// field's path (the value alone, before anything is derived from it).
TEST(HostileValues, GeneratedJsonFieldsPastFloat) {
    const fs::path dir = testDirectory();
    const json base = json::parse(R"({
        "objects": [{"procedural": "spheres",
                     "transform": {"translate": [0, 0, 0], "rotateDegrees": [0, 0, 0],
                                   "scale": [1, 1, 1]}}],
        "camera": {"position": [0, 2, 9], "target": [0, 0, 0], "up": [0, 1, 0],
                   "fovYDegrees": 50, "near": 0.1, "far": 100},
        "lights": [{"type": "spot", "position": [0, 5, 0], "direction": [0, -1, 0], "range": 8,
                    "innerConeDegrees": 20, "outerConeDegrees": 30, "color": [1, 1, 1],
                    "intensity": 1}],
        "lightGenerator": {"count": 2, "regionMin": [-1, 0, -1], "regionMax": [1, 1, 1],
                           "minRange": 1, "maxRange": 2, "minIntensity": 1, "maxIntensity": 2},
        "materials": [{"name": "*", "emissive": [0, 0, 0], "emissiveStrength": 1}]})");
    ASSERT_TRUE(load(write(dir / "base.json", base)).loaded);
    const std::vector<std::string> pointers = {"/objects/0/transform/translate/0",
                                               "/objects/0/transform/rotateDegrees/1",
                                               "/objects/0/transform/scale/2",
                                               "/camera/position/0",
                                               "/camera/target/1",
                                               "/camera/up/2",
                                               "/camera/fovYDegrees",
                                               "/camera/near",
                                               "/camera/far",
                                               "/lights/0/position/1",
                                               "/lights/0/direction/0",
                                               "/lights/0/range",
                                               "/lights/0/innerConeDegrees",
                                               "/lights/0/color/2",
                                               "/lights/0/intensity",
                                               "/lightGenerator/regionMin/0",
                                               "/lightGenerator/maxRange",
                                               "/lightGenerator/maxIntensity",
                                               "/materials/0/emissive/1",
                                               "/materials/0/emissiveStrength"};
    const double pastFloat[] = {1e39, -1e39, 2.0 * double(FLT_MAX), 1e300};
    int index = 0;
    for (const std::string& pointer : pointers) {
        // "/lights/0/color/2" -> "lights[0].color[2]"
        std::string field;
        std::stringstream tokens(pointer.substr(1));
        for (std::string token; std::getline(tokens, token, '/');)
            field += std::isdigit(static_cast<unsigned char>(token[0]))
                         ? "[" + token + "]"
                         : (field.empty() ? "" : ".") + token;
        for (double value : pastFloat) {
            json document = base;
            document[json::json_pointer(pointer)] = value;
            SCOPED_TRACE(pointer + " = " + scenes::numberText(value));
            expectError(write(dir / ("case-" + std::to_string(index++) + ".json"), document),
                        {field + ": " + scenes::numberText(value) + " is beyond float's range"});
        }
    }
}

// Values past float's range in every numeric field of a glTF file the converter stores.
TEST(HostileValues, GeneratedGltfFieldsPastFloat) {
    const fs::path dir = testDirectory();
    json base = triangleGltf();
    base["scenes"][0]["nodes"] = {0, 1, 2};
    base["nodes"][0]["translation"] = {0, 0, 0};
    base["nodes"][0]["rotation"] = {0, 0, 0, 1};
    base["nodes"][0]["scale"] = {1, 1, 1};
    base["nodes"].push_back({{"camera", 0}, {"translation", {0.3, 0.3, 3}}});
    base["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}},
                             {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}}});
    base["cameras"] = {
        {{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 10}}}}};
    base["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_emissive_strength"};
    base["extensions"] = {
        {"KHR_lights_punctual",
         {{"lights",
           {{{"type", "point"}, {"color", {1, 1, 1}}, {"intensity", 1}, {"range", 5}}}}}}};
    base["materials"] = {
        {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}}},
         {"normalTexture", {{"index", 0}, {"scale", 1}}},
         {"alphaCutoff", 0.5},
         {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 1}}}}}}};
    base["textures"] = {{{"source", 0}}};
    base["images"] = {{{"uri", "missing.png"}}};
    base["meshes"][0]["primitives"][0]["material"] = 0;
    const LoadResult loaded = load(write(dir / "base.gltf", base));
    ASSERT_TRUE(loaded.loaded) << loaded.error;

    const std::vector<std::pair<std::string, std::string>> cases = {
        {"/nodes/0/translation/2", "nodes[0].translation[2]"},
        {"/nodes/0/rotation/0", "nodes[0].rotation[0]"},
        {"/nodes/0/scale/1", "nodes[0].scale[1]"},
        {"/nodes/2/matrix/13", "nodes[2].matrix[13]"},
        {"/cameras/0/perspective/yfov", "cameras[0].perspective.yfov"},
        {"/cameras/0/perspective/znear", "cameras[0].perspective.znear"},
        {"/cameras/0/perspective/zfar", "cameras[0].perspective.zfar"},
        {"/extensions/KHR_lights_punctual/lights/0/color/1",
         "extensions.KHR_lights_punctual.lights[0].color[1]"},
        {"/extensions/KHR_lights_punctual/lights/0/intensity",
         "extensions.KHR_lights_punctual.lights[0].intensity"},
        {"/extensions/KHR_lights_punctual/lights/0/range",
         "extensions.KHR_lights_punctual.lights[0].range"},
        {"/materials/0/pbrMetallicRoughness/baseColorFactor/0",
         "materials[0].pbrMetallicRoughness.baseColorFactor[0]"},
        {"/materials/0/normalTexture/scale", "materials[0].normalTexture.scale"},
        {"/materials/0/alphaCutoff", "materials[0].alphaCutoff"},
        {"/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength",
         "materials[0].extensions.KHR_materials_emissive_strength.emissiveStrength"}};
    int index = 0;
    for (const auto& [pointer, field] : cases) {
        for (double value : {1e39, 2.0 * double(FLT_MAX), 1e300}) {
            json document = base;
            document[json::json_pointer(pointer)] = value;
            SCOPED_TRACE(pointer + " = " + scenes::numberText(value));
            expectError(write(dir / ("case-" + std::to_string(index++) + ".gltf"), document),
                        {field + ": " + scenes::numberText(value) + " is beyond float's range"});
        }
    }
}

// Chains of node scales, each finite, whose product overflows float (an error naming the node
// where it does) or stays finite but places the triangle past the coordinate limit.
TEST(HostileValues, GeneratedNodeScaleChains) {
    const fs::path dir = testDirectory();
    int index = 0;
    for (const double scale : {1e4, 1e10, 1e19, 1e30}) {
        for (int depth = 1; depth <= 5; ++depth) {
            json document = triangleGltf();
            document["nodes"] = json::array();
            for (int n = 0; n < depth; ++n) {
                json node = {{"scale", {scale, scale, scale}}};
                if (n + 1 < depth)
                    node["children"] = {n + 1};
                else
                    node["mesh"] = 0;
                document["nodes"].push_back(node);
            }
            const fs::path path =
                write(dir / ("chain-" + std::to_string(index++) + ".gltf"), document);
            SCOPED_TRACE(scenes::numberText(scale) + "^" + std::to_string(depth));
            // The first node whose composed scale passes float's range, in float arithmetic.
            float composed = 1.0f;
            int overflowAt = -1;
            for (int n = 0; n < depth && overflowAt < 0; ++n) {
                composed *= float(scale);
                if (std::isinf(composed))
                    overflowAt = n;
            }
            if (overflowAt >= 0)
                expectError(path, {"nodes[" + std::to_string(overflowAt) +
                                       "] (composed with its ancestors)",
                                   "non-finite entry"});
            else if (double(composed) > scenes::limits::kMaxCoordinateMetres)
                expectError(path, {"nodes[" + std::to_string(depth - 1) + "]",
                                   "beyond the limit of +-1e+15 m"});
            else
                EXPECT_TRUE(load(path).loaded) << load(path).error;
        }
    }
}

// Geometry right at the coordinate limit is valid, but the framing camera a file without one
// gets stands back from it (1.5x the bounds' reach here), past the limit: refused, naming it.
TEST(HostileValues, DefaultCameraPastTheLimitIsNamed) {
    const fs::path dir = testDirectory();
    json document = triangleGltf();
    document["nodes"][0]["scale"] = {1e15, 1e15, 1e15};
    expectError(write(dir / "edge.gltf", document),
                {"camera 'default': position", "beyond the limit of +-1e+15 m"});
}

// A JSON object's scale times a model's node scales: each finite, the product not.
TEST(HostileValues, GeneratedObjectTimesModelScales) {
    const fs::path dir = testDirectory();
    json model = triangleGltf();
    model["nodes"][0]["scale"] = {1e10, 1e10, 1e10};
    write(dir / "model.gltf", model);
    for (const double scale : {1e3, 1e6, 1e29, 1e30, 3e38}) {
        const json document = {
            {"objects", {{{"gltf", "model.gltf"}, {"transform", {{"scale", scale}}}}}}};
        const fs::path path = write(dir / "scene.json", document);
        SCOPED_TRACE(scenes::numberText(scale));
        if (scale * 1e10 <= scenes::limits::kMaxCoordinateMetres)
            EXPECT_TRUE(load(path).loaded) << load(path).error;
        else
            expectError(path,
                        {"objects[0].transform: composed with the object's own transforms",
                         scale * 1e10 > double(FLT_MAX) ? "non-finite entry" : "beyond the limit"});
    }
}

// glTF cameras whose node flattens an axis: the viewing axis is an error, the up axis is rebuilt
// from the right axis with a warning, for every axis-aligned flattening and a shear.
TEST(HostileValues, GltfCameraBasisFromFlattenedTransforms) {
    const fs::path dir = testDirectory();
    auto withCamera = [&](const json& cameraNode) {
        json document = triangleGltf();
        document["scenes"][0]["nodes"] = {0, 1};
        document["nodes"].push_back(cameraNode);
        document["cameras"] = {
            {{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
        return write(dir / "camera.gltf", document);
    };
    const json at = {0.3, 0.3, 3};
    expectError(withCamera({{"camera", 0}, {"translation", at}, {"scale", {1, 1, 0}}}),
                {"cameras[0]: the world transform of its node flattens the camera's viewing "
                 "axis (-Z)"});
    expectError(withCamera({{"camera", 0}, {"translation", at}, {"scale", {0, 0, 1}}}),
                {"cameras[0]", "flattens the camera's up (+Y) and right (+X) axes"});
    for (const json& node :
         {json{{"camera", 0}, {"translation", at}, {"scale", {1, 0, 1}}},
          json{{"camera", 0}, {"matrix", {1, 0, 0, 0, 0, 0, -2, 0, 0, 0, 1, 0, 0.3, 0.3, 3, 1}}},
          json{{"camera", 0}, {"matrix", {1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 3, 1}}}}) {
        SCOPED_TRACE(node.dump());
        const fs::path path = withCamera(node);
        const LoadResult result = load(path);
        ASSERT_TRUE(result.loaded) << result.error;
        ASSERT_EQ(result.warnings.size(), 1u);
        EXPECT_NE(result.warnings[0].find("up is taken from the camera's right axis (+X)"),
                  std::string::npos)
            << result.warnings[0];
        const scenes::Scene scene = scenes::loadScene(path.string(), {});
        EXPECT_NEAR(scene.cameras[0].upWorld.y, 1.0f, 1e-6f);
        EXPECT_NEAR(scene.cameras[0].forwardWorld.z, -1.0f, 1e-6f);
    }
}

} // namespace
