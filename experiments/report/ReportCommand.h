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

#include "experiments/output/ImageOutput.h"
#include "experiments/output/PlotScript.h"
#include "experiments/output/ReportHtml.h"
#include "experiments/report/PublishedFigures.h"
#include "experiments/sweep/ResultGroups.h"

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

// Writes DIR/report.html and DIR/report/; returns the exit code (0 on success). Prints the
// path of the page on stdout; errors go to stderr as "testbed: error: ...".
int runReportCommand(const ReportCommandOptions& options);

// The default plot script (the source tree's experiments/plots/report.py, fixed at build time).
std::filesystem::path defaultPlotsScript();

} // namespace experiments
