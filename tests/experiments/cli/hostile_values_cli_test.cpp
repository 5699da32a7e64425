// Hostile values through `testbed render` (issue 32, classes 1 and 2): every file of the scene
// side's hand-made corpus (tests/scenes/input/hostile-values/cases.txt) that must be refused
// ends in exactly one "testbed: error:" line naming the file and the field, exit code 1, and no
// output folder; and a render in which no pixel is covered warns in the summary, on stderr and in
// stats.json ("coverage", "warnings"), whether the geometry lies in front of the camera or not,
// while a render that covers pixels does not. Every command runs under `timeout` (a hang
// detector, not a timing).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/experiments/TestFolders.h"
#include "tests/experiments/cli/CliRun.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using experiments::test_files::freshTestFolder;
using experiments::test_files::readText;

using clitest::kTestbed;
const fs::path kCorpus =
    fs::path(TESTBED_SOURCE_DIR) / "tests" / "scenes" / "input" / "hostile-values";
using CommandResult = clitest::SeparateRun;
using clitest::lineCount;

CommandResult render(const fs::path& scene, const fs::path& out, const fs::path& dir) {
    return clitest::runSeparately("render --scene '" + scene.string() +
                                      "' --width 64 --height 48 --lights 4 --out '" + out.string() +
                                      "'",
                                  dir);
}

std::string trim(const std::string& text) {
    const size_t first = text.find_first_not_of(' ');
    const size_t last = text.find_last_not_of(' ');
    return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

TEST(HostileValuesCli, EveryRefusedCorpusFileIsOneErrorLineAndNoOutput) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshTestFolder();
    std::ifstream cases(kCorpus / "cases.txt");
    ASSERT_TRUE(cases);
    int refused = 0;
    for (std::string line; std::getline(cases, line);) {
        if (line.empty() || line[0] == '#')
            continue;
        std::vector<std::string> parts;
        std::stringstream fields(line);
        for (std::string part; std::getline(fields, part, '|');)
            parts.push_back(trim(part));
        if (parts.size() < 2 || parts[1] == "OK")
            continue;
        SCOPED_TRACE(parts[0]);
        ++refused;
        const fs::path scene = kCorpus / parts[0];
        const fs::path out = dir / ("out-" + parts[0]);
        const CommandResult run = render(scene, out, dir);
        EXPECT_EQ(run.exitCode, 1) << run.stderrText;
        EXPECT_EQ(lineCount(run.stderrText), 1) << run.stderrText;
        EXPECT_EQ(run.stderrText.rfind("testbed: error: " + scene.string() + ": ", 0), 0u)
            << run.stderrText;
        for (size_t i = 1; i < parts.size(); ++i)
            EXPECT_NE(run.stderrText.find(parts[i]), std::string::npos)
                << "'" << parts[i] << "' not in: " << run.stderrText;
        EXPECT_FALSE(fs::exists(out)) << "a refused scene left " << out;
    }
    EXPECT_GE(refused, 14);
}

void writeFile(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

nlohmann::json statsOf(const fs::path& out) {
    return nlohmann::json::parse(readText(out / "stats.json"));
}

// The warning: in the summary (stdout, "WARNING:"), on stderr ("testbed: warning:"), in
// stats.json's coverage block and its warnings list; exit code 0 (the render is not invalid).
void expectCoverageWarning(const CommandResult& run, const fs::path& out,
                           const std::string& fragment, int64_t trianglesInFront) {
    EXPECT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_NE(run.stdoutText.find("  WARNING: " + fragment), std::string::npos) << run.stdoutText;
    EXPECT_NE(run.stderrText.find("testbed: warning: " + fragment), std::string::npos)
        << run.stderrText;
    const nlohmann::json stats = statsOf(out);
    EXPECT_EQ(stats["coverage"]["covered_pixels"], 0);
    EXPECT_EQ(stats["coverage"]["triangles_in_front"], trianglesInFront);
    ASSERT_TRUE(stats["coverage"]["warning"].is_string());
    EXPECT_NE(stats["coverage"]["warning"].get<std::string>().find(fragment), std::string::npos);
    bool listed = false;
    for (const nlohmann::json& warning : stats["warnings"])
        listed = listed || warning.get<std::string>().find(fragment) != std::string::npos;
    EXPECT_TRUE(listed) << stats["warnings"].dump();
}

TEST(HostileValuesCli, NoCoveredPixelWarnsWithGeometryInFront) {
    const fs::path dir = freshTestFolder();
    // The spheres scene shrunk to a micrometre, 30 m away: every triangle in front of the camera
    // and inside its view, none covering a pixel centre.
    const fs::path scene = dir / "tiny.json";
    writeFile(scene, R"({"objects": [{"procedural": "spheres", "transform": {"scale": 1e-6}}],
        "camera": {"position": [0, 0, 30], "target": [0, 0, 0]}})");
    const CommandResult run = render(scene, dir / "out", dir);
    const int64_t triangles = statsOf(dir / "out")["triangles"].get<int64_t>();
    expectCoverageWarning(run, dir / "out",
                          "no pixel is covered, although " + std::to_string(triangles) +
                              " of the scene's",
                          triangles);
}

TEST(HostileValuesCli, NoCoveredPixelWarnsWithGeometryBehind) {
    const fs::path dir = freshTestFolder();
    const fs::path scene = dir / "away.json";
    writeFile(scene, R"({"objects": [{"procedural": "spheres"}],
        "camera": {"position": [0, 2, 30], "forward": [0, 0, 1]}})");
    const CommandResult run = render(scene, dir / "out", dir);
    expectCoverageWarning(run, dir / "out", "no pixel is covered: none of the scene's", 0);
}

TEST(HostileValuesCli, CoveredRenderHasNoCoverageWarning) {
    const fs::path dir = freshTestFolder();
    const CommandResult run = render("spheres", dir / "out", dir);
    EXPECT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_EQ(run.stdoutText.find("WARNING"), std::string::npos) << run.stdoutText;
    const nlohmann::json stats = statsOf(dir / "out");
    EXPECT_GT(stats["coverage"]["covered_pixels"].get<int64_t>(), 0);
    EXPECT_TRUE(stats["coverage"]["warning"].is_null());
    EXPECT_TRUE(stats["coverage"]["triangles_in_front"].is_null());
}

// A glTF camera whose node flattens its up axis renders the model (a basis from +X, with a
// warning), instead of the all-black image it rendered before.
TEST(HostileValuesCli, FlattenedCameraUpAxisRendersWithAWarning) {
    const fs::path dir = freshTestFolder();
    const fs::path scene = kCorpus / "camera-up-sheared-onto-view.gltf";
    const CommandResult run = render(scene, dir / "out", dir);
    EXPECT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_NE(run.stderrText.find("up is taken from the camera's right axis (+X)"),
              std::string::npos)
        << run.stderrText;
    EXPECT_GT(statsOf(dir / "out")["coverage"]["covered_pixels"].get<int64_t>(), 0);
}

} // namespace
} // namespace experiments
