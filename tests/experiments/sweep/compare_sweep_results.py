#!/usr/bin/env python3
"""Checks that a merged sweep table equals the table of a local run of the same sweep, up to
the timings: the same job ids, and for every job the same value in every column except the
time_* columns (status, error, settings, light counts, error metrics, bytes per pixel...).

    compare_sweep_results.py MERGED/results.json LOCAL/results.json EXPECTED_JOB_COUNT

Used by tests/experiments/sweep/cluster_slurm_test.sh and cluster_parallel_test.sh. Exit 0 when equal,
1 (with every difference listed) otherwise."""
import json
import sys

merged_path, local_path, expected = sys.argv[1], sys.argv[2], int(sys.argv[3])
merged, local = json.load(open(merged_path)), json.load(open(local_path))
problems = []
if merged.get("columns") != local.get("columns"):
    problems.append("columns differ:\n  merged %s\n  local  %s" % (merged.get("columns"), local.get("columns")))
rows = {}
for name, table in (("merged", merged), ("local", local)):
    rows[name] = {job["job_id"]: job for job in table["jobs"]}
    if len(rows[name]) != len(table["jobs"]):
        problems.append("%s has a job id twice" % name)
if set(rows["merged"]) != set(rows["local"]):
    problems.append("job ids differ: only merged %s, only local %s" % (
        sorted(set(rows["merged"]) - set(rows["local"])), sorted(set(rows["local"]) - set(rows["merged"]))))
if len(rows["local"]) != expected:
    problems.append("the local run has %d jobs, expected %d" % (len(rows["local"]), expected))
compared = set()
for job_id in sorted(set(rows["merged"]) & set(rows["local"])):
    a, b = rows["merged"][job_id], rows["local"][job_id]
    for column in sorted(set(a) | set(b)):
        if column.startswith("time_") or column == "peak_rss_bytes":
            continue  # measured: differ from run to run
        compared.add(column)
        if a.get(column) != b.get(column):
            problems.append("job %s column %s: merged %r, local %r" % (job_id, column, a.get(column), b.get(column)))
not_ok = [j for j, job in rows["local"].items() if job.get("status") != "ok"]
if not_ok:
    problems.append("local jobs not ok: %s" % {j: rows["local"][j].get("error") for j in not_ok})
for wanted in ("status", "error", "light_evaluations", "oracle_light_evaluations", "relative_rmse"):
    if wanted not in compared:
        problems.append("column %s is missing, so it was not compared" % wanted)
if problems:
    print("\n".join(problems), file=sys.stderr)
    sys.exit(1)
print("  %d jobs equal in %d columns (all but time_*): %s" % (len(rows["local"]), len(compared), ", ".join(sorted(compared))))
