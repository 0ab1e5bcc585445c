#!/usr/bin/env bash
# Runs a small study end to end under a real Slurm: a one-node cluster on this
# machine (Debian's slurm-wlm + munge), `inksim slurm` → sbatch job array →
# wait → `inksim merge` → check the merged result.
#
#   sudo scripts/slurm_demo.sh
#
# Root is needed to install the packages (if missing) and to start munge.
# Environment (all optional):
#   STUDY   sweep file            (default configs/study-tiny.toml)
#   PROFILE profile to run        (default: the study's default)
#   SHARDS  array tasks           (default 2)
#   WORK    working folder        (default a fresh /tmp/inksim-slurm-demo.XXXXXX)
#   INKSIM  inksim executable     (default target/release/inksim, built if missing)
# The Slurm configuration, state and logs live in $WORK/slurm (nothing under
# /etc/slurm is touched); the daemons this script starts are stopped at the
# end; $WORK keeps the results.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
STUDY="$(realpath "${STUDY:-$ROOT/configs/study-tiny.toml}")"
SHARDS="${SHARDS:-2}"
WORK="${WORK:-$(mktemp -d /tmp/inksim-slurm-demo.XXXXXX)}"
INKSIM="${INKSIM:-$ROOT/target/release/inksim}"
PROFILE_ARGS=()
[ -n "${PROFILE:-}" ] && PROFILE_ARGS=(--profile "$PROFILE")
say() { echo "[slurm_demo] $*"; }
die() { echo "[slurm_demo] FAILED: $*" >&2; exit 1; }

# 1. Packages.
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    [ "$(id -u)" = 0 ] || die "slurm-wlm/munge missing and not root: cannot install them"
    say "installing slurm-wlm and munge with apt-get"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq slurm-wlm munge >/dev/null
fi
say "$(slurmctld -V)"

# 2. inksim.
if [ ! -x "$INKSIM" ]; then
    say "building inksim"
    (cd "$ROOT" && cargo build --release)
fi
INKSIM="$(realpath "$INKSIM")"

# 3. Daemons: stopped on exit if this script started them.
SLURM_DIR="$WORK/slurm"
mkdir -p "$SLURM_DIR/state" "$SLURM_DIR/spool"
STARTED_MUNGE=""
cleanup() {
    local pids=()
    for f in "$SLURM_DIR/slurmd.pid" "$SLURM_DIR/slurmctld.pid"; do
        [ -s "$f" ] && pids+=("$(cat "$f")")
    done
    if [ -n "$STARTED_MUNGE" ] && [ -s /run/munge/munged.pid ]; then
        pids+=("$(cat /run/munge/munged.pid)")
    fi
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    # Wait (up to 15 s each) until they are gone, so a rerun finds the ports free.
    for p in "${pids[@]}"; do
        for _ in $(seq 30); do kill -0 "$p" 2>/dev/null || break; sleep 0.5; done
    done
}
trap cleanup EXIT

if ! (munge -n | unmunge) >/dev/null 2>&1; then
    say "starting munged"
    mkdir -p /etc/munge /var/lib/munge /var/log/munge /run/munge
    if [ ! -s /etc/munge/munge.key ]; then
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
    chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge /run/munge
    chmod 0700 /etc/munge
    chmod 0400 /etc/munge/munge.key
    runuser -u munge -- /usr/sbin/munged
    STARTED_MUNGE=1
    (munge -n | unmunge) >/dev/null || die "munge does not work"
fi

HOST="$(hostname -s)"
NCPU="$(nproc)"
MEM_MB=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))
export SLURM_CONF="$SLURM_DIR/slurm.conf"
cat > "$SLURM_CONF" <<EOF
ClusterName=inksimdemo
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$SLURM_DIR/state
SlurmdSpoolDir=$SLURM_DIR/spool
SlurmctldPidFile=$SLURM_DIR/slurmctld.pid
SlurmdPidFile=$SLURM_DIR/slurmd.pid
SlurmctldLogFile=$SLURM_DIR/slurmctld.log
SlurmdLogFile=$SLURM_DIR/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$NCPU RealMemory=$MEM_MB State=UNKNOWN
PartitionName=demo Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
say "one-node cluster: $HOST, $NCPU CPUs, $MEM_MB MB (config $SLURM_CONF)"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
    state="$(sinfo -h -n "$HOST" -o %t 2>/dev/null || true)"
    case "$state" in
        idle*|mix*|alloc*) break ;;
        down*|drain*) scontrol update nodename="$HOST" state=resume 2>/dev/null || true ;;
    esac
    sleep 1
done
case "$state" in idle*|mix*|alloc*) ;; *) die "node not up (state '$state'); see $SLURM_DIR/*.log" ;; esac
say "node $HOST is $state"

# 4. The study: plan, script, submit, wait.
cd "$WORK"
"$INKSIM" plan "$STUDY" "${PROFILE_ARGS[@]}" | tail -n 3
out="$("$INKSIM" slurm "$STUDY" "${PROFILE_ARGS[@]}" --shards "$SHARDS" --cpus 1)"
echo "$out"
SCRIPT="$(echo "$out" | sed -n 's/^wrote //p')"
[ -f "$SCRIPT" ] || die "no sbatch script"
JOB="$(sbatch --parsable "$SCRIPT")"
say "submitted job array $JOB ($SHARDS tasks)"
for _ in $(seq 600); do
    [ -z "$(squeue -h -j "$JOB" 2>/dev/null)" ] && break
    sleep 1
done
[ -z "$(squeue -h -j "$JOB" 2>/dev/null)" ] || die "job $JOB still queued after 10 min"
say "job array $JOB finished; task logs:"
for f in "$(dirname "$SCRIPT")"/slurm/*"_$JOB"_*.out "$(dirname "$SCRIPT")"/slurm/*-"$JOB"_*.out; do
    [ -f "$f" ] || continue
    echo "--- $f"
    grep -E "^study run:|^FAILED|^all .* finished|shard" "$f" || true
done

# 5. Merge and check.
"$INKSIM" merge "$STUDY" "${PROFILE_ARGS[@]}" | tee "$WORK/merge.out"
SUMMARY="$(sed -n 's/^summary: //p' "$WORK/merge.out")"
[ -s "$SUMMARY" ] || die "no summary file"
PAGE="$(dirname "$SUMMARY")/summary.md"
VARIANTS="$(grep -c '^| [0-9]' "$PAGE")"
PLAN="$("$INKSIM" plan "$STUDY" "${PROFILE_ARGS[@]}")"
EXPECTED="$(echo "$PLAN" | sed -n '1s/.*: \([0-9]*\) variants;.*/\1/p')"
say "summary page lists $VARIANTS of $EXPECTED variants; grids: $(ls "$(dirname "$SUMMARY")/grids" | tr '\n' ' ')"
[ "$VARIANTS" = "$EXPECTED" ] || die "summary lists $VARIANTS variants, the study has $EXPECTED"
say "OK: the study ran as a Slurm job array and merged ($SUMMARY)"
