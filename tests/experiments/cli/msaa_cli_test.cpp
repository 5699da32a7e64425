// The anti-aliasing options at the command line: --msaa and --complex-detect are validated before
// any work (one error line, exit code 1, nothing written), a stage that cannot take a multisampled
// frame is refused with its reason (the one `testbed list` shows), and a multisampled render
// writes complex.png, the msaa.complex EXR layer and the msaa block of stats.json.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "lighting/StageRegistry.h"

#include "tests/experiments/cli/CliRun.h"

namespace {

namespace fs = std::filesystem;

using clitest::CliRun;
using clitest::kTestbed;
using clitest::run;

fs::path outDir(const std::string& name) {
    const fs::path dir = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / name;
    fs::remove_all(dir);
    return dir;
}

void expectRefused(const std::string& arguments, const std::string& expected) {
    SCOPED_TRACE(arguments);
    const fs::path out = outDir("msaa-refused");
    const CliRun result = run(arguments + " --out " + out.string());
    EXPECT_EQ(result.exitCode, 1) << result.output;
    EXPECT_EQ(result.output.rfind("testbed: error: ", 0), 0u) << result.output;
    EXPECT_NE(result.output.find(expected), std::string::npos) << result.output;
    EXPECT_FALSE(fs::exists(out)) << "a refused render left " << out;
}

TEST(MsaaCli, BadSampleCountsAndDetectionsAreRefused) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    expectRefused("render --msaa 3", "--msaa 3 refused: samples per pixel must be 1, 2, 4 or 8");
    expectRefused("render --msaa 16", "must be 1, 2, 4 or 8");
    expectRefused("render --msaa 0", "must be 1, 2, 4 or 8");
    expectRefused("render --msaa 4 --complex-detect edges", "must be primitive or discontinuity");
    expectRefused("render --msaa 4 --alpha-to-coverage yes", "must be on or off");
    expectRefused("render --alpha-to-coverage on",
                  "--alpha-to-coverage on refused with --msaa 1: one sample per pixel has no "
                  "coverage to dither; alpha-masked materials are alpha-tested at 1x");
}

TEST(MsaaCli, AlphaToCoverageIsRecordedInStats) {
    for (const char* setting : {"on", "off"}) {
        const fs::path out = outDir(std::string("msaa-a2c-") + setting);
        const CliRun result = run(
            std::string("render --scene foliage --stage forward --msaa 4 --alpha-to-coverage ") +
            setting + " --width 96 --height 54 --lights 8 --threads 2 --out " + out.string());
        ASSERT_EQ(result.exitCode, 0) << result.output;
        std::ifstream file(out / "stats.json");
        const nlohmann::json stats = nlohmann::json::parse(file);
        EXPECT_EQ(stats.at("msaa").at("alpha_to_coverage"), setting);
    }
}

TEST(MsaaCli, StagesThatCannotTakeMultisampledFramesSaySo) {
    int refusing = 0;
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        if (info.msaaRefusal.empty())
            continue;
        ++refusing;
        expectRefused("render --stage " + info.name + " --msaa 4 --width 64 --height 36",
                      "refused for stage " + info.name + ": " + info.msaaRefusal);
    }
    EXPECT_GT(refusing, 0);
    const CliRun list = run("list");
    EXPECT_NE(list.output.find("msaa: refused: "), std::string::npos) << list.output;
    EXPECT_NE(list.output.find("msaa: yes"), std::string::npos) << list.output;
}

TEST(MsaaCli, MultisampledRenderWritesTheComplexMapAndStats) {
    const fs::path out = outDir("msaa-render");
    const CliRun result = run("render --scene glass --stage tiled --msaa 4 --complex-detect "
                              "discontinuity --width 160 --height 90 --threads 2 --out " +
                              out.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    EXPECT_TRUE(fs::is_regular_file(out / "complex.png"));
    std::ifstream file(out / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(file);
    const nlohmann::json& msaa = stats.at("msaa");
    EXPECT_EQ(msaa.at("samples"), 4);
    EXPECT_EQ(msaa.at("complex_detect"), "discontinuity");
    const double fraction = msaa.at("complex_fraction");
    EXPECT_GT(fraction, 0.0);
    EXPECT_LT(fraction, 0.5);
    EXPECT_GE(double(msaa.at("surfaces_per_covered_pixel")), 1.0);
    EXPECT_GT(double(msaa.at("gbuffer_bytes")), double(stats.at("bytes_per_pixel")) * 160 * 90);
    EXPECT_LE(double(msaa.at("gbuffer_bytes")), double(msaa.at("gbuffer_allocated_bytes")));
    EXPECT_TRUE(stats.at("timings_ms").contains("resolve"));
    // The single-sample render of the same frame: no complex pixels, no complex.png.
    const fs::path single = outDir("msaa-render-1x");
    ASSERT_EQ(
        run("render --scene glass --stage tiled --width 160 --height 90 --out " + single.string())
            .exitCode,
        0);
    EXPECT_FALSE(fs::exists(single / "complex.png"));
}

} // namespace
