// Tests of loadGltf and of loadScene's handling of names and glTF files.
//
// The shared models (TESTBED_GLTF_DIR) must load with the triangle counts stated in
// shared/scenes/README.md. Everything else is a small glTF written by the test into its own
// temporary directory (buffers embedded as base64 data URIs, or a hand-built GLB), so each case
// has a closed-form answer: a converted strip's triangle count and normals, area-weighted
// normals, a node's world transform. Malformed files must throw one SceneError naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scenes/SceneLoader.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using scenes::Scene;
using scenes::SceneError;

constexpr int kFloat = 5126;
constexpr int kUnsignedByte = 5121;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kTriangleStrip = 5;
constexpr int kTriangleFan = 6;
constexpr int kPoints = 0;

fs::path sharedModel(const std::string& relative) {
    return fs::path(TESTBED_GLTF_DIR) / relative;
}

// A fresh directory per test, named after it: a rerun replaces the previous run's files (left
// in place as evidence when a test fails) instead of accumulating them.
fs::path testDirectory() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name =
        std::string("gltf_loader_test.") + test->test_suite_name() + "." + test->name();
    for (char& c : name)
        if (c == '/')
            c = '_';
    const fs::path directory = fs::path(::testing::TempDir()) / name;
    fs::remove_all(directory);
    fs::create_directories(directory);
    return directory;
}

fs::path writeFile(const fs::path& path, const std::string& contents) {
    std::ofstream(path, std::ios::binary) << contents;
    return path;
}

std::string base64(const std::vector<uint8_t>& bytes) {
    static const char* kAlphabet =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string text;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const uint32_t a = bytes[i];
        const uint32_t b = i + 1 < bytes.size() ? bytes[i + 1] : 0;
        const uint32_t c = i + 2 < bytes.size() ? bytes[i + 2] : 0;
        const uint32_t triple = (a << 16) | (b << 8) | c;
        text += kAlphabet[(triple >> 18) & 63];
        text += kAlphabet[(triple >> 12) & 63];
        text += i + 1 < bytes.size() ? kAlphabet[(triple >> 6) & 63] : '=';
        text += i + 2 < bytes.size() ? kAlphabet[triple & 63] : '=';
    }
    return text;
}

// A glTF document under construction: accessors over one binary buffer, which is written either
// as a base64 data URI (.gltf) or as the BIN chunk of a GLB.
class GltfDocument {
public:
    GltfDocument() {
        mJson = {{"asset", {{"version", "2.0"}}},
                 {"accessors", json::array()},
                 {"bufferViews", json::array()}};
    }

    json& operator*() { return mJson; }

    template <class T>
    int addAccessor(const std::vector<T>& values, int componentType, const std::string& type,
                    size_t count) {
        while (mBin.size() % 4 != 0)
            mBin.push_back(0);
        const size_t offset = mBin.size();
        const size_t byteLength = values.size() * sizeof(T);
        mBin.resize(offset + byteLength);
        std::memcpy(mBin.data() + offset, values.data(), byteLength);
        mJson["bufferViews"].push_back(
            {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", byteLength}});
        mJson["accessors"].push_back({{"bufferView", mJson["bufferViews"].size() - 1},
                                      {"componentType", componentType},
                                      {"count", count},
                                      {"type", type}});
        return int(mJson["accessors"].size()) - 1;
    }
    int addVec3(const std::vector<glm::vec3>& values) {
        return addAccessor(values, kFloat, "VEC3", values.size());
    }
    int addIndices(const std::vector<uint32_t>& values) {
        return addAccessor(values, kUnsignedInt, "SCALAR", values.size());
    }

    // One primitive in mesh 0, drawn by node 0 of scene 0. mode < 0 leaves the mode absent.
    json& addPrimitive(int positions, int indices = -1, int mode = -1, int normals = -1) {
        json primitive = {{"attributes", {{"POSITION", positions}}}};
        if (indices >= 0)
            primitive["indices"] = indices;
        if (mode >= 0)
            primitive["mode"] = mode;
        if (normals >= 0)
            primitive["attributes"]["NORMAL"] = normals;
        if (!mJson.contains("meshes")) {
            mJson["meshes"] = {{{"primitives", json::array()}}};
            mJson["nodes"] = {{{"mesh", 0}}};
            mJson["scenes"] = {{{"nodes", {0}}}};
            mJson["scene"] = 0;
        }
        mJson["meshes"][0]["primitives"].push_back(primitive);
        return mJson["meshes"][0]["primitives"].back();
    }

    std::string gltfText() const {
        json document = mJson;
        document["buffers"] = {{{"byteLength", mBin.size()},
                                {"uri", "data:application/octet-stream;base64," + base64(mBin)}}};
        return document.dump();
    }

    // The GLB layout: 12-byte header, JSON chunk padded with spaces, BIN chunk padded with zeros.
    std::string glbBytes() const {
        json document = mJson;
        document["buffers"] = {{{"byteLength", mBin.size()}}};
        std::string jsonChunk = document.dump();
        while (jsonChunk.size() % 4 != 0)
            jsonChunk += ' ';
        std::string binChunk(mBin.begin(), mBin.end());
        while (binChunk.size() % 4 != 0)
            binChunk += '\0';
        std::string glb;
        auto word = [&](uint32_t value) { glb.append(reinterpret_cast<const char*>(&value), 4); };
        glb += "glTF";
        word(2);
        word(uint32_t(12 + 8 + jsonChunk.size() + 8 + binChunk.size()));
        word(uint32_t(jsonChunk.size()));
        word(0x4E4F534A);
        glb += jsonChunk;
        word(uint32_t(binChunk.size()));
        word(0x004E4942);
        glb += binChunk;
        return glb;
    }

private:
    json mJson;
    std::vector<uint8_t> mBin;
};

// The unit right triangle in the XY plane, counter-clockwise seen from +Z.
GltfDocument triangleDocument() {
    GltfDocument document;
    const int positions = document.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    document.addPrimitive(positions, document.addIndices({0, 1, 2}));
    return document;
}

// Loading must throw one SceneError whose message names the file and contains `detail`.
void expectSceneError(const std::function<Scene()>& load, const fs::path& file,
                      const std::string& detail) {
    try {
        load();
        ADD_FAILURE() << "no SceneError for " << file;
    } catch (const SceneError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find(file.filename().string()), std::string::npos) << message;
        EXPECT_NE(message.find(detail), std::string::npos)
            << "'" << message << "' does not mention '" << detail << "'";
    }
}

void expectGltfError(const fs::path& file, const std::string& detail) {
    expectSceneError([&] { return scenes::loadGltf(file); }, file, detail);
}

glm::vec3 faceNormal(const scenes::Mesh& mesh, size_t triangle) {
    const glm::vec3& a = mesh.positions[mesh.indices[3 * triangle]];
    const glm::vec3& b = mesh.positions[mesh.indices[3 * triangle + 1]];
    const glm::vec3& c = mesh.positions[mesh.indices[3 * triangle + 2]];
    return glm::normalize(glm::cross(b - a, c - a));
}

void expectNear(const glm::vec3& actual, const glm::vec3& expected, float tolerance = 1e-5f) {
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

// ---- the shared models -------------------------------------------------------------------

struct SharedModel {
    const char* path;
    uint64_t triangleCount;
};

// Test names (and ctest's) show the path, not the struct's bytes.
void PrintTo(const SharedModel& model, std::ostream* out) {
    *out << model.path;
}

class SharedModelTest : public ::testing::TestWithParam<SharedModel> {};

TEST_P(SharedModelTest, LoadsWithStatedTriangleCountAndTextures) {
    const Scene scene = scenes::loadGltf(sharedModel(GetParam().path));
    EXPECT_EQ(scene.triangleCount(), GetParam().triangleCount);
    // None of the models has a camera: the framing camera and three orbit views.
    ASSERT_EQ(scene.cameras.size(), 4u);
    EXPECT_EQ(scene.cameras[0].name, "default");
    ASSERT_EQ(scene.materials.size(), 1u);
    const scenes::Material& material = scene.materials[0];
    // Every model has a readable base colour texture; the helmet and the box have a normal map.
    ASSERT_GE(material.baseColorTexture, 0);
    EXPECT_TRUE(scene.textures[size_t(material.baseColorTexture)].valid());
    EXPECT_TRUE(scene.textures[size_t(material.baseColorTexture)].srgb);
    if (material.normalTexture >= 0) {
        EXPECT_TRUE(scene.textures[size_t(material.normalTexture)].valid());
        EXPECT_FALSE(scene.textures[size_t(material.normalTexture)].srgb);
    }
    for (const scenes::Texture& texture : scene.textures) {
        EXPECT_GT(texture.width, 0);
        EXPECT_GT(texture.height, 0);
    }
}

INSTANTIATE_TEST_SUITE_P(Models, SharedModelTest,
                         ::testing::Values(SharedModel{"DamagedHelmet/DamagedHelmet.gltf", 15452},
                                           SharedModel{"BoomBox/BoomBox.gltf", 6036},
                                           SharedModel{"Suzanne/Suzanne.gltf", 3936}),
                         [](const auto& info) {
                             const std::string path = info.param.path;
                             return path.substr(0, path.find('/'));
                         });

TEST(GltfLoader, CompleteModelsLoadWithoutWarnings) {
    EXPECT_TRUE(scenes::loadGltf(sharedModel("DamagedHelmet/DamagedHelmet.gltf")).warnings.empty());
    const Scene suzanne = scenes::loadGltf(sharedModel("Suzanne/Suzanne.gltf"));
    EXPECT_TRUE(suzanne.warnings.empty());
    EXPECT_EQ(suzanne.meshes[0].tangents.size(), suzanne.meshes[0].positions.size());
    EXPECT_EQ(suzanne.meshes[0].uvs.size(), suzanne.meshes[0].positions.size());
}

TEST(GltfLoader, BoomBoxWarnsOnceAboutItsMissingTextureAndUsesFactors) {
    const Scene scene = scenes::loadGltf(sharedModel("BoomBox/BoomBox.gltf"));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("BoomBox_occlusionRoughnessMetallic.png"), std::string::npos)
        << scene.warnings[0];
    // The missing image held metallic and roughness: the factors (glTF defaults, 1 and 1) apply.
    const scenes::Material& material = scene.materials[0];
    EXPECT_EQ(material.metallic, 1.0f);
    EXPECT_EQ(material.roughness, 1.0f);
    EXPECT_FLOAT_EQ(material.specularIntensity, 1.0f); // mix(0.04, 1, metallic = 1)
    EXPECT_FLOAT_EQ(material.specularPower, 1.0f);     // 2 / 1 - 2 = 0, clamped to 1
}

// ---- small files with closed-form answers ---------------------------------------------------

TEST(GltfLoader, MaterialFactorsMapToBlinnPhong) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    (*document)["meshes"][0]["primitives"][0]["material"] = 0;
    (*document)["materials"] = {{{"name", "half"},
                                 {"pbrMetallicRoughness",
                                  {{"baseColorFactor", {0.5, 0.25, 1.0, 1.0}},
                                   {"metallicFactor", 0.5},
                                   {"roughnessFactor", 0.5}}}}};
    const Scene scene = scenes::loadGltf(writeFile(directory / "m.gltf", document.gltfText()));
    ASSERT_EQ(scene.materials.size(), 1u);
    const scenes::Material& material = scene.materials[0];
    EXPECT_EQ(material.name, "half");
    expectNear(glm::vec3(material.baseColorFactor), {0.5f, 0.25f, 1.0f});
    EXPECT_FLOAT_EQ(material.specularIntensity, 0.52f); // 0.04 + 0.96 * 0.5
    EXPECT_FLOAT_EQ(material.specularPower, 30.0f);     // 2 / 0.5^4 - 2
    EXPECT_EQ(material.baseColorTexture, -1);
}

TEST(GltfLoader, PrimitiveWithoutMaterialGetsTheDefault) {
    const fs::path directory = testDirectory();
    const Scene scene =
        scenes::loadGltf(writeFile(directory / "t.gltf", triangleDocument().gltfText()));
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_EQ(scene.materials[0].name, "default");
    EXPECT_EQ(scene.meshes[0].material, 0u);
}

TEST(GltfLoader, NodeHierarchyAccumulatesTrsAndMatrixTransforms) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    // Parent: translate (1,0,0) after a 90 degree turn about +Z; child: a matrix translating
    // (2,0,0). The child's origin lands at (1,0,0) + Rz(90) (2,0,0) = (1,2,0).
    const double s = std::sqrt(0.5);
    (*document)["nodes"] = {
        {{"translation", {1, 0, 0}}, {"rotation", {0, 0, s, s}}, {"children", {1}}},
        {{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 2, 0, 0, 1}}}};
    const Scene scene = scenes::loadGltf(writeFile(directory / "h.gltf", document.gltfText()));
    ASSERT_EQ(scene.instances.size(), 1u);
    const glm::mat4& worldFromObject = scene.instances[0].worldFromObject;
    expectNear(glm::vec3(worldFromObject * glm::vec4(0, 0, 0, 1)), {1, 2, 0});
    expectNear(glm::vec3(worldFromObject * glm::vec4(1, 0, 0, 0)), {0, 1, 0});
}

TEST(GltfLoader, MeshUsedByTwoNodesIsStoredOnce) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    (*document)["nodes"] = {{{"mesh", 0}}, {{"mesh", 0}, {"translation", {0, 0, 3}}}};
    (*document)["scenes"][0]["nodes"] = {0, 1};
    const Scene scene = scenes::loadGltf(writeFile(directory / "two.gltf", document.gltfText()));
    EXPECT_EQ(scene.meshes.size(), 1u);
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.instances[1].mesh, 0u);
    expectNear(glm::vec3(scene.instances[1].worldFromObject[3]), {0, 0, 3});
    EXPECT_EQ(scene.triangleCount(), 2u);
}

TEST(GltfLoader, TriangleStripBecomesCounterClockwiseList) {
    const fs::path directory = testDirectory();
    GltfDocument document;
    // A zig-zag strip up the XY plane: 5 vertices, 3 triangles, all facing +Z once the odd
    // triangles' winding is flipped back.
    const int positions = document.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}});
    document.addPrimitive(positions, document.addIndices({0, 1, 2, 3, 4}), kTriangleStrip);
    const Scene scene = scenes::loadGltf(writeFile(directory / "strip.gltf", document.gltfText()));
    const scenes::Mesh& mesh = scene.meshes.at(0);
    ASSERT_EQ(mesh.triangleCount(), 3u);
    for (size_t t = 0; t < 3; ++t)
        expectNear(faceNormal(mesh, t), {0, 0, 1});
    for (const glm::vec3& normal : mesh.normals)
        expectNear(normal, {0, 0, 1});
}

TEST(GltfLoader, TriangleFanBecomesCounterClockwiseList) {
    const fs::path directory = testDirectory();
    GltfDocument document;
    // A fan around the origin, counter-clockwise seen from +Z; non-indexed.
    const int positions =
        document.addVec3({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}});
    document.addPrimitive(positions, -1, kTriangleFan);
    const Scene scene = scenes::loadGltf(writeFile(directory / "fan.gltf", document.gltfText()));
    const scenes::Mesh& mesh = scene.meshes.at(0);
    ASSERT_EQ(mesh.triangleCount(), 3u);
    for (size_t t = 0; t < 3; ++t)
        expectNear(faceNormal(mesh, t), {0, 0, 1});
    for (const glm::vec3& normal : mesh.normals)
        expectNear(normal, {0, 0, 1});
}

TEST(GltfLoader, NonIndexedMeshWithoutNormalsGetsOutwardFaceNormals) {
    const fs::path directory = testDirectory();
    GltfDocument document;
    // The corner tetrahedron, each face counter-clockwise seen from outside, non-indexed so
    // every vertex belongs to one face: its normal is that face's normal.
    const glm::vec3 o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
    const int positions = document.addVec3({o, y, x, o, x, z, o, z, y, x, y, z});
    document.addPrimitive(positions);
    const Scene scene = scenes::loadGltf(writeFile(directory / "tet.gltf", document.gltfText()));
    const scenes::Mesh& mesh = scene.meshes.at(0);
    ASSERT_EQ(mesh.triangleCount(), 4u);
    ASSERT_EQ(mesh.indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
    const glm::vec3 expected[4] = {
        {0, 0, -1}, {0, -1, 0}, {-1, 0, 0}, glm::normalize(glm::vec3(1))};
    for (size_t v = 0; v < 12; ++v)
        expectNear(mesh.normals[v], expected[v / 3]);
}

TEST(GltfLoader, IndexedMeshWithoutNormalsGetsAreaWeightedNormals) {
    const fs::path directory = testDirectory();
    GltfDocument document;
    // Vertex 0 is shared by a triangle of area 2 facing +Z and one of area 0.5 facing +Y, so its
    // normal is (0, 0.5, 2) normalized.
    const int positions = document.addVec3({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, {1, 0, 0}});
    document.addPrimitive(positions, document.addIndices({0, 1, 2, 0, 3, 4}));
    const Scene scene = scenes::loadGltf(writeFile(directory / "w.gltf", document.gltfText()));
    const scenes::Mesh& mesh = scene.meshes.at(0);
    expectNear(mesh.normals[0], glm::normalize(glm::vec3(0, 0.5f, 2)));
    expectNear(mesh.normals[1], {0, 0, 1});
    expectNear(mesh.normals[3], {0, 1, 0});
}

TEST(GltfLoader, ReadsByteIndicesNormalizedShortUvsAndGivenNormals) {
    const fs::path directory = testDirectory();
    GltfDocument document;
    const int positions = document.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    const int indices =
        document.addAccessor(std::vector<uint8_t>{2, 0, 1}, kUnsignedByte, "SCALAR", 3);
    const int normals = document.addVec3({{0, 0, 2}, {0, 0, 1}, {0, 0, 0}}); // 2 and 0: repaired
    const int uvs = document.addAccessor(std::vector<uint16_t>{0, 65535, 65535, 0, 0, 0},
                                         kUnsignedShort, "VEC2", 3);
    (*document)["accessors"][uvs]["normalized"] = true;
    document.addPrimitive(positions, indices, -1, normals)["attributes"]["TEXCOORD_0"] = uvs;
    const Scene scene = scenes::loadGltf(writeFile(directory / "u8.gltf", document.gltfText()));
    const scenes::Mesh& mesh = scene.meshes.at(0);
    EXPECT_EQ(mesh.indices, (std::vector<uint32_t>{2, 0, 1}));
    ASSERT_EQ(mesh.uvs.size(), 3u);
    EXPECT_FLOAT_EQ(mesh.uvs[0].y, 1.0f);
    EXPECT_FLOAT_EQ(mesh.uvs[1].x, 1.0f);
    for (const glm::vec3& normal : mesh.normals)
        expectNear(normal, {0, 0, 1});
}

TEST(GltfLoader, KeepsEveryPerspectiveCameraWithItsNodeTransform) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    // Turned 90 degrees about +Y, a camera looking down its -Z looks down world -X.
    const double s = std::sqrt(0.5);
    (*document)["cameras"] = {
        {{"type", "perspective"},
         {"name", "eye"},
         {"perspective", {{"yfov", 0.8}, {"znear", 0.05}}}},
        {{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 1}, {"zfar", 10}}}}};
    (*document)["nodes"].push_back(
        {{"camera", 0}, {"translation", {0, 1, 5}}, {"rotation", {0, s, 0, s}}});
    (*document)["nodes"].push_back({{"camera", 1}});
    (*document)["scenes"][0]["nodes"] = {0, 1, 2};
    const Scene scene = scenes::loadGltf(writeFile(directory / "cam.gltf", document.gltfText()));
    // Both cameras are views, in walk order: the first is the one rendered by default.
    ASSERT_EQ(scene.cameras.size(), 2u);
    EXPECT_EQ(scene.cameras[1].name, "camera 1"); // unnamed in the file
    EXPECT_FLOAT_EQ(scene.cameras[1].verticalFovRadians, 0.5f);
    EXPECT_FLOAT_EQ(scene.cameras[1].farMetres, 10.0f);
    const scenes::Camera& camera = scene.cameras[0];
    EXPECT_EQ(camera.name, "eye");
    expectNear(camera.positionWorld, {0, 1, 5});
    expectNear(camera.forwardWorld, {-1, 0, 0});
    expectNear(camera.upWorld, {0, 1, 0});
    EXPECT_FLOAT_EQ(camera.verticalFovRadians, 0.8f);
    EXPECT_FLOAT_EQ(camera.nearMetres, 0.05f);
    EXPECT_FLOAT_EQ(camera.farMetres, 1e4f * 0.05f); // zfar absent: 1e4 znear covers the model
}

TEST(GltfLoader, WithoutCamerasTheDefaultViewAndThreeOrbitViewsFrameTheModel) {
    const Scene scene = scenes::loadGltf(sharedModel("Suzanne/Suzanne.gltf"));
    ASSERT_EQ(scene.cameras.size(), 4u);
    EXPECT_EQ(scene.cameras[0].name, "default");
    EXPECT_EQ(scene.cameras[1].name, "left");
    EXPECT_EQ(scene.cameras[2].name, "right");
    EXPECT_EQ(scene.cameras[3].name, "above");
    const scenes::Camera& camera = scene.cameras.at(0);
    scenes::Aabb bounds;
    for (const scenes::Instance& instance : scene.instances)
        for (const glm::vec3& p : scene.meshes[instance.mesh].positions)
            bounds.extend(glm::vec3(instance.worldFromObject * glm::vec4(p, 1)));
    const glm::vec3 toCentre = bounds.centre() - camera.positionWorld;
    EXPECT_GT(glm::length(toCentre), 0.5f * glm::length(bounds.size())); // outside the bounds
    expectNear(camera.forwardWorld, glm::normalize(toCentre));
    EXPECT_LT(camera.nearMetres, glm::length(toCentre) - 0.5f * glm::length(bounds.size()));
    EXPECT_GT(camera.farMetres, glm::length(toCentre) + 0.5f * glm::length(bounds.size()));
    // The orbit views look at the centre the framing camera looks at (that of the geometry's
    // bounds) from the same distance, with the same planes.
    const glm::vec3 centre = bounds.centre();
    const float distance = glm::length(centre - camera.positionWorld);
    for (size_t i = 1; i < scene.cameras.size(); ++i) {
        const scenes::Camera& orbit = scene.cameras[i];
        const glm::vec3 orbitToCentre = centre - orbit.positionWorld;
        EXPECT_NEAR(glm::length(orbitToCentre), distance, 1e-4f * distance);
        expectNear(orbit.forwardWorld, glm::normalize(orbitToCentre), 1e-4f);
        EXPECT_EQ(orbit.nearMetres, camera.nearMetres);
        EXPECT_EQ(orbit.farMetres, camera.farMetres);
    }
}

TEST(GltfLoader, PunctualLightIsPlacedByItsNode) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    (*document)["extensionsUsed"] = {"KHR_lights_punctual"};
    (*document)["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 3}, {"range", 2}}};
    (*document)["nodes"].push_back(
        {{"translation", {0, 0, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    (*document)["scenes"][0]["nodes"] = {0, 1};
    const fs::path file = writeFile(directory / "lit.gltf", document.gltfText());
    const Scene scene = scenes::loadGltf(file);
    ASSERT_EQ(scene.lights.size(), 1u);
    EXPECT_EQ(scene.lights[0].type, scenes::LightType::Point);
    expectNear(scene.lights[0].positionWorld, {0, 0, 1});
    expectNear(scene.lights[0].color, {1, 0.5f, 0.25f});
    EXPECT_FLOAT_EQ(scene.lights[0].intensity, 3.0f);
    EXPECT_FLOAT_EQ(scene.lights[0].rangeMetres, 2.0f);
    EXPECT_TRUE(scene.lights[0].castsShadows); // every glTF punctual light casts (issue 29)

    // The file's lights define the scene: requested generated lights are not added, and a
    // warning says so.
    scenes::SceneRequest request;
    request.lightCount = 5;
    const Scene loaded = scenes::loadScene(file.string(), request);
    EXPECT_EQ(loaded.lights.size(), 1u);
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_NE(loaded.warnings[0].find("5 requested"), std::string::npos) << loaded.warnings[0];
}

TEST(GltfLoader, PointsAreSkippedWithOneWarning) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    document.addPrimitive(0, -1, kPoints);
    const Scene scene = scenes::loadGltf(writeFile(directory / "pts.gltf", document.gltfText()));
    EXPECT_EQ(scene.triangleCount(), 1u);
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("POINTS"), std::string::npos) << scene.warnings[0];
}

TEST(GltfLoader, LoadsHandWrittenGlb) {
    const fs::path directory = testDirectory();
    GltfDocument document = triangleDocument();
    const Scene scene = scenes::loadGltf(writeFile(directory / "tri.glb", document.glbBytes()));
    EXPECT_EQ(scene.triangleCount(), 1u);
    expectNear(scene.meshes.at(0).positions.at(1), {1, 0, 0});
}

// ---- textures -------------------------------------------------------------------------------

// A 2x1 24-bit BMP (stb decodes it like a PNG): a red pixel, then a green one.
std::vector<uint8_t> twoPixelBmp() {
    std::vector<uint8_t> bmp = {
        'B', 'M', 62, 0, 0, 0, 0, 0, 0,    0,    54, 0, 0,    0,           // file header
        40,  0,   0,  0, 2, 0, 0, 0, 1,    0,    0,  0, 1,    0,    24, 0, // info header
        0,   0,   0,  0, 8, 0, 0, 0, 0x13, 0x0B, 0,  0, 0x13, 0x0B, 0,  0, 0, 0, 0, 0, 0, 0, 0, 0};
    const std::vector<uint8_t> pixels = {0, 0, 255, 0, 255, 0, 0, 0}; // BGR BGR, row padding
    bmp.insert(bmp.end(), pixels.begin(), pixels.end());
    return bmp;
}

// Triangle with a material whose base colour and normal textures use image 0 at `imageUri`.
GltfDocument texturedDocument(const std::string& imageUri) {
    GltfDocument document = triangleDocument();
    (*document)["meshes"][0]["primitives"][0]["material"] = 0;
    (*document)["materials"] = {
        {{"pbrMetallicRoughness",
          {{"baseColorTexture", {{"index", 0}}}, {"baseColorFactor", {0.5, 0.5, 0.5, 1}}}},
         {"normalTexture", {{"index", 0}}}}};
    (*document)["textures"] = {{{"source", 0}}};
    (*document)["images"] = {{{"uri", imageUri}}};
    return document;
}

TEST(GltfLoader, EmbeddedImageBecomesColourAndDataTextures) {
    const fs::path directory = testDirectory();
    const GltfDocument document =
        texturedDocument("data:image/bmp;base64," + base64(twoPixelBmp()));
    const Scene scene = scenes::loadGltf(writeFile(directory / "tex.gltf", document.gltfText()));
    EXPECT_TRUE(scene.warnings.empty());
    ASSERT_EQ(scene.textures.size(), 2u);
    const scenes::Material& material = scene.materials.at(0);
    const scenes::Texture& colour = scene.textures.at(size_t(material.baseColorTexture));
    const scenes::Texture& normal = scene.textures.at(size_t(material.normalTexture));
    EXPECT_TRUE(colour.srgb);
    EXPECT_FALSE(normal.srgb);
    EXPECT_EQ(colour.width, 2);
    EXPECT_EQ(colour.height, 1);
    EXPECT_EQ(colour.rgba8, (std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255}));
}

TEST(GltfLoader, MissingImageWarnsOnceAndFallsBackToFactors) {
    const fs::path directory = testDirectory();
    const Scene scene = scenes::loadGltf(
        writeFile(directory / "miss.gltf", texturedDocument("absent.png").gltfText()));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("absent.png"), std::string::npos) << scene.warnings[0];
    const scenes::Material& material = scene.materials.at(0);
    EXPECT_EQ(material.baseColorTexture, -1);
    EXPECT_EQ(material.normalTexture, -1);
    EXPECT_FLOAT_EQ(material.baseColorFactor.r, 0.5f);
    EXPECT_TRUE(scene.textures.empty());
}

TEST(GltfLoader, UndecodableImageWarnsAndFallsBack) {
    const fs::path directory = testDirectory();
    writeFile(directory / "garbage.png", "this is not a PNG");
    const Scene scene = scenes::loadGltf(
        writeFile(directory / "bad.gltf", texturedDocument("garbage.png").gltfText()));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("garbage.png"), std::string::npos) << scene.warnings[0];
    EXPECT_EQ(scene.materials.at(0).baseColorTexture, -1);
}

// ---- metallic-roughness materials -----------------------------------------------------------

// The triangle with normals, TEXCOORD_0 and TEXCOORD_1, and a material (given) over image 0, the
// two-pixel BMP.
GltfDocument materialDocument(const json& material) {
    GltfDocument document;
    const int positions = document.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    json& primitive = document.addPrimitive(positions, document.addIndices({0, 1, 2}), -1,
                                            document.addVec3({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}));
    const std::vector<glm::vec2> uv0 = {{0, 1}, {1, 1}, {0, 0}}, uv1 = {{0.5f, 0}, {1, 0}, {0, 1}};
    primitive["attributes"]["TEXCOORD_0"] = document.addAccessor(uv0, kFloat, "VEC2", 3);
    primitive["attributes"]["TEXCOORD_1"] = document.addAccessor(uv1, kFloat, "VEC2", 3);
    primitive["material"] = 0;
    // json::array, not {material}: a one-element brace list is a copy of the element under clang
    // and an array under gcc (nlohmann/json brace-initialisation), so clang built no materials.
    (*document)["materials"] = json::array({material});
    (*document)["textures"] = {{{"source", 0}}};
    (*document)["images"] = {{{"uri", "data:image/bmp;base64," + base64(twoPixelBmp())}}};
    return document;
}

TEST(GltfLoader, MaterialReadsEveryTextureInItsColourSpaceWithItsFactors) {
    const json material = {
        {"pbrMetallicRoughness",
         {{"baseColorTexture", {{"index", 0}}},
          {"metallicRoughnessTexture", {{"index", 0}}},
          {"metallicFactor", 0.25},
          {"roughnessFactor", 0.75}}},
        {"normalTexture", {{"index", 0}, {"scale", 0.5}}},
        {"occlusionTexture", {{"index", 0}, {"strength", 0.25}}},
        {"emissiveTexture", {{"index", 0}}},
        {"emissiveFactor", {1.0, 0.5, 0.0}},
        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 3.0}}}}},
        {"alphaMode", "MASK"},
        {"alphaCutoff", 0.3},
        {"doubleSided", true}};
    const Scene scene = scenes::loadGltf(
        writeFile(testDirectory() / "m.gltf", materialDocument(material).gltfText()));
    EXPECT_TRUE(scene.warnings.empty());
    const scenes::Material& m = scene.materials.at(0);
    EXPECT_EQ(m.model, scenes::MaterialModel::MetallicRoughness);
    EXPECT_EQ(m.metallic, 0.25f);
    EXPECT_EQ(m.roughness, 0.75f);
    EXPECT_EQ(m.normalScale, 0.5f);
    EXPECT_EQ(m.occlusionStrength, 0.25f);
    EXPECT_EQ(m.emissiveFactor, glm::vec3(1.0f, 0.5f, 0.0f));
    EXPECT_EQ(m.emissiveStrength, 3.0f);
    EXPECT_EQ(m.alphaMode, scenes::AlphaMode::Mask);
    EXPECT_FLOAT_EQ(m.alphaCutoff, 0.3f);
    EXPECT_TRUE(m.doubleSided);
    // One image, two colour spaces: base colour and emissive are sRGB, the rest linear data.
    ASSERT_EQ(scene.textures.size(), 2u);
    for (int colour : {m.baseColorTexture, m.emissiveTexture})
        EXPECT_TRUE(scene.textures.at(size_t(colour)).srgb);
    for (int data : {m.metallicRoughnessTexture, m.normalTexture, m.occlusionTexture})
        EXPECT_FALSE(scene.textures.at(size_t(data)).srgb);
    EXPECT_EQ(m.baseColorTexture, m.emissiveTexture);
    EXPECT_EQ(m.normalTexture, m.occlusionTexture);
    // The red texel decodes to 1 either way; a mid-grey would not (sRGB 0.5 is linear 0.214).
    EXPECT_FLOAT_EQ(scene.textures[size_t(m.baseColorTexture)].sample({0.25f, 0.5f}).r, 1.0f);
    // No TEXCOORD_1 is read when no texture uses it; tangents are generated for the normal map.
    const scenes::Mesh& mesh = scene.meshes.at(0);
    EXPECT_TRUE(mesh.uvs1.empty());
    ASSERT_EQ(mesh.tangents.size(), 3u);
    for (const glm::vec4& t : mesh.tangents) // u along +X, v down: bitangent +Y, w = +1
        EXPECT_EQ(t, glm::vec4(1, 0, 0, 1));
}

TEST(GltfLoader, TextureTransformAndSecondUvSet) {
    const json transform = {{"offset", {0.0, 1.0}}, {"rotation", 1.5}, {"scale", {0.5, 2.0}}};
    const json material = {
        {"pbrMetallicRoughness",
         {{"baseColorTexture",
           {{"index", 0},
            {"texCoord", 1},
            {"extensions", {{"KHR_texture_transform", transform}}}}}}},
        {"emissiveTexture",
         {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}}}};
    GltfDocument document = materialDocument(material);
    (*document)["extensionsUsed"] = {"KHR_texture_transform"};
    (*document)["extensionsRequired"] = {"KHR_texture_transform"};
    const Scene scene =
        scenes::loadGltf(writeFile(testDirectory() / "t.gltf", document.gltfText()));
    const scenes::Material& m = scene.materials.at(0);
    EXPECT_EQ(m.baseColorMapping.texCoord, 1);
    EXPECT_EQ(m.baseColorMapping.offset, glm::vec2(0.0f, 1.0f));
    EXPECT_EQ(m.baseColorMapping.rotationRadians, 1.5f);
    EXPECT_EQ(m.baseColorMapping.scale, glm::vec2(0.5f, 2.0f));
    EXPECT_EQ(m.emissiveMapping.texCoord, 1); // the extension's texCoord overrides the slot's
    EXPECT_TRUE(m.emissiveMapping.isIdentity());
    const scenes::Mesh& mesh = scene.meshes.at(0);
    ASSERT_EQ(mesh.uvs1.size(), 3u);
    EXPECT_EQ(mesh.uvs1[0], glm::vec2(0.5f, 0.0f));
    EXPECT_TRUE(mesh.tangents.empty()); // no normal map
}

TEST(GltfLoader, TexCoordPastOneWarnsAndFallsBackToTheFactor) {
    const json material = {
        {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", 2}}}}}};
    const Scene scene = scenes::loadGltf(
        writeFile(testDirectory() / "c.gltf", materialDocument(material).gltfText()));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("TEXCOORD_2"), std::string::npos) << scene.warnings[0];
    EXPECT_EQ(scene.materials.at(0).baseColorTexture, -1);
}

TEST(GltfLoader, BadMaterialValuesAreErrors) {
    const fs::path directory = testDirectory();
    struct Bad {
        json material;
        std::string detail;
    };
    for (const Bad& bad :
         {Bad{{{"alphaMode", "CUTOUT"}}, "alphaMode 'CUTOUT'"},
          Bad{{{"alphaCutoff", -0.5}}, "alphaCutoff"},
          Bad{{{"occlusionTexture", {{"index", 0}, {"strength", 2}}}}, "occlusionTexture.strength"},
          Bad{{{"emissiveFactor", {2, 0, 0}}}, "emissiveFactor outside [0, 1]"},
          Bad{{{"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -1}}}}}},
              "emissiveStrength"},
          Bad{{{"emissiveTexture",
                {{"index", 0},
                 {"extensions", {{"KHR_texture_transform", {{"offset", {1, 2, 3}}}}}}}}},
              "KHR_texture_transform.offset needs 2 numbers"}}) {
        const fs::path file =
            writeFile(directory / "bad.gltf", materialDocument(bad.material).gltfText());
        expectGltfError(file, bad.detail);
    }
}

TEST(GltfLoader, SharedModelsBringTheirMaterials) {
    const Scene helmet = scenes::loadGltf(sharedModel("DamagedHelmet/DamagedHelmet.gltf"));
    const scenes::Material& h = helmet.materials.at(0);
    EXPECT_EQ(h.model, scenes::MaterialModel::MetallicRoughness);
    for (int texture : h.textureIndices())
        EXPECT_GE(texture, 0); // all five slots are filled
    EXPECT_TRUE(helmet.textures.at(size_t(h.emissiveTexture)).srgb);
    EXPECT_FALSE(helmet.textures.at(size_t(h.metallicRoughnessTexture)).srgb);
    EXPECT_FALSE(helmet.textures.at(size_t(h.occlusionTexture)).srgb);
    EXPECT_EQ(h.emissiveFactor, glm::vec3(1.0f));
    // The helmet ships no tangents: they are generated for its normal map.
    for (const scenes::Mesh& mesh : helmet.meshes)
        EXPECT_EQ(mesh.tangents.size(), mesh.positions.size());

    // BoomBox's occlusion-roughness-metallic image is missing: those slots fall back to the
    // factors; its emissive and normal textures are there.
    const Scene boomBox = scenes::loadGltf(sharedModel("BoomBox/BoomBox.gltf"));
    const scenes::Material& b = boomBox.materials.at(0);
    EXPECT_EQ(b.metallicRoughnessTexture, -1);
    EXPECT_EQ(b.occlusionTexture, -1);
    EXPECT_GE(b.emissiveTexture, 0);
    EXPECT_GE(b.normalTexture, 0);
}

// ---- malformed files ------------------------------------------------------------------------

// Writes `document` (after `breakIt`) as NAME.gltf and expects a SceneError mentioning `detail`.
void expectBrokenGltf(const std::string& name, const std::function<void(json&)>& breakIt,
                      const std::string& detail, GltfDocument document = triangleDocument()) {
    breakIt(*document);
    const fs::path file = writeFile(testDirectory() / (name + ".gltf"), document.gltfText());
    expectGltfError(file, detail);
}

TEST(GltfLoaderErrors, BadJson) {
    expectGltfError(writeFile(testDirectory() / "bad.gltf", "{\"asset\": {\"version\": \"2.0\"},"),
                    "");
}

TEST(GltfLoaderErrors, MissingFile) {
    expectGltfError(testDirectory() / "nowhere.gltf", "file not found");
}

TEST(GltfLoaderErrors, MissingBufferFile) {
    const fs::path directory = testDirectory();
    json document = json::parse(triangleDocument().gltfText());
    document["buffers"][0]["uri"] = "missing.bin";
    expectGltfError(writeFile(directory / "nobin.gltf", document.dump()), "missing.bin");
}

TEST(GltfLoaderErrors, AccessorPastTheEndOfItsBufferView) {
    expectBrokenGltf(
        "acc", [](json& d) { d["accessors"][0]["count"] = 1000; }, "run past the end");
    expectBrokenGltf(
        "offset", [](json& d) { d["accessors"][0]["byteOffset"] = 4; }, "run past the end");
}

TEST(GltfLoaderErrors, BufferViewPastTheEndOfItsBuffer) {
    expectBrokenGltf(
        "view", [](json& d) { d["bufferViews"][0]["byteOffset"] = 40; }, "past the end of buffer");
}

TEST(GltfLoaderErrors, AccessorIndicesOutOfRange) {
    expectBrokenGltf(
        "pos", [](json& d) { d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9; },
        "accessor 9 out of range");
    expectBrokenGltf(
        "bv", [](json& d) { d["accessors"][1]["bufferView"] = 7; }, "bufferView");
}

TEST(GltfLoaderErrors, WrongAccessorType) {
    expectBrokenGltf(
        "type", [](json& d) { d["accessors"][0]["type"] = "VEC4"; }, "expected VEC3");
}

TEST(GltfLoaderErrors, IndexOutOfRangeOfVertices) {
    GltfDocument document;
    const int positions = document.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    document.addPrimitive(positions, document.addIndices({0, 1, 7}));
    expectBrokenGltf(
        "index", [](json&) {}, "index 7", document);
}

TEST(GltfLoaderErrors, NanPosition) {
    GltfDocument document;
    const float nan = std::nanf("");
    document.addPrimitive(document.addVec3({{0, 0, 0}, {1, nan, 0}, {0, 1, 0}}));
    expectBrokenGltf(
        "nan", [](json&) {}, "NaN", document);
}

TEST(GltfLoaderErrors, IncompleteTriangleList) {
    GltfDocument document;
    document.addPrimitive(document.addVec3({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}));
    expectBrokenGltf(
        "four", [](json&) {}, "whole triangles", document);
}

TEST(GltfLoaderErrors, CyclicNodes) {
    expectBrokenGltf(
        "cycle",
        [](json& d) {
            d["nodes"] = {{{"mesh", 0}, {"children", {1}}}, {{"children", {0}}}};
        },
        "cyclic");
    expectBrokenGltf(
        "self", [](json& d) { d["nodes"][0]["children"] = {0}; }, "cyclic");
}

TEST(GltfLoaderErrors, NodeWithTwoParents) {
    expectBrokenGltf(
        "dag",
        [](json& d) {
            d["nodes"] = {{{"children", {2}}}, {{"children", {2}}}, {{"mesh", 0}}};
            d["scenes"][0]["nodes"] = {0, 1};
        },
        "more than one node");
}

TEST(GltfLoaderErrors, TooDeepHierarchy) {
    expectBrokenGltf(
        "deep",
        [](json& d) {
            d["nodes"] = json::array();
            for (int n = 0; n < 2000; ++n)
                d["nodes"].push_back({{"children", {n + 1}}});
            d["nodes"].push_back({{"mesh", 0}});
        },
        "deeper than");
}

TEST(GltfLoaderErrors, ReferencesOutOfRange) {
    expectBrokenGltf(
        "mesh", [](json& d) { d["nodes"][0]["mesh"] = 5; }, "mesh 5 out of range");
    expectBrokenGltf(
        "node", [](json& d) { d["scenes"][0]["nodes"] = {3}; }, "node 3 out of range");
    expectBrokenGltf(
        "child", [](json& d) { d["nodes"][0]["children"] = {4}; }, "child 4 out of range");
    expectBrokenGltf(
        "material", [](json& d) { d["meshes"][0]["primitives"][0]["material"] = 2; },
        "material 2 out of range");
    expectBrokenGltf(
        "camera", [](json& d) { d["nodes"][0]["camera"] = 1; }, "camera 1 out of range");
    expectBrokenGltf(
        "scene", [](json& d) { d["scene"] = 3; }, "scene 3 out of range");
    expectBrokenGltf(
        "texture",
        [](json& d) {
            d["meshes"][0]["primitives"][0]["material"] = 0;
            d["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 6}}}}}}};
        },
        "texture 6 out of range");
}

TEST(GltfLoaderErrors, EmptyScene) {
    expectBrokenGltf(
        "empty", [](json& d) { d["scenes"][0]["nodes"] = json::array(); }, "no triangles");
    expectBrokenGltf(
        "points", [](json& d) { d["meshes"][0]["primitives"][0]["mode"] = kPoints; },
        "no triangles");
}

TEST(GltfLoaderErrors, UnsupportedRequiredExtension) {
    expectBrokenGltf(
        "draco",
        [](json& d) {
            d["extensionsUsed"] = {"KHR_draco_mesh_compression"};
            d["extensionsRequired"] = {"KHR_draco_mesh_compression"};
        },
        "KHR_draco_mesh_compression");
}

TEST(GltfLoaderErrors, TruncatedGlb) {
    const fs::path directory = testDirectory();
    const std::string glb = triangleDocument().glbBytes();
    expectGltfError(writeFile(directory / "short.glb", glb.substr(0, glb.size() - 4)), "length");
    // Consistent total length, but a BIN chunk claiming more bytes than the file holds.
    std::string lying = glb;
    const uint32_t jsonLength = *reinterpret_cast<const uint32_t*>(lying.data() + 12);
    const uint32_t binLength =
        *reinterpret_cast<const uint32_t*>(lying.data() + 20 + jsonLength) + 4;
    std::memcpy(lying.data() + 20 + jsonLength, &binLength, 4);
    expectGltfError(writeFile(directory / "lying.glb", lying), "BIN chunk");
}

// ---- loadScene ------------------------------------------------------------------------------

TEST(LoadScene, MissingGltfFileIsNamed) {
    const fs::path file = testDirectory() / "absent.gltf";
    try {
        scenes::loadScene(file.string(), {});
        ADD_FAILURE() << "no SceneError";
    } catch (const SceneError& error) {
        EXPECT_EQ(std::string(error.what()), file.string() + ": file not found");
    }
}

TEST(LoadScene, UnknownExtensionAndUnknownName) {
    const fs::path file = writeFile(testDirectory() / "notes.txt", "hello");
    expectSceneError([&] { return scenes::loadScene(file.string(), {}); }, file,
                     "unknown scene file type");
    try {
        scenes::loadScene("no-such-scene", {});
        ADD_FAILURE() << "no SceneError";
    } catch (const SceneError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("no-such-scene"), std::string::npos) << message;
        EXPECT_NE(message.find("atrium"), std::string::npos) << message;
        EXPECT_NE(message.find("spheres"), std::string::npos) << message;
    }
}

TEST(LoadScene, GltfRejectsOptions) {
    const fs::path file = sharedModel("Suzanne/Suzanne.gltf");
    scenes::SceneRequest request;
    request.options["behind"] = "10";
    expectSceneError([&] { return scenes::loadScene(file.string(), request); }, file, "behind");
}

TEST(LoadScene, GltfWithoutLightsGetsGeneratedLights) {
    scenes::SceneRequest request;
    request.lightCount = 16;
    request.seed = 7;
    const Scene scene = scenes::loadScene(sharedModel("Suzanne/Suzanne.gltf").string(), request);
    // The 16 generated point lights plus the default ambient and key light of a light-less model.
    ASSERT_EQ(scene.lights.size(), 18u);
    EXPECT_EQ(scene.lights[0].type, scenes::LightType::Ambient);
    EXPECT_EQ(scene.lights[1].type, scenes::LightType::Directional);
    for (size_t i = 2; i < scene.lights.size(); ++i)
        EXPECT_EQ(scene.lights[i].type, scenes::LightType::Point);
    EXPECT_EQ(scene.triangleCount(), 3936u);
    const Scene again = scenes::loadScene(sharedModel("Suzanne/Suzanne.gltf").string(), request);
    ASSERT_EQ(again.lights.size(), 18u);
    expectNear(again.lights[5].positionWorld, scene.lights[5].positionWorld, 0.0f);
}

} // namespace
