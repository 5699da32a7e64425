#!/usr/bin/env bash
# The README's GNU parallel recipe: runs tests/experiments/fixtures/cluster-smoke.json as three
# shards with experiments/cluster/parallel-sweep.sh (exactly what experiments/README.md tells
# users to run) and checks that the merged table equals a local unsharded run of the same sweep
# in every column but the timings (compare_sweep_results.py). Registered with ctest by
# tests/CMakeLists.txt; by hand:
#   tests/experiments/sweep/cluster_parallel_test.sh build/bin/testbed /tmp/cluster-parallel-test
#
# Skips (exit 77, ctest's SKIP_RETURN_CODE) when GNU parallel is not installed (./run.sh test
# installs Debian's parallel). The recipe runs under `timeout`, so it cannot hang.
set -euo pipefail

testbed=${1:?usage: $0 TESTBED_BINARY WORK_DIR}
work=${2:?usage: $0 TESTBED_BINARY WORK_DIR}
here=$(cd "$(dirname "$0")/.." && pwd) # tests/experiments
source_root=$(cd "$here/../.." && pwd)
sweep_file=$here/fixtures/cluster-smoke.json
shards=3
jobs=8 # every view of spheres (4) x 2 stages

fail() { echo "cluster_parallel_test: FAIL: $*" >&2; exit 1; }
command -v parallel > /dev/null ||
    { echo "cluster_parallel_test: SKIP: GNU parallel not found (install Debian's parallel; ./run.sh test does)"; exit 77; }
parallel --version 2> /dev/null | grep -q 'GNU parallel' ||
    { echo "cluster_parallel_test: SKIP: 'parallel' is not GNU parallel (moreutils'?)"; exit 77; }
command -v python3 > /dev/null || fail "python3 not found"

rm -rf "$work"
mkdir -p "$work"
start=$(date +%s)
TESTBED=$testbed timeout 240 "$source_root/experiments/cluster/parallel-sweep.sh" \
    "$sweep_file" "$work/out" "$shards" > "$work/recipe.log" 2>&1 ||
    { tail -n 30 "$work/recipe.log" >&2; fail "parallel-sweep.sh failed (log: $work/recipe.log)"; }
echo "cluster_parallel_test: $shards shards and the merge took $(($(date +%s) - start)) s"
for shard in $(seq 1 "$shards"); do
    [ -f "$work/out/shard-$shard/results.json" ] || fail "shard $shard wrote no results.json"
done
timeout 120 "$testbed" sweep "$sweep_file" --out "$work/local" --threads 1 > "$work/local.log" 2>&1 ||
    { tail -n 20 "$work/local.log" >&2; fail "the local sweep failed"; }
python3 "$here/sweep/compare_sweep_results.py" "$work/out/all/results.json" \
    "$work/local/results.json" "$jobs" || fail "the merged table differs from the local run's"
echo "cluster_parallel_test: PASS"
