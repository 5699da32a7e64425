// PublishedFigures: a sweep file's "published" tables (figures from the seeds' papers) matched
// with the jobs that reproduce them, and their section of the report (ReportCommand.h describes
// the matching).
// Thread safety: pure functions.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace experiments {

// One published entry compared with the jobs: a JSON object
//   { "title", "source", "metric" (as given), "metric_label", "finding", "ratio_to",
//     "modelled" (the cost model's column, e.g. simt_lane_slots, or null), "columns": [labels...],
//     "rows": [ { "label", "cells": [ { "published", "measured", "published_ratio",
//                                       "measured_ratio", "modelled", "modelled_ratio",
//                                       "matched_jobs", "differ_in" } ] } ] }
// where differ_in lists the columns of `axisColumns` whose values differ among the matched jobs
// (what the median is taken over; empty when they agree or only one matched).
// with null for anything unknown (not published, no matching job, baseline missing or zero).
// Throws std::runtime_error naming the entry and the field when the entry is malformed (no
// columns, a row whose values do not have one entry per column, ratio_to out of range, ...).
nlohmann::json comparePublished(const nlohmann::json& published, const nlohmann::json& jobs,
                                const std::vector<std::string>& axisColumns = {});

// Appends the report's section for one compared table (comparePublished's result), with the
// anchor id "published-<index>".
void appendPublishedSection(std::ostringstream& html, const nlohmann::json& table, int index);

} // namespace experiments
