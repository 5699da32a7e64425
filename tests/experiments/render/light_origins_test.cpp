// Where a render's lights come from (issue 16): a JSON scene's lightGenerator.count is used
// unless the light count is given (--lights, a sweep's `lights`), built-in scenes get the
// default 256, and LightOrigins says how many lights came from where.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "experiments/render/LightOrigins.h"
#include "experiments/render/RenderOptions.h"
#include "experiments/render/RenderPlan.h"
#include "experiments/sweep/SweepFile.h"
#include "tests/experiments/TestFolders.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using experiments::test_files::freshTestFolder;

// Spheres (its options: one ambient light, no sun) with two explicit lights and a generator of 5.
fs::path writeJsonScene(const fs::path& dir) {
    const nlohmann::json document = {
        {"objects", {{{"procedural", "spheres"}, {"options", {{"ambient", true}}}}}},
        {"lights",
         {{{"type", "point"}, {"position", {0, 2, 0}}, {"range", 3}, {"intensity", 1}},
          {{"type", "directional"}, {"direction", {0, -1, 0}}, {"intensity", 1}}}},
        {"lightGenerator", {{"count", 5}, {"seed", 3}}}};
    const fs::path path = dir / "generated.json";
    std::ofstream(path) << document.dump(2);
    return path;
}

TEST(LightOrigins, AJsonScenesGeneratorCountWinsOverTheDefault) {
    RenderOptions options;
    options.scene = writeJsonScene(freshTestFolder()).string();
    EXPECT_FALSE(requestedLights(options).has_value());
    const scenes::Scene scene = loadRequestedScene(options);
    EXPECT_EQ(scene.lights.size(), 8u); // 5 generated + 2 explicit + the ambient
    EXPECT_EQ(scene.generatedLightCount, 5);
    const LightOrigins origins = lightOrigins(options, scene);
    EXPECT_EQ(origins.generated, 5);
    EXPECT_EQ(origins.generatedBy, "lightGenerator");
    EXPECT_EQ(origins.point, 1);
    EXPECT_EQ(origins.directional, 1);
    EXPECT_EQ(origins.ambient, 1);
    EXPECT_EQ(origins.summary(), "8 = 5 generated (the file's lightGenerator) + 1 point + 1 "
                                 "directional + 1 ambient (the file's own)");
    EXPECT_EQ(lightsText(options), "file");
}

TEST(LightOrigins, AGivenLightCountReplacesTheGenerator) {
    RenderOptions options;
    options.scene = writeJsonScene(freshTestFolder()).string();
    options.lights = 12;
    scenes::Scene scene = loadRequestedScene(options);
    EXPECT_EQ(scene.lights.size(), 15u);
    EXPECT_EQ(lightOrigins(options, scene).summary(),
              "15 = 12 generated (--lights 12) + 1 point + 1 directional + 1 ambient (the "
              "file's own)");
    // Zero given is zero, not "the file's".
    options.lights = 0;
    scene = loadRequestedScene(options);
    EXPECT_EQ(scene.lights.size(), 3u);
    EXPECT_EQ(scene.generatedLightCount, 0);
    EXPECT_EQ(lightOrigins(options, scene).summary(),
              "3 = 0 generated (--lights 0) + 1 point + 1 directional + 1 ambient (the file's "
              "own)");
}

TEST(LightOrigins, BuiltInScenesGetTheDefaultCount) {
    RenderOptions options;
    options.scene = "spheres";
    options.sceneOptions = {{"ambient", "1"}, {"sun", "1"}};
    EXPECT_EQ(requestedLights(options), kDefaultLights);
    const scenes::Scene scene = loadRequestedScene(options);
    EXPECT_EQ(scene.generatedLightCount, kDefaultLights);
    EXPECT_EQ(lightOrigins(options, scene).summary(),
              "258 = 256 generated (--lights default 256) + 1 directional + 1 ambient (the "
              "built-in scene's own)");
    EXPECT_EQ(lightOrigins(options, scene).toJson()["generated_by"], "--lights default");
    EXPECT_EQ(lightsText(options), "256");
}

TEST(LightOrigins, SweepKeysOfBuiltInScenesAreThoseOfAnExplicitDefault) {
    // A sweep that does not set `lights` keeps the reference keys of one that sets 256.
    nlohmann::ordered_json sweep = {{"name", "keys"},
                                    {"fixed", {{"scene", "spheres"}, {"resolution", "32x18"}}},
                                    {"axes", {{"stage", {"brute"}}}}};
    const SweepExpansion unset = expandSweep(parseSweep(sweep, "keys.json"));
    sweep["fixed"]["lights"] = kDefaultLights;
    const SweepExpansion given = expandSweep(parseSweep(sweep, "keys.json"));
    ASSERT_EQ(unset.jobs().size(), 1u);
    EXPECT_EQ(unset.jobs()[0].referenceKey, given.jobs()[0].referenceKey);
    EXPECT_NE(unset.jobs()[0].referenceKey.find("-256l-"), std::string::npos);
}

} // namespace
} // namespace experiments
