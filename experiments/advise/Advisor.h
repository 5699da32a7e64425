// Advisor: `testbed advise SWEEP_DIR --budget-ms X [--max-flip Y | --max-rmse Z]
// [--group KEY=VALUE ...]` reads a finished sweep (DIR/results.json) and answers, for each
// comparable group (ResultGroups.h: the jobs that differ only in method columns -- stage, layout,
// normals, normal-space, depth, position -- so one scene, view, light count, size, threads...):
//   fastest      the method that is fastest (median total frame time) among those whose error is
//                within the error budget (--max-flip: mean HDR-ꟻLIP; --max-rmse: relative RMSE;
//                neither: every method qualifies);
//   least error  the method with the least error among those whose median total time is within
//                --budget-ms;
//   pareto       the methods no other method beats in both time and error, fastest first;
// each with its margin over the runner-up (how many times faster, or how much less error) and
// whether the margin is real: two methods are INDISTINGUISHABLE in time when their repetitions'
// [min, max] ranges overlap (the sweep's timed repetitions are the only spread a single run has),
// and the answer then names every method tied with the best instead of picking one. Errors carry
// no spread (a render is deterministic), so a tie in error is an exact tie.
// Across views: groups that differ only in the view form a family; the answer says, per family,
// in how many of its views each winner wins, so a recommendation that holds for one camera only
// is visible as such.
//
// Output: a short text answer on stdout, DIR/advice.json (the same content, with the criteria),
// and the report's "Advice" section (ReportCommand reads advice.json when it is there).
// The error metric is the one budgeted; without an error budget, ꟻLIP when every candidate has
// it, else relative RMSE. Jobs that failed, or lack the time or the error figure, are listed as
// excluded with the reason, never silently dropped.
//
// Thread safety: pure functions except runAdviseCommand (writes a file, prints).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace experiments {

struct AdviceCriteria {
    double budgetMs = 0.0;                 // the frame-time budget (median total time), > 0
    std::optional<double> maxFlip;         // error budget on the mean HDR-ꟻLIP (0..1)
    std::optional<double> maxRelativeRmse; // error budget on relative RMSE (--max-rmse)
    // Only groups whose fixed settings match every KEY=VALUE (values compared as
    // normalisedSelectValue does: 256 == "256").
    std::vector<std::pair<std::string, std::string>> groupFilters;
};

struct AdviseCommandOptions {
    std::filesystem::path dir; // the sweep's results folder
    AdviceCriteria criteria;
};

// The advice for a results object (results.json's content); see above for what it holds:
//   { "criteria": {...}, "error_metric", "groups": [ { "id", "label", "fixed", "jobs",
//       "excluded": [{"job_id", "reason"}], "fastest": ANSWER|null, "least_error": ANSWER|null,
//       "pareto": [CANDIDATE...] } ], "families": [ { "label", "views", "fastest_wins":
//       {method: count}, "least_error_wins": {method: count} } ] }
//   ANSWER    = { "best": CANDIDATE, "tied": [CANDIDATE...], "runner_up": CANDIDATE|null,
//                 "margin": number|null, "distinguishable": bool, "why_none": "" }
//   CANDIDATE = { "method", "settings": {column: value}, "job_id", "time_ms", "time_min_ms",
//                 "time_max_ms", "error" }
// When no method qualifies, the answer's best is null and why_none says why (e.g. "no method
// within flip <= 0.01; the least flip is 0.02 (tiled)").
// Throws std::invalid_argument for a budget that is not a positive finite number, both error
// budgets at once, or a filter naming no setting of the results.
nlohmann::json adviseOnResults(const nlohmann::json& results, const AdviceCriteria& criteria);

// The short text answer: per group its label and one line per answer.
std::string adviceText(const nlohmann::json& advice);

// The report's "Advice" section (an <h2 id="advice"> and one table row per group) for an advice
// object; the report shows it when DIR/advice.json exists.
std::string adviceHtml(const nlohmann::json& advice);

// Reads DIR/results.json, prints adviceText, writes DIR/advice.json atomically. Returns the
// exit code: 0, or 1 with one "testbed: error:" line (missing or malformed results, bad criteria).
int runAdviseCommand(const AdviseCommandOptions& options);

} // namespace experiments
