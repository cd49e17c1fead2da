#!/bin/bash
# Smoke test of deploy/slurm/render-array.sbatch on a real Slurm: installs Slurm and
# munge from the distribution's packages (Debian/Ubuntu, as root), starts a one-node
# cluster on localhost (munged, slurmctld, slurmd), submits the array for the 48 frames
# of examples/animation/orbit.scn, waits for it, and checks that every frame exists and
# equals a local render byte for byte. Not part of .ci/run (it needs root and starts
# daemons); the contract it relies on is tested by `cargo test` (tests/scnc/animation.rs).
#
#   sudo bash scripts/slurm-smoke.sh            # from the checkout
#
# The cluster runs only until the script ends; its state is under a temporary
# directory removed at the end (KEEP_STATE=1 keeps both, to read the daemons' logs).
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
FRAMES=48

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "== installing slurm-wlm and munge"
    DEBIAN_FRONTEND=noninteractive apt-get install -y slurm-wlm munge >/dev/null
fi
echo "== $(slurmctld -V)"

cargo build --release --quiet
SCNC=$ROOT/target/release/scnc

STATE=$(mktemp -d /tmp/scnc-slurm.XXXXXX)
CONF=$STATE/slurm.conf
chmod 755 "$STATE"
OUT=$STATE/frames
LOCAL=$STATE/local
mkdir -p "$OUT" "$LOCAL" "$STATE/spool" "$STATE/ctld" "$STATE/log"

cleanup() {
    scancel --user=root >/dev/null 2>&1 || true
    # Stops slurmctld and every slurmd; then anything of this cluster still running.
    scontrol shutdown >/dev/null 2>&1 || true
    sleep 1
    pkill -f "slurm(ctld|d) -f $CONF" 2>/dev/null || true
    [ -f "$STATE/munged.pid" ] && kill "$(cat "$STATE/munged.pid")" 2>/dev/null || true
    rm -rf "$STATE"
}
trap cleanup EXIT
[ -n "${KEEP_STATE:-}" ] && trap - EXIT

echo "== munge"
if [ ! -s /etc/munge/munge.key ]; then
    mkdir -p /etc/munge
    dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null
fi
chown munge:munge /etc/munge/munge.key 2>/dev/null || true
chmod 400 /etc/munge/munge.key
mkdir -p /run/munge /var/log/munge /var/lib/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null || true
if ! munge -n >/dev/null 2>&1; then
    if id munge >/dev/null 2>&1; then
        su -s /bin/sh munge -c "munged --pid-file=$STATE/munged.pid" || munged --force --pid-file="$STATE/munged.pid"
    else
        munged --force --pid-file="$STATE/munged.pid"
    fi
    sleep 1
fi
munge -n | unmunge >/dev/null

echo "== slurm.conf (one node: localhost, $(nproc) CPUs)"
cat >"$CONF" <<EOF
ClusterName=scnc-smoke
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/spool
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=localhost CPUs=$(nproc) State=UNKNOWN
PartitionName=main Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$CONF

slurmctld -f "$CONF"
slurmd -f "$CONF"
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
    sleep 1
done
sinfo

echo "== sbatch deploy/slurm/render-array.sbatch"
started=$(date +%s.%N)
JOB=$(SCNC=$SCNC OUT=$OUT/orbit-####.png sbatch --parsable --chdir="$ROOT" \
    --output="$STATE/log/task-%a.log" deploy/slurm/render-array.sbatch)
echo "job $JOB submitted"
for _ in $(seq 600); do
    [ -z "$(squeue -h -j "$JOB" 2>/dev/null)" ] && break
    sleep 0.5
done
finished=$(date +%s.%N)
if [ -n "$(squeue -h -j "$JOB" 2>/dev/null)" ]; then
    echo "FAIL: the array did not finish in 5 minutes"
    squeue
    exit 1
fi
printf "array finished in %.1f s (submission to the last task's end)\n" "$(echo "$finished - $started" | bc)"
for log in "$STATE"/log/task-*.log; do
    echo "-- $(basename "$log"): $(grep -c '^rendered' "$log") frames rendered"
    grep -E '^error' "$log" || true
done

echo "== checking the frames against a local render"
"$SCNC" render examples/animation/orbit.scn -o "$LOCAL/orbit-####.png" 2>/dev/null
count=$(find "$OUT" -name 'orbit-*.png' | wc -l)
same=0
for f in "$LOCAL"/orbit-*.png; do
    if cmp -s "$f" "$OUT/$(basename "$f")"; then
        same=$((same + 1))
    else
        echo "differs or missing: $(basename "$f")"
    fi
done
echo "frames from the array: $count of $FRAMES; byte-identical to the local render: $same of $FRAMES"
[ "$count" -eq "$FRAMES" ] && [ "$same" -eq "$FRAMES" ] && echo "PASS" || { echo "FAIL"; exit 1; }
