#!/usr/bin/env bash
# The README's Slurm recipe on a real, one-node Slurm: starts a private munged and a slurmctld
# and slurmd of Debian's slurm-wlm (own config, ports, state and sockets under a temporary
# folder; nothing of the machine's /etc/slurm or /run/munge is used or changed), submits
# tests/experiments/fixtures/cluster-smoke.json with experiments/cluster/slurm-submit.sh (the job
# array of shards and the dependent merge + report job, exactly as experiments/README.md tells
# users), waits, and checks that the merged table equals a local unsharded run of the same sweep
# in every column but the timings (compare_sweep_results.py) and that the report was written.
# Registered with ctest by tests/CMakeLists.txt; by hand:
#   tests/experiments/sweep/cluster_slurm_test.sh build/bin/testbed /tmp/cluster-slurm-test
#
# Skips (exit 77, ctest's SKIP_RETURN_CODE) with the reason when it cannot run a cluster: not
# root (munged must run as the munge user and slurmd as root), slurm-wlm or munge not installed
# (./run.sh test installs them), or a daemon that does not start (its log is printed). Every wait
# has a deadline and the daemons run in the foreground as children of this script, stopped by the
# exit trap (and reached by ctest's kill of the process tree on its timeout), so it cannot hang.
set -euo pipefail

testbed=${1:?usage: $0 TESTBED_BINARY WORK_DIR}
work=${2:?usage: $0 TESTBED_BINARY WORK_DIR}
here=$(cd "$(dirname "$0")/.." && pwd) # tests/experiments
source_root=$(cd "$here/../.." && pwd)
sweep_file=$here/fixtures/cluster-smoke.json
shards=3
jobs=8 # every view of spheres (4) x 2 stages
testbed=$(realpath "$testbed")

skip() { echo "cluster_slurm_test: SKIP: $*"; exit 77; }
fail() { echo "cluster_slurm_test: FAIL: $*" >&2; exit 1; }

[ "$(id -u)" = 0 ] || skip "needs root (munged runs as the munge user, slurmd as root)"
for tool in munged munge slurmctld slurmd sbatch squeue scontrol sinfo setpriv python3; do
    command -v "$tool" > /dev/null || [ -x "/usr/sbin/$tool" ] ||
        skip "$tool not found (install Debian's slurm-wlm and munge; ./run.sh test does)"
done
id munge > /dev/null 2>&1 || skip "no munge user (install Debian's munge)"
PATH=$PATH:/usr/sbin

rm -rf "$work"
mkdir -p "$work"
work=$(realpath "$work")
# munged wants its socket folder reachable by everyone and its key private to the munge user.
munge_dir=$(mktemp -d /tmp/testbed-munge.XXXXXX)
chmod 755 "$munge_dir"
mkdir -m 755 "$munge_dir/socket"
mkdir -m 700 "$munge_dir/private"
head -c 1024 /dev/urandom > "$munge_dir/private/munge.key"
chmod 600 "$munge_dir/private/munge.key"
chown -R munge:munge "$munge_dir"
socket=$munge_dir/socket/munge.socket

pids=()
cleanup() {
    set +e
    if [ -f "$work/slurm.conf" ]; then
        # Jobs still running (a failed wait) are cancelled first: their steps outlive slurmd.
        SLURM_CONF=$work/slurm.conf timeout 10 scancel --full -u "$(id -un)" > /dev/null 2>&1
        SLURM_CONF=$work/slurm.conf timeout 10 scontrol shutdown > /dev/null 2>&1
    fi
    for pid in "${pids[@]}"; do
        for _ in 1 2 3 4 5 6 7 8 9 10; do kill -0 "$pid" 2> /dev/null || break; sleep 0.5; done
        kill -0 "$pid" 2> /dev/null && kill -TERM "$pid" 2> /dev/null
    done
    sleep 0.5
    for pid in "${pids[@]}"; do kill -KILL "$pid" 2> /dev/null; done
    rm -rf "$munge_dir"
}
trap cleanup EXIT

# Waits up to $1 seconds for the command after it to succeed.
wait_for() {
    local deadline=$(($(date +%s) + $1))
    shift
    until "$@" > /dev/null 2>&1; do
        (($(date +%s) < deadline)) || return 1
        sleep 0.5
    done
}

setpriv --reuid=munge --regid=munge --init-groups -- munged --foreground \
    --socket="$socket" --key-file="$munge_dir/private/munge.key" \
    --pid-file="$munge_dir/private/munged.pid" --seed-file="$munge_dir/private/munged.seed" \
    --log-file="$munge_dir/private/munged.log" > "$work/munged.out" 2>&1 &
pids+=($!)
if ! wait_for 10 bash -c "munge -S '$socket' -n | unmunge -S '$socket'"; then
    cat "$work/munged.out" "$munge_dir/private/munged.log" 2> /dev/null | tail -20
    skip "munged did not start (log above)"
fi

# Two free TCP ports for slurmctld and slurmd, so that runs on one machine do not collide.
read -r ctld_port slurmd_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$work/state" "$work/spool" "$work/jobs"
cat > "$work/slurm.conf" << CONF
ClusterName=testbed-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=100 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=10 State=UP
CONF
export SLURM_CONF=$work/slurm.conf

slurmctld -D -i -f "$SLURM_CONF" > "$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" > "$work/slurmd.out" 2>&1 &
pids+=($!)
node_idle() { [ "$(timeout 5 sinfo -h -n "$host" -o %T)" = idle ]; }
if ! wait_for 30 node_idle; then
    tail -n 15 "$work"/slurmctld.out "$work"/slurmd.out "$work"/slurmctld.log "$work"/slurmd.log 2> /dev/null
    skip "the one-node Slurm did not come up (logs above, in $work)"
fi
echo "cluster_slurm_test: one-node Slurm up (ports $ctld_port, $slurmd_port; $cpus CPUs)"

# The recipe, from the folder the jobs start in (their slurm-*.out land there).
start=$(date +%s)
ids=$(cd "$work/jobs" && TESTBED=$testbed timeout 30 \
    "$source_root/experiments/cluster/slurm-submit.sh" "$sweep_file" "$work/out" "$shards" \
    --cpus-per-task=1 --time=5) || fail "slurm-submit.sh failed"
read -r array_id merge_id <<< "$ids"
echo "cluster_slurm_test: submitted array $array_id ($shards tasks) and merge job $merge_id"
job_gone() { ! timeout 5 squeue -h -j "$1" 2> /dev/null | grep -q .; }
if ! wait_for 200 job_gone "$merge_id"; then
    timeout 5 squeue -a
    tail -n 5 "$work"/jobs/slurm-*.out 2> /dev/null
    fail "the merge job $merge_id did not finish within 200 s"
fi
echo "cluster_slurm_test: array and merge finished in $(($(date +%s) - start)) s"
state=$(timeout 5 scontrol show job "$merge_id" | grep -o 'JobState=[A-Z_]*' || true)
for task in $(seq 1 "$shards"); do
    task_state=$(timeout 5 scontrol show job "${array_id}_$task" | grep -o 'JobState=[A-Z_]*' || true)
    [ "$task_state" = JobState=COMPLETED ] ||
        { tail -n 20 "$work"/jobs/slurm-*.out >&2; fail "array task $task: $task_state"; }
done
[ "$state" = JobState=COMPLETED ] ||
    { tail -n 20 "$work"/jobs/slurm-*.out >&2; fail "merge job $merge_id: $state"; }
for task in $(seq 1 "$shards"); do
    [ -f "$work/out/shard-$task/results.json" ] || fail "shard $task wrote no results.json"
done
[ -f "$work/out/all/report.html" ] || fail "the merge job wrote no report (out/all/report.html)"

# The same sweep on this machine, unsharded, with the tasks' --threads.
timeout 100 "$testbed" sweep "$sweep_file" --out "$work/local" --threads 1 > "$work/local.log" 2>&1 ||
    { tail -n 20 "$work/local.log" >&2; fail "the local sweep failed"; }
python3 "$here/sweep/compare_sweep_results.py" "$work/out/all/results.json" \
    "$work/local/results.json" "$jobs" || fail "the merged table differs from the local run's"
echo "cluster_slurm_test: PASS"
