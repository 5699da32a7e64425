// The command-line contract (issue 16): every error of `testbed`, the argument parser's own
// included (unknown option, missing subcommand, a value it cannot convert), is one line
// "testbed: error: ..." on stderr and exit code 1, and a mistyped name (subcommand, option, stage,
// scene, normal codec) gets the closest valid one suggested. Runs build/bin/testbed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;

const fs::path kTestbed = fs::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

struct CliRun {
    int exitCode = -1;
    std::string output; // stdout and stderr
};

CliRun run(const std::string& arguments) {
    CliRun result;
    const std::string command = kTestbed.string() + " " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe)
        return result;
    std::array<char, 4096> buffer{};
    for (size_t n; (n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0;)
        result.output.append(buffer.data(), n);
    const int status = pclose(pipe);
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

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

TEST(CliContract, CodecWithOneBitDepthAcceptsItsBareName) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path out = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / "cli-bare";
    const CliRun bare = run("render --normals float32 --explain-layout --out " + out.string());
    EXPECT_EQ(bare.exitCode, 0) << bare.output;
    expectOneErrorLine("render --normals octahedral --explain-layout --out " + out.string(),
                       "missing ':BITS'");
}

} // namespace
