#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A design sweep through a real Slurm: starts munged (generated key) and a single-node
# slurmctld + slurmd (generated slurm.conf) on localhost in a temporary folder, submits
# a small sweep as a job array with scripts/slurm/submit-sweep.sh, waits for the merge
# job, and checks the merged results equal one unsharded run (rows identical apart from
# timings). Everything it starts is stopped and the folder removed on exit.
#   slurm_sweep_test.sh BINOCLE SOURCE_DIR
# Exit 77 (CTest: skipped) only when Slurm cannot run here, with the reason.
set -euo pipefail
binocle=$(realpath "$1") src=$(realpath "$2")
skip() { echo "SKIPPED: $*" >&2; exit 77; }

[ "$(id -u)" = 0 ] || skip "needs root (slurmd runs jobs as any user only as root; munged key ownership)"
for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo scontrol; do
  command -v "$tool" >/dev/null || skip "'$tool' is not installed (Debian packages slurm-wlm and munge: scripts/install-deps.sh)"
done

tmp=$(mktemp -d /tmp/binocle-slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  local rc=$?
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  if [ $rc -ne 0 ] && [ $rc -ne 77 ]; then
    for log in "$tmp"/*.log "$tmp"/out/logs/*; do [ -f "$log" ] && { echo "--- $log"; tail -20 "$log"; }; done >&2
  fi
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT

# munge: a generated key, its own socket; nothing of the system's is used.
mkdir -p "$tmp/munge"
chmod 711 "$tmp/munge" # the socket's folder: others may reach the socket, not list it
mungekey --create --keyfile="$tmp/munge/munge.key" --bits=1024
chmod 400 "$tmp/munge/munge.key"
munged --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.socket" --pid-file="$tmp/munge/munged.pid" \
  --log-file="$tmp/munged.log" --seed-file="$tmp/munge/munge.seed" --foreground --force >"$tmp/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -S "$tmp/munge/munge.socket" ] && break; sleep 0.1; done
[ -S "$tmp/munge/munge.socket" ] || skip "munged did not start: $(tail -3 "$tmp/munged.log" 2>/dev/null)"

# Free TCP ports for the two daemons.
port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])' 2>/dev/null ||
         echo $((20000 + RANDOM % 20000)); }
ctld_port=$(port) d_port=$(port)
host=$(hostname -s)
cpus=$(nproc)
mem=$(awk '/MemTotal/ { print int($2 / 1024 / 2) }' /proc/meminfo)
mkdir -p "$tmp/state" "$tmp/spool"
cat >"$tmp/slurm.conf" <<CONF
ClusterName=binocle-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MaxArraySize=10000
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
ready=""
for _ in $(seq 100); do
  if sinfo -h -N -o '%T' 2>/dev/null | grep -qE '^(idle|mixed)'; then ready=1; break; fi
  sleep 0.2
done
if [ -z "$ready" ]; then
  reason=$(cat "$tmp/slurmctld.out" "$tmp/slurmd.out" "$tmp"/slurm*.log 2>/dev/null | grep -iE 'error|fatal' | head -3)
  skip "slurmctld/slurmd did not bring the node up within 20 s: ${reason:-no error logged}"
fi
echo "slurm up: node $host, $cpus CPUs, ports $ctld_port/$d_port"

# A small sweep: 2 baselines x 2 lenses x 1 range, 2 repeats -> 4 tests in 3 shards.
"$src/scripts/slurm/make-sweep.sh" "$tmp/sweep.yaml" --baselines 100,150 --lenses 8,12 --ranges 6000 --repeats 2
mkdir -p "$tmp/out"
BINOCLE="$binocle" "$src/scripts/slurm/submit-sweep.sh" "$tmp/sweep.yaml" "$tmp/out" 3 --time=10 | tee "$tmp/submit.txt"
for _ in $(seq 600); do
  [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
  sleep 0.2
done
[ -z "$(squeue -h -o %i)" ] || { echo "FAIL: jobs still queued after 120 s:"; squeue; exit 1; } >&2
[ -f "$tmp/out/merged/results.json" ] || { echo "FAIL: the merge job wrote no results.json" >&2; exit 1; }
for k in 1 2 3; do
  grep -q "\"index\": $k" "$tmp/out/shard_$k/results.json" || { echo "FAIL: shard $k has no shard record" >&2; exit 1; }
done

# The same sweep, unsharded, on this host.
"$binocle" experiment "$tmp/sweep.yaml" --out "$tmp/whole" --quiet
strip() { grep -v '"seconds":' "$1"; }
if ! diff <(strip "$tmp/whole/results.json") <(strip "$tmp/out/merged/results.json"); then
  echo "FAIL: merged results.json differs from the unsharded run (beyond timings)" >&2
  exit 1
fi
# CSV: every column but the timing one.
col=$(head -1 "$tmp/whole/results.csv" | tr ',' '\n' | grep -n '^seconds$' | cut -d: -f1)
cut -d, -f"$col" --complement "$tmp/whole/results.csv" >"$tmp/a.csv"
cut -d, -f"$col" --complement "$tmp/out/merged/results.csv" >"$tmp/b.csv"
diff "$tmp/a.csv" "$tmp/b.csv" || { echo "FAIL: merged results.csv differs from the unsharded run" >&2; exit 1; }
rows=$(($(wc -l <"$tmp/a.csv") - 1))
[ "$rows" = 4 ] || { echo "FAIL: expected 4 rows, got $rows" >&2; exit 1; }
echo "PASS: 4 tests in 3 Slurm array tasks merged equal the unsharded run"
