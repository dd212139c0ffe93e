#!/usr/bin/env bash
# End to end on a real Slurm: starts a one-node cluster on this machine (munged, slurmctld,
# slurmd as root, no systemd, no cgroups), runs `mirage slurm --shards 4 -- synth ...` (a job array
# and a merge job that depends on it), waits for the merge, and checks that the merged session
# equals an unsharded `mirage synth` of the same session bit for bit. Prints both wall times.
#
#   slurm_cluster_test.sh MIRAGE SCENE WORKDIR
#
# Logs: WORKDIR/run.*/log (daemons), WORKDIR/run.*/split.slurm/logs (jobs).
# Exit 0: passed; 1: failed; 77: skipped, with the reason (not root, Slurm or munge missing, a
# daemon that does not start here). Every daemon is stopped by its PID on exit.
set -uo pipefail
mirage=$1
scene=$2
workroot=$3

skip() {
  echo "SKIP: $*"
  exit 77
}
fail() {
  echo "FAIL: $*"
  exit 1
}

[ "$(id -u)" -eq 0 ] || skip "needs root to run slurmctld and slurmd"
for b in munged slurmctld slurmd sbatch scontrol sinfo; do
  command -v "$b" >/dev/null || skip "$b is not installed (scripts/install-deps.sh installs slurm-wlm and munge)"
done

mkdir -p "$workroot"
work=$(mktemp -d "$workroot/run.XXXXXX")
chmod 0755 "$work"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  sleep 1
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done
}
trap cleanup EXIT

# ---- munge: its own key, socket and files under $work (the socket folder must be 0755) --------
mkdir -p "$work/munge/run" "$work/munge/lib" "$work/munge/log"
chmod 0755 "$work/munge" "$work/munge/run"
chmod 0700 "$work/munge/lib" "$work/munge/log"
head -c 1024 /dev/urandom >"$work/munge/munge.key"
chmod 0400 "$work/munge/munge.key"
socket="$work/munge/run/munge.socket.2"
munged --force --socket="$socket" --key-file="$work/munge/munge.key" \
  --pid-file="$work/munge/run/munged.pid" --seed-file="$work/munge/lib/munged.seed" \
  --log-file="$work/munge/log/munged.log" --foreground >"$work/munge/log/stdout" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -S "$socket" ] && break; sleep 0.1; done
[ -S "$socket" ] || skip "munged did not start: $(tail -3 "$work/munge/log/munged.log" 2>/dev/null)"

# ---- slurm.conf: this machine as node "localhost", ports chosen per run -----------------------
node=$(slurmd -C 2>/dev/null | head -1)
cpus=$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<<"$node")
memory=$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$node")
[ -n "$cpus" ] && [ -n "$memory" ] || skip "slurmd -C did not describe this machine: $node"
port=$((20000 + RANDOM % 20000))
mkdir -p "$work/state" "$work/spool" "$work/log"
conf="$work/slurm.conf"
cat >"$conf" <<EOF
ClusterName=miragetest
SlurmctldHost=localhost
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MinJobAge=600
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$conf"
slurmctld -D -i -f "$conf" >"$work/log/slurmctld.stdout" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$conf" >"$work/log/slurmd.stdout" 2>&1 &
pids+=($!)
up=""
for _ in $(seq 100); do
  state=$(sinfo -h -n localhost -o %T 2>/dev/null)
  case "$state" in idle*|mixed*|allocated*) up=1; break ;; esac
  sleep 0.2
done
[ -n "$up" ] || skip "the Slurm node did not come up (state '${state:-none}'): $(tail -3 "$work/log/slurmctld.log" "$work/log/slurmd.log" 2>/dev/null)"
echo "cluster up: 1 node, $cpus CPUs, ports $port/$((port + 1))"

# ---- the run: 4 shards and a merge through Slurm, and one process for comparison --------------
export SOURCE_DATE_EPOCH=1764547200  # equal creation times in both sessions
# MIRAGE_SLURM_SYNTH_SIZE="W H FPS SECONDS SPP" makes a larger session (docs/scale.md's figure).
read -r width height fps seconds spp <<<"${MIRAGE_SLURM_SYNTH_SIZE:-64 48 4 2 2}"
args=(synth "$scene" --width "$width" --height "$height" --fps "$fps" --seconds "$seconds"
  --spp "$spp" --env-size 32 --noise 0.01 --ground-truth-composite)
start=$(date +%s.%N)
out=$("$mirage" slurm --shards 4 --cpus 1 --mem 1024 --time 00:15:00 -- "${args[@]}" -o "$work/split" 2>&1)
echo "$out"
array=$(sed -n 's/.*submitted: array job \([0-9]*\).*/\1/p' <<<"$out")
merge=$(sed -n 's/.*merge job \([0-9]*\).*/\1/p' <<<"$out")
[ -n "$array" ] && [ -n "$merge" ] || fail "mirage slurm did not report the job ids"

# Wait for the merge job to end. Jobs leave squeue when they end, failed or not: read the state
# with scontrol, and judge by the outputs.
state=""
for _ in $(seq 600); do
  state=$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
  case "$state" in COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|DEADLINE) break ;; esac
  sleep 0.5
done
split_seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
scontrol show job "$array" 2>/dev/null | grep -E "JobId|JobState|ExitCode" | head -12
[ "$state" = COMPLETED ] || {
  tail -20 "$work/split.slurm/logs/"*.out 2>/dev/null
  fail "the merge job ended $state"
}
[ -f "$work/split/session.json" ] || fail "the merge job completed but wrote no session"

start=$(date +%s.%N)
"$mirage" "${args[@]}" --threads 1 -o "$work/whole" >/dev/null 2>&1 || fail "the unsharded synth failed"
whole_seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
start=$(date +%s.%N)
"$mirage" "${args[@]}" -o "$work/whole_all_cores" >/dev/null 2>&1 || fail "the unsharded synth failed"
all_cores_seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')

# ---- bit for bit ---------------------------------------------------------------------------
files=0
while IFS= read -r f; do
  rel=${f#"$work/whole/"}
  cmp -s "$f" "$work/split/$rel" || fail "$rel differs between the sharded and the whole run"
  files=$((files + 1))
done < <(find "$work/whole" -type f)
extra=$(cd "$work/split" && find . -type f | wc -l)
[ "$extra" -eq "$files" ] || fail "the merged session has $extra files, the whole run $files"
echo "PASS: $files files equal bit for bit; 4 shards through Slurm (1 CPU each, incl. queueing and merge) ${split_seconds} s; one process: ${whole_seconds} s with 1 thread, ${all_cores_seconds} s with all $cpus cores (load average $(cut -d' ' -f1-3 /proc/loadavg))"
