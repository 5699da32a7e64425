// Hostile conditions for the experiments side (issue 15): a full disk (simulated with
// RLIMIT_FSIZE, `ulimit -f`, which makes writes past the limit fail with EFBIG as ENOSPC would:
// no root or mount needed), temporaries left by killed writers, seeds the CLI parser would wrap
// (-1, 2^64), sweep files nested deeper than limits::kMaxNestingDepth (JSON, and TOML's dotted
// keys and headers, which crashed toml++ itself), and sweeps whose axes multiply past any
// integer. Every input is generated here.
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "experiments/output/AtomicFile.h"
#include "experiments/output/ImageOutput.h"
#include "experiments/sweep/SweepFile.h"
#include "scenes/input/Limits.h"
#include "tests/experiments/TestFolders.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using experiments::test_files::freshTestFolder;
using experiments::test_files::readText;

const fs::path kTestbed = fs::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

struct CommandResult {
    int exitCode;
    std::string stderrText;
};

// Runs `testbed args...` through bash, after `prefix` (e.g. a ulimit), with stderr captured.
CommandResult runTestbed(const std::string& args, const fs::path& dir,
                         const std::string& prefix = "") {
    const fs::path errors = dir / "stderr.txt";
    const std::string command = "bash -c '" + prefix + " exec \"$0\" \"$@\"' " + kTestbed.string() +
                                " " + args + " > /dev/null 2> " + errors.string();
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), readText(errors)};
}

int countLinesStartingWith(const std::string& text, const std::string& prefix) {
    int count = 0;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos)
            end = text.size();
        count += text.compare(start, prefix.size(), prefix) == 0;
        start = end + 1;
    }
    return count;
}

// Noise compresses badly, so the PNGs and the EXR of a 256x256 diff are far over 16 KiB.
void writeNoiseExr(const fs::path& path, unsigned seed) {
    constexpr int kSide = 256;
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> value(0.0f, 1.0f);
    std::vector<float> r(kSide * kSide), g(kSide * kSide), b(kSide * kSide);
    for (size_t i = 0; i < r.size(); ++i) {
        r[i] = value(random);
        g[i] = value(random);
        b[i] = value(random);
    }
    writeMultiLayerExr(path, kSide, kSide, {{"R", r.data()}, {"G", g.data()}, {"B", b.data()}}, {});
}

TEST(FullDisk, DiffLeavesNoFileUnderAFinalNameAndNoTemporary) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshTestFolder();
    writeNoiseExr(dir / "a.exr", 1);
    writeNoiseExr(dir / "b.exr", 2);
    const fs::path out = dir / "out";
    // SIGXFSZ ignored: the write then fails with EFBIG instead of killing the process.
    const CommandResult run = runTestbed("diff " + (dir / "a.exr").string() + " " +
                                             (dir / "b.exr").string() + " --out " + out.string(),
                                         dir, "trap \"\" XFSZ; ulimit -f 16;");
    EXPECT_EQ(run.exitCode, 1) << run.stderrText;
    EXPECT_EQ(countLinesStartingWith(run.stderrText, "testbed: error: cannot write "), 1)
        << run.stderrText;
    ASSERT_TRUE(fs::is_directory(out));
    for (const auto& entry : fs::directory_iterator(out))
        ADD_FAILURE() << "left behind: " << entry.path() << " (" << fs::file_size(entry.path())
                      << " bytes)";
}

TEST(FullDisk, ImageWriterReportsTheFailedWriteAndKeepsThePreviousFile) {
    const fs::path dir = freshTestFolder();
    const fs::path png = dir / "preview.png";
    { std::ofstream(png) << "previous"; }
    // The write fails in a child process whose file size limit is 16 KiB.
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        signal(SIGXFSZ, SIG_IGN);
        const rlimit limit{16 << 10, 16 << 10};
        setrlimit(RLIMIT_FSIZE, &limit);
        constexpr int kSide = 256;
        std::mt19937 random(3);
        std::vector<float> noise(kSide * kSide);
        for (float& v : noise)
            v = float(random() % 1000) / 1000.0f;
        try {
            writePreviewPng(png, kSide, kSide, noise.data(), noise.data(), noise.data(), 1.0f);
        } catch (const std::runtime_error& error) {
            const std::string message = error.what();
            _exit(message.find("cannot write " + png.string()) != std::string::npos ? 0 : 2);
        }
        _exit(3); // no error reported
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "3: the failed write was not reported";
    EXPECT_EQ(readText(png), "previous");
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_EQ(entry.path(), png) << "left behind: " << entry.path();
}

TEST(StaleTemporaries, OnlyThoseOfDeadWritersOnThisHostAreRemoved) {
    const fs::path dir = freshTestFolder();
    // A pid that is surely dead: a child that has exited and been reaped.
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0)
        _exit(0);
    ASSERT_EQ(waitpid(child, nullptr, 0), child);

    // Names as writeFileAtomically makes them, with the pid swapped in.
    const std::string ours = temporaryPathFor(dir / "render.exr").filename().string();
    const std::string ownPid = std::to_string(getpid());
    auto withPid = [&](pid_t pid) {
        std::string name = ours;
        name.replace(name.find(".tmp-") + 5, ownPid.size(), std::to_string(pid));
        return name;
    };
    const std::string dead = withPid(child);
    const std::string live = withPid(getppid());
    std::string otherHost = dead;
    otherHost.replace(otherHost.rfind('.') - 8, 8, "00000000");
    if (otherHost == dead)
        otherHost.replace(otherHost.rfind('.') - 8, 8, "11111111");
    const std::vector<std::string> kept = {live, otherHost, ".render.tmp-1-2.exr", "render.exr",
                                           ".results.tmp-x-1-" + dead.substr(dead.size() - 12)};
    for (const std::string& name : kept)
        std::ofstream(dir / name) << "x";
    std::ofstream(dir / dead) << "x";
    const std::string deadNoExtension = dead.substr(0, dead.rfind('.'));
    std::ofstream(dir / deadNoExtension) << "x";

    // The first write into the folder cleans it.
    writeTextAtomically(dir / "stats.json", "{}\n");
    EXPECT_FALSE(fs::exists(dir / dead));
    EXPECT_FALSE(fs::exists(dir / deadNoExtension));
    for (const std::string& name : kept)
        EXPECT_TRUE(fs::exists(dir / name)) << name;
    EXPECT_EQ(readText(dir / "stats.json"), "{}\n");
}

TEST(SeedOption, NegativeAndTooLargeSeedsAreRefused) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshTestFolder();
    for (const std::string seed :
         {"-1", "18446744073709551616", "99999999999999999999999", "1e3", "0x10"}) {
        const CommandResult run = runTestbed("render --seed '" + seed + "' --explain-layout", dir);
        EXPECT_NE(run.exitCode, 0) << "seed '" << seed << "' accepted";
        EXPECT_NE(run.stderrText.find("seed '" + seed + "' is not an integer in 0.."),
                  std::string::npos)
            << run.stderrText;
    }
    const CommandResult largest =
        runTestbed("render --seed 18446744073709551615 --explain-layout", dir);
    EXPECT_EQ(largest.exitCode, 0) << largest.stderrText;
}

std::string sweepError(const std::string& text, bool toml) {
    try {
        readSweepText(text, "hostile", toml);
    } catch (const SweepError& error) {
        return error.what();
    }
    return "(no error)";
}

TEST(SweepNesting, DeepJsonAndTomlAreRefusedBeforeParsing) {
    constexpr int kDeep = 100000;
    std::string json = "{\"name\": \"x\", \"notes\": ";
    json += std::string(kDeep, '[') + std::string(kDeep, ']') + "}";
    EXPECT_NE(sweepError(json, false).find("hostile:1: nests deeper than 256 levels"),
              std::string::npos);
    std::string dotted;
    for (int i = 0; i < kDeep; ++i)
        dotted += "a.";
    EXPECT_NE(sweepError("name = 'x'\n" + dotted + "b = 1\n", true)
                  .find("hostile:2: nests deeper than 256 levels"),
              std::string::npos);
    EXPECT_NE(sweepError("[" + dotted + "b]\n", true).find("nests deeper than 256 levels"),
              std::string::npos);
    EXPECT_NE(
        sweepError("notes = " + std::string(kDeep, '['), true).find("nests deeper than 256 levels"),
        std::string::npos);
    // A number past double's range is nlohmann's out_of_range, not a parse_error: it escaped the
    // reader and terminated the process (found by sweep_fuzzer).
    EXPECT_NE(sweepError("{\"warmup\": 4444e444}", false).find("hostile: JSON syntax error"),
              std::string::npos);
    // Shallow files still reach the parser and the checks of the sweep format.
    EXPECT_NE(sweepError("{\"bogus\": [[1]]}", false).find("unknown key 'bogus'"),
              std::string::npos);
}

TEST(SweepJobs, AxesMultiplyingPastAnyIntegerAreRefused) {
    // 20 axes of 10 values: 10^20 jobs, more than 2^64; the product once wrapped around.
    std::string json = "{\"fixed\": {\"scene\": \"wall\"}, \"axes\": {";
    for (int a = 0; a < 20; ++a)
        json += std::string(a ? "," : "") + "\"scene-option.k" + std::to_string(a) +
                "\": [0,1,2,3,4,5,6,7,8,9]";
    json += "}}";
    const SweepSpec spec = readSweepText(json, "many", false);
    try {
        expandSweep(spec, std::nullopt);
        FAIL() << "no error";
    } catch (const SweepError& error) {
        EXPECT_NE(std::string(error.what()).find("jobs refused (at most 1000000)"),
                  std::string::npos)
            << error.what();
    }
}

} // namespace
} // namespace experiments
