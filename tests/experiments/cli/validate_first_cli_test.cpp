// Issue 32, classes 4 and 8, through the testbed binary. Class 4: a failed run leaves its output
// folder byte for byte as it was (a snapshot of the folder before and after), whether it fails up
// front (--error-max -1, an unknown view, a memory limit), after rendering (the commit refused by
// a folder in the way) or in a sweep whose jobs cannot run (exit 2 before any job, before --out
// is created). Class 8: scene, sweep, output and diff paths with bytes that are not UTF-8 work,
// and the JSON outputs name them by the reversible escape (output/JsonText.h).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "experiments/output/JsonText.h"
#include "tests/experiments/TestFolders.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using test_files::freshTestFolder;
using test_files::readText;

const fs::path kTestbed = fs::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

struct CommandRun {
    int exitCode;
    std::string errors;
};

// Arguments are quoted for the shell with single quotes (paths may hold any byte but ').
std::string quoted(const std::string& text) {
    return "'" + text + "'";
}

CommandRun testbed(const std::vector<std::string>& args, const fs::path& dir) {
    std::string command = "timeout -s KILL 120 " + kTestbed.string();
    for (const std::string& arg : args)
        command += " " + quoted(arg);
    command += " > " + quoted((dir / "stdout.txt").string()) + " 2> " +
               quoted((dir / "stderr.txt").string()) + " < /dev/null";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status),
            readText(dir / "stderr.txt")};
}

std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> entries;
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir))
        entries[entry.path().lexically_relative(dir).string()] =
            entry.is_directory() ? "<dir>" : readText(entry.path());
    return entries;
}

void expectOneError(const CommandRun& run, int exitCode, const std::string& part) {
    EXPECT_EQ(run.exitCode, exitCode) << run.errors;
    EXPECT_EQ(run.errors.rfind("testbed: error: ", 0), 0u) << run.errors;
    EXPECT_EQ(std::count(run.errors.begin(), run.errors.end(), '\n'), 1) << run.errors;
    EXPECT_NE(run.errors.find(part), std::string::npos) << run.errors;
}

const std::vector<std::string> kSmall = {"--scene", "spheres", "--lights", "8",
                                         "--width", "48",      "--height", "32"};

std::vector<std::string> render(std::vector<std::string> extra, const fs::path& out) {
    std::vector<std::string> args = {"render"};
    args.insert(args.end(), kSmall.begin(), kSmall.end());
    args.insert(args.end(), extra.begin(), extra.end());
    args.push_back("--out");
    args.push_back(out.string());
    return args;
}

TEST(ValidateFirst, AFailedRenderLeavesTheFolderAsItWas) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshTestFolder();
    const fs::path out = dir / "out";
    ASSERT_EQ(testbed(render({"--compare-reference", "--reference-spp", "1"}, out), dir).exitCode,
              0);
    std::ofstream(out / "notes.txt") << "the user's";
    const auto before = snapshot(out);
    ASSERT_TRUE(before.count("error.png") && before.count("stats.json"));

    expectOneError(testbed(render({"--compare-reference", "--error-max", "-1"}, out), dir), 1,
                   "--error-max -1 refused");
    EXPECT_EQ(snapshot(out), before);
    expectOneError(testbed(render({"--compare-reference", "--error-max", "1e300"}, out), dir), 1,
                   "finite as a 32-bit float");
    EXPECT_EQ(snapshot(out), before);
    expectOneError(testbed(render({"--view", "nosuchview"}, out), dir), 1, "no view 'nosuchview'");
    EXPECT_EQ(snapshot(out), before);
    expectOneError(testbed({"render", "--scene", "spheres", "--width", "8192", "--height", "8192",
                            "--max-memory", "2G", "--out", out.string()},
                           dir),
                   1, "over the limit 2.00 GiB");
    EXPECT_EQ(snapshot(out), before);

    // A failure after the whole render: a folder where flip.png goes refuses the commit before
    // its first rename.
    fs::path blocker = dir / "blocked";
    fs::copy(out, blocker, fs::copy_options::recursive);
    fs::remove(blocker / "flip.png");
    fs::create_directory(blocker / "flip.png");
    const auto blocked = snapshot(blocker);
    expectOneError(testbed(render({"--compare-reference", "--reference-spp", "1"}, blocker), dir),
                   1, "a folder of that name is in the way");
    EXPECT_EQ(snapshot(blocker), blocked);

    // A failed run into a folder that did not exist leaves no folder.
    expectOneError(testbed(render({"--view", "nosuchview"}, dir / "new" / "out"), dir), 1,
                   "nosuchview");
    EXPECT_FALSE(fs::exists(dir / "new"));

    // A successful run replaces the render outputs it owns: no error.png of the earlier run.
    ASSERT_EQ(testbed(render({}, out), dir).exitCode, 0);
    EXPECT_FALSE(fs::exists(out / "error.png"));
    EXPECT_FALSE(fs::exists(out / "flip.png"));
    EXPECT_TRUE(fs::exists(out / "notes.txt"));
}

// A sweep's jobs are planned against their scenes before the first runs: a bad view, a layout
// lacking what the stage reads or a job over the memory limit is exit 2, nothing run, --out
// untouched (not created when missing, unchanged when present).
TEST(ValidateFirst, ASweepWhoseJobsCannotRunRunsNone) {
    const fs::path dir = freshTestFolder();
    const std::map<std::string, std::string> sweeps = {
        {"view", R"({"name": "v", "fixed": {"scene": "spheres", "lights": 4, "width": 32,
            "height": 24}, "axes": {"stage": ["brute", "tiled"], "view": ["front", "nosuch"]}})"},
        {"memory", R"({"name": "m", "fixed": {"scene": "spheres", "lights": 4, "width": 8192,
            "height": 8192, "max-memory": "1G"}, "axes": {"stage": ["brute"]}})"},
        {"scene-option", R"({"name": "o", "fixed": {"scene": "spheres", "lights": 4,
            "width": 32, "height": 24}, "axes": {"scene-option.segments": [8, 100000]}})"}};
    fs::create_directories(dir / "existing");
    std::ofstream(dir / "existing" / "keep.txt") << "keep";
    for (const auto& [name, text] : sweeps) {
        const fs::path file = dir / (name + ".json");
        std::ofstream(file) << text;
        expectOneError(testbed({"sweep", file.string(), "--out", (dir / name).string()}, dir), 2,
                       "cannot run; nothing was run");
        EXPECT_FALSE(fs::exists(dir / name)) << name;
        const auto before = snapshot(dir / "existing");
        expectOneError(testbed({"sweep", file.string(), "--out", (dir / "existing").string()}, dir),
                       2, "nothing was run");
        EXPECT_EQ(snapshot(dir / "existing"), before) << name;
    }
}

// Class 8: paths with bytes that are not UTF-8 are read and written, and JSON names them by the
// reversible escape.
TEST(ValidateFirst, FileNamesAreBytes) {
    const fs::path dir = freshTestFolder();
    const fs::path scene = dir / "sc\xff\xfe.json";
    std::ofstream(scene) << R"({"name": "odd", "camera": {"position": [0, 2, 8],
        "target": [0, 0, 0]}, "objects": [{"procedural": "spheres"}],
        "lights": [{"type": "point", "position": [0, 3, 3], "range": 10}]})";
    const fs::path out = dir / "out\xff";
    ASSERT_EQ(testbed({"render", "--scene", scene.string(), "--width", "48", "--height", "32",
                       "--out", out.string()},
                      dir)
                  .exitCode,
              0)
        << readText(dir / "stderr.txt");
    std::ifstream statsFile(out / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    EXPECT_EQ(stats.at("scene_source").get<std::string>(), pathForJson(scene));
    EXPECT_EQ(pathFromJson(stats.at("scene_source").get<std::string>()), scene);

    const fs::path sweep = dir / "sw\xfe.json";
    std::ofstream(sweep) << R"({"name": "s", "fixed": {"scene": "spheres", "lights": 4,
        "width": 32, "height": 24}, "axes": {"stage": ["brute"]}})";
    const fs::path sweepOut = dir / "sweep\xff";
    ASSERT_EQ(testbed({"sweep", sweep.string(), "--out", sweepOut.string()}, dir).exitCode, 0)
        << readText(dir / "stderr.txt");
    std::ifstream resultsFile(sweepOut / "results.json");
    const nlohmann::json results = nlohmann::json::parse(resultsFile);
    EXPECT_EQ(pathFromJson(results.at("sweep_file").get<std::string>()), sweep);
    EXPECT_EQ(results.at("jobs").at(0).at("status"), "ok");

    const fs::path diffOut = dir / "diff\xfe";
    const CommandRun diff = testbed({"diff", (out / "render.exr").string(),
                                     (out / "render.exr").string(), "--out", diffOut.string()},
                                    dir);
    ASSERT_EQ(diff.exitCode, 0) << diff.errors;
    std::ifstream diffFile(diffOut / "diff.json");
    const nlohmann::json diffJson = nlohmann::json::parse(diffFile);
    EXPECT_EQ(pathFromJson(diffJson.at("a").get<std::string>()), out / "render.exr");
}

} // namespace
} // namespace experiments
