// kill -9 for real: `testbed sweep` runs as a child process and is killed with SIGKILL as soon as
// its first job is finished; the rerun must skip every job finished before (markers untouched,
// "skipped" in its progress output), redo the rest, and end with every job exactly once.
#include <gtest/gtest.h>

#include "tests/experiments/SpawnTestbed.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

const fs::path kTestbed = fs::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

// Starts testbed with args, stdout and stderr to `log`; returns the child's pid.
pid_t spawn(const std::vector<std::string>& args, const fs::path& log) {
    return experimentstest::spawnTestbed(args, log, experimentstest::LogMode::Append);
}

std::vector<fs::path> markers(const fs::path& out) {
    std::vector<fs::path> found;
    if (!fs::exists(out / "jobs"))
        return found;
    for (const auto& job : fs::directory_iterator(out / "jobs"))
        if (fs::is_regular_file(job.path() / "done.json"))
            found.push_back(job.path() / "done.json");
    return found;
}

std::string readText(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

struct Identity {
    ino_t inode;
    int64_t mtimeNs;
    bool operator==(const Identity&) const = default;
};

Identity identity(const fs::path& path) {
    struct stat info {};
    EXPECT_EQ(stat(path.c_str(), &info), 0) << path;
    return {info.st_ino, int64_t(info.st_mtim.tv_sec) * 1'000'000'000 + info.st_mtim.tv_nsec};
}

TEST(SweepKill, KilledSweepResumesWithoutRedoingFinishedJobs) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir =
        fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / "sweep-kill";
    fs::remove_all(dir);
    fs::create_directories(dir);
    // 12 jobs of a few tens of milliseconds each, 2 references.
    std::ofstream(dir / "sweep.json") << R"({
        "name": "kill",
        "fixed": {"scene": "atrium", "resolution": "240x136", "lights": 48},
        "axes": {"seed": [1, 2], "stage": ["brute", "tiled", "deferred", "clustered", "forward", "light-indexed"]},
        "repetitions": 2
    })";
    const fs::path out = dir / "out";
    const std::vector<std::string> args = {
        "sweep", (dir / "sweep.json").string(), "--out", out.string(), "--threads", "1"};

    const pid_t child = spawn(args, dir / "first.log");
    ASSERT_GT(child, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (markers(out).empty() && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_FALSE(markers(out).empty()) << "no job finished in time; log:\n"
                                       << readText(dir / "first.log");

    std::map<std::string, Identity> before;
    for (const fs::path& marker : markers(out))
        before[marker.parent_path().filename().string()] = identity(marker);
    std::cout << before.size() << " of 12 jobs finished when killed\n";

    const pid_t rerun = spawn(args, dir / "second.log");
    ASSERT_GT(rerun, 0);
    waitpid(rerun, &status, 0);
    const std::string log = readText(dir / "second.log");
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log;

    for (const auto& [id, was] : before) {
        EXPECT_NE(log.find("skipped " + id), std::string::npos) << id << "\n" << log;
        EXPECT_EQ(log.find("running " + id), std::string::npos) << id << " was run again\n" << log;
        EXPECT_TRUE(identity(out / "jobs" / id / "done.json") == was)
            << id << "'s marker was rewritten";
    }
    const Json results = Json::parse(readText(out / "results.json"));
    ASSERT_EQ(results["jobs"].size(), 12u);
    std::set<std::string> ids;
    for (const Json& job : results["jobs"]) {
        ids.insert(job["job_id"].get<std::string>());
        EXPECT_EQ(job["status"], "ok") << job.dump();
    }
    EXPECT_EQ(ids.size(), 12u);
    EXPECT_EQ(markers(out).size(), 12u);
}

} // namespace
