#!/usr/bin/env bash
# A private single-node Slurm for the campaign e2e tests (tests/e2e/slurm): munged with its own
# key and socket, slurmctld and slurmd with a generated slurm.conf, everything (state, spool,
# logs, pid files) in one folder. Needs root and Debian's slurm-wlm and munge.
#
#   local-slurm.sh start DIR [WATCH_PID]  start; prints SLURM_CONF=DIR/slurm.conf. With
#                                         WATCH_PID, a watchdog stops everything when that
#                                         process ends (a crashed test leaves nothing behind)
#   local-slurm.sh stop DIR               cancel the jobs, stop the daemons and every process
#                                         of this cluster's jobs, by their PIDs
#
# Exit codes of start: 0 up; 77 cannot run here (not root, packages missing: the reason on
# stderr, the tests skip); 1 a daemon did not come up (its log on stderr).
set -uo pipefail

cmd=${1:-}
dir=${2:-}
if [[ -z "$cmd" || -z "$dir" ]]; then
  echo "usage: $0 start|stop DIR [WATCH_PID]" >&2
  exit 2
fi
dir=$(cd "$dir" 2>/dev/null && pwd) || { echo "local-slurm: no folder ${2}" >&2; exit 2; }
conf="$dir/slurm.conf"

log_tail() { # file, title
  if [[ -s "$1" ]]; then
    echo "---- $2 ($1), last lines:" >&2
    tail -n 25 "$1" >&2
  else
    echo "---- $2 ($1): empty" >&2
  fi
}

# PIDs of processes started for this cluster: the daemons and every job process (slurmstepd and
# the jobs inherit SLURM_CONF=$conf from slurmd / sbatch).
# This script and its callers (which may have SLURM_CONF set too) are left alone.
cluster_pids() {
  local p a ancestors=" "
  a=$$
  while [[ -n "$a" && "$a" != "0" && "$a" != "1" ]]; do
    ancestors+="$a "
    a=$(awk '{print $4}' "/proc/$a/stat" 2>/dev/null)
  done
  for p in /proc/[0-9]*; do
    p=${p#/proc/}
    [[ "$ancestors" == *" $p "* ]] && continue
    if { tr '\0' '\n' <"/proc/$p/environ"; } 2>/dev/null | grep -qxF "SLURM_CONF=$conf"; then
      echo "$p"
    fi
  done
}

stop_all() {
  export SLURM_CONF="$conf"
  if [[ -f "$dir/slurmctld.pid" ]] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null; then
    timeout 10 scancel --quiet --full --signal=KILL --user=root >/dev/null 2>&1 || true
    timeout 10 scancel --quiet --user=root >/dev/null 2>&1 || true
  fi
  local f pid
  # the watchdog first (it would call stop again), then slurmd, slurmctld, munged
  for f in watchdog slurmd slurmctld munged; do
    [[ -f "$dir/$f.pid" ]] || continue
    pid=$(cat "$dir/$f.pid")
    [[ "$pid" =~ ^[0-9]+$ ]] && [[ "$pid" != "$$" ]] && [[ "$pid" != "$PPID" ]] && kill -TERM "$pid" 2>/dev/null
  done
  for _ in $(seq 1 50); do
    local alive=0
    for f in slurmd slurmctld munged; do
      [[ -f "$dir/$f.pid" ]] && kill -0 "$(cat "$dir/$f.pid")" 2>/dev/null && alive=1
    done
    [[ $alive -eq 0 ]] && break
    sleep 0.2
  done
  for f in slurmd slurmctld munged; do
    [[ -f "$dir/$f.pid" ]] || continue
    pid=$(cat "$dir/$f.pid")
    [[ "$pid" =~ ^[0-9]+$ ]] && kill -KILL "$pid" 2>/dev/null
    rm -f "$dir/$f.pid"
  done
  # job steps outlive slurmd (slurmstepd and what it started)
  for pid in $(cluster_pids); do
    kill -KILL "$pid" 2>/dev/null
  done
  rm -f "$dir/watchdog.pid"
}

if [[ "$cmd" == "stop" ]]; then
  stop_all
  exit 0
fi
[[ "$cmd" == "start" ]] || { echo "local-slurm: unknown command $cmd" >&2; exit 2; }
watch_pid=${3:-}

# slurmstepd makes Unix sockets DIR/spool/<node>_<job>.<step> (at most 108 bytes)
if [[ ${#dir} -gt 60 ]]; then
  echo "local-slurm: $dir is too long for slurmstepd's socket names (spool/<node>_<job>.<step>" \
    "must stay under 108 bytes); use a folder path of at most 60 characters" >&2
  exit 2
fi

# --- can Slurm run here at all?
if [[ $(id -u) -ne 0 ]]; then
  echo "local-slurm: needs root (slurmd runs jobs as their user; SlurmUser=root)" >&2
  exit 77
fi
missing=()
for c in munged mungekey slurmctld slurmd sbatch squeue scontrol scancel; do
  command -v "$c" >/dev/null 2>&1 || PATH="$PATH:/usr/sbin:/sbin" command -v "$c" >/dev/null 2>&1 || missing+=("$c")
done
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "local-slurm: missing ${missing[*]}; install Debian's slurm-wlm and munge (scripts/install-deps.sh)" >&2
  exit 77
fi
export PATH="$PATH:/usr/sbin:/sbin"

free_port() {
  /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}

mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
chmod 700 "$dir" "$dir/munge"

# --- munge: own key, socket, pid, log, seed
if ! mungekey --create --keyfile="$dir/munge/munge.key" --force >"$dir/mungekey.out" 2>&1; then
  echo "local-slurm: mungekey failed" >&2
  log_tail "$dir/mungekey.out" mungekey
  exit 1
fi
chmod 600 "$dir/munge/munge.key"
sock="$dir/munge/munge.socket"
munged --force --socket="$sock" --key-file="$dir/munge/munge.key" \
  --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" \
  --seed-file="$dir/munge/munge.seed" >"$dir/munged.out" 2>&1
if [[ $? -ne 0 || ! -S "$sock" ]]; then
  echo "local-slurm: munged did not start" >&2
  log_tail "$dir/munged.out" "munged output"
  log_tail "$dir/munged.log" "munged log"
  exit 1
fi

# --- slurm.conf
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 / 2)}' /proc/meminfo)
ctld_port=$(free_port)
slurmd_port=$(free_port)
while [[ "$slurmd_port" == "$ctld_port" ]]; do slurmd_port=$(free_port); done
cat >"$conf" <<CONF
# generated by tests/e2e/slurm/local-slurm.sh
ClusterName=coredemtest
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock,cred_expire=10
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=2,bf_interval=2
MpiDefault=none
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MailProg=/bin/true
KillWait=30
MinJobAge=600
# a requeued job waits cred_expire seconds (AuthInfo) before it starts again
InactiveLimit=0
MessageTimeout=20
NodeName=coredem-node CPUs=$cpus RealMemory=$mem NodeHostname=$(hostname) NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=coredem-node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$conf"

fail() {
  echo "local-slurm: $1" >&2
  log_tail "$dir/slurmctld.out" "slurmctld output"
  log_tail "$dir/slurmctld.log" "slurmctld log"
  log_tail "$dir/slurmd.out" "slurmd output"
  log_tail "$dir/slurmd.log" "slurmd log"
  stop_all
  exit 1
}

# -D: foreground (the PID is ours), -i/-c: a fresh cluster without saved state
setsid slurmctld -D -c -i -f "$conf" >"$dir/slurmctld.out" 2>&1 </dev/null &
echo $! >"$dir/slurmctld.pid.start"
setsid slurmd -D -f "$conf" -N coredem-node >"$dir/slurmd.out" 2>&1 </dev/null &
echo $! >"$dir/slurmd.pid.start"
# the daemons write their own pid files; keep ours if they fail before that
cp "$dir/slurmctld.pid.start" "$dir/slurmctld.pid" 2>/dev/null
cp "$dir/slurmd.pid.start" "$dir/slurmd.pid" 2>/dev/null

if [[ -n "$watch_pid" ]]; then
  setsid bash -c "while kill -0 $watch_pid 2>/dev/null; do sleep 1; done; '$0' stop '$dir'" \
    >/dev/null 2>&1 </dev/null &
  echo $! >"$dir/watchdog.pid"
fi

# wait for the node to be idle (up to 60 s)
for i in $(seq 1 300); do
  kill -0 "$(cat "$dir/slurmctld.pid.start")" 2>/dev/null || fail "slurmctld exited while starting"
  kill -0 "$(cat "$dir/slurmd.pid.start")" 2>/dev/null || fail "slurmd exited while starting"
  state=$(timeout 5 sinfo -h -n coredem-node -o %T 2>/dev/null | head -n 1)
  if [[ "$state" == "idle" ]]; then
    echo "SLURM_CONF=$conf"
    exit 0
  fi
  sleep 0.2
done
fail "the node did not become idle within 60 s (sinfo: '${state:-no answer}')"
