#!/usr/bin/env python3
"""Plots of the depth/position study (`testbed depth`, experiments/studies/DepthStudy.h), matplotlib.

Called by the C++ command, not by hand (but it can be):

  depth.py DIR/depth.json OUTDIR

writes OUTDIR/position_error_vs_distance.png (log-log max relative position error |p' - p| / d
against view depth d, one panel per near/far camera, one line per format x far plane x method;
distances where samples are lost to background are marked "x" at error 1)
and OUTDIR/depth_step_vs_distance.png (metres between neighbouring depth codes against d, one
panel per camera, one line per format x far plane, with d * 1e-3 as a guide). Samples lost to
background (null errors / steps) are gaps in the lines. Each PNG is written to a temporary name
in OUTDIR and renamed (os.replace), so an interrupted run leaves no partial file.
Exit status 0 on success, 2 on bad arguments or input, 3 when matplotlib is missing (plotfiles.py).
"""
import json
import math
import os
import sys

from plotfiles import pyplot, save_png

plt = pyplot("depth.py")

DPI = 100
# Drawing order: f32 last, on top of unorm24, which it equals wherever NDC depth >= 1/2 (there the
# float spacing of standard depth, 2^-24, is the 24-bit step); unorm24 is drawn wide and light.
FORMATS = ["unorm24", "unorm16", "f16-linear", "f32-reversed", "f32"]
WIDTHS = {"unorm24": 3.5}
ALPHAS = {"unorm24": 0.45}
# Okabe & Ito (2008) colour-vision-friendly palette, one colour per format.
COLOURS = {"f32": "#D55E00", "f32-reversed": "#0072B2", "unorm24": "#009E73",
           "unorm16": "#CC79A7", "f16-linear": "#E69F00"}
# (infinite, method) -> line style
STYLES = {(False, "inverse-projection"): "-", (False, "view-ray"): "--",
          (True, "inverse-projection"): ":", (True, "view-ray"): "-."}


def value(x):
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) and \
        math.isfinite(float(x)) and float(x) > 0.0 else math.nan


def grouped(rows, keys):
    """rows grouped by the values of `keys`, each group sorted by distance."""
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in keys), []).append(r)
    for series in groups.values():
        series.sort(key=lambda r: r["distance"])
    return groups


def cameras_of(rows):
    return sorted({(r["near"], r["far"]) for r in rows}, key=lambda c: (c[1], c[0]))


def grid(count):
    columns = 2 if count > 1 else 1
    return (count + columns - 1) // columns, columns


def save(fig, path):
    save_png(fig, path, dpi=DPI)


def panels(cameras, title):
    # Fixed margins (subplots_adjust), not tight_layout: measuring every log-axis minor tick label
    # took most of the script's time.
    rows, columns = grid(len(cameras))
    fig, axes = plt.subplots(rows, columns, figsize=(7.5 * columns, 5.0 * rows), squeeze=False)
    fig.suptitle(title)
    for extra in axes.flat[len(cameras):]:
        extra.set_visible(False)
    return fig, list(axes.flat)


def style_panel(axis, near, far, y_label):
    """Log-log axes of one camera's panel, against view depth."""
    axis.set_xscale("log")
    axis.set_yscale("log")
    axis.set_title(f"near {near:g} m, far {far:g} m")
    axis.set_xlabel("view depth d (m)")
    axis.set_ylabel(y_label)
    axis.grid(True, which="major", alpha=0.3)
    axis.minorticks_off()  # hundreds of log-axis minor ticks cost most of the drawing time


def plot_errors(data, out):
    rows = data["rows"]
    cameras = cameras_of(rows)
    fig, axes = panels(cameras, "Max relative position error |p' - p| / d over a 1280x720 pixel "
                                "grid (solid/dashed: finite far, inverse projection/view ray; "
                                "dotted/dash-dot: infinite far;\nx at 1: samples lost to "
                                "background, their depth rounds to the clear value)")
    groups = grouped(rows, ("near", "far", "format", "infinite", "method"))
    for axis, (near, far) in zip(axes, cameras):
        for fmt in FORMATS:
            for (infinite, method), style in STYLES.items():
                series = groups.get((near, far, fmt, infinite, method))
                if not series:
                    continue
                label = f"{fmt}{':infinite' if infinite else ''} {method}"
                axis.plot([r["distance"] for r in series],
                          [value(r["max_rel_error"]) for r in series],
                          style, color=COLOURS.get(fmt), linewidth=WIDTHS.get(fmt, 1.2),
                          alpha=ALPHAS.get(fmt, 1.0), label=label)
                lost = [r["distance"] for r in series if r.get("lost_samples", 0) > 0]
                if lost:  # the surface reads as background there: drawn as error 1 (100%)
                    axis.plot(lost, [1.0] * len(lost), "x", color=COLOURS.get(fmt), markersize=5)
        axis.axhline(1e-3, color="grey", linewidth=0.8, linestyle=(0, (1, 3)))
        style_panel(axis, near, far, "max relative error")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.07, right=0.98, top=0.89, bottom=0.2, hspace=0.3, wspace=0.18)
    save(fig, os.path.join(out, "position_error_vs_distance.png"))


def plot_steps(data, out):
    steps = data["steps"]
    cameras = cameras_of(steps)
    fig, axes = panels(cameras, "Depth step: metres between neighbouring codes "
                                "(solid: finite far, dashed: infinite far; grey: d x 1e-3)")
    groups = grouped(steps, ("near", "far", "format", "infinite"))
    for axis, (near, far) in zip(axes, cameras):
        distances = None
        for fmt in FORMATS:
            for infinite, style in ((False, "-"), (True, "--")):
                series = groups.get((near, far, fmt, infinite))
                if not series:
                    continue
                distances = [r["distance"] for r in series]
                axis.plot(distances, [value(r["depth_step_m"]) for r in series], style,
                          color=COLOURS.get(fmt), linewidth=WIDTHS.get(fmt, 1.2),
                          alpha=ALPHAS.get(fmt, 1.0), label=f"{fmt}{':infinite' if infinite else ''}")
        if distances:
            axis.plot(distances, [d * 1e-3 for d in distances], color="grey", linewidth=0.8,
                      linestyle=(0, (1, 3)))
        style_panel(axis, near, far, "depth step (m)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.07, right=0.98, top=0.92, bottom=0.13, hspace=0.3, wspace=0.18)
    save(fig, os.path.join(out, "depth_step_vs_distance.png"))


def main(argv):
    if len(argv) != 3:
        print("usage: depth.py DIR/depth.json OUTDIR", file=sys.stderr)
        return 2
    try:
        with open(argv[1], encoding="utf-8") as f:
            data = json.load(f)
        if not isinstance(data.get("rows"), list) or not isinstance(data.get("steps"), list):
            raise ValueError("no 'rows' and 'steps' lists")
    except (OSError, ValueError) as e:
        print(f"depth.py: cannot read {argv[1]}: {e}", file=sys.stderr)
        return 2
    if not os.path.isdir(argv[2]):
        print(f"depth.py: output folder {argv[2]} does not exist", file=sys.stderr)
        return 2
    plot_errors(data, argv[2])
    plot_steps(data, argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
