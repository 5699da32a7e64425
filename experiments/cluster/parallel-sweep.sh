#!/bin/bash
# Runs a sweep as SHARDS shards with GNU parallel, then merges them into OUT_DIR/all:
#
#   experiments/cluster/parallel-sweep.sh SWEEP_FILE OUT_DIR SHARDS [SWEEP_OPTION...]
#
# Shard I runs `testbed sweep SWEEP_FILE --out OUT_DIR/shard-I --shard I/SHARDS --threads 1`
# (plus the SWEEP_OPTIONs, e.g. --quick), JOBS of them at once (default 2). PARALLEL_OPTIONS go to
# parallel, e.g. "-S host1,host2 --wd /shared/project" to run the shards on other machines over
# ssh (OUT_DIR then on a shared file system). TESTBED names the binary (default
# build/bin/testbed). A failed shard does not stop the others nor the merge (its failed jobs are
# in the merged table with their errors); the exit status is then parallel's (the number of
# failed shards). Tested by tests/experiments/sweep/cluster_parallel_test.sh.
set -euo pipefail
if (($# < 3)); then
    echo "usage: $0 SWEEP_FILE OUT_DIR SHARDS [SWEEP_OPTION...]" >&2
    exit 2
fi
sweep=$1
out=$2
shards=$3
shift 3
testbed=${TESTBED:-build/bin/testbed}
status=0
# shellcheck disable=SC2086 # PARALLEL_OPTIONS is a list of options
parallel --will-cite --quote -j "${JOBS:-2}" --halt never ${PARALLEL_OPTIONS:-} \
    "$testbed" sweep "$sweep" "$@" --out "$out/shard-{}" --shard "{}/$shards" --threads 1 \
    ::: $(seq 1 "$shards") || status=$?
"$testbed" merge "$out"/shard-* --out "$out/all"
exit "$status"
