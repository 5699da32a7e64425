#include "experiments/SweepRunner.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <OpenImageIO/imagebuf.h>

#include "experiments/AtomicFile.h"
#include "experiments/CommandErrors.h"
#include "experiments/ImageOutput.h"
#include "experiments/RenderCommand.h"
#include "experiments/RenderJob.h"
#include "experiments/ResultsTable.h"
#include "experiments/RunMetrics.h"
#include "experiments/SweepFile.h"

namespace experiments {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

namespace {

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string formatDuration(double seconds) {
    char text[32];
    if (seconds < 60.0) {
        std::snprintf(text, sizeof text, "%.1fs", seconds);
    } else {
        const long whole = std::lround(seconds);
        if (whole < 3600)
            std::snprintf(text, sizeof text, "%ldm%02lds", whole / 60, whole % 60);
        else
            std::snprintf(text, sizeof text, "%ldh%02ldm%02lds", whole / 3600, whole / 60 % 60,
                          whole % 60);
    }
    return text;
}

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return text;
}

// The marker's status, or "" when there is no readable marker (then the job is not finished).
std::string markerStatus(const fs::path& marker) {
    std::ifstream in(marker, std::ios::binary);
    if (!in)
        return "";
    try {
        const Json json = Json::parse(in);
        return json.value("status", "");
    } catch (const std::exception&) {
        return ""; // cannot happen with atomic writes; treat as unfinished
    }
}

std::optional<Json> markerRow(const fs::path& marker) {
    std::ifstream in(marker, std::ios::binary);
    if (!in)
        return std::nullopt;
    try {
        Json json = Json::parse(in);
        if (json.contains("row") && json["row"].is_object())
            return json["row"];
    } catch (const std::exception&) {
    }
    return std::nullopt;
}

Json number(double value) {
    return std::isfinite(value) ? Json(value) : Json(nullptr);
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

// The run's metrics as result columns: time_<pass>_{median,min,max}_ms for every pass and the
// stage's sum, then RunMetrics' figures (runFigureColumns() order); non-finite values are null.
void addMetrics(Json& row, const RunMetrics& metrics) {
    std::vector<PassTiming> passes = metrics.passes;
    if (!metrics.stage.samplesMs.empty())
        passes.push_back(metrics.stage);
    for (const PassTiming& timing : passes) {
        row["time_" + timing.pass + "_median_ms"] = number(timing.medianMs());
        row["time_" + timing.pass + "_min_ms"] = number(timing.minMs());
        row["time_" + timing.pass + "_max_ms"] = number(timing.maxMs());
    }
    row[metric::kLightEvaluations] = metrics.lightEvaluations;
    row[metric::kOracleLightEvaluations] = metrics.oracleLightEvaluations;
    row[metric::kCullingEfficiency] = metrics.cullingEfficiency;
    row[metric::kSimtLaneSlots] =
        metrics.simtLaneSlots ? Json(*metrics.simtLaneSlots) : Json(nullptr);
    row[metric::kSimtEfficiency] =
        metrics.simtEfficiency ? number(*metrics.simtEfficiency) : Json(nullptr);
    row[metric::kBytesPerPixel] = metrics.bytesPerPixel;
    for (const NamedFigure& figure : metrics.errorFigures())
        row[figure.name] = number(figure.value); // psnr +inf (identical images) -> null
}

void writeReferenceExr(const fs::path& path, const std::string& key,
                       const lighting::StageResult& image) {
    writeMultiLayerExr(path, image.width, image.height,
                       {{"R", image.radiance[0].data()},
                        {"G", image.radiance[1].data()},
                        {"B", image.radiance[2].data()}},
                       {{"testbed:reference_key", key},
                        {"testbed:what", "double-precision reference, stored as float32"}});
}

// Reads a cached reference; nullopt when absent or not the expected image (then it is rendered).
std::optional<lighting::StageResult> readReferenceExr(const fs::path& path, const std::string& key,
                                                      int width, int height) {
    if (!fs::is_regular_file(path))
        return std::nullopt;
    OIIO::ImageBuf buffer(path.string());
    if (!buffer.read(0, 0, true, OIIO::TypeDesc::FLOAT))
        return std::nullopt;
    const OIIO::ImageSpec& spec = buffer.spec();
    if (spec.width != width || spec.height != height ||
        spec.get_string_attribute("testbed:reference_key") != key)
        return std::nullopt;
    lighting::StageResult image;
    image.width = width;
    image.height = height;
    const size_t pixels = size_t(width) * size_t(height);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        const int channel = spec.channelindex(names[c]);
        if (channel < 0)
            return std::nullopt;
        image.radiance[c].resize(pixels);
        OIIO::ROI roi = buffer.roi();
        roi.chbegin = channel;
        roi.chend = channel + 1;
        if (!buffer.get_pixels(roi, OIIO::TypeDesc::FLOAT, image.radiance[c].data()))
            return std::nullopt;
    }
    return image;
}

class Runner {
public:
    Runner(const SweepOptions& options, std::ostream& log) : mOptions(options), mLog(log) {}

    SweepSummary run() {
        SweepSpec spec = readSweepFile(mOptions.file);
        if (mOptions.quick)
            spec = applyQuick(spec);
        mSpec = spec;
        const SweepExpansion expansion = expandSweep(spec, mOptions.threads);
        mAllJobs = expansion.jobs;
        mAxisColumns = expansion.axisColumns;
        const std::vector<SweepJob> jobs =
            shardJobs(mAllJobs, mOptions.shardIndex, mOptions.shardCount);
        ensureWritableDirectory(mOptions.out);
        fs::create_directories(mOptions.out / "jobs");
        fs::create_directories(mOptions.out / "references");

        mSummary.jobsInSweep = mAllJobs.size();
        mSummary.jobsInShard = jobs.size();
        const std::string name = spec.name.empty() ? mOptions.file.stem().string() : spec.name;
        mLog << "sweep " << name << (mOptions.quick ? " (quick)" : "") << ": " << jobs.size()
             << " jobs";
        if (mOptions.shardCount > 1)
            mLog << " (shard " << mOptions.shardIndex << "/" << mOptions.shardCount << " of "
                 << mAllJobs.size() << ")";
        mLog << ", output " << mOptions.out.string() << "\n";

        // Which jobs still need a reference: a reference is dropped after its last user.
        std::map<std::string, size_t> remainingUsers;
        std::vector<bool> finished(jobs.size());
        size_t toRun = 0;
        for (size_t i = 0; i < jobs.size(); ++i) {
            finished[i] = markerStatus(jobDir(jobs[i]) / kDoneMarker) == "ok";
            if (!finished[i]) {
                ++toRun;
                if (jobs[i].compareReference)
                    ++remainingUsers[jobs[i].referenceKey];
            }
        }

        const auto start = Clock::now();
        double runSeconds = 0.0;
        for (size_t i = 0; i < jobs.size(); ++i) {
            const SweepJob& job = jobs[i];
            const std::string position =
                "[" + std::to_string(i + 1) + "/" + std::to_string(jobs.size()) + "]";
            if (finished[i]) {
                ++mSummary.skipped;
                mLog << position << " skipped " << job.id << " (finished before)\n";
                continue;
            }
            const size_t left = toRun - mSummary.ran;
            const std::string remaining =
                mSummary.ran == 0
                    ? "?"
                    : formatDuration(runSeconds / double(mSummary.ran) * double(left));
            mLog << position << " running " << job.id << ": " << describeSettings(job.settings)
                 << " | done " << (mSummary.ran + mSummary.skipped) << "/" << jobs.size()
                 << ", skipped " << mSummary.skipped << ", failed " << mSummary.failed
                 << " | elapsed " << formatDuration(secondsSince(start)) << ", remaining ~"
                 << remaining << "\n";
            mLog.flush();
            const auto jobStart = Clock::now();
            const std::string error = runJob(job);
            const double seconds = secondsSince(jobStart);
            runSeconds += seconds;
            ++mSummary.ran;
            if (!error.empty())
                ++mSummary.failed;
            if (job.compareReference && --remainingUsers[job.referenceKey] == 0 &&
                mReferenceKey == job.referenceKey) {
                mReference.reset(); // no later job of this shard needs it
                mReferenceKey.clear();
            }
            mLog << position << (error.empty() ? " ok " : " FAILED ") << job.id << " in "
                 << formatDuration(seconds) << (error.empty() ? "" : ": " + error) << "\n";
            rebuildTable();
        }
        rebuildTable();
        mLog << "sweep " << name << " finished in " << formatDuration(secondsSince(start)) << ": "
             << jobs.size() << " jobs, " << mSummary.ran << " ran, " << mSummary.skipped
             << " skipped, " << mSummary.failed
             << " failed; references: " << mSummary.referencesRendered << " rendered, "
             << mSummary.referencesLoaded << " read from disk; table of " << mSummary.rowsInTable
             << " jobs in " << (mOptions.out / "results.csv").string() << " and "
             << (mOptions.out / "results.json").string() << "\n";
        return mSummary;
    }

private:
    fs::path jobDir(const SweepJob& job) const { return mOptions.out / "jobs" / job.id; }

    // The reference of the job's key: memory, then DIR/references, then rendered (and cached).
    const lighting::StageResult& reference(const SweepJob& job) {
        if (mReferenceKey == job.referenceKey && mReference)
            return *mReference;
        if (const auto failed = mReferenceErrors.find(job.referenceKey);
            failed != mReferenceErrors.end())
            throw std::runtime_error(failed->second);
        mReference.reset();
        mReferenceKey = job.referenceKey;
        const fs::path path = mOptions.out / "references" / (job.referenceKey + ".exr");
        if (auto loaded =
                readReferenceExr(path, job.referenceKey, job.options.width, job.options.height)) {
            mReference = std::move(*loaded);
            ++mSummary.referencesLoaded;
            return *mReference;
        }
        mLog << "  rendering reference " << job.referenceKey << "\n";
        mLog.flush();
        try {
            mReference = renderReference(job.options);
        } catch (const std::exception& e) {
            const std::string message =
                std::string("reference ") + job.referenceKey + ": " + e.what();
            mReferenceErrors[job.referenceKey] = message; // the key's other jobs fail at once
            throw std::runtime_error(message);
        }
        ++mSummary.referencesRendered;
        writeReferenceExr(path, job.referenceKey, *mReference);
        return *mReference;
    }

    // Runs one job and writes its folder; returns "" or the error text.
    std::string runJob(const SweepJob& job) {
        const fs::path dir = jobDir(job);
        Json row = baseRow(job, mAxisColumns);
        std::string error;
        try {
            fs::create_directories(dir);
            fs::remove(dir / kDoneMarker); // a failed job's old marker: the job is rerun now
            const lighting::StageResult* referenceImage =
                job.compareReference ? &reference(job) : nullptr;
            RenderOptions options = job.options;
            options.compareReference = job.compareReference;
            const RenderRun run = runRender(planRender(options), {}, referenceImage);
            writeRenderOutputs(run, dir, 0);
            addMetrics(row, run.metrics);
        } catch (const std::exception& e) {
            error = e.what();
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

    // results.* from the markers of every job of the sweep present in DIR (any shard's).
    void rebuildTable() {
        std::vector<Json> rows;
        for (const SweepJob& job : mAllJobs)
            if (auto row = markerRow(jobDir(job) / kDoneMarker))
                rows.push_back(std::move(*row));
        mSummary.rowsInTable = rows.size();
        writeResults(mOptions.out, resultsJson(mSpec.source, mOptions.file.string(), mOptions.quick,
                                               mAxisColumns, std::move(rows)));
    }

    const SweepOptions& mOptions;
    std::ostream& mLog;
    SweepSpec mSpec;
    std::vector<SweepJob> mAllJobs;
    std::vector<std::string> mAxisColumns;
    SweepSummary mSummary;
    std::string mReferenceKey;
    std::optional<lighting::StageResult> mReference;
    std::map<std::string, std::string> mReferenceErrors;
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
