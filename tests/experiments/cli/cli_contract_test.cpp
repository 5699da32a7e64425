// The command-line contract (issue 16): every error of `testbed`, the argument parser's own
// included (unknown option, missing subcommand, a value it cannot convert), is one line
// "testbed: error: ..." on stderr and exit code 1, and a mistyped name (subcommand, option, stage,
// scene, normal codec) gets the closest valid one suggested; `testbed list` lists every choice of
// the render options; help texts name no path of the machine the binary was built on; a JSON
// scene's light generator is not replaced by the --lights default. Runs build/bin/testbed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <fstream>

#include <sys/wait.h>

#include "experiments/output/PlotScript.h"
#include "lighting/StageRegistry.h"

#include "tests/experiments/cli/CliRun.h"

namespace {

namespace fs = std::filesystem;

using clitest::CliRun;
using clitest::kTestbed;
using clitest::run;

// One line "testbed: error: ...", exit code 1, containing `expected`.
void expectOneErrorLine(const std::string& arguments, const std::string& expected) {
    SCOPED_TRACE("testbed " + arguments);
    const CliRun result = run(arguments);
    EXPECT_EQ(result.exitCode, 1) << result.output;
    EXPECT_EQ(result.output.rfind("testbed: error: ", 0), 0u) << result.output;
    EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
    EXPECT_NE(result.output.find(expected), std::string::npos) << result.output;
}

TEST(CliContract, ParserErrorsAreOneLineAndExitCodeOne) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    expectOneErrorLine("", "subcommand");
    expectOneErrorLine("render --width abc", "abc");
    expectOneErrorLine("render --no-such-option", "--no-such-option");
    expectOneErrorLine("merge", "required");
    expectOneErrorLine("sweep no-such.json --job-timeout -5",
                       "--job-timeout must be a number of seconds");
    expectOneErrorLine("sweep no-such.json --job-timeout soon", "soon");
    const CliRun help = run("--help");
    EXPECT_EQ(help.exitCode, 0) << help.output;
    EXPECT_NE(help.output.find("render"), std::string::npos) << help.output;
}

TEST(CliContract, TyposGetTheClosestName) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    expectOneErrorLine("rendr", "did you mean 'render'?");
    expectOneErrorLine("render --lighs 4", "did you mean '--lights'?");
    const fs::path out = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / "cli";
    const std::string outArg = " --out " + out.string();
    expectOneErrorLine("render --stage tiledd" + outArg, "did you mean 'tiled'?");
    expectOneErrorLine("render --scene atrum" + outArg, "did you mean 'atrium'?");
    expectOneErrorLine("render --normals octahedrl:24 --explain-layout" + outArg,
                       "did you mean 'octahedral'?");
    // Nothing close: no suggestion rather than a random one.
    const CliRun far = run("render --stage zzzzzzzzzz" + outArg);
    EXPECT_EQ(far.output.find("did you mean"), std::string::npos) << far.output;
}

TEST(CliContract, ReferenceSamplesOutsideTheSquaresAreRefused) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path out = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / "cli-spp";
    for (const char* spp : {"15", "0", "-4", "512"})
        expectOneErrorLine("render --reference-spp " + std::string(spp) + " --out " + out.string(),
                           "--reference-spp " + std::string(spp) +
                               " refused: must be a square from 1 to 256");
    expectOneErrorLine("render --reference-spp many --out " + out.string(), "many");
    const CliRun help = run("render --help");
    EXPECT_NE(help.output.find("--reference-spp"), std::string::npos) << help.output;
    EXPECT_NE(help.output.find("--reference-spp INT=16"), std::string::npos)
        << "the default is stated";
}

TEST(CliContract, CodecWithOneBitDepthAcceptsItsBareName) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path out = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / "cli-bare";
    const CliRun bare = run("render --normals float32 --explain-layout --out " + out.string());
    EXPECT_EQ(bare.exitCode, 0) << bare.output;
    expectOneErrorLine("render --normals octahedral --explain-layout --out " + out.string(),
                       "missing ':BITS'");
}

TEST(CliContract, ListShowsEveryChoiceOfTheRenderOptions) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const CliRun list = run("list");
    EXPECT_EQ(list.exitCode, 0) << list.output;
    for (const char* expected :
         {// scenes and their option tables (default, range, meaning)
          "atrium", "detail=1..16  default 1", "wall", "behind=0..the light count  default 0",
          "spheres", "segments=4..1024  default 64", "ambient=0|1", "sun=0|1",
          // stages, normal encodings
          "tiled-backface", "octahedral-precise:",
          // layout presets, depth formats, position methods, normal spaces, with defaults
          "layout presets", "thesis", "killzone2", "compact",
          "depth formats (--depth NAME or NAME:infinite; default f32-reversed)", "unorm24",
          "f16-linear", "position methods (--position; default inverse-projection)", "view-ray",
          "normal spaces (--normal-space; default view)", "world"})
        EXPECT_NE(list.output.find(expected), std::string::npos) << expected << "\n" << list.output;
}

TEST(CliContract, ListShowsEveryOptionOfEveryStageFromItsTable) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const CliRun list = run("list");
    EXPECT_EQ(list.exitCode, 0) << list.output;
    size_t previous = 0;
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        // Stages in registry order, each with its options beneath it.
        const size_t at = list.output.find("\n  " + info.name + "  - " + info.description + "\n");
        ASSERT_NE(at, std::string::npos) << info.name << "\n" << list.output;
        EXPECT_GT(at, previous) << info.name;
        previous = at;
        for (const lighting::StageOption& option : info.options) {
            const std::string line = "\n    " + option.key + "=" + option.range() + "  " +
                                     option.typeName() + ", default " + option.defaultText + ": " +
                                     option.doc + "\n";
            EXPECT_NE(list.output.find(line, at), std::string::npos)
                << info.name << ": " << line << "\n"
                << list.output;
        }
    }
    // Spot checks of what the table generates.
    for (const char* expected :
         {"    tile=4..128  int, default 16: tile size in pixels",
          "    depth=(0, 1e+30]  float, default 0.1:",
          "    slices=exp|uniform  choice, default exp:", "    vfc=1|0  bool, default 1:"})
        EXPECT_NE(list.output.find(expected), std::string::npos) << expected << "\n" << list.output;
}

TEST(CliContract, HelpTextsNameNoPathOfTheBuildMachine) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const std::string source = fs::weakly_canonical(experiments::sourceDirectory()).string();
    const std::string build = fs::weakly_canonical(TESTBED_BINARY_DIR).string();
    for (const char* command :
         {"", "render", "list", "report", "diff", "sweep", "merge", "normals", "depth"}) {
        // Started by its absolute path, which the usage line must not repeat either.
        const CliRun help = run(std::string(command) + " --help");
        SCOPED_TRACE(std::string("testbed ") + command + " --help");
        EXPECT_EQ(help.exitCode, 0) << help.output;
        EXPECT_EQ(help.output.find(source), std::string::npos) << help.output;
        EXPECT_EQ(help.output.find(build), std::string::npos) << help.output;
        EXPECT_NE(help.output.find("Usage: testbed"), std::string::npos) << help.output;
    }
}

TEST(CliContract, AJsonScenesLightGeneratorIsNotReplacedByTheDefault) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir =
        fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / "cli-lights";
    fs::create_directories(dir);
    const fs::path scene = dir / "five.json";
    std::ofstream(scene) << R"({"objects": [{"procedural": "spheres"}],
                               "lightGenerator": {"count": 5}})";
    const std::string common = "render --scene " + scene.string() +
                               " --width 32 --height 18 --threads 1 --out " +
                               (dir / "out").string();
    const CliRun fromFile = run(common);
    EXPECT_EQ(fromFile.exitCode, 0) << fromFile.output;
    EXPECT_NE(fromFile.output.find("lights: 5 = 5 generated (the file's lightGenerator)"),
              std::string::npos)
        << fromFile.output;
    const CliRun given = run(common + " --lights 7");
    EXPECT_EQ(given.exitCode, 0) << given.output;
    EXPECT_NE(given.output.find("lights: 7 = 7 generated (--lights 7)"), std::string::npos)
        << given.output;
    std::ifstream stats(dir / "out" / "stats.json");
    const std::string text((std::istreambuf_iterator<char>(stats)), {});
    EXPECT_NE(text.find("\"light_origins\""), std::string::npos) << text;
    EXPECT_NE(text.find("\"generated_by\": \"--lights\""), std::string::npos) << text;
}

} // namespace
