// ReportCommand: `testbed report DIR` turns a sweep's results folder (DIR/results.json and
// DIR/jobs/<job_id>/, see experiments/sweeps and the sweep runner) into one HTML page,
// DIR/report.html, with everything it shows under DIR/report/:
//   report/published.json     the published-vs-measured tables (input of the plot script)
//   report/groups.json        the comparable groups (input of the plot script, see below)
//   report/views.json         the aggregates over views (see Views below)
//   report/plots.json         the plot script's manifest: plots drawn and plots skipped (why),
//                             each with its group ("" for plots across groups) and kind
//   report/*.png              matplotlib plots (experiments/plots/report.py): per group, time
//                             against error with the Pareto front and the timing spread as error
//                             bars, bytes per pixel against error; across groups, light
//                             evaluations, culling efficiency and time against light count and
//                             time against resolution; published and measured ratios
//   report/maps/*.png         every job's heatmap, error and ꟻLIP map redrawn at its group's one
//                             scale (from render.exr), and report/thumbs/*.png thumbnails
// The page references these (and the full-size job images) by relative paths, so DIR can be
// moved or copied as a whole; it loads nothing from the network and carries two small inline
// scripts: one records image-load and script errors into #page-check (the headless Chromium test
// reads it), one toggles the results table between the columns a reader compares and all.
//
// Comparable groups: jobs are compared (Pareto fronts, shared map scales) only with jobs of the
// same group: the same value of every setting that is not a method column (method columns:
// stage, layout, normals, normal-space, depth, position; everything else -- scene, view, scene
// options, lights, seed, width, height, threads, repetitions, warmup, and any setting added
// later -- makes the group). Jobs of different sizes are never pooled. Plots across groups (vs
// light count, vs resolution) draw one line per method and one plot per remaining context, and
// say which settings vary with the x axis; any median says over which jobs it is taken.
//
// Views: a view (camera) is a setting like the scene, so each view is its own comparable group
// (its own Pareto plot and map scales): views are never pooled silently. The "Across views"
// section then aggregates explicitly: jobs whose groups differ only in the view form a view
// family; per family and method, the median and the min-max over the views of each job's median
// total time, of the error metric and of ꟻLIP, with the number of views that count (ok jobs with
// the figure) and the per-view rows behind a toggle. The aggregates also go to
// report/views.json (aggregateOverViews).
//
// Published figures: every entry of results.json's sweep.published becomes a table with, per
// cell, the published value, the measured value, and both ratios to the baseline column
// (ratio_to, default 0). A job matches a cell when, for every key of the row's and the column's
// "select", the job's value equals the selected one compared as text after normalising numbers
// (1500 == "1500" == 1500.0); only jobs with status "ok" count; several matches give the median
// of the metric, and the cell names the settings those jobs differ in; a metric given as a list
// of columns is the sum of those columns per job (a job missing any of them counts as missing).
//
// ꟻLIP: the results carry a flip column (FlipMetric.h); when it is null the page says why
// (flip_unavailable) in a visible note, and plots of flip are skipped with that reason.
//
// Errors: a missing or malformed results.json, a missing python3 with matplotlib, a failing
// plot script or an unknown --error-metric give one line "testbed: error: ..." and exit code 1.
// Every file is written through AtomicFile (the plot script writes to a temporary name and
// renames, too).
//
// Thread safety: the functions share no state.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/ImageOutput.h"
#include "experiments/PlotScript.h"

namespace experiments {

struct ReportCommandOptions {
    std::filesystem::path dir;         // the results folder (holds results.json)
    std::filesystem::path plotsScript; // empty = experiments/plots/report.py of the source tree
    std::string python;                // empty = the first of /usr/bin/python3, python3 that
                                       // imports matplotlib
    int thumbnailWidth = 192;          // pixels; thumbnails keep the image's aspect ratio
    std::string errorMetric = "relative_rmse"; // the y axis of the Pareto plots (an error column)
    std::optional<MapScale> errorScale;        // the error maps' scale; default: the sweep's
};

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
