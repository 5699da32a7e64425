#!/bin/bash
# Submits a sharded sweep to Slurm: a job array of SHARDS tasks (slurm-sweep.sbatch, task I runs
# shard I/SHARDS into OUT_DIR/shard-I) and a merge job that starts when every task has ended
# (afterany: also when some failed, so their errors are in the merged table) and runs
# `testbed merge OUT_DIR/shard-* --out OUT_DIR/all && testbed report OUT_DIR/all`.
#
#   experiments/cluster/slurm-submit.sh SWEEP_FILE OUT_DIR SHARDS [SBATCH_OPTION...] [-- SWEEP_OPTION...]
#
# SBATCH_OPTIONs go to both sbatch calls (e.g. --partition=p --cpus-per-task=8 --time=02:00:00);
# SWEEP_OPTIONs to every `testbed sweep` (e.g. --quick). TESTBED names the binary (default
# build/bin/testbed). Run it from the folder the jobs should start in (their slurm-*.out land
# there); OUT_DIR must be on a file system every node sees. Prints "ARRAY_JOB_ID MERGE_JOB_ID".
# Tested on a one-node Slurm by tests/experiments/sweep/cluster_slurm_test.sh.
set -euo pipefail
if (($# < 3)); then
    echo "usage: $0 SWEEP_FILE OUT_DIR SHARDS [SBATCH_OPTION...] [-- SWEEP_OPTION...]" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
sweep=$(realpath "$1")
out=$(realpath -m "$2")
shards=$3
shift 3
sbatch_options=()
while (($#)) && [ "$1" != -- ]; do
    sbatch_options+=("$1")
    shift
done
if (($#)); then shift; fi # the --
TESTBED=$(realpath "${TESTBED:-build/bin/testbed}")
SWEEP=$sweep OUT=$out SWEEP_OPTIONS="$*"
export TESTBED SWEEP OUT SWEEP_OPTIONS
mkdir -p "$out"

array=$(sbatch --parsable --array="1-$shards" "${sbatch_options[@]}" "$here/slurm-sweep.sbatch")
array=${array%%;*} # "id;cluster" on multi-cluster set-ups
merge_command="$(printf '%q' "$TESTBED") merge $(printf '%q' "$out")/shard-* --out $(printf '%q' "$out/all") && $(printf '%q' "$TESTBED") report $(printf '%q' "$out/all")"
merge=$(sbatch --parsable --job-name=testbed-merge --dependency="afterany:$array" \
    "${sbatch_options[@]}" --wrap "$merge_command")
echo "$array ${merge%%;*}"
