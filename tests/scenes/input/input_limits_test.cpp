// Hostile scene inputs (issue 15): every one must end in one SceneError naming the file, or in a
// warning where scenes/README.md says the problem is not fatal; never a crash, a std::bad_alloc
// or an allocation of the size the file claims. Covered: nesting far past
// limits::kMaxNestingDepth in glTF extras, a GLB's JSON chunk and JSON scenes (and the pre-scans
// themselves, on strings, escapes and TOML's ways to nest); URIs naming a folder; an image whose
// header declares more pixels than the texture limit; accessors shared so that a small file asks
// for more vertices or triangles than the limits; KHR_lights_punctual values outside the
// extension's rules; light counts over limits::kMaxLights. Every input is generated here; the
// large ones (a few MiB) at run time.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scenes/SceneLoader.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using scenes::SceneError;
namespace limits = scenes::limits;

constexpr int kDeep = 100000; // levels: overflowed the stack inside tinygltf before the bound

fs::path testDirectory() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path directory =
        fs::path(::testing::TempDir()) /
        (std::string("input_limits_test.") + test->test_suite_name() + "." + test->name());
    fs::remove_all(directory);
    fs::create_directories(directory);
    return directory;
}

fs::path writeFile(const fs::path& path, const std::string& contents) {
    std::ofstream(path, std::ios::binary) << contents;
    return path;
}

std::string nested(const std::string& open, const std::string& close, int levels,
                   const std::string& inner = "0") {
    std::string text;
    text.reserve(size_t(levels) * (open.size() + close.size()) + inner.size());
    for (int i = 0; i < levels; ++i)
        text += open;
    text += inner;
    for (int i = 0; i < levels; ++i)
        text += close;
    return text;
}

// One triangle in a buffer file beside the model (positions only), drawn by node 0; `extra` is
// merged into the document.
json triangleDocument(const fs::path& directory) {
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::string bytes(reinterpret_cast<const char*>(positions), sizeof positions);
    writeFile(directory / "triangle.bin", bytes);
    return {{"asset", {{"version", "2.0"}}},
            {"buffers", {{{"uri", "triangle.bin"}, {"byteLength", 36}}}},
            {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
            {"accessors",
             {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
            {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"scenes", {{{"nodes", {0}}}}},
            {"scene", 0}};
}

std::string errorOf(const fs::path& path) {
    try {
        scenes::loadGltf(path);
    } catch (const SceneError& error) {
        return error.what();
    }
    return "(no error)";
}

TEST(NestingDepth, JsonCountsBracketsOutsideStringsOnly) {
    scenes::NestingViolation violation;
    EXPECT_FALSE(scenes::jsonNestsDeeperThan(nested("[", "]", 3), 3, &violation));
    EXPECT_TRUE(scenes::jsonNestsDeeperThan(nested("[", "]", 4), 3, &violation));
    EXPECT_EQ(violation.offset, 3u);
    EXPECT_EQ(violation.line, 1u);
    EXPECT_TRUE(scenes::jsonNestsDeeperThan("{\n\"a\": [\n[[]]]}", 3, &violation));
    EXPECT_EQ(violation.line, 3u);
    // Brackets inside strings, also after escaped quotes and backslashes, do not nest.
    EXPECT_FALSE(
        scenes::jsonNestsDeeperThan(R"({"a": "[[[[\"[[[[", "b": "\\", "c": [1]})", 2, &violation));
    EXPECT_TRUE(scenes::jsonNestsDeeperThan(R"({"a": "\\", "c": [[1]]})", 2, &violation));
    // Siblings do not add up.
    EXPECT_FALSE(scenes::jsonNestsDeeperThan("[[],[],[[]],{}]", 3, &violation));
    // Malformed text never makes the scan fail or under-count.
    EXPECT_FALSE(scenes::jsonNestsDeeperThan("]]]]}}\"", 1, &violation));
    EXPECT_TRUE(scenes::jsonNestsDeeperThan("]][[", 1, &violation));
}

TEST(NestingDepth, TomlCountsHeadersDottedKeysArraysAndInlineTables) {
    scenes::NestingViolation violation;
    auto deeper = [&](const std::string& text, int maxDepth) {
        return scenes::tomlNestsDeeperThan(text, maxDepth, &violation);
    };
    EXPECT_FALSE(deeper("a = 1\n[t]\nb = 2\n", 2));
    EXPECT_TRUE(deeper("a = 1\n[t]\nb = 2\n", 1)); // b is inside t
    EXPECT_FALSE(deeper("a.b.c = 1\n", 3));
    EXPECT_TRUE(deeper("a.b.c = 1\n", 2));
    EXPECT_FALSE(deeper("[a.b]\nc = 1\n", 3));
    EXPECT_TRUE(deeper("[a.b]\nc.d = 1\n", 3));
    EXPECT_TRUE(deeper("[[a.b]]\nc = 1\n", 3)); // the array of tables is a level too
    EXPECT_FALSE(deeper("a = [[1], [2]]\n", 3));
    EXPECT_TRUE(deeper("a = [[[1]]]\n", 3));
    EXPECT_FALSE(deeper("a = {b = {c.d = 1}}\n", 4)); // a, b, c, d
    EXPECT_TRUE(deeper("a = {b = {c.d = 1}}\n", 3));
    EXPECT_FALSE(deeper("a = {b = 1, c = [1]}\n", 3));
    // Dots and brackets in strings, comments, multi-line strings and float values do not nest.
    EXPECT_FALSE(deeper("\"a.b.c\" = 'x.[y'\n# [[[[a.b.c]]]]\nd = 1.5\n", 1));
    EXPECT_FALSE(deeper("a = \"\"\"\n[[[\n\"\"\"\nb = '''[[.'''\n", 1));
    EXPECT_FALSE(deeper("'q.r' = \"\\\"[[[\"\n", 1));
    // Multi-line arrays keep their level across lines (a is level 1, its array's elements 2).
    EXPECT_TRUE(deeper("a = [\n[\n[1]\n]\n]\n", 2));
    EXPECT_EQ(violation.line, 2u);
    // What crashed toml++ itself: 10^5 dotted key segments or header segments.
    EXPECT_TRUE(deeper(nested("a.", "", kDeep, "a = 1\n"), limits::kMaxNestingDepth));
    EXPECT_TRUE(deeper("[" + nested("a.", "", kDeep, "a]\n"), limits::kMaxNestingDepth));
}

TEST(InputLimits, DeeplyNestedGltfExtrasAreRefused) {
    const fs::path directory = testDirectory();
    json document = triangleDocument(directory);
    document["extras"] = "PLACEHOLDER";
    std::string text = document.dump();
    text.replace(text.find("\"PLACEHOLDER\""), 13, nested("{\"a\":", "}", kDeep));
    const fs::path path = writeFile(directory / "deep.gltf", text);
    const std::string error = errorOf(path);
    EXPECT_NE(error.find("deep.gltf: JSON nests deeper than 256 levels"), std::string::npos)
        << error;

    // At the limit the same document loads (extras are not used, only parsed).
    text = document.dump();
    text.replace(text.find("\"PLACEHOLDER\""), 13, nested("[", "]", limits::kMaxNestingDepth - 1));
    EXPECT_NO_THROW(scenes::loadGltf(writeFile(directory / "at-limit.gltf", text)));
}

TEST(InputLimits, DeeplyNestedGlbJsonChunkIsRefused) {
    const fs::path directory = testDirectory();
    std::string jsonText =
        "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + nested("[", "]", kDeep) + "}";
    while (jsonText.size() % 4 != 0)
        jsonText += ' ';
    std::string glb = "glTF";
    auto word = [&](uint32_t value) { glb.append(reinterpret_cast<const char*>(&value), 4); };
    word(2);
    word(uint32_t(12 + 8 + jsonText.size()));
    word(uint32_t(jsonText.size()));
    word(0x4E4F534A);
    glb += jsonText;
    const std::string error = errorOf(writeFile(directory / "deep.glb", glb));
    EXPECT_NE(error.find("deep.glb: JSON nests deeper than 256 levels"), std::string::npos)
        << error;
}

TEST(InputLimits, DeeplyNestedJsonSceneIsRefused) {
    const fs::path directory = testDirectory();
    const fs::path path =
        writeFile(directory / "deep.json", "{\"objects\": " + nested("[", "]", kDeep) + "}");
    try {
        scenes::loadScene(path.string(), {});
        FAIL() << "no error";
    } catch (const SceneError& error) {
        EXPECT_NE(std::string(error.what()).find("nests deeper than 256 levels"), std::string::npos)
            << error.what();
    }
}

TEST(InputLimits, JsonSceneNumberPastDoubleIsAnError) {
    // nlohmann reports it as out_of_range, not parse_error (sweep_fuzzer found it in sweeps).
    const fs::path directory = testDirectory();
    const fs::path path = writeFile(directory / "overflow.json", "{\"objects\": [1e999]}");
    try {
        scenes::loadScene(path.string(), {});
        FAIL() << "no error";
    } catch (const SceneError& error) {
        EXPECT_NE(std::string(error.what()).find("overflow.json: invalid JSON"), std::string::npos)
            << error.what();
    }
}

TEST(InputLimits, BufferUriNamingAFolderIsAnError) {
    const fs::path directory = testDirectory();
    json document = triangleDocument(directory);
    document["buffers"][0]["uri"] = ".";
    const std::string error = errorOf(writeFile(directory / "folder-buffer.gltf", document.dump()));
    EXPECT_NE(error.find("folder-buffer.gltf: "), std::string::npos) << error;
    EXPECT_EQ(error.find("bad_alloc"), std::string::npos) << error;
}

TEST(InputLimits, ImageUriNamingAFolderIsAWarningAndTheFactorIsUsed) {
    const fs::path directory = testDirectory();
    json document = triangleDocument(directory);
    document["images"] = {{{"uri", "."}}};
    document["textures"] = {{{"source", 0}}};
    document["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    document["meshes"][0]["primitives"][0]["material"] = 0;
    const scenes::Scene scene =
        scenes::loadGltf(writeFile(directory / "folder-image.gltf", document.dump()));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("image 0 '.' is not a regular file"), std::string::npos)
        << scene.warnings[0];
    EXPECT_EQ(scene.materials.at(0).baseColorTexture, -1);
}

// A PNG that is only a signature and an IHDR chunk declaring width x height RGBA8: enough for the
// header check; decoding it would ask for width * height * 4 bytes.
std::string pngHeader(uint32_t width, uint32_t height) {
    auto bigEndian = [](uint32_t value) {
        return std::string{char(value >> 24), char(value >> 16), char(value >> 8), char(value)};
    };
    std::string png = "\x89PNG\r\n\x1a\n";
    png += bigEndian(13) + "IHDR" + bigEndian(width) + bigEndian(height);
    png += std::string{8, 6, 0, 0, 0};
    png += bigEndian(0); // CRC: stb_image does not check it
    return png;
}

TEST(InputLimits, ImageDeclaringTooManyPixelsIsNotDecoded) {
    const fs::path directory = testDirectory();
    writeFile(directory / "huge.png", pngHeader(16384, 16384)); // 2^28 pixels: 1 GiB as RGBA8
    json document = triangleDocument(directory);
    document["images"] = {{{"uri", "huge.png"}}};
    document["textures"] = {{{"source", 0}}};
    document["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    document["meshes"][0]["primitives"][0]["material"] = 0;
    const scenes::Scene scene =
        scenes::loadGltf(writeFile(directory / "huge-image.gltf", document.dump()));
    ASSERT_EQ(scene.warnings.size(), 1u);
    EXPECT_NE(scene.warnings[0].find("is 16384x16384, over the texture limit"), std::string::npos)
        << scene.warnings[0];
    EXPECT_EQ(scene.materials.at(0).baseColorTexture, -1);
}

// 3 vertices and 3 * 2^20 byte indices (one triangle repeated) in a 3 MiB buffer; the mesh is
// placed by `nodes` nodes, so the file asks for nodes * 2^20 drawn triangles.
json repeatedTriangleDocument(const fs::path& directory, int nodes, int primitives) {
    const size_t indexCount = size_t(3) << 20;
    std::string bytes(36 + indexCount, '\0');
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::memcpy(bytes.data(), positions, 36);
    for (size_t i = 0; i < indexCount; ++i)
        bytes[36 + i] = char(i % 3);
    writeFile(directory / "repeated.bin", bytes);
    json document = {
        {"asset", {{"version", "2.0"}}},
        {"buffers", {{{"uri", "repeated.bin"}, {"byteLength", bytes.size()}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteLength", 36}},
          {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", indexCount}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5121}, {"count", indexCount}, {"type", "SCALAR"}}}},
        {"meshes", {{{"primitives", json::array()}}}},
        {"nodes", json::array()},
        {"scenes", {{{"nodes", json::array()}}}},
        {"scene", 0}};
    for (int p = 0; p < primitives; ++p)
        document["meshes"][0]["primitives"].push_back(
            {{"attributes", {{"POSITION", 0}}}, {"indices", 1}});
    for (int n = 0; n < nodes; ++n) {
        document["nodes"].push_back({{"mesh", 0}});
        document["scenes"][0]["nodes"].push_back(n);
    }
    return document;
}

TEST(InputLimits, SharedAccessorsCannotAskForMoreTrianglesThanTheLimit) {
    const fs::path directory = testDirectory();
    // 65 placements of 2^20 triangles: one placement more than limits::kMaxTriangles = 2^26.
    static_assert(limits::kMaxTriangles == uint64_t(64) << 20);
    const fs::path path =
        writeFile(directory / "many.gltf", repeatedTriangleDocument(directory, 65, 1).dump());
    const std::string error = errorOf(path);
    EXPECT_NE(error.find("many.gltf: the instances would draw 68157440 triangles"),
              std::string::npos)
        << error;
    // Two primitives in one placement are counted the same way.
    const fs::path primitives =
        writeFile(directory / "primitives.gltf", repeatedTriangleDocument(directory, 1, 65).dump());
    EXPECT_NE(errorOf(primitives).find("would draw 68157440 triangles"), std::string::npos);
}

TEST(InputLimits, SharedAccessorsCannotAskForMoreVerticesThanTheLimit) {
    const fs::path directory = testDirectory();
    // 2^20 vertices (12 MiB) used by 65 primitives: 65 * 2^20 > limits::kMaxVertices = 2^26.
    static_assert(limits::kMaxVertices == uint64_t(64) << 20);
    const size_t vertexCount = size_t(1) << 20;
    writeFile(directory / "vertices.bin", std::string(vertexCount * 12, '\0'));
    json document = {
        {"asset", {{"version", "2.0"}}},
        {"buffers", {{{"uri", "vertices.bin"}, {"byteLength", vertexCount * 12}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteLength", vertexCount * 12}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", vertexCount}, {"type", "VEC3"}}}},
        {"meshes", {{{"primitives", json::array()}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"scenes", {{{"nodes", {0}}}}},
        {"scene", 0}};
    for (int p = 0; p < 65; ++p)
        document["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 0}}}});
    const std::string error = errorOf(writeFile(directory / "vertices.gltf", document.dump()));
    EXPECT_NE(error.find("the meshes would store 68157440 vertices (about 3.0 GiB)"),
              std::string::npos)
        << error;
}

TEST(InputLimits, JsonScenePlacementsCannotDrawMoreTrianglesThanTheLimit) {
    const fs::path directory = testDirectory();
    writeFile(directory / "model.gltf", repeatedTriangleDocument(directory, 1, 1).dump());
    json scene = {{"objects", json::array()}};
    for (int i = 0; i < 65; ++i) // 65 placements of 2^20 triangles: one over 2^26
        scene["objects"].push_back({{"gltf", "model.gltf"}});
    const fs::path path = writeFile(directory / "placed.json", scene.dump());
    try {
        scenes::loadScene(path.string(), {});
        FAIL() << "no error";
    } catch (const SceneError& error) {
        EXPECT_NE(std::string(error.what())
                      .find("objects[64]: the objects placed so far and this one draw 68157440 "
                            "triangles, over the limit of 67108864"),
                  std::string::npos)
            << error.what();
    }
}

struct LightCase {
    const char* name;
    json light;
    const char* expected; // in the error, or "" when the light is valid
};

class GltfLights : public ::testing::TestWithParam<LightCase> {};

TEST_P(GltfLights, AreCheckedAgainstTheExtensionsRules) {
    const fs::path directory = testDirectory();
    json document = triangleDocument(directory);
    document["extensionsUsed"] = {"KHR_lights_punctual"};
    document["extensions"] = {{"KHR_lights_punctual", {{"lights", {GetParam().light}}}}};
    document["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    document["scenes"][0]["nodes"].push_back(1);
    const fs::path path = writeFile(directory / "light.gltf", document.dump());
    const std::string expected = GetParam().expected;
    if (expected.empty()) {
        EXPECT_EQ(scenes::loadGltf(path).lights.size(), 1u);
        return;
    }
    const std::string error = errorOf(path);
    EXPECT_NE(error.find("KHR_lights_punctual light 0: " + expected), std::string::npos) << error;
}

json spot(double inner, double outer) {
    json light = {{"type", "spot"}, {"range", 5.0}};
    light["spot"] = {{"innerConeAngle", inner}, {"outerConeAngle", outer}};
    return light;
}

INSTANTIATE_TEST_SUITE_P(
    InputLimits, GltfLights,
    ::testing::Values(
        LightCase{"valid_point", {{"type", "point"}, {"range", 2.0}}, ""},
        LightCase{"valid_spot", spot(0.1, 0.5), ""},
        LightCase{"valid_spot_right_angle", spot(0.0, 1.5707963267948966), ""},
        LightCase{"negative_range", {{"type", "point"}, {"range", -1.0}}, "range must be"},
        LightCase{"negative_intensity", {{"type", "point"}, {"intensity", -2.0}}, "intensity"},
        LightCase{"negative_color", {{"type", "point"}, {"color", {1, -1, 1}}}, "color"},
        LightCase{"inner_equals_outer", spot(0.5, 0.5), "spot cone angles"},
        LightCase{"inner_above_outer", spot(0.6, 0.5), "spot cone angles"},
        LightCase{"negative_inner", spot(-0.1, 0.5), "spot cone angles"},
        LightCase{"outer_past_right_angle", spot(0.1, 1.6), "spot cone angles"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(InputLimits, JsonSceneLightGeneratorCountHasTheCliLimit) {
    const fs::path directory = testDirectory();
    for (const int64_t count :
         {int64_t(limits::kMaxLights) + 1, int64_t(2147483647), int64_t(1) << 40}) {
        const json scene = {{"objects", {{{"procedural", "spheres"}}}},
                            {"lightGenerator", {{"count", count}}}};
        const fs::path path = writeFile(directory / "lights.json", scene.dump());
        try {
            scenes::loadScene(path.string(), {});
            FAIL() << "no error for " << count;
        } catch (const SceneError& error) {
            EXPECT_NE(std::string(error.what())
                          .find("lightGenerator.count: " + std::to_string(count) +
                                " lights, over the limit of 1000000"),
                      std::string::npos)
                << error.what();
        }
    }
}

} // namespace
