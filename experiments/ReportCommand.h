// ReportCommand: `testbed report DIR` turns a sweep's results folder (DIR/results.json and
// DIR/jobs/<job_id>/, see experiments/sweeps and the sweep runner) into one HTML page,
// DIR/report.html, with everything it shows under DIR/report/:
//   report/published.json     the published-vs-measured tables (input of the plot script)
//   report/plots.json         the plot script's manifest: plots drawn and plots skipped (why)
//   report/*.png              matplotlib plots (experiments/plots/report.py): time against error
//                             per stage and per encoding with the Pareto front, light evaluations,
//                             culling efficiency and time against light count, published and
//                             measured ratios
//   report/thumbs/*.png       thumbnails of every job's preview.png, heatmap.png and error.png
// The page references these (and the full-size job images) by relative paths, so DIR can be
// moved or copied as a whole; it loads nothing from the network and carries one small inline
// script that records image-load and script errors into the element #page-check (the headless
// Chromium test reads it).
//
// Published figures: every entry of results.json's sweep.published becomes a table with, per
// cell, the published value, the measured value, and both ratios to the baseline column
// (ratio_to, default 0). A job matches a cell when, for every key of the row's and the column's
// "select", the job's value equals the selected one compared as text after normalising numbers
// (1500 == "1500" == 1500.0); only jobs with status "ok" count; several matches give the median
// of the metric; a metric given as a list of columns is the sum of those columns per job (a job
// missing any of them counts as missing).
//
// Errors: a missing or malformed results.json, a missing python3 with matplotlib, or a failing
// plot script give one line "testbed: error: ..." and exit code 1. Every file is written through
// AtomicFile (the plot script writes to a temporary name and renames, too).
//
// Thread safety: the functions share no state.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/PlotScript.h"

namespace experiments {

struct ReportCommandOptions {
    std::filesystem::path dir;         // the results folder (holds results.json)
    std::filesystem::path plotsScript; // empty = experiments/plots/report.py of the source tree
    std::string python;                // empty = the first of /usr/bin/python3, python3 that
                                       // imports matplotlib
    int thumbnailWidth = 192;          // pixels; thumbnails keep the image's aspect ratio
};

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

// One published entry compared with the jobs: a JSON object
//   { "title", "source", "metric" (as given), "metric_label", "finding", "ratio_to",
//     "columns": [labels...],
//     "rows": [ { "label", "cells": [ { "published", "measured", "published_ratio",
//                                       "measured_ratio", "matched_jobs" } ] } ] }
// with null for anything unknown (not published, no matching job, baseline missing or zero).
// Throws std::runtime_error naming the entry and the field when the entry is malformed (no
// columns, a row whose values do not have one entry per column, ratio_to out of range, ...).
nlohmann::json comparePublished(const nlohmann::json& published, const nlohmann::json& jobs);

// Writes DIR/report.html and DIR/report/; returns the exit code (0 on success). Prints the
// path of the page on stdout; errors go to stderr as "testbed: error: ...".
int runReportCommand(const ReportCommandOptions& options);

// The default plot script (the source tree's experiments/plots/report.py, fixed at build time).
std::filesystem::path defaultPlotsScript();

// A number as the report and diff pages show it: `significantDigits` (%g), integers whole when
// wholeIntegers (below 1e15), "NaN", "inf", "-inf".
std::string displayNumber(double value, int significantDigits, bool wholeIntegers = false);

// HTML pieces shared by the report and the diff pages.
std::string htmlEscape(const std::string& text);
// An inline <script> for <head> that, once the page has loaded, writes "PAGE-CHECK: OK (N images)"
// or "PAGE-CHECK: FAILED" plus one line per script error or image that failed to load into the
// element with id "page-check" (which the page must contain).
const char* pageCheckScript();

} // namespace experiments
