#!/usr/bin/env bash
# The Slurm test: a real single-node Slurm cluster (controller and node on this machine,
# from Debian's slurmctld, slurmd, slurm-client and munge packages) renders a scene as a
# 4-part job array followed by a dependent merge; the merged image must be the
# single-process render's with the same settings, `--parts 4` (their digests, of every
# pixel's f64 bits, must agree).
#
#   bash examples/slurm/test.sh            # from the repository's root
#
# Skipped, with a message and exit 0, where Slurm cannot run (its programs missing and no
# root to install them). It stops only the daemons it started, by their process ids, and
# removes its folder. Every wait is bounded (SLURM_TEST_TIMEOUT seconds in all, default 300).
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
limit=${SLURM_TEST_TIMEOUT:-300}
start=$SECONDS

skip() {
  echo "slurm test: SKIPPED: $*"
  exit 0
}

need=(slurmctld slurmd munged sbatch squeue sinfo)
missing=()
for c in "${need[@]}"; do
  command -v "$c" >/dev/null 2>&1 || [ -x "/usr/sbin/$c" ] || missing+=("$c")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "slurm test: installing slurmctld slurmd slurm-client munge (missing: ${missing[*]})"
    install() { DEBIAN_FRONTEND=noninteractive timeout 300 apt-get install -y -q slurmctld slurmd slurm-client munge >/dev/null 2>&1; }
    install || { timeout 300 apt-get update -q >/dev/null 2>&1 && install; } ||
      skip "could not install Slurm from the package manager (missing: ${missing[*]})"
  else
    skip "Slurm is not installed (missing: ${missing[*]}) and this user cannot install it"
  fi
fi
export PATH="$PATH:/usr/sbin"
[ "$(id -u)" = 0 ] || skip "a single-node Slurm runs its daemons as root here (SlurmUser=root); run as root"

cargo build --release -q -p cov-cli
export COVTRACE="$root/target/release/covtrace"

dir=$(mktemp -d /tmp/covtrace-slurm.XXXXXX)
pids=()
cleanup() {
  local p
  for p in "${pids[@]}"; do
    kill "$p" 2>/dev/null || true
  done
  for p in "${pids[@]}"; do
    for _ in $(seq 50); do
      kill -0 "$p" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "$p" 2>/dev/null || true
  done
  rm -rf "$dir"
}
trap cleanup EXIT

fail() {
  echo "slurm test: FAILED: $*"
  for f in "$dir"/slurmctld.log "$dir"/slurmd.log "$dir"/work/*.log; do
    [ -f "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }
  done
  exit 1
}

left() { echo $((limit - (SECONDS - start))); }

# Waits until `$1` succeeds, within the time left.
wait_for() {
  local what=$1
  shift
  while ! "$@" >/dev/null 2>&1; do
    [ "$(left)" -gt 0 ] || fail "timed out waiting for $what"
    sleep 0.5
  done
}

# Munge, with its own key, socket and files (the system's munge, if any, is not touched).
mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/work"
chmod 700 "$dir/munge"
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$dir/munge/munge.key"
sock="$dir/munge/munge.socket"
munged --foreground --force --key-file="$dir/munge/munge.key" --socket="$sock" \
  --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
  --seed-file="$dir/munge/munged.seed" >/dev/null 2>&1 &
pids+=($!)
wait_for "munged's socket" test -S "$sock"

# A free pair of ports for the controller and the node.
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])' 2>/dev/null || echo 16817)
host=$(hostname -s)
cpus=$(nproc)
cat >"$dir/slurm.conf" <<CONF
ClusterName=covtrace-test
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$sock
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
slurmctld -D -c -f "$SLURM_CONF" >/dev/null 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >/dev/null 2>&1 &
pids+=($!)
node_idle() { sinfo -h -N -o '%T' | grep -qE '^(idle|mixed)'; }
wait_for "the node to be idle" node_idle
echo "slurm test: a single-node cluster is up ($host, $cpus CPUs) after $((SECONDS - start)) s"

# The render: 4 parts and a merge, through Slurm; then the same in one process.
scene="$root/examples/scenes/chess.ron"
opts=(--size 96x160 --spp 8 --seed 3)
cd "$dir/work"
jobs=$(bash "$root/examples/slurm/submit.sh" 4 "$scene" "$dir/work/merged.exr" "${opts[@]}") || fail "sbatch refused the jobs"
echo "$jobs" | sed 's/^/slurm test: /'
merge_id=$(echo "$jobs" | sed -n 's/^merge: job \([0-9]*\).*/\1/p')
in_queue() { [ -n "$(squeue -h -j "$merge_id" 2>/dev/null)" ]; }
while in_queue; do
  [ "$(left)" -gt 0 ] || fail "timed out waiting for the merge job $merge_id"
  sleep 1
done
log=$(ls "$dir"/work/covtrace-merge-*.log 2>/dev/null | head -n 1)
[ -n "$log" ] || fail "the merge job left no log"
merged=$(sed -n 's/^image digest: //p' "$log")
[ -n "$merged" ] || fail "the merge printed no image digest: $(cat "$log")"
single=$("$COVTRACE" render "$scene" --parts 4 "${opts[@]}" -o "$dir/work/single.exr" 2>/dev/null | sed -n 's/^image digest: //p')
grep '^  part' "$log" | sed 's/^ */slurm test: /'
if [ "$merged" != "$single" ]; then
  fail "the merged image ($merged) is not the single-process render ($single)"
fi
echo "slurm test: passed in $((SECONDS - start)) s: the merged image is the single-process render (digest $merged)"
