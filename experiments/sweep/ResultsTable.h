// ResultsTable: the results of a sweep as one table, one row per job, written as
// DIR/results.json and DIR/results.csv (experiments/README.md and contract.md describe them):
//   results.json  {"sweep": <the sweep file's object>, "sweep_file", "quick", "columns",
//                  "axis_columns", "jobs": [{column: value}]}, jobs sorted by job_id
//   results.csv   header = columns, then the same rows; null is an empty field, strings are
//                 quoted when they hold a comma, quote, line break or outer space (RFC 4180)
// Columns: job_id, status ("ok" | "failed"), error, the axis columns (SweepFile's axisColumns),
// then the metric columns: time_<pass>_{median,min,max}_ms for every pass any row has (passes in
// pipeline order, lighting/passes/PassNames.h: gbuffer, exact_surface, transform, prepass, cull,
// assign, index, shading, lighting, material, then stage, others by name, total last; "stage" is
// the sum of the stage's own passes, i.e. total without the G-buffer pass), then RunMetrics'
// figures (runFigureColumns): light_evaluations, oracle_light_evaluations, culling_efficiency,
// bytes_per_pixel, rmse, relative_rmse, psnr, max_abs, relative_mean, p99_abs. A missing value
// is null (JSON) / empty (CSV); psnr is null when rmse is 0.
//
// Merging (`testbed merge`): shard outputs of one sweep become one results set; see
// mergeSweepOutputs.
//
// Files are written through AtomicFile (temporary name, then rename), so a reader or a killed
// writer never sees a partial table. Thread safety: no shared state.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace experiments {

// A job is finished when DIR/jobs/<job_id>/done.json exists: {"job_id", "status", "error", "row":
// {column: value}, ...}. It is written last and atomically, so its presence means every other
// file of the job is complete.
inline constexpr const char* kDoneMarker = "done.json";

// The metric column names of rows (see above), in table order.
std::vector<std::string> metricColumns(const std::vector<nlohmann::ordered_json>& rows);

// The results object; rows are completed with null for missing columns and sorted by job_id.
nlohmann::ordered_json resultsJson(const nlohmann::ordered_json& sweep,
                                   const std::string& sweepFile, bool quick,
                                   const std::vector<std::string>& axisColumns,
                                   std::vector<nlohmann::ordered_json> rows);

// The CSV text of a results object (header line, one line per job, "\n" line ends).
std::string resultsCsv(const nlohmann::ordered_json& results);

// Writes dir/results.json and dir/results.csv, each atomically.
void writeResults(const std::filesystem::path& dir, const nlohmann::ordered_json& results);

// Reads dir/results.json; throws SweepError naming the file when missing or malformed.
nlohmann::ordered_json readResults(const std::filesystem::path& dir);

// Combines the outputs of several runs (shards) of the same sweep into `out`: checks that every
// input's results.json has the same sweep object, quick flag and axis columns (else throws
// SweepError naming the inputs); takes the union of their jobs, where a job present in several
// inputs must have identical rows (else SweepError naming the job and both folders); copies (hard
// links when possible) each job's folder into out/jobs/<job_id>/ with its done.json written last;
// writes out/results.json and out/results.csv. `out` may be one of the inputs. Returns the
// number of jobs in the merged table.
size_t mergeSweepOutputs(const std::vector<std::filesystem::path>& inputs,
                         const std::filesystem::path& out);

} // namespace experiments
