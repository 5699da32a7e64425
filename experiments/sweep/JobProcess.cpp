#include "experiments/sweep/JobProcess.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "experiments/output/JsonText.h"
#include "experiments/sweep/SanitizerBuild.h"
#include "experiments/sweep/SweepJobRun.h"

extern char** environ;

namespace experiments {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

constexpr int kReportFd = 3; // the child's end of the report pipe

// Closes a descriptor when it goes out of scope.
struct Descriptor {
    int fd = -1;
    ~Descriptor() {
        if (fd >= 0)
            close(fd);
    }
};

std::string signalName(int signal) {
    switch (signal) {
    case SIGSEGV:
        return "SIGSEGV";
    case SIGABRT:
        return "SIGABRT";
    case SIGKILL:
        return "SIGKILL";
    case SIGBUS:
        return "SIGBUS";
    case SIGFPE:
        return "SIGFPE";
    case SIGILL:
        return "SIGILL";
    case SIGTERM:
        return "SIGTERM";
    case SIGINT:
        return "SIGINT";
    default:
        return "signal " + std::to_string(signal);
    }
}

// Writes one report line; a failed write (the parent is gone) is ignored: nobody is listening.
void report(int fd, const Json& line) {
    const std::string text = line.dump() + "\n";
    size_t written = 0;
    while (written < text.size()) {
        const ssize_t n = write(fd, text.data() + written, text.size() - written);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return;
        written += size_t(n);
    }
}

// ThreadSanitizer kills a child forked from a process of several threads (here the idle pools
// libraries start before main(), which fork otherwise tolerates) as soon as the child starts a
// thread ("starting new threads after multi-threaded fork is not supported"), as every job does:
// that build always spawns.
constexpr bool kForkSupported = !kThreadSanitizerBuild;

// The threads libraries started before main() (noteStartupThreads); 1 when not noted.
int gStartupThreads = 1;

int threadsOfThisProcess() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("Threads:", 0) == 0)
            return std::atoi(line.c_str() + 8);
    return 0; // unknown: treated as more than one
}

// The child's work, in a forked or a spawned child: runs the job and reports on reportFd.
// Returns the exit code (0 ok, 1 failed).
int runJobAndReport(const SweepJob& job, const fs::path& out, int reportFd) {
    bool referenceFailed = false;
    try {
        const fs::path jobDir = out / "jobs" / job.id;
        ReferenceStore references(out / "references");
        const ReferenceStore::Listener listener = [&](ReferenceStore::Event event,
                                                      const std::string& key) {
            const char* what = event == ReferenceStore::Event::Rendering  ? "rendering"
                               : event == ReferenceStore::Event::Rendered ? "rendered"
                                                                          : "loaded";
            report(reportFd, Json{{"reference", what}, {"key", key}});
        };
        if (job.compareReference) {
            try {
                references.get(job, listener);
            } catch (const std::exception&) {
                referenceFailed = true;
                throw;
            }
        }
        const Json metrics = runSweepJob(job, jobDir, references, listener);
        report(reportFd, Json{{"status", "ok"}, {"metrics", metrics}});
        return 0;
    } catch (const std::exception& e) {
        std::string error = e.what();
        if (error.empty())
            error = "unknown error";
        report(reportFd,
               Json{{"status", "failed"}, {"error", error}, {"reference_failed", referenceFailed}});
        return 1;
    }
}

// Asks the kernel to kill this (child) process when its parent dies, so kill -9 of `testbed
// sweep` stops its job too; false when the parent is already gone (the job is not wanted).
bool dieWithParent(pid_t parent) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    return getppid() == parent;
}

// posix_spawn of `executable sweep-job --parent PID --report-fd 3 JSON` with writeFd as its fd 3.
pid_t spawnJob(const fs::path& executable, const SweepJob& job, const fs::path& out, int writeFd) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, writeFd, kReportFd);
    const std::string parent = std::to_string(getpid());
    const std::string fd = std::to_string(kReportFd);
    const std::string jobText = Json{{"out", pathForJson(out)}, {"job", sweepJobJson(job)}}.dump();
    const std::string program = executable.string();
    std::vector<std::string> arguments = {program,       "sweep-job", "--parent", parent,
                                          "--report-fd", fd,          jobText};
    std::vector<char*> argv;
    for (std::string& argument : arguments)
        argv.push_back(argument.data());
    argv.push_back(nullptr);
    pid_t child = 0;
    const int spawned =
        posix_spawn(&child, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0)
        throw std::runtime_error("cannot start a job process (" + program +
                                 "): " + std::strerror(spawned));
    return child;
}

// Waits until fd is readable (or at its end) or the deadline passes; false when the deadline
// passed first. No deadline: waits as long as it takes.
bool waitReadable(int fd, std::optional<std::chrono::steady_clock::time_point> deadline) {
    for (;;) {
        int timeoutMs = -1;
        if (deadline) {
            const auto left = std::chrono::ceil<std::chrono::milliseconds>(
                *deadline - std::chrono::steady_clock::now());
            if (left.count() <= 0)
                return false;
            timeoutMs = int(std::min<long long>(left.count(), INT_MAX));
        }
        pollfd entry{fd, POLLIN, 0};
        const int ready = poll(&entry, 1, timeoutMs);
        if (ready > 0)
            return true;
        if (ready < 0 && errno != EINTR)
            return true; // cannot poll: let read() report the descriptor's state
    }
}

} // namespace

std::string formatTimeLimit(double seconds) {
    char text[32];
    std::snprintf(text, sizeof text, "%g s", seconds);
    return text;
}

void noteStartupThreads() {
    gStartupThreads = std::max(1, threadsOfThisProcess());
}

std::string describeProcessEnd(int status) {
    if (WIFSIGNALED(status)) {
        const int signal = WTERMSIG(status);
        std::string text = "killed by signal " + std::to_string(signal) + " (" +
                           signalName(signal) + ", " + strsignal(signal) + ")";
        if (signal == SIGKILL)
            text += "; the kernel's out-of-memory killer sends SIGKILL when memory runs out";
        return text;
    }
    if (WIFEXITED(status))
        return "exited with code " + std::to_string(WEXITSTATUS(status));
    return "ended with wait status " + std::to_string(status);
}

JobProcessOutcome runJobProcess(const SweepJob& job, const fs::path& out, JobStart start,
                                const fs::path& executable, double timeLimitSeconds) {
    if (!(timeLimitSeconds >= 0.0) || !std::isfinite(timeLimitSeconds))
        throw std::invalid_argument("job time limit " + std::to_string(timeLimitSeconds) +
                                    " s: expected a finite number >= 0 (0 = no limit)");
    int ends[2];
    if (pipe2(ends, O_CLOEXEC) != 0)
        throw std::runtime_error(std::string("cannot create a pipe for a job process: ") +
                                 std::strerror(errno));
    Descriptor readEnd{ends[0]}, writeEnd{ends[1]};
    // The write end must not already be fd 3: dup2(3, 3) would keep its close-on-exec flag.
    if (writeEnd.fd == kReportFd) {
        const int moved = fcntl(writeEnd.fd, F_DUPFD_CLOEXEC, kReportFd + 1);
        if (moved < 0)
            throw std::runtime_error(std::string("cannot move a pipe descriptor: ") +
                                     std::strerror(errno));
        close(writeEnd.fd);
        writeEnd.fd = moved;
    }
    // fork copies only the calling thread: with threads of ours alive, a lock one of them held
    // would stay locked in the child for ever, so a process that started threads starts a fresh
    // one (see the file comment for the idle threads of libraries, which do not count).
    const int threads = threadsOfThisProcess();
    const bool useFork =
        kForkSupported && start == JobStart::Fork && threads >= 1 && threads <= gStartupThreads;
    if (!useFork && executable.empty())
        throw std::runtime_error("cannot start a job process: this process started threads "
                                 "and no testbed executable was given");
    // The time limit counts from the start of the child, loading its libraries (Spawn) included.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    if (timeLimitSeconds > 0.0)
        deadline = std::chrono::steady_clock::now() +
                   std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                       std::chrono::duration<double>(timeLimitSeconds));
    pid_t child = 0;
    if (useFork) {
        std::cout.flush();
        std::cerr.flush();
        const pid_t parent = getpid();
        child = fork();
        if (child < 0)
            throw std::runtime_error(std::string("cannot start a job process: ") +
                                     std::strerror(errno));
        if (child == 0) {
            close(readEnd.fd);
            // _exit: no atexit handlers or static destructors of the parent's state run twice.
            _exit(dieWithParent(parent) ? runJobAndReport(job, out, writeEnd.fd) : 1);
        }
    } else {
        child = spawnJob(executable, job, out, writeEnd.fd);
    }
    close(writeEnd.fd); // only the child writes now: EOF when it exits
    writeEnd.fd = -1;

    JobProcessOutcome outcome;
    bool finished = false;    // a status line arrived
    bool inReference = false; // "rendering" seen without "rendered"
    std::string pending;
    char buffer[4096];
    auto handleLine = [&](const std::string& line) {
        Json message;
        try {
            message = Json::parse(line);
        } catch (const std::exception&) {
            return; // not ours (cannot happen: only the child writes here)
        }
        if (!message.is_object())
            return;
        if (message.contains("reference") && message["reference"].is_string()) {
            const std::string what = message["reference"].get<std::string>();
            inReference = what == "rendering";
            outcome.referenceRendered |= what == "rendered";
            outcome.referenceLoaded |= what == "loaded";
        }
        if (message.contains("status") && message["status"].is_string()) {
            finished = true;
            outcome.ok = message["status"] == "ok";
            if (outcome.ok && message.contains("metrics"))
                outcome.metrics = message["metrics"];
            if (!outcome.ok) {
                outcome.error = message.value("error", std::string("unknown error"));
                outcome.referenceFailed = message.value("reference_failed", false);
            }
        }
    };
    bool timedOut = false;
    for (;;) {
        if (!waitReadable(readEnd.fd, deadline)) {
            // Past the limit: SIGKILL, which a hung, stopped or signal-blocking process cannot
            // ignore. Its report pipe is not read further: what it said so far is all we use.
            kill(child, SIGKILL);
            timedOut = true;
            break;
        }
        const ssize_t n = read(readEnd.fd, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        pending.append(buffer, size_t(n));
        for (size_t end; (end = pending.find('\n')) != std::string::npos;) {
            handleLine(pending.substr(0, end));
            pending.erase(0, end + 1);
        }
    }
    int status = 0;
    while (waitpid(child, &status, 0) < 0)
        if (errno != EINTR)
            throw std::runtime_error(std::string("cannot wait for a job process: ") +
                                     std::strerror(errno));
    // A status line means the job's files are written: a process killed at the limit after it
    // (while exiting) keeps its result.
    if (finished && timedOut)
        return outcome;
    const bool cleanExit = WIFEXITED(status) && (WEXITSTATUS(status) == 0 || finished);
    if (finished && cleanExit)
        return outcome;
    // Died without a result, or exited 0 without one: the process's end is the error.
    outcome.ok = false;
    outcome.metrics = Json();
    const std::string end = describeProcessEnd(status);
    if (timedOut) {
        const std::string limit = "timed out after " + formatTimeLimit(timeLimitSeconds) +
                                  " (the sweep's job time limit) and was killed";
        outcome.referenceFailed = inReference;
        outcome.error = inReference ? "reference " + job.referenceKey +
                                          ": the job process rendering it " + limit
                                    : "the job process " + limit;
    } else if (inReference) {
        outcome.referenceFailed = true;
        outcome.error =
            "reference " + job.referenceKey + ": the job process rendering it crashed: " + end;
    } else {
        outcome.error = "the job process crashed: " + end;
    }
    return outcome;
}

int runSweepJobCommand(const std::string& jobText, long parentPid, int reportFd) {
    if (!dieWithParent(pid_t(parentPid)))
        return 1;
    SweepJob job;
    fs::path out;
    try {
        const Json input = Json::parse(jobText);
        out = pathFromJson(input.at("out").get<std::string>());
        job = sweepJobFromJson(input.at("job"));
    } catch (const std::exception& e) {
        report(reportFd, Json{{"status", "failed"}, {"error", e.what()}});
        return 1;
    }
    return runJobAndReport(job, out, reportFd);
}

} // namespace experiments
