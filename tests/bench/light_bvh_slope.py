#!/usr/bin/env python3
"""Fits the log-log slope of light_bvh_bench's times against the light count.

Reads the JSON of
  testbed_bench --benchmark_filter=lightBvh --benchmark_out=bvh.json --benchmark_out_format=json
and prints, per row and thread count, the median (and min) time at each light count and the
least-squares slope of log(median time) against log(light count) (1 = linear; N log N over
10^3..10^6 fits about 1.1; the slope between the two largest counts beside it).
"""
import json
import math
import sys
from collections import defaultdict

ROWS = ["build", "clusters walk", "clusters bvh", "tiles loop", "tiles bvh", "tiles loop hier",
        "tiles bvh hier", "clustered:assign=walk", "clustered:assign=bvh"]


def slope(points):
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def main(path):
    with open(path) as f:
        data = json.load(f)
    times = defaultdict(dict)  # (row, threads) -> n -> {stat: ms}
    for b in data["benchmarks"]:
        if b.get("run_type") != "aggregate" or b["aggregate_name"] not in ("median", "min"):
            continue
        n, row, threads = (int(v) for v in b["run_name"].split("/")[1:4])
        times[(row, threads)].setdefault(n, {})[b["aggregate_name"]] = b["real_time"]
    for (row, threads), by_n in sorted(times.items()):
        counts = sorted(by_n)
        cells = "  ".join(f"{n:>7}: {by_n[n]['median']:9.3f} ({by_n[n]['min']:9.3f})"
                          for n in counts)
        fit = slope([(n, by_n[n]["median"]) for n in counts]) if len(counts) > 1 else float("nan")
        last = (slope([(n, by_n[n]["median"]) for n in counts[-2:]])
                if len(counts) > 1 else float("nan"))
        print(f"{ROWS[row]:<22} threads={threads}  {cells}  slope {fit:.2f} (last {last:.2f})")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bvh.json")
