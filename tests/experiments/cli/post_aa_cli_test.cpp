// `testbed render --post-aa`: a bad value is one error line naming the option, the value and the
// valid names (exit code 1, before any work); --help states the default; --explain-layout says
// why edge-blur stores normals for a forward stage; `testbed list` lists the modes; a small render
// records the mode in stats.json and writes the edge layer. Runs build/bin/testbed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "tests/experiments/TestFolders.h"

#include "tests/experiments/cli/CliRun.h"

namespace {

namespace fs = std::filesystem;

using clitest::CliRun;
using clitest::kTestbed;
using clitest::run;

TEST(PostAaCli, BadValueIsOneErrorLineNamingTheValidOnes) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path out = experiments::test_files::freshTestFolder();
    for (const auto& [value, expected] :
         {std::pair<std::string, std::string>{"smaa", "none, edge-blur, fxaa"},
          {"fxa", "did you mean 'fxaa'?"},
          {"EDGE-BLUR", "'EDGE-BLUR'"}}) {
        SCOPED_TRACE(value);
        const CliRun result = run("render --post-aa " + value + " --out " + out.string());
        EXPECT_EQ(result.exitCode, 1) << result.output;
        EXPECT_EQ(result.output.rfind("testbed: error: option 'post-aa': ", 0), 0u)
            << result.output;
        EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
        EXPECT_NE(result.output.find(expected), std::string::npos) << result.output;
    }
    EXPECT_FALSE(fs::exists(out / "stats.json")) << "refused before any work";
}

TEST(PostAaCli, HelpStatesTheDefaultAndExplainLayoutTheReason) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const CliRun help = run("render --help");
    EXPECT_EQ(help.exitCode, 0) << help.output;
    const size_t option = help.output.find("--post-aa");
    ASSERT_NE(option, std::string::npos) << help.output;
    EXPECT_EQ(help.output.compare(option, 19, "--post-aa TEXT=none"), 0) << help.output;
    const CliRun list = run("list");
    EXPECT_NE(list.output.find("post-process anti-aliasing (--post-aa; default none):\n"
                               "  none, edge-blur, fxaa"),
              std::string::npos)
        << list.output;
    const CliRun explain = run("render --stage forward --post-aa edge-blur --explain-layout");
    EXPECT_EQ(explain.exitCode, 0) << explain.output;
    EXPECT_NE(explain.output.find("--post-aa edge-blur (not the stage) reads normals"),
              std::string::npos)
        << explain.output;
}

TEST(PostAaCli, RenderRecordsTheModeAndWritesTheEdgeLayer) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path out = experiments::test_files::freshTestFolder();
    const CliRun result = run("render --stage tiled --post-aa fxaa --width 96 --height 64 "
                              "--lights 16 --out " +
                              out.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    EXPECT_NE(result.output.find("post_aa: "), std::string::npos) << result.output;
    const nlohmann::json stats =
        nlohmann::json::parse(experiments::test_files::readText(out / "stats.json"));
    EXPECT_EQ(stats["post_aa"]["mode"], "fxaa");
    EXPECT_EQ(stats["post_aa"]["parameters"]["edge_threshold"], "0.166");
    EXPECT_TRUE(stats["timings_ms"].contains("post_aa"));
    EXPECT_NE(experiments::test_files::readText(out / "render.exr").find("post_aa.edges"),
              std::string::npos);
}

} // namespace
