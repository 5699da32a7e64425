// ResultGroups: what a sweep's results compare with what, read from results.json's jobs: the
// comparable groups (jobs that differ only in method columns), the aggregates over views, a job's
// metric and the select matching of published cells. Used by the report and the advisor, so that
// both group and match jobs the same way (ReportCommand.h says what a group is and why).
// Thread safety: pure functions.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace experiments {

// The error columns --error-metric accepts; psnr is the one where higher is better.
std::vector<std::string> reportErrorMetrics();

// Settings that name a method (what a group compares); every other setting makes the group.
bool isMethodColumn(const std::string& column);

// The axis columns of a results object: its "axis_columns", else (older or hand-made results)
// the columns that are neither metrics nor job_id/status/error.
std::vector<std::string> axisColumnsOf(const nlohmann::json& results);

struct JobGroup {
    std::string id;               // "g1", "g2", ... in the order of the jobs' first appearance
    std::string label;            // e.g. "atrium, 256 lights, 320x180, 2 threads"
    nlohmann::ordered_json fixed; // {column: value} of every grouping column, in axis order
    std::vector<size_t> jobs;     // indices into the jobs array, in order
};

// The comparable groups of jobs (every job, failed ones included): equal normalised values of
// every axis column that is not a method column nor "resolution" (width and height carry it).
std::vector<JobGroup> comparableGroups(const nlohmann::json& jobs,
                                       const std::vector<std::string>& axisColumns);

// The aggregates over views (see Views above) as JSON, empty "families" when no family has two
// views or more:
//   { "aggregated_over": "view", "statistic": "median, min and max over the views",
//     "metrics": ["time_total_median_ms", ERROR_METRIC, "flip"],
//     "families": [ { "id": "v1", "label", "fixed": {column: value but view},
//                     "views": [names in order of appearance], "groups": [group ids],
//                     "methods": [ { "label", "settings": {method column: value},
//                                    "views_ok": n, "views_failed": n,
//                                    METRIC: {"median", "min", "max", "count"} (null: no view
//                                            has the figure),
//                                    "rows": [ {"view", "job_id", "group", "status",
//                                               METRIC: value} ] } ] } ] }
// The duplicate metric when errorMetric is flip is listed once.
nlohmann::json aggregateOverViews(const nlohmann::json& jobs, const std::vector<JobGroup>& groups,
                                  const std::vector<std::string>& axisColumns,
                                  const std::string& errorMetric);

// The text a value is compared as when matching "select" entries: numbers (and strings that
// parse completely as numbers) in their shortest round-trip form with integers printed without
// a fraction ("1500", "0.25"), booleans as "true"/"false", other strings unchanged, null as "".
std::string normalisedSelectValue(const nlohmann::json& value);

// True when job[key] equals every select[key] after normalisation (a key missing from the job
// never matches).
bool jobMatchesSelect(const nlohmann::json& job, const nlohmann::json& select);

// The metric of one job: a column name or a list of column names (summed). nullopt when the job
// lacks one of them, or one of them is null or not a finite number.
std::optional<double> jobMetric(const nlohmann::json& job, const nlohmann::json& metric);

// The median of values (mean of the two middle ones for an even count); nullopt when empty.
std::optional<double> median(std::vector<double> values);

// The columns of the results table: "columns" when present, else every key of the jobs in
// first-seen order.
std::vector<std::string> resultColumns(const nlohmann::json& results);

// True when the job's status is "ok".
bool jobOk(const nlohmann::json& job);

} // namespace experiments
