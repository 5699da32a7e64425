#!/usr/bin/env python3
"""Plots of the testbed's reports, drawn with matplotlib (Debian: python3-matplotlib).

Called by the C++ commands, not by hand (but it can be, for debugging):

  report.py results --results DIR/results.json --published DIR/report/published.json --out DIR/report
      Plots of a sweep's results (see experiments/ReportCommand.h): time against error per stage
      and per encoding with the Pareto front marked, error against bytes per G-buffer pixel,
      light evaluations / culling efficiency / time against light count and time against pixel
      count per stage, and published against measured ratios. Writes OUT/<name>.png and the
      manifest OUT/plots.json: {"plots": [{"file", "title", "caption"}],
      "skipped": [{"title", "reason"}]} -- a plot whose axes would hold fewer than two distinct
      values is not drawn but listed under "skipped".

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
ERROR = "rmse"
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

    def save(self, fig, name, title, caption):
        save_png(fig, os.path.join(self.out, name + ".png"), dpi=DPI)
        self.plots.append({"file": name + ".png", "title": title, "caption": caption})

    def skip(self, title, reason):
        self.skipped.append({"title": title, "reason": reason})

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


def series_key(job, columns, by, scenes_vary):
    key = text(job.get(by))
    if scenes_vary and by != "scene":
        key += " @ " + text(job.get("scene"))
    return key


def colour_of(index):
    return PALETTE[index % len(PALETTE)]


def scatter_with_front(report, jobs, by, name, x_column, x_label, title, caption_extra):
    points = [(number(j.get(x_column)), number(j.get(ERROR)), text(j.get(by))) for j in jobs]
    points = [p for p in points if p[0] is not None and p[1] is not None]
    for axis, column in ((0, x_column), (1, ERROR)):
        if len({p[axis] for p in points}) < 2:
            report.skip(title, "fewer than two distinct values of %s among the jobs with %s and %s"
                        % (column, x_column, ERROR))
            return
    groups = sorted({g for _, _, g in points})
    fig, ax = plt.subplots(figsize=(7.2, 4.8))
    for i, group in enumerate(groups):
        xs = [x for x, _, g in points if g == group]
        ys = [y for _, y, g in points if g == group]
        ax.scatter(xs, ys, label=group, color=colour_of(i), marker=MARKERS[i % len(MARKERS)],
                   s=36, alpha=0.85, zorder=3)
    front = pareto_front([(x, y) for x, y, _ in points])
    ax.step([x for x, _ in front], [y for _, y in front], where="post", color="0.3",
            linestyle="--", linewidth=1, zorder=2, label="Pareto front")
    ax.scatter([x for x, _ in front], [y for _, y in front], s=110, facecolors="none",
               edgecolors="0.1", linewidths=1.2, zorder=4)
    if log_scale_fits([x for x, _, _ in points]):
        ax.set_xscale("log")
    if log_scale_fits([y for _, y, _ in points]):
        ax.set_yscale("log")
    ax.set_xlabel(x_label)
    ax.set_ylabel("RMSE against the reference")
    ax.set_title(title, fontsize=11)
    ax.grid(True, alpha=0.3, which="both")
    ax.legend(title=by, fontsize=7, title_fontsize=8, loc="best")
    fig.tight_layout()
    report.save(fig, name, title,
                "One point per job (%d jobs); circled points are on the Pareto front (no job is "
                "both faster and more accurate). %s" % (len(points), caption_extra))


def against_axis(report, jobs, x_column, y_column, name, title, x_label, y_label, scenes_vary,
                 x_of=None):
    """Median of y_column per (stage, x) as one line per stage."""
    x_of = x_of or (lambda j: number(j.get(x_column)))
    series = {}
    for job in jobs:
        x, y = x_of(job), number(job.get(y_column))
        if x is None or y is None:
            continue
        series.setdefault(series_key(job, None, "stage", scenes_vary), {}).setdefault(x, []).append(y)
    xs_all = {x for s in series.values() for x in s}
    if len(xs_all) < 2:
        report.skip(title, "fewer than two distinct values of %s with %s measured" % (x_column, y_column))
        return
    fig, ax = plt.subplots(figsize=(7.2, 4.8))
    for i, (label, values) in enumerate(sorted(series.items())):
        xs = sorted(values)
        ax.plot(xs, [statistics.median(values[x]) for x in xs], label=label, color=colour_of(i),
                marker=MARKERS[i % len(MARKERS)], markersize=5)
    if log_scale_fits(sorted(xs_all)):
        ax.set_xscale("log")
    ys = [statistics.median(v) for s in series.values() for v in s.values()]
    if y_column != "culling_efficiency" and log_scale_fits(ys):
        ax.set_yscale("log")
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.set_title(title, fontsize=11)
    ax.grid(True, alpha=0.3, which="both")
    ax.legend(title="stage", fontsize=7, title_fontsize=8, loc="best")
    fig.tight_layout()
    report.save(fig, name, title, "Median over the jobs that share stage and %s." % x_column)


def published_ratios(report, table, index):
    title = "Ratios to %s: %s" % (table["columns"][table["ratio_to"]], table["title"])
    rows, columns = table["rows"], table["columns"]
    if not rows or all(c["measured_ratio"] is None for r in rows for c in r["cells"]):
        report.skip(title, "no measured ratio (no matching ok jobs)")
        return
    fig, ax = plt.subplots(figsize=(min(9.0, max(6.0, 1.1 * len(rows) * len(columns))), 4.8))
    width = 0.8 / (2 * len(columns))
    positions = np.arange(len(rows))
    for c, column in enumerate(columns):
        for kind, offset, hatch in (("published_ratio", 0, None), ("measured_ratio", 1, "//")):
            values = [r["cells"][c][kind] for r in rows]
            heights = [v if v is not None else 0.0 for v in values]
            bars = ax.bar(positions - 0.4 + width * (2 * c + offset + 0.5), heights, width,
                          color=colour_of(c), alpha=0.55 if offset == 0 else 0.95, hatch=hatch,
                          edgecolor="0.2", linewidth=0.5,
                          label="%s (%s)" % (column, "published" if offset == 0 else "measured"))
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
    report.save(fig, "published_%d" % index, title,
                "Light bars: published ratio; hatched bars: measured ratio (median of matching jobs).")


def plot_results(args):
    with open(args.results, encoding="utf-8") as f:
        results = json.load(f)
    published = []
    if args.published:
        with open(args.published, encoding="utf-8") as f:
            published = json.load(f)
    jobs = [j for j in results.get("jobs", []) if j.get("status") == "ok"]
    columns = results.get("columns") or sorted({k for j in jobs for k in j})
    report = Report(args.out)
    if not jobs:
        report.skip("All plots", "no job finished ok")
    else:
        scenes_vary = len({text(j.get("scene")) for j in jobs}) > 1
        for by in ("stage", "normals", "layout", "depth", "position"):
            if by not in columns:
                continue
            title = "Time against error, per %s" % by
            if by != "stage" and len({text(j.get(by)) for j in jobs}) < 2:
                report.skip(title, "only one value of %s" % by)
                continue
            scatter_with_front(report, jobs, by, "time_vs_error_by_%s" % by, TIME,
                               "total time, median (ms)", title, "")
        if "bytes_per_pixel" in columns:
            by = "normals" if "normals" in columns else "stage"
            scatter_with_front(report, jobs, by, "bytes_vs_error", "bytes_per_pixel",
                               "G-buffer bytes per pixel", "Bytes per pixel against error, per %s" % by,
                               "The front: the most accurate encoding for a memory budget.")
        for column, label, name, title in (
                ("light_evaluations", "light evaluations (total over the image)", "evaluations_vs_lights",
                 "Light evaluations against light count"),
                ("culling_efficiency", "culling efficiency (oracle / evaluated)", "culling_vs_lights",
                 "Culling efficiency against light count"),
                (TIME, "total time, median (ms)", "time_vs_lights", "Time against light count")):
            against_axis(report, jobs, "lights", column, name, title, "generated lights", label, scenes_vary)

        def pixels(job):
            w, h = number(job.get("width")), number(job.get("height"))
            return w * h / 1e6 if w is not None and h is not None else None
        against_axis(report, jobs, "width x height", TIME, "time_vs_pixels",
                     "Time against resolution", "megapixels", "total time, median (ms)", scenes_vary,
                     x_of=pixels)
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
