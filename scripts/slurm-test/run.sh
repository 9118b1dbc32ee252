#!/usr/bin/env bash
# `make slurm-test`: a real one-node SLURM cluster on localhost runs a sharded sweep as a job
# array, a dependent job merges the parts, and the result must equal a local run bit for bit.
#
# Installs Debian's slurm-wlm and munge when missing (needs root), starts munged, slurmctld and
# slurmd from a private config in a temporary directory, and stops them by their PIDs on exit.
set -euo pipefail
cd "$(dirname "$0")/../.."
WOODPILE=${WOODPILE:-target/release/woodpile}
PIPELINE=scripts/slurm-test/pipeline
STAGE=slurm_sweep
TASKS=4

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "installing slurm-wlm and munge"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

WORK=$(mktemp -d /tmp/woodpile-slurm.XXXXXX)
chmod 755 "$WORK"
PIDS=()
PASSED=0
stop() {
    for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
    if [ "$PASSED" = 1 ]; then rm -rf "$WORK"; else echo "slurm-test: logs kept in $WORK" >&2; fi
}
trap stop EXIT

# munge: a fresh key and socket of our own, so nothing on the machine is touched.
mkdir -p "$WORK/munge"
dd if=/dev/urandom of="$WORK/munge/munge.key" bs=1 count=1024 status=none
chmod 700 "$WORK/munge"; chmod 400 "$WORK/munge/munge.key"
MUNGE_SOCKET="$WORK/munge/munge.socket"
munged --foreground --force --key-file="$WORK/munge/munge.key" --socket="$MUNGE_SOCKET" \
    --pid-file="$WORK/munge/munged.pid" --log-file="$WORK/munge/munged.log" --seed-file="$WORK/munge/seed" 2>>"$WORK/daemons.log" &
PIDS+=($!)

HOST=$(hostname -s)
CPUS=$(nproc)
mkdir -p "$WORK/state" "$WORK/spool"
cat > "$WORK/slurm.conf" <<CONF
ClusterName=woodpile
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCKET
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerParameters=kill_invalid_depend
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$WORK/slurm.conf"

for _ in $(seq 50); do [ -S "$MUNGE_SOCKET" ] && break; sleep 0.1; done
slurmctld -D -f "$SLURM_CONF" 2>>"$WORK/daemons.log" &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" 2>>"$WORK/daemons.log" &
PIDS+=($!)
started=$(date +%s)
until sinfo -h -o %t 2>/dev/null | grep -qE '^(idle|mix|alloc)'; do
    if (( $(date +%s) - started > 60 )); then
        echo "slurm did not come up; logs:" >&2
        tail -n 20 "$WORK"/daemons.log "$WORK"/slurmctld.log "$WORK"/slurmd.log "$WORK"/munge/munged.log >&2 || true
        exit 1
    fi
    sleep 0.5
done
echo "one-node cluster up: $(sinfo -h -o '%P %D %t %c')"

# The reference: the same sweep on this machine, no SLURM.
"$WOODPILE" run "$STAGE" --pipeline "$PIPELINE" --results "$WORK/local"

# The cluster: an array of $TASKS shards, then the merge job after them (afterok), waited for.
"$WOODPILE" slurm "$STAGE" --tasks "$TASKS" --out "$WORK/jobs" --pipeline "$PIPELINE" --results "$WORK/cluster"
timeout 300 bash "$WORK/jobs/$STAGE.submit.sh" --wait
cat "$WORK"/jobs/logs/*.out

parts=$(ls "$WORK/cluster/parts/$STAGE" | wc -l)
if [ "$parts" -ne "$TASKS" ]; then
    echo "expected $TASKS parts, found $parts" >&2
    exit 1
fi
# Bit for bit: zero tolerance.
"$WOODPILE" diff "$WORK/local" "$WORK/cluster"
echo "slurm-test: $TASKS-task array + merge equals the local run"
PASSED=1
