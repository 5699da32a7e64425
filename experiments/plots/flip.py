#!/usr/bin/env python3
"""HDR-FLIP (NVIDIA's perceptual image difference, written ꟻLIP) of a render against its
reference, computed by NVIDIA's official implementation: the Python package flip-evaluator
(`import flip_evaluator`), which ./run.sh installs into the project's virtual environment .venv/.
This script only moves data in and out of that package; it computes nothing itself.

Called by the C++ commands (experiments/compare/FlipMetric.h), not by hand (but it can be):

  flip.py check --out JSON
      Writes {"version": "<flip-evaluator's version>"} to JSON and exits 0 when the package
      imports. Exit 4 when flip_evaluator is not installed in this Python, 3 when numpy is not,
      with the reason on stderr.

  flip.py evaluate --reference REF --test TEST --width W --height H --map MAP --out JSON
      REF, TEST: W*H*3 little-endian float32, interleaved linear R,G,B, row 0 at the top (what
      FlipMetric writes). Runs flip_evaluator.evaluate(reference, test, "HDR", applyMagma=False)
      with the package's default parameters, and writes MAP (W*H little-endian float32, the
      per-pixel FLIP error in [0, 1], row 0 at the top) and JSON {"mean", "parameters",
      "version"}: the mean FLIP error and the parameters the package used (pixels per degree,
      tone mapper, start and stop exposure, number of exposures).

Why HDR-FLIP: the testbed's images are linear, scene-referred radiance, not display values in
[0, 1]. HDR-FLIP (Andersson et al., Eurographics 2021) tone-maps both images at a range of
exposures computed from the reference and keeps, per pixel, the largest LDR-FLIP error over
them; LDR-FLIP would need sRGB-encoded values in [0, 1]. Both images must be non-negative and
finite: FlipMetric checks that before calling (negative radiance is clamped to 0 here, as the
package requires; the testbed's stages never produce it).

Exit status: 0 on success, 2 on bad arguments or input (message on stderr), 3 numpy missing, 4
flip_evaluator missing, 5 when the package failed.
"""
import argparse
import json
import os
import sys


def fail(status, message):
    print("flip.py: %s" % message, file=sys.stderr)
    sys.exit(status)


def import_flip():
    try:
        import numpy  # noqa: F401 (flip_evaluator returns numpy arrays)
    except ImportError:
        fail(3, "numpy is not installed in %s (Debian: python3-numpy; a venv made with "
                "--system-site-packages sees it)" % sys.executable)
    try:
        import flip_evaluator
    except ImportError as error:
        fail(4, "flip_evaluator is not installed in %s (%s); ./run.sh installs the package "
                "flip-evaluator into .venv/" % (sys.executable, error))
    return flip_evaluator


def package_version():
    from importlib import metadata
    for name in ("flip-evaluator", "flip_evaluator"):
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return "unknown"


def write_atomically(path, data, binary):
    directory, name = os.path.split(path)
    temp = os.path.join(directory, ".%s.tmp-%d" % (name, os.getpid()))
    with open(temp, "wb" if binary else "w") as f:
        f.write(data)
    os.replace(temp, path)


def read_rgb(path, width, height):
    import numpy as np
    data = np.fromfile(path, dtype="<f4")
    if data.size != width * height * 3:
        fail(2, "%s holds %d values, expected %d x %d x 3" % (path, data.size, width, height))
    if not np.all(np.isfinite(data)):
        fail(2, "%s holds non-finite values" % path)
    return np.ascontiguousarray(np.maximum(data, 0.0).reshape(height, width, 3), dtype=np.float32)


def evaluate(args):
    import numpy as np
    flip = import_flip()
    reference = read_rgb(args.reference, args.width, args.height)
    test = read_rgb(args.test, args.width, args.height)
    try:
        error_map, mean, parameters = flip.evaluate(reference, test, "HDR", applyMagma=False)
    except SystemExit as error:  # the package exits on inputs it refuses
        fail(5, "flip_evaluator.evaluate refused the input (exit %s)" % error.code)
    except Exception as error:  # noqa: BLE001 (any failure of the package is reported)
        fail(5, "flip_evaluator.evaluate failed: %s" % error)
    error_map = np.asarray(error_map, dtype="<f4").reshape(args.height, args.width)
    write_atomically(args.map, error_map.tobytes(), True)
    clean = {key: (value if isinstance(value, (int, float, str)) else str(value))
             for key, value in dict(parameters).items()}
    write_atomically(args.out, json.dumps({"mean": float(mean), "parameters": clean,
                                           "version": package_version()}) + "\n", False)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    check = commands.add_parser("check")
    check.add_argument("--out", required=True)
    run = commands.add_parser("evaluate")
    run.add_argument("--reference", required=True)
    run.add_argument("--test", required=True)
    run.add_argument("--width", type=int, required=True)
    run.add_argument("--height", type=int, required=True)
    run.add_argument("--map", required=True)
    run.add_argument("--out", required=True)
    args = parser.parse_args()
    try:
        if args.command == "check":
            import_flip()
            write_atomically(args.out, json.dumps({"version": package_version()}) + "\n", False)
        else:
            if args.width <= 0 or args.height <= 0:
                fail(2, "image size %dx%d is not positive" % (args.width, args.height))
            evaluate(args)
    except OSError as error:
        fail(2, str(error))
    return 0


if __name__ == "__main__":
    sys.exit(main())
