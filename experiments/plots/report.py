#!/usr/bin/env python3
"""Plots of the testbed's reports, drawn with matplotlib (Debian: python3-matplotlib).

Called by the C++ commands, not by hand (but it can be, for debugging):

  report.py results --results DIR/results.json --published DIR/report/published.json
            --groups DIR/report/groups.json [--error-metric relative_rmse] --out DIR/report
      Plots of a sweep's results (see experiments/report/ReportCommand.h). groups.json (written by the
      report command) lists the comparable groups: jobs with the same value of every setting but
      the method columns (stage, layout, normals, ...). Per group: time against the error metric
      with the Pareto front and the repetitions' min-max time as error bars ("pareto"), and bytes
      per G-buffer pixel against the error ("bytes") when the group's layouts differ in size.
      Across groups: light evaluations, culling efficiency and time against the light count, and
      time against the pixel count ("vs_lights", "vs_pixels"), one line per method and one plot per
      context (the grouping settings other than the x axis's; a setting that changes together
      with x, like a sweep case's lights and lights behind the wall, is named in the caption, not
      split). Points are single jobs; a point that is a median says over which jobs. Published
      against measured ratios ("published"). Writes OUT/<name>.png and the manifest
      OUT/plots.json: {"plots": [{"file", "title", "caption", "group", "kind"}],
      "skipped": [{"title", "reason", "group", "kind"}]} -- group is a group id or "" for plots
      across groups; a plot without data to compare is listed under "skipped" with the reason.

  report.py diff --raw FILE --width W --height H --vmax V --out PNG [--title T]
      False-colour image of a per-pixel absolute difference (FILE: W*H little-endian float32,
      row 0 at the top) with a colour bar from 0 to V.

Only ok jobs are plotted; a metric that is null, missing, a string ("inf") or not finite
(NaN/inf PSNR) is left out of the plot it would be in. Every file is written to a temporary name
in the same folder and renamed (os.replace), so an interrupted run leaves no partial PNG.
Exit status 0 on success, 2 on bad arguments or input (message on stderr), 3 when matplotlib is
missing. PNGs are written through plotfiles.py (beside this script).
"""
import argparse
import json
import math
import os
import statistics
import sys

from plotfiles import pyplot, save_png, write_text

plt = pyplot("report.py")
import matplotlib  # noqa: E402 (after the backend is chosen)
import numpy as np  # noqa: E402

TIME = "time_total_median_ms"
TIME_MIN = "time_total_min_ms"
TIME_MAX = "time_total_max_ms"
# Error columns where a larger value is better (the Pareto front then keeps the largest).
HIGHER_IS_BETTER = {"psnr"}
ERROR_LABELS = {
    "relative_rmse": "relative RMSE against the reference (RMSE / RMS of the reference)",
    "rmse": "RMSE against the reference (linear radiance)",
    "flip": "HDR-FLIP against the reference (mean, 0..1)",
    "psnr": "PSNR against the reference (dB, higher is better)",
    "max_abs": "largest absolute error against the reference",
    "relative_mean": "mean absolute error / mean of the reference",
    "p99_abs": "99th percentile of the absolute error",
}
DPI = 100
# Colour-vision-friendly palette (Okabe & Ito 2008), then matplotlib's tab10 for more groups.
PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442",
           "#000000"] + [matplotlib.colormaps["tab10"](i) for i in range(10)]
MARKERS = "osD^v<>pPX*h"


def number(value):
    """A finite float, or None for null, strings, booleans, NaN and infinities."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def text(value):
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


class Report:
    def __init__(self, out):
        self.out = out
        self.plots = []
        self.skipped = []

    def save(self, fig, name, title, caption, group="", kind=""):
        save_png(fig, os.path.join(self.out, name + ".png"), dpi=DPI)
        self.plots.append({"file": name + ".png", "title": title, "caption": caption,
                           "group": group, "kind": kind})

    def skip(self, title, reason, group="", kind=""):
        self.skipped.append({"title": title, "reason": reason, "group": group, "kind": kind})

    def manifest(self):
        return json.dumps({"plots": self.plots, "skipped": self.skipped}, indent=2) + "\n"


def log_scale_fits(values):
    """Log axis when every value is positive and they span more than a factor of 20."""
    return len(values) > 1 and min(values) > 0 and max(values) / min(values) > 20


def pareto_front(points):
    """Points (x, y) not dominated by another (smaller or equal in both, smaller in one),
    sorted by x: the best error for any time budget."""
    front = []
    for x, y in sorted(set(points)):
        if not front or y < front[-1][1]:
            front.append((x, y))
    return front


def colour_of(index):
    return PALETTE[index % len(PALETTE)]


def method_label(job, method_columns):
    """The job's method inside its group: the varying method columns, stage first."""
    parts = [text(job.get("stage"))]
    parts += ["%s %s" % (c, text(job.get(c))) for c in method_columns if c != "stage"]
    return ", ".join(parts)


def repetitions_note(jobs):
    counts = sorted({int(number(j.get("repetitions"))) for j in jobs
                     if number(j.get("repetitions")) is not None})
    if not counts:
        return "the repetitions' min-max total time"
    return "min-max of the total time over %s repetition%s" % (
        "/".join(str(c) for c in counts), "" if counts == [1] else "s")


def pareto_plot(report, group, jobs, metric, method_columns, x_column=TIME, kind="pareto"):
    """Time (or bytes) against the error metric inside one comparable group, with its front."""
    gid, label = group["id"], group["label"]
    what = "Time" if x_column == TIME else "Bytes per pixel"
    title = "%s against %s, group %s: %s" % (what, metric, gid, label)
    points = []
    missing = []
    for job in jobs:
        x, y = number(job.get(x_column)), number(job.get(metric))
        if x is None or y is None:
            missing.append(job)
            continue
        low, high = number(job.get(TIME_MIN)), number(job.get(TIME_MAX))
        points.append({"x": x, "y": y, "label": method_label(job, method_columns),
                       "low": low if low is not None else x, "high": high if high is not None else x})
    if len(points) < 2:
        reasons = sorted({text(j.get("flip_unavailable")) for j in missing
                          if metric == "flip" and j.get("flip_unavailable")})
        report.skip(title, "%d job%s of the group with both %s and %s: nothing to compare%s" % (
            len(points), "" if len(points) == 1 else "s", x_column, metric,
            " (flip unavailable: %s)" % "; ".join(reasons) if reasons else ""), gid, kind)
        return
    sign = -1.0 if metric in HIGHER_IS_BETTER else 1.0
    front = pareto_front([(p["x"], sign * p["y"]) for p in points])
    front = [(x, sign * y) for x, y in front]
    labels = []
    for p in points:
        if p["label"] not in labels:
            labels.append(p["label"])
    fig, ax = plt.subplots(figsize=(7.2, 4.8))
    spread = False
    for i, label_text in enumerate(labels):
        mine = [p for p in points if p["label"] == label_text]
        xs, ys = [p["x"] for p in mine], [p["y"] for p in mine]
        if x_column == TIME:
            lows = [max(0.0, p["x"] - p["low"]) for p in mine]
            highs = [max(0.0, p["high"] - p["x"]) for p in mine]
            spread = spread or any(v > 0 for v in lows + highs)
            ax.errorbar(xs, ys, xerr=[lows, highs], fmt="none", ecolor=colour_of(i), elinewidth=1,
                        capsize=3, alpha=0.8, zorder=2)
        ax.scatter(xs, ys, label=label_text, color=colour_of(i), marker=MARKERS[i % len(MARKERS)],
                   s=36, alpha=0.9, zorder=3)
    ax.step([x for x, _ in front], [y for _, y in front], where="post", color="0.3",
            linestyle="--", linewidth=1, zorder=1, label="Pareto front")
    ax.scatter([x for x, _ in front], [y for _, y in front], s=110, facecolors="none",
               edgecolors="0.1", linewidths=1.2, zorder=4)
    if log_scale_fits([p["x"] for p in points]):
        ax.set_xscale("log")
    if metric not in HIGHER_IS_BETTER and log_scale_fits([p["y"] for p in points]):
        ax.set_yscale("log")
    ax.set_xlabel("total time, median over the repetitions (ms)" if x_column == TIME
                  else "G-buffer bytes per pixel")
    ax.set_ylabel(ERROR_LABELS.get(metric, metric), fontsize=8)
    ax.set_title("Group %s: %s" % (gid, label), fontsize=10)
    ax.grid(True, alpha=0.3, which="both")
    ax.legend(fontsize=6 if len(labels) > 8 else 7, ncol=2 if len(labels) > 12 else 1, loc="best")
    fig.tight_layout()
    if x_column == TIME:
        bars = ("Horizontal bars: %s%s." % (repetitions_note(jobs), "" if spread else
                " (no spread: one repetition, or equal times)"))
    else:
        bars = "The front: the most accurate layout for a memory budget."
    caption = ("One point per job of this group (%d of its %d jobs have both figures; nothing is "
               "averaged). Circled points are on the Pareto front: no other job of the group is "
               "both %s and more accurate. %s" % (
                   len(points), len(jobs), "faster" if x_column == TIME else "smaller", bars))
    if missing:
        caption += " Left out (no %s or %s): %s." % (x_column, metric, ", ".join(
            text(j.get("job_id")) for j in missing))
    report.save(fig, "%s_%s" % (kind, gid), title, caption, gid, kind)


def split_contexts(jobs, groups, x_of, x_columns, y_column):
    """The jobs with x and y measured, split by context: the grouping settings other than x's and
    those that change with x. Returns (contexts {key: jobs}, context_columns, varying_context,
    covarying), or None when fewer than two distinct x values are measured."""
    grouping = [c for c in groups["axis_columns"] if c not in groups["method_columns"]
                and c not in ("stage", "layout", "normals", "normal-space", "depth", "position",
                              "resolution")]
    others = [c for c in grouping if c not in x_columns]
    measured = [j for j in jobs if x_of(j) is not None and number(j.get(y_column)) is not None]
    if len({x_of(j) for j in measured}) < 2:
        return None
    # Settings that change together with x (one value per x) are not a context of their own.
    covarying = []
    for column in others:
        per_x = {}
        for job in measured:
            per_x.setdefault(x_of(job), set()).add(text(job.get(column)))
        values = {text(j.get(column)) for j in measured}
        if len(values) > 1 and all(len(v) == 1 for v in per_x.values()):
            covarying.append(column)
    context_columns = [c for c in others if c not in covarying]
    contexts = {}
    for job in measured:
        key = tuple(text(job.get(c)) for c in context_columns)
        contexts.setdefault(key, []).append(job)
    varying_context = [c for i, c in enumerate(context_columns)
                       if len({k[i] for k in contexts}) > 1]
    return contexts, context_columns, varying_context, covarying


def context_title(title, context_columns, key, varying_context):
    """A plot's title with the context settings that vary between its sibling plots."""
    context = ", ".join("%s %s" % (c, v) for c, v in zip(context_columns, key)
                        if c in varying_context)
    return title + (" (%s)" % context if context else "")


def context_plots(report, jobs, groups, x_of, x_columns, x_label, y_column, y_label, name, title,
                  kind):
    """y against x across groups: one plot per context (the grouping settings other than x's and
    those that change with x), one line per method."""
    split = split_contexts(jobs, groups, x_of, x_columns, y_column)
    if split is None:
        report.skip(title, "fewer than two distinct values of %s among the jobs with %s measured"
                    % (" x ".join(x_columns), y_column), "", kind)
        return
    contexts, context_columns, varying_context, covarying = split
    for index, (key, members) in enumerate(sorted(contexts.items())):
        plot_title = context_title(title, context_columns, key, varying_context)
        series = {}
        for job in members:
            series.setdefault(method_label(job, groups["method_columns"]), {}).setdefault(
                x_of(job), []).append(job)
        xs_all = {x for s in series.values() for x in s}
        if len(xs_all) < 2:
            report.skip(plot_title, "fewer than two distinct values of %s with %s measured" % (
                " x ".join(x_columns), y_column), "", kind)
            continue
        fig, ax = plt.subplots(figsize=(7.2, 4.8))
        aggregated = set()
        for i, (label_text, values) in enumerate(sorted(series.items())):
            xs = sorted(values)
            ys = []
            for x in xs:
                group_jobs = values[x]
                ys.append(statistics.median(number(j.get(y_column)) for j in group_jobs))
                if len(group_jobs) > 1:
                    aggregated.update(c for c in set(k for j in group_jobs for k in j)
                                      if not c.startswith("time_") and c not in
                                      ("job_id", "error", "status") and
                                      len({text(j.get(c)) for j in group_jobs}) > 1
                                      and c in groups["axis_columns"])
            ax.plot(xs, ys, label=label_text, color=colour_of(i), marker=MARKERS[i % len(MARKERS)],
                    markersize=5)
        if log_scale_fits(sorted(xs_all)):
            ax.set_xscale("log")
        ys_all = [number(j.get(y_column)) for j in members]
        if y_column != "culling_efficiency" and log_scale_fits(ys_all):
            ax.set_yscale("log")
        ax.set_xlabel(x_label)
        ax.set_ylabel(y_label)
        ax.set_title(plot_title, fontsize=10)
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(title="method", fontsize=7, title_fontsize=8, loc="best")
        fig.tight_layout()
        fixed = ", ".join("%s %s" % (c, v) for c, v in zip(context_columns, key)) or "nothing else"
        caption = "Fixed: %s. " % fixed
        if covarying:
            caption += "Changes with the x axis: %s. " % ", ".join(
                "%s (%s)" % (c, ", ".join(sorted({text(j.get(c)) for j in members},
                                                  key=lambda v: (len(v), v))))
                for c in covarying)
        caption += ("Each point is one job." if not aggregated else
                    "Points with several jobs are their median; those jobs differ in: %s." %
                    ", ".join(sorted(aggregated)))
        report.save(fig, "%s_%d" % (name, index + 1), plot_title, caption, "", kind)


ASSIGNMENT_PASSES = ("clusters", "cull", "assign", "index")


def assignment_ms(job):
    """The median time of the job's light-assignment passes (clusters, cull, assign, index), or None."""
    times = [number(job.get("time_%s_median_ms" % p)) for p in ASSIGNMENT_PASSES]
    times = [t for t in times if t is not None]
    return sum(times) if times else None


def loglog_slope(points):
    """Least-squares slope of log(y) against log(x) over points with x >= 1000 (the issue's range;
    below it fixed costs dominate), or None with fewer than two such points."""
    pts = [(math.log(x), math.log(y)) for x, y in points if x >= 1000 and y > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else None


def scaling_plots(report, jobs, groups):
    """The light-scaling study: per context, light assignment time, shading time and peak resident
    memory against the light count on log-log axes, one line per method, the fitted slope of each
    line from 10^3 lights up in its label; the 'ideal' stage's shading (each pixel shades exactly its
    contributing lights: the oracle-bounded ceiling of exact culling) drawn as the ideal line."""
    lights = lambda j: number(j.get("lights"))  # noqa: E731
    title = "Scaling with the light count"
    split = split_contexts(jobs, groups, lights, ["lights"], "time_shading_median_ms")
    if split is None or len({lights(j) for j in jobs if lights(j)}) < 3:
        report.skip(title, "fewer than three light counts with shading measured", "", "scaling")
        return
    contexts, context_columns, varying_context, covarying = split
    panels = (("light assignment, median (ms)", assignment_ms),
              ("shading, median (ms)", lambda j: number(j.get("time_shading_median_ms"))),
              ("peak resident memory (MiB)",
               lambda j: (number(j.get("peak_rss_bytes")) or 0) / 2**20 or None))
    for index, (key, members) in enumerate(sorted(contexts.items())):
        plot_title = context_title(title, context_columns, key, varying_context)
        series = {}
        for job in members:
            series.setdefault(method_label(job, groups["method_columns"]), []).append(job)
        fig, axes = plt.subplots(1, 3, figsize=(14.4, 4.8))
        slopes = []
        for ax, (label, value_of) in zip(axes, panels):
            drawn = 0
            panel_ys = []
            for i, (method, method_jobs) in enumerate(sorted(series.items())):
                per_x = {}
                for job in method_jobs:
                    v = value_of(job)
                    if v is not None and v > 0:
                        per_x.setdefault(lights(job), []).append(v)
                if len(per_x) < 2:
                    continue
                xs = sorted(per_x)
                ys = [statistics.median(per_x[x]) for x in xs]
                slope = loglog_slope(list(zip(xs, ys)))
                ideal = method.startswith("ideal")
                if ideal and value_of is not panels[1][1]:
                    continue  # the ideal stage's lists are made outside the timer: shading only
                legend = ("ideal (oracle-bounded)" if ideal else method) + (
                    "" if slope is None else ", slope %.2f" % slope)
                if slope is not None and value_of is panels[0][1]:
                    slopes.append("%s %.2f" % (method, slope))
                panel_ys += ys
                ax.plot(xs, ys, label=legend, color="black" if ideal else colour_of(i),
                        linestyle="--" if ideal else "-", marker=MARKERS[i % len(MARKERS)],
                        markersize=4)
                drawn += 1
            ax.set_xscale("log")
            if log_scale_fits(panel_ys):  # else linear: a log axis over 5% says nothing
                ax.set_yscale("log")
            ax.set_xlabel("generated lights")
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3, which="both")
            if drawn:
                ax.legend(fontsize=6, loc="best")
        fig.suptitle(plot_title, fontsize=10)
        fig.tight_layout()
        fixed = ", ".join("%s %s" % (c, v) for c, v in zip(context_columns, key)) or "nothing else"
        caption = ("Fixed: %s. Each point is the median over the jobs of that method and "
                   "light count; axes are log-log where the values span over 20x; slopes are "
                   "least-squares fits of log value against log lights from 10^3 lights up "
                   "(1 = linear; N log N from 10^3 to 10^6 fits a slope of about 1.10). "
                   "Assignment = clusters + cull + assign + index passes (explicit clusters "
                   "count their finding). Memory is the job process's peak resident set (the "
                   "whole render, reference excluded)."
                   % fixed)
        if slopes:
            caption += " Assignment slopes: %s." % "; ".join(slopes)
        report.save(fig, "scaling_%d" % (index + 1), plot_title, caption, "", "scaling")


def published_ratios(report, table, index):
    title = "Ratios to %s: %s" % (table["columns"][table["ratio_to"]], table["title"])
    rows, columns = table["rows"], table["columns"]
    if not rows or all(c["measured_ratio"] is None for r in rows for c in r["cells"]):
        report.skip(title, "no measured ratio (no matching ok jobs)", "", "published")
        return
    # Published, then (when the table names a cost model) modelled, then measured ratios.
    kinds = [("published_ratio", "published", None, 0.55)]
    if table.get("modelled"):
        kinds.append(("modelled_ratio", "modelled", "..", 0.75))
    kinds.append(("measured_ratio", "measured", "//", 0.95))
    fig, ax = plt.subplots(figsize=(min(9.0, max(6.0, 1.1 * len(rows) * len(columns))), 4.8))
    width = 0.8 / (len(kinds) * len(columns))
    positions = np.arange(len(rows))
    for c, column in enumerate(columns):
        for offset, (kind, label, hatch, alpha) in enumerate(kinds):
            values = [r["cells"][c].get(kind) for r in rows]
            heights = [v if v is not None else 0.0 for v in values]
            bars = ax.bar(positions - 0.4 + width * (len(kinds) * c + offset + 0.5), heights,
                          width, color=colour_of(c), alpha=alpha, hatch=hatch, edgecolor="0.2",
                          linewidth=0.5, label="%s (%s)" % (column, label))
            for bar, value in zip(bars, values):
                if value is None:
                    ax.annotate("n/a", (bar.get_x() + bar.get_width() / 2, 0), ha="center",
                                va="bottom", fontsize=6, rotation=90)
    ax.axhline(1.0, color="0.4", linewidth=0.8)
    ax.set_xticks(positions, [r["label"] for r in rows])
    ax.set_ylabel("ratio to %s (%s)" % (columns[table["ratio_to"]], table["metric_label"]))
    ax.set_title(table["title"], fontsize=10)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=6, ncol=max(1, len(columns)), loc="best")
    fig.tight_layout()
    modelled = ("dotted bars: the ratio %s predicts (the same jobs); " % table["modelled"]
                if table.get("modelled") else "")
    report.save(fig, "published_%d" % index, title,
                "Light bars: published ratio; " + modelled + "hatched bars: measured ratio "
                "(median of matching jobs; the table says which settings those jobs differ in).",
                "", "published")


def plot_results(args):
    with open(args.results, encoding="utf-8") as f:
        results = json.load(f)
    published = []
    if args.published:
        with open(args.published, encoding="utf-8") as f:
            published = json.load(f)
    with open(args.groups, encoding="utf-8") as f:
        groups = json.load(f)
    metric = args.error_metric
    jobs = [j for j in results.get("jobs", []) if j.get("status") == "ok"]
    by_id = {j.get("job_id"): j for j in jobs}
    report = Report(args.out)
    if not jobs:
        report.skip("All plots", "no job finished ok")
    for group in groups["groups"]:
        members = [by_id[i] for i in group["jobs"] if i in by_id]
        if not members:
            report.skip("Group %s: %s" % (group["id"], group["label"]), "no job finished ok",
                        group["id"], "pareto")
            continue
        pareto_plot(report, group, members, metric, groups["method_columns"])
        if len({number(j.get("bytes_per_pixel")) for j in members
                if number(j.get("bytes_per_pixel")) is not None}) > 1:
            pareto_plot(report, group, members, metric, groups["method_columns"],
                        x_column="bytes_per_pixel", kind="bytes")
    if jobs:
        lights = lambda j: number(j.get("lights"))  # noqa: E731
        for column, label, name, title in (
                ("light_evaluations", "light evaluations (over the counted pixels)",
                 "evaluations_vs_lights", "Light evaluations against light count"),
                ("culling_efficiency", "culling efficiency (oracle / evaluated)", "culling_vs_lights",
                 "Culling efficiency against light count"),
                (TIME, "total time, median (ms)", "time_vs_lights", "Time against light count")):
            context_plots(report, jobs, groups, lights, ["lights"], "generated lights", column,
                          label, name, title, "vs_lights")

        def pixels(job):
            w, h = number(job.get("width")), number(job.get("height"))
            return w * h / 1e6 if w is not None and h is not None else None
        context_plots(report, jobs, groups, pixels, ["width", "height", "resolution"], "megapixels",
                      TIME, "total time, median (ms)", "time_vs_pixels", "Time against resolution",
                      "vs_pixels")
        if len({lights(j) for j in jobs if assignment_ms(j) is not None}) >= 3:
            scaling_plots(report, jobs, groups)
    for i, table in enumerate(published):
        published_ratios(report, table, i)
    write_text(os.path.join(args.out, "plots.json"), report.manifest())


def plot_diff(args):
    data = np.fromfile(args.raw, dtype="<f4")
    if data.size != args.width * args.height:
        raise ValueError("%s holds %d values, expected %d x %d" % (args.raw, data.size, args.width, args.height))
    image = data.reshape(args.height, args.width)
    vmax = args.vmax if args.vmax > 0 and math.isfinite(args.vmax) else 1.0
    aspect = args.height / args.width
    width_inches = min(max(args.width, 400), 1000) / DPI + 1.2
    fig, ax = plt.subplots(figsize=(width_inches, max(2.0, (width_inches - 1.2) * aspect + 0.8)))
    shown = ax.imshow(np.nan_to_num(image, nan=vmax, posinf=vmax), cmap="turbo", vmin=0.0, vmax=vmax,
                      interpolation="nearest")
    ax.set_axis_off()
    ax.set_title(args.title, fontsize=10)
    bar = fig.colorbar(shown, ax=ax, fraction=0.046, pad=0.02)
    bar.set_label("absolute difference (linear radiance)", fontsize=8)
    fig.tight_layout()
    save_png(fig, args.out, dpi=DPI)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    results = commands.add_parser("results")
    results.add_argument("--results", required=True)
    results.add_argument("--published", default="")
    results.add_argument("--groups", required=True)
    results.add_argument("--error-metric", default="relative_rmse")
    results.add_argument("--out", required=True)
    diff = commands.add_parser("diff")
    diff.add_argument("--raw", required=True)
    diff.add_argument("--width", type=int, required=True)
    diff.add_argument("--height", type=int, required=True)
    diff.add_argument("--vmax", type=float, required=True)
    diff.add_argument("--out", required=True)
    diff.add_argument("--title", default="|A - B|, maximum over R, G, B")
    args = parser.parse_args()
    try:
        if args.command == "results":
            plot_results(args)
        else:
            plot_diff(args)
    except (OSError, ValueError, KeyError, TypeError) as error:
        print("report.py: error: %s" % error, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
