// Hostile input files through the testbed binary (issue 32, classes 5, 6 and 7): sweep files
// (JSON and TOML) and results.json with a key given twice; a sweep file, results.json or diff
// input that is a FIFO, /dev/zero or a folder; and a JSON scene whose light type carries a
// newline, a forged "testbed: error:" line and a terminal escape. Each must end in exactly one
// "testbed: error:" line naming the file, with the documented exit code (2 for an invalid sweep
// file, else 1). Every command runs under `timeout`, so a read that hangs fails the test rather
// than the suite. Every input is generated here.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/stat.h>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include "experiments/output/ReportHtml.h"
#include "tests/experiments/TestFolders.h"
#include "tests/experiments/cli/CliRun.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using experiments::test_files::freshTestFolder;
using experiments::test_files::readText;

using clitest::kTestbed;
using CommandResult = clitest::SeparateRun;
using clitest::lineCount;

CommandResult runTestbed(const std::string& args, const fs::path& dir) {
    return clitest::runSeparately(args, dir);
}

void expectOneErrorLine(const CommandResult& run, int exitCode,
                        const std::vector<std::string>& parts) {
    EXPECT_EQ(run.exitCode, exitCode) << run.stderrText;
    EXPECT_EQ(lineCount(run.stderrText), 1) << run.stderrText;
    EXPECT_EQ(run.stderrText.rfind("testbed: error: ", 0), 0u) << run.stderrText;
    for (const std::string& part : parts)
        EXPECT_NE(run.stderrText.find(part), std::string::npos)
            << "'" << part << "' not in: " << run.stderrText;
}

void writeFile(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

TEST(HostileDuplicateKeys, SweepFilesAreRefusedWithExitCode2) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshTestFolder();
    const fs::path json = dir / "twice.json";
    writeFile(json, R"({"name": "twice", "fixed": {"scene": "spheres"},
        "axes": {"stage": ["brute"], "lights": [4], "stage": ["tiled"]}})");
    expectOneErrorLine(
        runTestbed("sweep " + json.string() + " --out " + (dir / "out").string(), dir), 2,
        {json.string(), "key 'axes.stage' is given twice in the same object"});
    EXPECT_FALSE(fs::exists(dir / "out"));

    // toml++ refuses a redefined key itself; the reader keeps its message and position.
    const fs::path toml = dir / "twice.toml";
    writeFile(toml, "name = 'twice'\n[axes]\nstage = ['brute']\nstage = ['tiled']\n");
    expectOneErrorLine(
        runTestbed("sweep " + toml.string() + " --out " + (dir / "out").string(), dir), 2,
        {toml.string() + ":4:", "TOML syntax error"});
}

TEST(HostileDuplicateKeys, ResultsJsonIsRefusedByReportAdviseAndMerge) {
    const fs::path dir = freshTestFolder();
    const fs::path results = dir / "sweep";
    fs::create_directories(results);
    writeFile(results / "results.json",
              R"({"sweep": "x", "sweep_file": "x.json", "quick": false, "columns": [],
                  "axis_columns": [], "jobs": [], "jobs": []})");
    const std::string problem = "key 'jobs' is given twice in the same object";
    expectOneErrorLine(runTestbed("advise " + results.string() + " --budget-ms 10", dir), 1,
                       {(results / "results.json").string(), problem});
    expectOneErrorLine(runTestbed("report " + results.string(), dir), 1,
                       {(results / "results.json").string(), problem});
    expectOneErrorLine(
        runTestbed("merge " + results.string() + " --out " + (dir / "merged").string(), dir), 1,
        {(results / "results.json").string(), problem});
}

TEST(HostileSpecialFiles, SweepFileFifoDevZeroAndFolderFailAtOnce) {
    const fs::path dir = freshTestFolder();
    ASSERT_EQ(mkfifo((dir / "fifo.json").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", dir / "zero.toml");
    fs::create_directory(dir / "folder.json");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"fifo.json", "is a FIFO (named pipe), not a regular file"},
        {"zero.toml", "is a character device, not a regular file"},
        {"folder.json", "is a directory, not a regular file"},
    };
    for (const auto& [name, problem] : cases)
        expectOneErrorLine(
            runTestbed("sweep " + (dir / name).string() + " --out " + (dir / "out").string(), dir),
            2, {(dir / name).string() + ": " + problem});
}

TEST(HostileSpecialFiles, ResultsJsonAndDiffInputsThatAreFifosFailAtOnce) {
    const fs::path dir = freshTestFolder();
    fs::create_directories(dir / "sweep");
    ASSERT_EQ(mkfifo((dir / "sweep" / "results.json").c_str(), 0600), 0);
    const std::string fifo = (dir / "sweep" / "results.json").string();
    expectOneErrorLine(runTestbed("advise " + (dir / "sweep").string() + " --budget-ms 10", dir), 1,
                       {fifo, "is a FIFO (named pipe), not a regular file"});
    expectOneErrorLine(runTestbed("report " + (dir / "sweep").string(), dir), 1,
                       {fifo, "is a FIFO (named pipe), not a regular file"});

    ASSERT_EQ(mkfifo((dir / "a.exr").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", dir / "b.exr");
    expectOneErrorLine(runTestbed("diff " + (dir / "a.exr").string() + " " +
                                      (dir / "b.exr").string() + " --out " +
                                      (dir / "diff").string(),
                                  dir),
                       1, {(dir / "a.exr").string(), "is a FIFO (named pipe), not a regular file"});
    expectOneErrorLine(runTestbed("diff " + (dir / "b.exr").string() + " " +
                                      (dir / "b.exr").string() + " --out " +
                                      (dir / "diff").string(),
                                  dir),
                       1, {(dir / "b.exr").string(), "is a character device, not a regular file"});
}

TEST(HostileMessages, AForgedLightTypeStaysOnOneEscapedLine) {
    const fs::path dir = freshTestFolder();
    const fs::path scene = dir / "forged.json";
    // JSON's own escapes put a real newline and ESC into the parsed string.
    writeFile(scene, R"({"objects": [{"procedural": "spheres"}],
        "lights": [{"type": "\n testbed: error: forged\u001b[31m"}]})");
    const CommandResult run = runTestbed("render --scene " + scene.string() + " --width 32 " +
                                             "--height 18 --out " + (dir / "out").string(),
                                         dir);
    expectOneErrorLine(run, 1,
                       {scene.string(), "lights[0].type",
                        "unknown light type '\\n testbed: error: forged\\x1b[31m'"});
    EXPECT_EQ(run.stderrText.find('\x1b'), std::string::npos);

    // A file name is user-controlled too: bytes that are not UTF-8 come out as escapes.
    const fs::path odd = dir / "odd\xff\x1b.json";
    const CommandResult missing =
        runTestbed("render --scene '" + odd.string() + "' --out " + (dir / "out").string(), dir);
    EXPECT_EQ(missing.exitCode, 1) << missing.stderrText;
    EXPECT_EQ(lineCount(missing.stderrText), 1) << missing.stderrText;
    EXPECT_NE(missing.stderrText.find("odd\\xff\\x1b.json"), std::string::npos)
        << missing.stderrText;
}

// A successful render's summary quotes the scene's name, its views and the output folder, all
// input-controlled: printed escaped, they cannot forge a line or recolour the terminal.
TEST(HostileMessages, TheRenderSummaryPrintsNamesAndPathsEscaped) {
    const fs::path dir = freshTestFolder();
    const fs::path scene = dir / "named.json";
    writeFile(scene, R"({"name": "atrium\n testbed: error: forged\u001b[31m",
        "objects": [{"procedural": "spheres"}],
        "cameras": [{"name": "front\u001b[2J", "position": [0, 1, 6], "target": [0, 0.5, 0]}],
        "lights": [{"type": "point", "position": [0, 3, 2], "range": 10}]})");
    const fs::path out = dir / "out\x1b";
    for (const char* view : {"", " --view all"}) {
        const CommandResult run =
            runTestbed("render --scene " + scene.string() + " --width 32 --height 18 --out '" +
                           out.string() + "'" + view,
                       dir);
        EXPECT_EQ(run.exitCode, 0) << run.stderrText;
        EXPECT_EQ(run.stdoutText.find('\x1b'), std::string::npos) << view;
        EXPECT_EQ(run.stdoutText.find("\ntestbed: error:"), std::string::npos) << view;
        EXPECT_EQ(run.stdoutText.find("\n testbed: error:"), std::string::npos) << view;
        EXPECT_NE(run.stdoutText.find("atrium\\n testbed: error: forged\\x1b[31m"),
                  std::string::npos)
            << run.stdoutText;
        EXPECT_NE(run.stdoutText.find("out\\x1b"), std::string::npos) << run.stdoutText;
    }
}

TEST(HostileMessages, HtmlEscapeAlsoEscapesControlCharacters) {
    EXPECT_EQ(htmlEscape("<b>\x1b[31m\xff & \"x\"\n</b>"),
              "&lt;b&gt;\\x1b[31m\\xff &amp; &quot;x&quot;\n&lt;/b&gt;");
}

} // namespace
} // namespace experiments
