// SweepRunner: `testbed sweep FILE --out DIR`: expands a sweep file (SweepFile.h, jobs made on
// demand), validates every job before running any (its options, then its plan against its scene
// and its memory estimate: SweepPreflight.h) and before DIR is created or touched, locks the
// shard's jobs in DIR against a second sweep (SweepLock.h), then runs the jobs of this shard one
// after the other:
//   - isolation: the CLI runs each job in a child process (JobProcess.h), so a job that crashes,
//     aborts or is killed (SIGKILL by the out-of-memory killer) is recorded as failed with its
//     signal and the sweep goes on; tests may run jobs in this process (JobIsolation::InProcess);
//   - time limit: with --job-timeout (or the file's job-timeout), a job's process still running
//     that long after its start is killed and the job fails ("timed out after N s");
//   - reference: one double-precision reference per (scene, scene options, lights, seed, size),
//     cached as DIR/references/<key>.exr (float R,G,B, bit-exact) by the first job that needs
//     it, and read back by the key's later jobs (kept in memory between them when in-process),
//     a rerun and other shards writing to DIR;
//   - the job: planRender then runRender (as `testbed render` does) with its warmup,
//     repetitions and the reference, then writeRenderOutputs into DIR/jobs/<job_id>/ and, LAST and
//     atomically, the done.json marker holding its results row (the run's RunMetrics), written by
//     this process whether the job succeeded, failed or crashed;
//   - the table: DIR/results.json and DIR/results.csv rebuilt (atomically) from the markers of
//     the jobs of the sweep found in DIR, after a job (at most ~10% of the sweep's time: see
//     rebuildTable) and at the end.
// A job whose marker says "ok" is finished and skipped by a rerun; a failed job (any exception,
// or its process crashed) gets a marker with status "failed" and its error, the sweep goes on,
// and a rerun retries it. kill -9 at any moment leaves at worst a job folder without marker
// (redone on rerun) or hidden temporary files; nothing partial is ever counted.
// Progress goes to the `log` stream (stderr for the CLI), one line per event: jobs done/total,
// skipped, failed, the current job's settings, elapsed and estimated remaining time.
//
// Thread safety: one runSweep per process at a time. Several processes (shards) may share DIR
// when their jobs are disjoint: each writes only its own jobs' folders, and references and tables
// by rename; a process whose jobs overlap a running one's is refused (or waits, with --wait).
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace experiments {

enum class JobIsolation { InProcess, Fork, Spawn };

struct SweepOptions {
    std::filesystem::path file; // the sweep file (.json or .toml)
    std::filesystem::path out = "sweep-out";
    int shardIndex = 1; // 1-based
    int shardCount = 1;
    bool quick = false;         // apply the file's "quick" block
    std::optional<int> threads; // overrides every job's threads (0 = all hardware threads)
    // Where jobs run. InProcess: in this process, where a crash of one job ends the sweep (tests);
    // Fork / Spawn: each in a child process (JobProcess.h), the CLI's choice (Fork).
    JobIsolation isolation = JobIsolation::InProcess;
    // The testbed binary a Spawn child runs (`testbed sweep-job`); Fork uses it when this process
    // has several threads. The CLI passes "/proc/self/exe".
    std::filesystem::path jobExecutable;
    bool waitForLock = false; // --wait: wait for a sweep running the same jobs into out
    // --job-timeout: wall-time limit of each job's process in seconds, 0 = none; overrides the
    // file's job-timeout (SweepFile.h). A job past it is killed and fails ("timed out after N s").
    // Needs isolated jobs: InProcess with a limit is refused.
    std::optional<double> jobTimeoutSeconds;
};

struct SweepSummary {
    size_t jobsInSweep = 0; // full expansion
    size_t jobsInShard = 0;
    size_t ran = 0;     // run in this invocation (ok or failed)
    size_t skipped = 0; // finished before (marker "ok")
    size_t failed = 0;  // failed in this invocation
    size_t referencesRendered = 0;
    size_t referencesLoaded = 0; // read back from DIR/references
    size_t rowsInTable = 0;      // jobs in DIR/results.json
};

// Runs the sweep. Throws SweepError (file or jobs invalid: nothing was run) or
// std::runtime_error (DIR not writable). Job failures do not throw: see summary.failed.
SweepSummary runSweep(const SweepOptions& options, std::ostream& log);

// The CLI: runs, prints errors as "testbed: error: ..." on stderr; exit code 0 when every job of
// the shard is ok, 1 when a job failed or the sweep could not start (DIR unusable, or in use by
// another sweep: SweepBusyError), 2 for an invalid sweep.
int runSweepCommand(const SweepOptions& options);

// `testbed merge DIR... --out DIR` (ResultsTable.h mergeSweepOutputs); exit code 0 or 1.
int runMergeCommand(const std::vector<std::filesystem::path>& inputs,
                    const std::filesystem::path& out);

} // namespace experiments
