#include "experiments/sweep/SweepRunner.h"

#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "experiments/CommandErrors.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/JsonText.h"
#include "experiments/output/Progress.h"
#include "experiments/sweep/JobProcess.h"
#include "experiments/sweep/ResultsTable.h"
#include "experiments/sweep/SweepFile.h"
#include "experiments/sweep/SweepJobRun.h"
#include "experiments/sweep/SweepLock.h"
#include "experiments/sweep/SweepPreflight.h"
#include "scenes/input/MessageText.h"
#include "scenes/input/WholeFile.h"

namespace experiments {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

namespace {

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return text;
}

// A marker's JSON, or nullopt when there is no readable marker. Read as every input file is
// (scenes/input/WholeFile.h): a FIFO or device put in its place is unreadable, never a hang.
std::optional<Json> readMarker(const fs::path& marker) {
    std::string text;
    if (!scenes::readWholeFile(marker, &text).empty())
        return std::nullopt;
    try {
        return Json::parse(text);
    } catch (const std::exception&) {
        return std::nullopt; // cannot happen with atomic writes; treat as unfinished
    }
}

// The marker's status, or "" when there is no readable marker (then the job is not finished).
std::string markerStatus(const fs::path& marker) {
    const std::optional<Json> json = readMarker(marker);
    try {
        return json && json->is_object() ? json->value("status", "") : "";
    } catch (const std::exception&) {
        return ""; // a status that is not a string: not a marker we wrote
    }
}

std::optional<Json> markerRow(const fs::path& marker) {
    std::optional<Json> read = readMarker(marker);
    if (!read)
        return std::nullopt;
    try {
        Json& json = *read;
        if (json.contains("row") && json["row"].is_object())
            return json["row"];
    } catch (const std::exception&) {
    }
    return std::nullopt;
}

// The row's axis values and status; metrics are added by the caller.
Json baseRow(const SweepJob& job, const std::vector<std::string>& axisColumns) {
    Json row = Json::object();
    row["job_id"] = job.id;
    row["status"] = "ok";
    row["error"] = "";
    for (const std::string& column : axisColumns)
        row[column] = axisValue(job, column);
    return row;
}

// The ordinal of a job folder's name "<ordinal>-<hash>", or nullopt for another name.
std::optional<size_t> ordinalOfFolder(const std::string& name) {
    const size_t dash = name.find('-');
    if (dash == 0 || dash == std::string::npos || dash > 20)
        return std::nullopt;
    size_t ordinal = 0;
    for (size_t i = 0; i < dash; ++i) {
        if (name[i] < '0' || name[i] > '9')
            return std::nullopt;
        ordinal = ordinal * 10 + size_t(name[i] - '0');
    }
    return ordinal;
}

class Runner {
public:
    Runner(const SweepOptions& options, std::ostream& log)
        : mOptions(options), mLog(log), mReferences(options.out / "references") {}

    SweepSummary run() {
        SweepSpec spec = readSweepFile(mOptions.file);
        if (mOptions.quick)
            spec = applyQuick(spec);
        mSpec = spec;
        mTimeLimitSeconds = mOptions.jobTimeoutSeconds.value_or(spec.jobTimeoutSeconds);
        if (const std::string error = jobTimeoutError(mTimeLimitSeconds, "the job time limit");
            !error.empty())
            throw std::invalid_argument(error);
        if (mTimeLimitSeconds > 0.0 && mOptions.isolation == JobIsolation::InProcess)
            throw std::invalid_argument("a job time limit needs jobs in their own process (a job "
                                        "in this process cannot be killed alone)");
        mExpansion = expandSweep(spec, mOptions.threads);
        const auto [first, last] =
            shardRange(mExpansion.size(), mOptions.shardIndex, mOptions.shardCount);
        // Every job planned against its scene (and its memory estimate) before DIR is touched.
        preflightSweepJobs(mExpansion, first, last, spec.origin);
        ensureWritableDirectory(mOptions.out);
        const SweepLock lock(mOptions.out, first, last, mOptions.waitForLock, mLog);
        fs::create_directories(mOptions.out / "jobs");
        fs::create_directories(mOptions.out / "references");

        const size_t shardSize = last - first;
        mSummary.jobsInSweep = mExpansion.size();
        mSummary.jobsInShard = shardSize;
        const std::string name = spec.name.empty() ? mOptions.file.stem().string() : spec.name;
        mLog << "sweep " << name << (mOptions.quick ? " (quick)" : "") << ": " << shardSize
             << " jobs";
        if (mOptions.shardCount > 1)
            mLog << " (shard " << mOptions.shardIndex << "/" << mOptions.shardCount << " of "
                 << mExpansion.size() << ")";
        mLog << ", output " << mOptions.out.string()
             << (mOptions.isolation == JobIsolation::InProcess ? ", jobs in this process" : "")
             << (mTimeLimitSeconds > 0.0 ? ", job time limit " + formatTimeLimit(mTimeLimitSeconds)
                                         : std::string())
             << "\n";

        std::vector<bool> finished(shardSize);
        size_t toRun = 0;
        for (size_t i = 0; i < shardSize; ++i) {
            finished[i] = markerStatus(jobDir(mExpansion.jobId(mExpansion.ordinalAt(first + i))) /
                                       kDoneMarker) == "ok";
            toRun += finished[i] ? 0 : 1;
        }

        const auto start = Clock::now();
        double runSeconds = 0.0;
        for (size_t i = 0; i < shardSize; ++i) {
            const std::string position =
                "[" + std::to_string(i + 1) + "/" + std::to_string(shardSize) + "]";
            if (finished[i]) {
                ++mSummary.skipped;
                mLog << position << " skipped " << mExpansion.jobId(mExpansion.ordinalAt(first + i))
                     << " (finished before)\n";
                continue;
            }
            const SweepJob job = mExpansion.job(first + i);
            mLog << position << " running " << job.id << ": " << describeSettings(job.settings)
                 << " | done " << (mSummary.ran + mSummary.skipped) << "/" << shardSize
                 << ", skipped " << mSummary.skipped << ", failed " << mSummary.failed << " | "
                 << elapsedAndRemaining(secondsSince(start), runSeconds, mSummary.ran,
                                        toRun - mSummary.ran)
                 << "\n";
            mLog.flush();
            const auto jobStart = Clock::now();
            const std::string error = runJob(job);
            const double seconds = secondsSince(jobStart);
            runSeconds += seconds;
            ++mSummary.ran;
            if (!error.empty())
                ++mSummary.failed;
            mLog << position << (error.empty() ? " ok " : " FAILED ") << job.id << " in "
                 << formatDuration(seconds) << (error.empty() ? "" : ": " + error) << "\n";
            rebuildTable(false);
        }
        rebuildTable(true);
        mLog << "sweep " << name << " finished in " << formatDuration(secondsSince(start)) << ": "
             << shardSize << " jobs, " << mSummary.ran << " ran, " << mSummary.skipped
             << " skipped, " << mSummary.failed
             << " failed; references: " << mSummary.referencesRendered << " rendered, "
             << mSummary.referencesLoaded << " read from disk; table of " << mSummary.rowsInTable
             << " jobs in " << (mOptions.out / "results.csv").string() << " and "
             << (mOptions.out / "results.json").string() << "\n";
        return mSummary;
    }

private:
    fs::path jobDir(const std::string& id) const { return mOptions.out / "jobs" / id; }

    void onReference(ReferenceStore::Event event, const std::string& key) {
        if (event == ReferenceStore::Event::Rendering) {
            mLog << "  rendering reference " << key << "\n";
            mLog.flush();
        }
        mSummary.referencesRendered += event == ReferenceStore::Event::Rendered ? 1 : 0;
        mSummary.referencesLoaded += event == ReferenceStore::Event::Loaded ? 1 : 0;
    }

    // Runs one job (in a child process unless options.isolation is InProcess) and writes its
    // marker; returns "" or the error text.
    std::string runJob(const SweepJob& job) {
        const fs::path dir = jobDir(job.id);
        Json row = baseRow(job, mExpansion.axisColumns());
        std::string error;
        try {
            fs::create_directories(dir);
            fs::remove(dir / kDoneMarker); // a failed job's old marker: the job is rerun now
            Json metrics;
            if (mOptions.isolation == JobIsolation::InProcess) {
                metrics = runSweepJob(job, dir, mReferences,
                                      [&](ReferenceStore::Event event, const std::string& key) {
                                          onReference(event, key);
                                      });
            } else {
                metrics = runIsolated(job);
            }
            for (const auto& [column, value] : metrics.items())
                row[column] = value;
        } catch (const std::exception& e) {
            // A message (it may quote a file name that is not UTF-8): escaped for JSON.
            error = scenes::escapeControlCharacters(e.what());
            if (error.empty())
                error = "unknown error";
            row["status"] = "failed";
            row["error"] = error;
        }
        Json marker = Json::object();
        marker["job_id"] = job.id;
        marker["status"] = row["status"];
        marker["error"] = error;
        marker["settings"] = describeSettings(job.settings);
        marker["finished_at"] = utcNow();
        marker["row"] = row;
        writeTextAtomically(dir / kDoneMarker, marker.dump(2) + "\n"); // last: the job counts now
        return error;
    }

    // The job in a child process: its metrics, or throws its error (a crash included).
    Json runIsolated(const SweepJob& job) {
        if (job.compareReference) {
            // A reference that failed (or crashed its process) fails its key's other jobs at
            // once, as in-process; a reference not yet cached is announced like in-process.
            if (const auto failed = mReferenceErrors.find(job.referenceKey);
                failed != mReferenceErrors.end())
                throw std::runtime_error(failed->second);
            if (!fs::exists(mReferences.cachePath(job.referenceKey)))
                onReference(ReferenceStore::Event::Rendering, job.referenceKey);
        }
        const JobProcessOutcome outcome = runJobProcess(
            job, mOptions.out,
            mOptions.isolation == JobIsolation::Fork ? JobStart::Fork : JobStart::Spawn,
            mOptions.jobExecutable, mTimeLimitSeconds);
        if (outcome.referenceRendered)
            onReference(ReferenceStore::Event::Rendered, job.referenceKey);
        if (outcome.referenceLoaded)
            onReference(ReferenceStore::Event::Loaded, job.referenceKey);
        if (!outcome.ok) {
            if (outcome.referenceFailed)
                mReferenceErrors[job.referenceKey] = outcome.error;
            throw std::runtime_error(outcome.error);
        }
        return outcome.metrics;
    }

    // results.* from the markers of every job of this sweep in DIR (any shard's): the job folders
    // present are listed and each is checked against the expansion (ordinal and id), so the cost
    // grows with the jobs run, not the jobs of the sweep. After a job the table is rebuilt only
    // when at least ten times the last rebuild's duration has passed since it, so that rebuilding
    // takes at most ~10% of a sweep's time however many jobs it has; `force` rebuilds now.
    void rebuildTable(bool force) {
        if (!force && mLastRebuild && secondsSince(*mLastRebuild) < 10.0 * mLastRebuildSeconds)
            return;
        const auto start = Clock::now();
        std::vector<Json> rows;
        std::error_code error;
        for (fs::directory_iterator it(mOptions.out / "jobs", error), end; !error && it != end;
             it.increment(error)) {
            const std::string name = it->path().filename().string();
            const std::optional<size_t> ordinal = ordinalOfFolder(name);
            if (!ordinal || *ordinal >= mExpansion.size() || mExpansion.jobId(*ordinal) != name)
                continue; // not a job of this sweep (another file, --quick, or an edited sweep)
            if (auto row = markerRow(it->path() / kDoneMarker))
                rows.push_back(std::move(*row));
        }
        mSummary.rowsInTable = rows.size();
        writeResults(mOptions.out,
                     resultsJson(mSpec.source, pathForJson(mOptions.file), mOptions.quick,
                                 mExpansion.axisColumns(), std::move(rows)));
        mLastRebuild = Clock::now();
        mLastRebuildSeconds = secondsSince(start);
    }

    const SweepOptions& mOptions;
    std::ostream& mLog;
    SweepSpec mSpec;
    SweepExpansion mExpansion;
    SweepSummary mSummary;
    double mTimeLimitSeconds = 0.0; // of each job's process; 0 = none
    ReferenceStore mReferences;
    std::map<std::string, std::string> mReferenceErrors; // isolated jobs: key -> error
    std::optional<Clock::time_point> mLastRebuild;
    double mLastRebuildSeconds = 0.0;
};

} // namespace

SweepSummary runSweep(const SweepOptions& options, std::ostream& log) {
    return Runner(options, log).run();
}

int runSweepCommand(const SweepOptions& options) {
    try {
        const SweepSummary summary = runSweep(options, std::cerr);
        if (summary.failed > 0) {
            std::cerr
                << "testbed: " << summary.failed << " of " << summary.jobsInShard
                << " jobs failed (status \"failed\" and the error in the results); exit code 1\n";
            return 1;
        }
        return 0;
    } catch (const SweepError& e) {
        return reportError(e, 2);
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

int runMergeCommand(const std::vector<fs::path>& inputs, const fs::path& out) {
    try {
        const size_t jobs = mergeSweepOutputs(inputs, out);
        std::cerr << "testbed: merged " << inputs.size() << " folders: " << jobs << " jobs in "
                  << (out / "results.csv").string() << " and " << (out / "results.json").string()
                  << "\n";
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
