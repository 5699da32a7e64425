#!/usr/bin/env python3
"""Plots of the normal-encoding precision study (`testbed normals`, experiments/studies/NormalStudy.h).

Called by the C++ command after it has written DIR/normals.json and the error grids
DIR/maps/<codec>-<bits>.f32 (it can also be run by hand):

  normals.py --out DIR

writes
  DIR/error_vs_bits.png        mean (solid, o) and max (dashed, x) angular error against total
                               bits, one colour per codec, log scale; left panel the uniform
                               sphere, right panel visible-60 (normals a 60 degree FOV camera sees)
  DIR/maps/<codec>-<bits>.png  equirectangular map of the max error per 0.5 degree cell (log
                               colour scale), longitude = azimuth atan2(y, x), latitude = asin(z):
                               top row +Z (facing the camera), bottom row -Z
Each PNG is written to a temporary name and renamed (os.replace): no partial files.
Exit status 0 on success, 2 on bad arguments or input, 3 when matplotlib is missing (plotfiles.py).
"""
import argparse
import json
import os
import sys

from plotfiles import pyplot, save_png

plt = pyplot("normals.py")
from matplotlib.colors import LogNorm  # noqa: E402 (after the backend is chosen)
import numpy as np  # noqa: E402 (Debian's python3-matplotlib depends on python3-numpy)

DPI = 100
# Floor of the log colour scale and of the error axis (degrees): float32's float rounding.
FLOOR_DEG = 1e-6


def save(fig, path):
    save_png(fig, path, dpi=DPI, bbox_inches="tight")


def error_vs_bits(study, out_dir):
    rows = study["rows"]
    names = []
    for row in rows:
        if row["name"] not in names and row["name"] != "float32":
            names.append(row["name"])
    cmap = plt.get_cmap("tab20")
    fig, axes = plt.subplots(1, 2, figsize=(15, 6.5), sharey=True)
    for ax, dataset, title in ((axes[0], "sphere", "uniform sphere"),
                               (axes[1], "visible-60", "visible normals, 60° FOV (16:9)")):
        for index, name in enumerate(names):
            points = sorted((r["bits"], r["mean_deg"], r["max_deg"]) for r in rows
                            if r["name"] == name and r["dataset"] == dataset)
            if not points:
                continue
            bits = [p[0] for p in points]
            mean = [max(p[1], FLOOR_DEG) for p in points]
            worst = [max(p[2], FLOOR_DEG) for p in points]
            colour = cmap(index % 20)
            ax.plot(bits, mean, "-o", color=colour, label=f"{name} mean")
            ax.plot(bits, worst, "--x", color=colour, label=f"{name} max")
        ax.set_yscale("log")
        ax.set_xlabel("total bits per normal")
        ax.set_title(f"{title} ({study['config']['directions']:,} samples)")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xticks([16, 20, 24, 30, 32, 48])
    axes[0].set_ylabel("angular error (degrees)")
    axes[1].legend(loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=8, ncol=1)
    # float32 (96 bits, ~1e-6 degrees of float rounding) would squash both axes.
    fig.suptitle("Normal encodings: angular error against bits (solid = mean, dashed = max); "
                 "float32 (96 bits) not shown")
    for ax in axes:
        ax.set_xlim(14, 50)
    save(fig, os.path.join(out_dir, "error_vs_bits.png"))


def error_maps(study, out_dir):
    for entry in study["maps"]:
        path = os.path.join(out_dir, entry["data"])
        width, height = entry["width"], entry["height"]
        grid = np.fromfile(path, dtype="<f4")
        if grid.size != width * height:
            raise ValueError(f"{path}: {grid.size} values, expected {width} x {height}")
        grid = np.maximum(grid.reshape(height, width), FLOOR_DEG)
        fig, ax = plt.subplots(figsize=(10, 5.4))
        image = ax.imshow(grid, extent=(-180, 180, -90, 90), aspect="auto", cmap="magma",
                          norm=LogNorm(vmin=max(FLOOR_DEG, float(grid.min())),
                                       vmax=max(float(grid.max()), 2 * FLOOR_DEG)),
                          interpolation="nearest")
        ax.set_xlabel("azimuth atan2(y, x) (degrees)")
        ax.set_ylabel("elevation asin(z) (degrees); +90 = +Z, facing the camera")
        ax.set_xticks(range(-180, 181, 45))
        ax.set_yticks(range(-90, 91, 30))
        ax.set_title(f"{entry['codec']}: max angular error per cell "
                     f"({entry['samples_per_cell']} samples), max {entry['max_deg']:.3g}°")
        fig.colorbar(image, ax=ax, label="angular error (degrees, log scale)")
        save(fig, os.path.join(out_dir, entry["png"]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True, help="the study's output folder (has normals.json)")
    args = parser.parse_args()
    try:
        with open(os.path.join(args.out, "normals.json"), encoding="utf-8") as file:
            study = json.load(file)
        error_vs_bits(study, args.out)
        error_maps(study, args.out)
    except (OSError, ValueError, KeyError) as error:
        print(f"normals.py: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
