// `testbed sweep` run as a child process, as a user runs it: a job whose process crashes or
// aborts is recorded as failed with its signal and the sweep runs the rest (JobProcess.h); a
// second sweep over the same jobs in the same --out is refused while the first holds the lock,
// waits with --wait, and a disjoint shard runs beside it (SweepLock.h); a sweep at the job cap
// starts its first job in bounded memory, and one past the cap is refused before any job is made.
//
// The crash is delivered from outside: the test stops a job's process (SIGSTOP, so that a job
// that just finished cannot turn the signal into a no-op on a zombie), sends it SIGSEGV or
// SIGABRT and resumes it; the process dies of the signal exactly as it would of its own fault.
// A hang is made the same way, without a hook in the testbed: a job process stopped and never
// resumed makes no progress, exactly like one stuck in a loop or a wait, until --job-timeout.
#include <gtest/gtest.h>

#include "tests/experiments/SpawnTestbed.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "experiments/sweep/SanitizerBuild.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

const fs::path kTestbed = fs::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// Starts testbed with args, stdout and stderr to `log`; returns the child's pid.
// Whether this test binary (and so the testbed it runs: one build) has AddressSanitizer.
constexpr bool kUnderAddressSanitizer = experiments::kAddressSanitizerBuild;

pid_t spawn(const std::vector<std::string>& args, const fs::path& log) {
    return experimentstest::spawnTestbed(args, log, experimentstest::LogMode::Truncate);
}

// Waits for pid; its exit code, or -signal when a signal ended it.
int waitExit(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

std::string readText(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// The state letter of /proc/PID/stat (R, S, T, Z...) and the parent pid, or nullopt when gone.
std::optional<std::pair<char, pid_t>> processState(pid_t pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text;
    if (!std::getline(stat, text))
        return std::nullopt;
    const size_t close = text.rfind(')'); // the command name may hold spaces and parentheses
    if (close == std::string::npos)
        return std::nullopt;
    std::istringstream rest(text.substr(close + 1));
    char state = 0;
    long parent = 0;
    rest >> state >> parent;
    return std::make_pair(state, pid_t(parent));
}

// The child processes of parent (its job processes), found through /proc.
std::vector<pid_t> childrenOf(pid_t parent) {
    std::vector<pid_t> children;
    for (const auto& entry : fs::directory_iterator("/proc")) {
        const std::string name = entry.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos)
            continue;
        const pid_t pid = pid_t(std::stol(name));
        if (const auto state = processState(pid); state && state->second == parent)
            children.push_back(pid);
    }
    return children;
}

// Waits for a running job process of `sweep` other than those in `seen` and stops it (SIGSTOP);
// returns its pid, or nullopt when none appeared within the time limit.
std::optional<pid_t> stopNextJobProcess(pid_t sweep, std::set<pid_t>& seen) {
    const auto deadline = Clock::now() + std::chrono::seconds(120);
    while (Clock::now() < deadline) {
        for (const pid_t child : childrenOf(sweep)) {
            if (seen.count(child))
                continue;
            seen.insert(child);
            kill(child, SIGSTOP);
            // A job that ended before the stop is a zombie: a signal would do nothing, try the
            // next one.
            for (int tries = 0; tries < 1000; ++tries) {
                const auto state = processState(child);
                if (!state || state->first == 'Z' || state->first == 'X')
                    break;
                if (state->first == 'T' || state->first == 't')
                    return child;
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return std::nullopt;
}

// 8 jobs of a few tens of milliseconds each, without references (a crashed reference would
// fail its key's other jobs too, which is not what this test is about).
void writeSweep(const fs::path& file) {
    std::ofstream(file) << R"({
        "name": "isolation",
        "fixed": {"scene": "atrium", "resolution": "240x136", "lights": 48},
        "axes": {"seed": [1, 2], "stage": ["brute", "tiled", "deferred", "clustered"]},
        "reference": false
    })";
}

TEST(SweepIsolation, CrashedAndAbortedJobsFailAloneAndTheSweepGoesOn) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    // In the AddressSanitizer build (./run.sh sanitize) ASan's own SIGSEGV handler would turn the
    // SIGSEGV sent below into its report and an abort (SIGABRT); the job must die of the signal
    // it was sent, as it does in every other build. The sweep and its jobs inherit this.
    const char* asanOptions = std::getenv("ASAN_OPTIONS");
    const std::string withSegv =
        (asanOptions && *asanOptions ? std::string(asanOptions) + ":" : std::string()) +
        "handle_segv=0";
    setenv("ASAN_OPTIONS", withSegv.c_str(), 1);
    const fs::path dir = freshDir("sweep-isolation-crash");
    writeSweep(dir / "sweep.json");
    const fs::path out = dir / "out";
    const pid_t sweep =
        spawn({"sweep", (dir / "sweep.json").string(), "--out", out.string(), "--threads", "1"},
              dir / "sweep.log");
    ASSERT_GT(sweep, 0);

    std::set<pid_t> seen;
    for (const int signal : {SIGSEGV, SIGABRT}) {
        const std::optional<pid_t> job = stopNextJobProcess(sweep, seen);
        if (!job) {
            kill(sweep, SIGKILL);
            waitExit(sweep);
            FAIL() << "no job process of the sweep appeared (jobs run in the sweep's process?); "
                      "log:\n"
                   << readText(dir / "sweep.log");
        }
        kill(*job, signal);
        kill(*job, SIGCONT);
    }
    const int code = waitExit(sweep);
    const std::string log = readText(dir / "sweep.log");
    EXPECT_EQ(code, 1) << log; // some job failed; the sweep itself ended normally
    EXPECT_NE(log.find("killed by signal 11 (SIGSEGV"), std::string::npos) << log;
    EXPECT_NE(log.find("killed by signal 6 (SIGABRT"), std::string::npos) << log;
    EXPECT_NE(log.find("8 jobs, 8 ran, 0 skipped, 2 failed"), std::string::npos) << log;

    const Json results = Json::parse(readText(out / "results.json"));
    ASSERT_EQ(results["jobs"].size(), 8u);
    int failed = 0;
    for (const Json& row : results["jobs"]) {
        if (row["status"] == "ok")
            continue;
        ++failed;
        EXPECT_NE(row["error"].get<std::string>().find("the job process crashed: killed by signal"),
                  std::string::npos)
            << row.dump();
    }
    EXPECT_EQ(failed, 2);

    // A rerun retries the two crashed jobs and skips the rest.
    const pid_t rerun =
        spawn({"sweep", (dir / "sweep.json").string(), "--out", out.string(), "--threads", "1"},
              dir / "rerun.log");
    EXPECT_EQ(waitExit(rerun), 0) << readText(dir / "rerun.log");
    EXPECT_NE(readText(dir / "rerun.log").find("8 jobs, 2 ran, 6 skipped, 0 failed"),
              std::string::npos)
        << readText(dir / "rerun.log");
}

TEST(SweepIsolation, AJobPastTheTimeLimitIsKilledAndTheSweepGoesOn) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshDir("sweep-isolation-timeout");
    // 4 of the smallest jobs: every job runs under the limit, which must stay far above a healthy
    // job's time on a loaded machine (0.7 s each in Release at a load of 16 on 2 cores).
    std::ofstream(dir / "sweep.json") << R"({
        "name": "timeout",
        "fixed": {"scene": "wall", "resolution": "64x36", "lights": 1},
        "axes": {"seed": [1, 2, 3, 4]},
        "reference": false
    })";
    const fs::path out = dir / "out";
    const std::vector<std::string> args = {"sweep",         (dir / "sweep.json").string(),
                                           "--out",         out.string(),
                                           "--threads",     "1",
                                           "--job-timeout", "15"};
    const auto start = Clock::now();
    const pid_t sweep = spawn(args, dir / "sweep.log");
    ASSERT_GT(sweep, 0);
    std::set<pid_t> seen;
    const std::optional<pid_t> hung = stopNextJobProcess(sweep, seen);
    if (!hung) {
        kill(sweep, SIGKILL);
        waitExit(sweep);
        FAIL() << "no job process of the sweep appeared; log:\n" << readText(dir / "sweep.log");
    }
    // Without the limit the sweep would wait for its stopped job for ever: give up after 5 min.
    std::optional<int> code;
    while (!code && Clock::now() - start < std::chrono::minutes(5)) {
        int status = 0;
        if (waitpid(sweep, &status, WNOHANG) == sweep)
            code = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
        else
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (!code) {
        kill(sweep, SIGKILL); // its stopped job dies with it (PR_SET_PDEATHSIG)
        waitExit(sweep);
        FAIL() << "the sweep did not end with a job stopped; log:\n" << readText(dir / "sweep.log");
    }
    const std::string log = readText(dir / "sweep.log");
    EXPECT_EQ(*code, 1) << log;
    EXPECT_NE(log.find("job time limit 15 s"), std::string::npos) << log;
    EXPECT_NE(log.find("timed out after 15 s"), std::string::npos) << log;
    EXPECT_NE(log.find("4 jobs, 4 ran, 0 skipped, 1 failed"), std::string::npos) << log;
    EXPECT_GE(seconds, 15.0); // the stopped job held the sweep until its limit, no shorter

    const Json results = Json::parse(readText(out / "results.json"));
    ASSERT_EQ(results["jobs"].size(), 4u);
    int failed = 0;
    for (const Json& row : results["jobs"]) {
        if (row["status"] == "ok")
            continue;
        ++failed;
        EXPECT_EQ(row["error"].get<std::string>(),
                  "the job process timed out after 15 s (the sweep's job time limit) and was "
                  "killed")
            << row.dump();
    }
    EXPECT_EQ(failed, 1);

    // A rerun retries the timed-out job and skips the rest.
    const pid_t rerun = spawn(args, dir / "rerun.log");
    EXPECT_EQ(waitExit(rerun), 0) << readText(dir / "rerun.log");
    EXPECT_NE(readText(dir / "rerun.log").find("4 jobs, 1 ran, 3 skipped, 0 failed"),
              std::string::npos)
        << readText(dir / "rerun.log");
}

TEST(SweepLock, SecondSweepOnTheSameJobsIsRefusedOrWaits) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshDir("sweep-lock");
    writeSweep(dir / "sweep.json");
    const std::string file = (dir / "sweep.json").string();
    const std::string out = (dir / "out").string();

    // The first sweep runs shard 1/2 and is held (stopped) in its first job: it holds its lock.
    const pid_t first =
        spawn({"sweep", file, "--out", out, "--threads", "1", "--shard", "1/2"}, dir / "first.log");
    std::set<pid_t> seen;
    const std::optional<pid_t> job = stopNextJobProcess(first, seen);
    if (!job) {
        kill(first, SIGKILL);
        waitExit(first);
        FAIL() << "the first sweep started no job; log:\n" << readText(dir / "first.log");
    }
    kill(first, SIGSTOP);

    // The whole sweep overlaps shard 1/2: refused at once with one error line naming the holder.
    const pid_t second = spawn({"sweep", file, "--out", out, "--threads", "1"}, dir / "second.log");
    EXPECT_EQ(waitExit(second), 1);
    const std::string refused = readText(dir / "second.log");
    EXPECT_EQ(refused.rfind("testbed: error: ", 0), 0u) << refused;
    EXPECT_EQ(std::count(refused.begin(), refused.end(), '\n'), 1) << refused;
    EXPECT_NE(refused.find("is in use: process " + std::to_string(first)), std::string::npos)
        << refused;
    EXPECT_NE(refused.find("--wait"), std::string::npos) << refused;

    // Shard 2/2 has none of shard 1/2's jobs: it runs beside it.
    const pid_t disjoint = spawn({"sweep", file, "--out", out, "--threads", "1", "--shard", "2/2"},
                                 dir / "disjoint.log");
    EXPECT_EQ(waitExit(disjoint), 0) << readText(dir / "disjoint.log");

    // With --wait, the whole sweep waits for the first one, then runs what is left.
    const pid_t waiting =
        spawn({"sweep", file, "--out", out, "--threads", "1", "--wait"}, dir / "waiting.log");
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    while (readText(dir / "waiting.log").find("waiting until it ends") == std::string::npos &&
           Clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_NE(readText(dir / "waiting.log").find("waiting until it ends (--wait)"),
              std::string::npos)
        << readText(dir / "waiting.log");
    int status = 0;
    EXPECT_EQ(waitpid(waiting, &status, WNOHANG), 0)
        << "the waiting sweep ended while the lock was held";
    kill(first, SIGKILL); // its stopped job process dies with it (PR_SET_PDEATHSIG)
    waitExit(first);
    // Unless it was stopped before it set PR_SET_PDEATHSIG: then it stayed behind, stopped and
    // orphaned, after every run of this test. It is not our child, so it is killed, not waited.
    kill(*job, SIGKILL);
    EXPECT_EQ(waitExit(waiting), 0) << readText(dir / "waiting.log");
    const std::string waited = readText(dir / "waiting.log");
    EXPECT_NE(waited.find("8 jobs, 4 ran, 4 skipped, 0 failed"), std::string::npos) << waited;
}

// Peak resident memory of the children waited for so far, in MB.
double peakChildMegabytes() {
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    return double(usage.ru_maxrss) / 1024.0;
}

TEST(SweepJobCap, SweepPastTheCapIsRefusedBeforeAnyJobIsMade) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshDir("sweep-job-cap");
    // 1001 x 1000 = 1 001 000 jobs, one past 10^6.
    std::ofstream file(dir / "sweep.json");
    file << R"({"name": "big", "fixed": {"scene": "wall", "resolution": "64x36"},)"
         << R"("reference": false, "axes": {"seed": [)";
    for (int i = 0; i < 1001; ++i)
        file << (i ? "," : "") << i;
    file << R"(], "lights": [)";
    for (int i = 1; i <= 1000; ++i)
        file << (i > 1 ? "," : "") << i;
    file << "]}}";
    file.close();
    const pid_t sweep =
        spawn({"sweep", (dir / "sweep.json").string(), "--out", (dir / "out").string()},
              dir / "sweep.log");
    EXPECT_EQ(waitExit(sweep), 2);
    const std::string log = readText(dir / "sweep.log");
    EXPECT_EQ(log.rfind("testbed: error: ", 0), 0u) << log;
    EXPECT_NE(log.find("1001000 jobs refused (at most 1000000)"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(dir / "out" / "jobs")) << "a refused sweep made its output folder";
    // The refusal comes before the jobs are made: the process stays near the size of the
    // binary's own libraries (~130 MB resident for `testbed list`), far from the 2.5 GB that a
    // vector of 10^6 jobs took.
    EXPECT_LT(peakChildMegabytes(), 400.0);
}

TEST(SweepJobCap, SweepAtTheCapStartsItsFirstJobInBoundedMemory) {
    ASSERT_TRUE(fs::is_regular_file(kTestbed)) << kTestbed << " not built";
    const fs::path dir = freshDir("sweep-job-cap-start");
    // 1000 x 1000 = 10^6 jobs, the cap: every job is made and validated once before the first
    // runs, but none is kept (SweepExpansion).
    std::ofstream file(dir / "sweep.json");
    file << R"({"name": "at-cap", "fixed": {"scene": "wall", "resolution": "64x36"},)"
         << R"("reference": false, "axes": {"seed": [)";
    for (int i = 0; i < 1000; ++i)
        file << (i ? "," : "") << i;
    file << R"(], "lights": [)";
    for (int i = 1; i <= 1000; ++i)
        file << (i > 1 ? "," : "") << i;
    file << "]}}";
    file.close();
    const pid_t sweep = spawn(
        {"sweep", (dir / "sweep.json").string(), "--out", (dir / "out").string(), "--threads", "1"},
        dir / "sweep.log");
    const auto deadline = Clock::now() + std::chrono::seconds(300);
    while (readText(dir / "sweep.log").find("running 000000-") == std::string::npos &&
           Clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    // VmHWM: the sweep process's peak resident memory so far (its job processes are separate).
    std::ifstream status("/proc/" + std::to_string(sweep) + "/status");
    double peakMegabytes = -1.0;
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmHWM:", 0) == 0)
            peakMegabytes = std::stod(line.substr(6)) / 1024.0;
    kill(sweep, SIGKILL);
    waitExit(sweep);
    const std::string log = readText(dir / "sweep.log");
    ASSERT_NE(log.find("running 000000-"), std::string::npos) << "no job started:\n" << log;
    std::cout << "peak resident memory before the first job: " << peakMegabytes << " MB\n";
    // 183 MB measured (most of it the libraries OpenImageIO pulls in); a vector of 10^6 job
    // records reached 2.5 GB before the first job. Under AddressSanitizer the same process
    // measured 765 MB (its allocator keeps freed blocks in a 256 MB quarantine and adds redzones
    // and shadow memory to every allocation), so that build gets twice the bound.
    EXPECT_GT(peakMegabytes, 0.0);
    EXPECT_LT(peakMegabytes, kUnderAddressSanitizer ? 1200.0 : 600.0);
}

} // namespace
