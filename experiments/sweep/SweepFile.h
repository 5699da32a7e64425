// SweepFile: a sweep file (JSON or TOML) parsed, checked and expanded into jobs. The format is
// documented in experiments/README.md; in short, one object with
//   name, description, notes      text
//   fixed: {key: value}           settings of every job
//   axes: {key: [values]}         crossed with each other (cross product, first axis slowest)
//   cases: [{key: value, ...}]    zipped groups of settings, crossed with the axes (outermost)
//   warmup, repetitions           untimed and timed runs of every job (may also be axes)
//   reference: true|false         measure the error against the reference image (default true)
//   quick: {fixed, axes, cases, warmup, repetitions, reference}   overrides for `--quick`
//   published: [...]              published figures of a reproduction (schema in the README)
//   heatmap-max, error-scale, error-max   scales of every job's heatmap.png and error.png (and
//                                 of the report's maps): display only, not part of a job's id
//   job-timeout                   wall-time limit of one job in seconds (0 = none, the
//                                 default): the runner's, not part of a job's id
// Keys are the names experiments::setRenderOption accepts (scene, stage, lights, seed, width,
// height, resolution, threads, isa, simt-warp, layout, normals, normal-space, depth, position,
// post-aa, scene-option.KEY: whatever renderOptionKeys() lists) plus warmup and repetitions. Values
// are strings or numbers and reach setRenderOption as text, so this file knows no stage, encoding
// or scene: anything registered later works unchanged.
// Reading and checking a file is SweepFile.cpp; expanding a spec into jobs, their ids and shards is
// SweepExpansion.cpp.
//
// Jobs: the full expansion (cases x axes) numbers jobs 0..n-1 in that order; a job's id is its
// zero-padded ordinal and a hash of every setting that makes it ("0007-1a2b3c4d"), identical in
// every shard and every rerun of the same file, and different when a setting changes.
//
// Views: the setting view = "all" (in fixed, a case, or as the only value of the view axis)
// stands for every view of the job's scene (scenes/Viewpoints.h, `testbed list --views SCENE`),
// resolved per scene (and scene options) by loading each distinct scene once at expansion: a
// job with view=all becomes one job per view, in the scene's view order, at its place in the
// expansion (so the views are the fastest-varying setting of those jobs). Each resulting job
// has the view's name as its setting, hence its own id and reference key (a reference per view),
// exactly as if the views had been listed.
//
// Jobs are then run grouped by reference key (scene, scene options, lights, seed, size), so that
// one reference image serves a run of adjacent jobs. Jobs are made on demand (SweepExpansion), so
// memory does not grow with the job count beyond 4 bytes a job.
//
// Errors: SweepError with a message naming the file and the key; expandSweep reports the invalid
// jobs together (the first kMaxListedInvalidJobs of them, and how many there are) instead of
// stopping at the first.
//
// Thread safety: pure functions over values; no shared state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/output/ImageOutput.h"
#include "experiments/render/RenderOptions.h"

namespace experiments {

struct SweepError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Invalid jobs listed by expandSweep's error (the rest are counted): a typo in an axis of 10^6
// jobs must not make a message of 10^6 lines.
inline constexpr size_t kMaxListedInvalidJobs = 20;

// One key = value of a sweep; value is a JSON string or number, as written in the file.
struct SweepSetting {
    std::string key;
    nlohmann::ordered_json value;
};

struct SweepSpec {
    std::string origin;            // the file name, for messages
    nlohmann::ordered_json source; // the file's object verbatim (TOML converted to JSON)
    std::string name;
    std::string description;
    std::vector<SweepSetting> fixed;
    std::vector<std::pair<std::string, std::vector<nlohmann::ordered_json>>> axes; // file order
    std::vector<std::vector<SweepSetting>> cases;
    int warmup = 0;
    int repetitions = 1;
    bool reference = true;
    // Scales of the false-colour images of every job (RenderCommand.h RenderOutputScales): the
    // same for all jobs, so that their images compare side by side. 0 = each image's own maximum.
    uint32_t heatmapMax = 0;
    MapScale errorScale = MapScale::Linear;
    double errorMax = 0.0;
    // Wall-time limit of each job's process in seconds (JobProcess.h); 0 = no limit. The sweep
    // command's --job-timeout overrides it.
    double jobTimeoutSeconds = 0.0;
};

// Upper bound of a job time limit: 10^8 s (over three years) stays far inside the range of the
// nanosecond steady clock the deadline is kept in (~292 years), and no real limit is near it.
inline constexpr double kMaxJobTimeoutSeconds = 1e8;

// Checks a job time limit (seconds, 0 = none) from the sweep file or the command line; the error
// text names `where` and what is expected. Returns "" when valid.
std::string jobTimeoutError(double seconds, const std::string& where);

// Reads FILE (.toml as TOML, anything else as JSON) and checks its structure. Throws SweepError
// naming the file (and line for syntax errors, key for unknown or mistyped keys).
// Files over scenes::limits::kMaxFileBytes or nested deeper than kMaxNestingDepth are refused
// before parsing.
SweepSpec readSweepFile(const std::filesystem::path& file);
// The same from the file's text (isToml: TOML, else JSON); origin names it in messages.
SweepSpec readSweepText(const std::string& text, const std::string& origin, bool isToml);
// The same from an already parsed object; origin names it in messages.
SweepSpec parseSweep(const nlohmann::ordered_json& object, const std::string& origin);

// The spec with its "quick" block applied: quick.fixed and quick.axes replace settings of the
// same key (a key moved from the axes to fixed or back leaves its old place), quick.cases
// replaces the cases, quick.warmup/repetitions/reference replace those. Without a quick block
// `--quick` is an error (a CI size must be chosen on purpose).
SweepSpec applyQuick(const SweepSpec& spec);

struct SweepJob {
    size_t ordinal = 0;                 // in the full (unsharded) expansion
    std::string id;                     // "<ordinal>-<hash>", filesystem-safe
    std::vector<SweepSetting> settings; // fixed, then the case's, then the axes' (file order)
    RenderOptions options;              // settings applied through setRenderOption
    bool compareReference = true;
    std::string referenceKey; // filesystem-safe, e.g. "wall-1280x720-1500l-s1-9f3a0c11"
    // The spec's map scales (SweepSpec), the same for every job: display only, not in the id.
    uint32_t heatmapMax = 0;
    MapScale errorScale = MapScale::Linear;
    double errorMax = 0.0;
};

// The jobs of a sweep, made on demand: the expansion keeps the sweep's settings and one 4-byte
// run-order entry per job (4 MB at limits::kMaxSweepJobs), never the jobs themselves, so a sweep
// of 10^6 jobs starts in tens of megabytes (a vector of job records took 2.7 GB before its first
// job). Making a job costs O(settings).
//
// Run order: jobs grouped by reference key, groups in order of first appearance in the full
// expansion, ordinal order inside a group; so one reference image serves a run of adjacent jobs,
// and a shard (a contiguous block of the run order) shares references as far as possible.
class SweepExpansion {
public:
    // Every job of the full expansion, in run order.
    size_t size() const { return mJobCount; }
    // The job at a position of the run order (0 <= position < size()).
    SweepJob job(size_t position) const { return jobAtOrdinal(ordinalAt(position)); }
    // The ordinal of the job at a position of the run order.
    size_t ordinalAt(size_t position) const { return mOrdinalAt.at(position); }
    // The job with this ordinal (0 <= ordinal < size()).
    SweepJob jobAtOrdinal(size_t ordinal) const;
    // The id of the job with this ordinal, without the rest of the job (cheaper).
    std::string jobId(size_t ordinal) const;
    // Result columns of the settings (axisColumns below).
    const std::vector<std::string>& axisColumns() const { return mAxisColumns; }
    // Every job, in run order: O(jobs) memory, for tests and small sweeps; the runner never
    // holds them all.
    std::vector<SweepJob> jobs() const;

private:
    friend SweepExpansion expandSweep(const SweepSpec& spec, std::optional<int> threads);
    std::vector<SweepSetting> settingsOf(size_t ordinal) const;
    // The settings of a job of the expansion before view=all is resolved (cases x axes).
    std::vector<SweepSetting> unresolvedSettingsOf(size_t unresolvedOrdinal) const;
    // Resolves view=all (see the top of the file): fills the view members below; `total` is the
    // unresolved job count on entry, the resolved one on return. Throws SweepError naming the
    // scenes that cannot be loaded, or when the jobs would exceed limits::kMaxSweepJobs.
    static void resolveEveryView(SweepExpansion& expansion, const std::string& origin,
                                 size_t& total);
    std::string idOf(size_t ordinal, const std::vector<SweepSetting>& settings) const;

    std::vector<SweepSetting> mFixed;
    std::vector<std::vector<SweepSetting>> mCases; // at least one (empty) case
    std::vector<std::pair<std::string, std::vector<nlohmann::ordered_json>>> mAxes;
    size_t mJobCount = 0;
    size_t mCombinations = 1; // product of the axes' sizes
    // view=all (see the top of the file); all three empty when no job has it. Unresolved job u
    // becomes the jobs mFirstOrdinal[u] .. mFirstOrdinal[u+1]-1, with the views of
    // mViewLists[mViewListOf[u]] (kNoViewList: u has a view of its own, one job). 8 bytes a job.
    static constexpr uint32_t kNoViewList = UINT32_MAX;
    std::vector<uint32_t> mFirstOrdinal;
    std::vector<uint32_t> mViewListOf;
    std::vector<std::vector<std::string>> mViewLists;
    size_t mIdDigits = 4; // zero padding of the ordinal in ids
    int mWarmup = 0;
    int mRepetitions = 1;
    bool mReference = true;
    uint32_t mHeatmapMax = 0; // the spec's map scales, copied into every job
    MapScale mErrorScale = MapScale::Linear;
    double mErrorMax = 0.0;
    std::vector<std::string> mAxisColumns;
    std::vector<uint32_t> mOrdinalAt; // run position -> ordinal
};

// Expands the spec (after applyQuick when wanted) and validates every job (setRenderOption, then
// experiments::validate), making each job once and keeping none. `threads`, when set, is a fixed
// setting added by the command line (an error if the file makes threads an axis or case key).
// Throws SweepError when the sweep has more than limits::kMaxSweepJobs jobs (before making any)
// or when any job is invalid (listing the first ones: id, settings, reason, and how many there
// are).
SweepExpansion expandSweep(const SweepSpec& spec, std::optional<int> threads = std::nullopt);

// A job as JSON and back, for handing a job to a child process (JobProcess.h):
// {"ordinal", "id", "settings": [{"key", "value"}...], "warmup", "repetitions", "reference"}.
// sweepJobFromJson makes the options and the reference key again from the settings, as the
// expansion does; it throws SweepError for a malformed object or an invalid setting.
nlohmann::ordered_json sweepJobJson(const SweepJob& job);
SweepJob sweepJobFromJson(const nlohmann::ordered_json& json);

// The result columns for settings: every key the sweep sets, in the canonical order scene,
// stage, lights, seed, resolution, width, height, threads, isa, simt-warp, layout, normals,
// normal-space, depth, position, post-aa,
// then scene-option.* and any other key in name order; width and height are always present
// (the effective size), and repetitions and warmup close the list.
std::vector<std::string> axisColumns(const std::vector<std::string>& settingKeys);

// A job's value for an axis column: the setting as written, or the effective width / height /
// repetitions / warmup.
nlohmann::ordered_json axisValue(const SweepJob& job, const std::string& column);

// The run positions [first, last) of shard `index` (1-based) of `count` among `jobCount` jobs: a
// contiguous block of the run order, so a reference is shared by the jobs of one shard as far as
// possible; blocks differ in size by at most one job. Throws SweepError when not
// 1 <= index <= count.
std::pair<size_t, size_t> shardRange(size_t jobCount, int index, int count);
// The jobs of a shard of a job list (shardRange of its size).
std::vector<SweepJob> shardJobs(const std::vector<SweepJob>& jobs, int index, int count);

// Parses "I/N" (both positive, I <= N). Throws SweepError otherwise.
std::pair<int, int> parseShard(const std::string& text);

// Setting values as the text setRenderOption receives: strings verbatim, integers (and floats
// with an integral value) in decimal, other floats in JSON's shortest form. Throws SweepError for
// other types.
std::string settingText(const nlohmann::ordered_json& value, const std::string& where);

// "key=value key=value" for progress lines and messages.
std::string describeSettings(const std::vector<SweepSetting>& settings);

// Upper bound of warmup and repetitions: a typo must not keep a sweep running for days.
inline constexpr int kMaxRunCount = 1000;

// Throws SweepError("ORIGIN: MESSAGE").
[[noreturn]] void failSweep(const std::string& origin, const std::string& message);

// view = "all" cannot sit beside named views in one axis (the named ones would run twice).
// Throws SweepError naming the axis.
void checkEveryViewAlone(const SweepSpec& spec);

// Every key the spec sets, in fixed, axes or cases.
std::set<std::string> settingKeys(const SweepSpec& spec);

// True for the setting view = "all" (every view of the job's scene).
bool isEveryView(const SweepSetting& setting);

} // namespace experiments
