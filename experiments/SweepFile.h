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
// Keys are the names experiments::setRenderOption accepts (scene, stage, lights, seed, width,
// height, resolution, threads, isa, simt-warp, layout, normals, normal-space, depth, position,
// scene-option.KEY: whatever renderOptionKeys() lists) plus warmup and repetitions. Values are
// strings or numbers and reach setRenderOption as text, so this file knows no stage, encoding or
// scene: anything registered later works unchanged.
//
// Jobs: the full expansion (cases x axes) numbers jobs 0..n-1 in that order; a job's id is its
// zero-padded ordinal and a hash of every setting that makes it ("0007-1a2b3c4d"), identical in
// every shard and every rerun of the same file, and different when a setting changes. Jobs are
// then run grouped by reference key (scene, scene options, lights, seed, size), so that one
// reference image serves a run of adjacent jobs.
//
// Errors: SweepError with a message naming the file and the key; expandSweep reports every
// invalid job at once instead of stopping at the first.
//
// Thread safety: pure functions over values; no shared state.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/RenderOptions.h"

namespace experiments {

struct SweepError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

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
};

// Reads FILE (.toml as TOML, anything else as JSON) and checks its structure. Throws SweepError
// naming the file (and line for syntax errors, key for unknown or mistyped keys).
SweepSpec readSweepFile(const std::filesystem::path& file);
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
};

struct SweepExpansion {
    std::vector<SweepJob> jobs;           // in run order: grouped by referenceKey
    std::vector<std::string> axisColumns; // result columns of the settings, see axisColumns()
};

// Expands the spec (after applyQuick when wanted) into jobs and validates every one of them
// (setRenderOption, then experiments::validate). `threads`, when set, is a fixed setting added
// by the command line (an error if the file makes threads an axis or case key). Throws
// SweepError listing every invalid job (id, settings, reason) when any is invalid.
SweepExpansion expandSweep(const SweepSpec& spec, std::optional<int> threads = std::nullopt);

// The result columns for settings: every key the sweep sets, in the canonical order scene,
// stage, lights, seed, resolution, width, height, threads, layout, normals, normal-space, depth,
// position,
// then scene-option.* and any other key in name order; width and height are always present
// (the effective size), and repetitions and warmup close the list.
std::vector<std::string> axisColumns(const std::vector<std::string>& settingKeys);

// A job's value for an axis column: the setting as written, or the effective width / height /
// repetitions / warmup.
nlohmann::ordered_json axisValue(const SweepJob& job, const std::string& column);

// The jobs of shard `index` (1-based) of `count`: a contiguous block of the run order, so a
// reference is shared by the jobs of one shard as far as possible; blocks differ in size by at
// most one job. Throws SweepError when not 1 <= index <= count.
std::vector<SweepJob> shardJobs(const std::vector<SweepJob>& jobs, int index, int count);

// Parses "I/N" (both positive, I <= N). Throws SweepError otherwise.
std::pair<int, int> parseShard(const std::string& text);

// Setting values as the text setRenderOption receives: strings verbatim, integers (and floats
// with an integral value) in decimal, other floats in JSON's shortest form. Throws SweepError for
// other types.
std::string settingText(const nlohmann::ordered_json& value, const std::string& where);

// "key=value key=value" for progress lines and messages.
std::string describeSettings(const std::vector<SweepSetting>& settings);

} // namespace experiments
