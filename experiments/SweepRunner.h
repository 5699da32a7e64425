// SweepRunner: `testbed sweep FILE --out DIR`: expands a sweep file (SweepFile.h), validates every
// job before running any, then runs the jobs of this shard one after the other:
//   - reference: one double-precision reference per (scene, scene options, lights, seed, size),
//     kept in memory while adjacent jobs need it and cached as DIR/references/<key>.exr (float
//     R,G,B, bit-exact) so that a rerun or another shard writing to DIR reads it back;
//   - the job: planRender then runRender (as `testbed render` does) with its warmup, repetitions
//     and the reference, then writeRenderOutputs into DIR/jobs/<job_id>/ and, LAST and
//     atomically, the done.json marker holding its results row (the run's RunMetrics);
//   - the table: DIR/results.json and DIR/results.csv rebuilt (atomically) from the markers of
//     every job of the sweep found in DIR, after each job and at the end.
// A job whose marker says "ok" is finished and skipped by a rerun; a failed job (any exception)
// gets a marker with status "failed" and its error, the sweep goes on, and a rerun retries it.
// kill -9 at any moment leaves at worst a job folder without marker (redone on rerun) or hidden
// temporary files; nothing partial is ever counted.
// Progress goes to the `log` stream (stderr for the CLI), one line per event: jobs done/total,
// skipped, failed, the current job's settings, elapsed and estimated remaining time.
//
// Thread safety: one runSweep per output folder at a time per shard; several processes (shards)
// may share DIR: each writes only its own jobs' folders, and references and tables by rename.
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace experiments {

struct SweepOptions {
    std::filesystem::path file; // the sweep file (.json or .toml)
    std::filesystem::path out = "sweep-out";
    int shardIndex = 1; // 1-based
    int shardCount = 1;
    bool quick = false;         // apply the file's "quick" block
    std::optional<int> threads; // overrides every job's threads (0 = all hardware threads)
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
// the shard is ok, 1 when a job failed or the sweep could not start, 2 for an invalid sweep.
int runSweepCommand(const SweepOptions& options);

// `testbed merge DIR... --out DIR` (ResultsTable.h mergeSweepOutputs); exit code 0 or 1.
int runMergeCommand(const std::vector<std::filesystem::path>& inputs,
                    const std::filesystem::path& out);

} // namespace experiments
