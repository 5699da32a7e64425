// JobProcess: a sweep job run in a child process, so that a job that crashes (SIGSEGV), aborts
// (SIGABRT, a failed assertion, std::terminate) or is killed (SIGKILL from the kernel's
// out-of-memory killer) fails alone, and the sweep records it and goes on.
//
// Starting the child: `testbed sweep` forks without exec (JobStart::Fork). Its process never
// renders, so it starts no thread of its own, and the child starts from the parent's memory in
// about a millisecond; a fresh process spends 0.5-0.8 s on an idle machine (1.5-2.7 s at a load
// of 16 on 2 cores) linking the ~260 shared libraries that OpenImageIO pulls in (measured with
// `/usr/bin/time testbed list`), more than many jobs take. fork copies only the calling thread,
// and a lock another thread held would stay locked in the child, so fork is used only while the
// process has no more threads than it had when main() began (noteStartupThreads): those are the
// idle pools that libraries start from their constructors (log4cplus, through OpenVDB, starts 4),
// which the parent never calls into. A process that started threads (TBB's workers, OIIO's pool)
// starts `executable sweep-job --parent PID --report-fd 3 '<job JSON>'` instead (JobStart::Spawn,
// posix_spawn; "sweep-job" is a hidden subcommand), and so does every ThreadSanitizer build (it
// kills a child forked from a process of several threads once the child starts one).
//
// The child reports on a pipe (its fd 3 when spawned) and the parent reads until the child closes
// it, then waits for it. Each report line is one JSON object:
//   {"reference": "rendering" | "rendered" | "loaded", "key": KEY}
//   {"status": "ok", "metrics": {column: value}}     (last line of a job that succeeded)
//   {"status": "failed", "error": TEXT, "reference_failed": bool}
// A child that dies without a status line is reported by its signal or exit code; when it died
// after "rendering" and before "rendered", the reference is what crashed, and the runner fails
// the key's other jobs at once instead of crashing on it again.
//
// Time limit: with a limit, the parent waits for the pipe with poll() until the limit after the
// child's start, then kills the child (SIGKILL: a hung or stopped process cannot ignore it) and
// reports "the job process timed out after N s ... and was killed"; a limit that passes while the
// child renders a reference fails the reference as a crash there does. A child that sent its
// status line keeps its result even when killed at the limit while exiting.
//
// The child first asks the kernel to kill it when the parent dies (PR_SET_PDEATHSIG), so kill -9
// of `testbed sweep` stops its job too, as it did when jobs ran in-process; then it runs the job
// (SweepJobRun.h) with the reference read from DIR/references or rendered and cached there,
// writes the job's files, and reports. It prints nothing else; its stderr is the parent's, so a
// sanitizer report or an abort message of a job shows in the sweep's log. A forked child ends
// with _exit (the parent's atexit handlers and static destructors do not run twice).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/sweep/SweepFile.h"

namespace experiments {

struct JobProcessOutcome {
    bool ok = false;
    std::string error;              // when !ok: the job's error, or how the process ended
    nlohmann::ordered_json metrics; // when ok: the row's metric columns (SweepJobRun.h)
    bool referenceFailed = false;   // the job's reference could not be made (error says why)
    bool referenceRendered = false; // the child rendered (and cached) the reference
    bool referenceLoaded = false;   // the child read the reference from DIR/references
};

enum class JobStart {
    Fork,  // fork without exec when this process has started no thread, else as Spawn
    Spawn, // posix_spawn of the executable's hidden `sweep-job` subcommand
};

// Runs the job in a child process writing into out/jobs/<job id>/ (which must exist) and
// out/references/. `executable` is the testbed binary for Spawn ("/proc/self/exe" runs the very
// binary of this process even if the file was replaced since); it may be empty for Fork when this
// process has started no thread. timeLimitSeconds > 0: the child is killed that long after its
// start (wall time) and the job fails; 0: no limit. Never throws for a failure of the job; throws
// std::runtime_error when the process cannot be started at all, std::invalid_argument for a
// negative or non-finite limit.
JobProcessOutcome runJobProcess(const SweepJob& job, const std::filesystem::path& out,
                                JobStart start, const std::filesystem::path& executable,
                                double timeLimitSeconds = 0.0);

// A time limit in the words of the timeout error: "2 s", "0.5 s", "3600 s".
std::string formatTimeLimit(double seconds);

// Records how many threads this process has now: call it first in main(), before any code of the
// testbed starts a thread. Without it, Fork forks only a process of one thread.
void noteStartupThreads();

// How a child process ended, in words: "killed by signal 11 (SIGSEGV, Segmentation fault)",
// "exited with code 3". status is waitpid's.
std::string describeProcessEnd(int status);

// The hidden `testbed sweep-job` subcommand (the child side, see above). jobText is the JSON that
// runJobProcess passes: {"out": DIR, "job": sweepJobJson(job)}. Returns the exit code: 0 when the
// job succeeded, 1 when it failed (the reason is on the report pipe).
int runSweepJobCommand(const std::string& jobText, long parentPid, int reportFd);

} // namespace experiments
