// SweepJobRun: one job of a sweep run in this process, and the reference images jobs share.
//   - ReferenceStore: the double-precision reference of a reference key (scene, scene options,
//     lights, seed, size), kept in memory while consecutive jobs use it and cached as
//     DIR/references/<key>.exr (float R,G,B: bit-exact), so that a later job, a rerun, another
//     shard or a job's child process reads it back instead of rendering it again;
//   - runSweepJob: the job's reference, then planRender and runRender (as `testbed render`
//     does), then writeRenderOutputs into its folder; returns the metric columns of its row.
// The sweep runner calls runSweepJob directly (in-process: tests) or through a child process
// (JobProcess.h: the CLI), where a crash of the job takes down only the child. The done.json
// marker is the runner's business, not this file's.
//
// Thread safety: a ReferenceStore belongs to one thread; runSweepJob uses TBB inside.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "experiments/render/RunMetrics.h"
#include "experiments/sweep/SweepFile.h"
#include "lighting/ShadingStage.h"

namespace experiments {

class ReferenceStore {
public:
    // What get() did, for progress lines and counts.
    enum class Event { Rendering, Rendered, Loaded };
    using Listener = std::function<void(Event, const std::string& key)>;

    // folder: DIR/references (created by the caller).
    explicit ReferenceStore(std::filesystem::path folder) : mFolder(std::move(folder)) {}

    // The reference of job.referenceKey: the one in memory, else the cached EXR, else rendered
    // (renderReference) and cached. Only one reference is kept in memory: jobs run grouped by
    // key, so a new key means the previous one's jobs are done. Throws std::runtime_error
    // "reference KEY: ..." when it cannot be rendered; the key's later jobs then fail at once
    // with the same message instead of rendering it again.
    const lighting::StageResult& get(const SweepJob& job, const Listener& listener = {});

    // Makes later get() calls for key throw `message` (the runner learns of a reference that a
    // child process failed to render this way).
    void markFailed(const std::string& key, const std::string& message);

    std::filesystem::path cachePath(const std::string& key) const;

private:
    std::filesystem::path mFolder;
    std::string mKey;
    std::optional<lighting::StageResult> mImage;
    std::map<std::string, std::string> mErrors; // key -> message
};

// Runs the job in this process and writes render.exr, the PNGs and stats.json into jobDir (which
// must exist). Returns the row's metric columns: time_<pass>_{median,min,max}_ms for every pass
// and the stage's sum, then RunMetrics' figures (runFigureColumns() order); non-finite values are
// null. Throws on any failure (bad scene, reference, write).
nlohmann::ordered_json runSweepJob(const SweepJob& job, const std::filesystem::path& jobDir,
                                   ReferenceStore& references,
                                   const ReferenceStore::Listener& listener = {});

// The row columns of a run's metrics, as runSweepJob returns them.
nlohmann::ordered_json metricColumnsOf(const RunMetrics& metrics);

} // namespace experiments
