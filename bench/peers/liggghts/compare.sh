#!/usr/bin/env bash
# bench/peers/liggghts/compare.sh N STEPS
#
# Runs the decks of bench/decks.md (`packed` and `agitated`) with N particles for STEPS timed
# steps in CoReDEM (`coredem-bench dem --case DECK ... --backend cpu --threads C --json`) and in
# LIGGGHTS (Debian's liggghts 3.8, C MPI ranks), for C = 1 and 2 cores, REPEAT times each,
# interleaved (CoReDEM, LIGGGHTS, CoReDEM, ...), printing the load average before each run, and
# prints one table: the median throughputs (particle-steps/s over the timed loop only) and the
# ratio ours/LIGGGHTS per deck and core count. Both codes run WARMUP untimed steps first and
# start from the same particles (the agitated deck's velocities are generated once by
# make_deck.py and given to both). Before a ratio is printed, LIGGGHTS' own output (echoed
# input, thermo and loop lines) and CoReDEM's JSON are checked against the intended deck:
# step counts, timestep, neighbour settings, rank/thread counts, initial kinetic energy; a
# mismatch is an error.
#
# Environment (all optional):
#   DECK           decks to run, space-separated         (default: "packed agitated")
#   CORES          core counts, NP = THREADS = each      (default: "1 2")
#   NP, THREADS    set both to run one pairing NP ranks vs THREADS threads instead of CORES
#   REPEAT         runs of each code per deck and core count, interleaved (default: 3)
#   WARMUP         untimed steps before the timed ones, both codes (default: 20)
#   LOAD_MAX       refuse to start a run while the 1-min load average is >= this (default 0.5)
#   LOAD_WAIT      seconds to wait for the load to fall below LOAD_MAX before refusing
#                  (default 180; the previous run itself raises the 1-min average)
#   ALLOW_LOAD     1: run anyway; such runs are labelled LOADED in the table
#   BUILD_DIR      where bin/coredem-bench lives        (default: <project>/build)
#   LIGGGHTS       LIGGGHTS executable                   (default: liggghts)
#   MPIRUN         MPI launcher                          (default: mpirun)
#   MPI_FLAGS      extra launcher flags                  (default: none)
#   SKIN           neighbour skin in metres, both codes  (default: 1e-4 = 0.1 d_p)
#   RUN_TIMEOUT    seconds allowed for each run          (default: 3600)
#   KEEP_DIR       keep the generated decks and logs here (default: a temp dir, removed)
#   LIGGGHTS_ONLY  set to 1 to skip CoReDEM
#
# Exit status: 0 all ran and passed the checks; 2 bad usage or LIGGGHTS missing/failed;
# 3 CoReDEM's binary missing or failed (LIGGGHTS figures still printed); 5 the load average was
# >= LOAD_MAX before a run (without ALLOW_LOAD=1); 6 a run did not match the intended deck.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"

usage() {
  sed -n '2,40p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
SCRIPT=compare.sh
# shellcheck source=common.sh
source "$here/common.sh" # die, require_peer_tools, check_load, liggghts_run

[[ $# -eq 2 ]] || usage
N="$1"
STEPS="$2"
[[ "$N" =~ ^[0-9]+$ && "$N" -ge 1 ]] || die "N must be a positive integer (particle count), got '$N'"
[[ "$STEPS" =~ ^[0-9]+$ && "$STEPS" -ge 1 ]] || die "STEPS must be a positive integer, got '$STEPS'"

DECKS="${DECK:-packed agitated}"
CORES="${CORES:-1 2}"
BUILD_DIR="${BUILD_DIR:-$root/build}"
LIGGGHTS="${LIGGGHTS:-liggghts}"
MPIRUN="${MPIRUN:-mpirun}"
MPI_FLAGS="${MPI_FLAGS:-}"
SKIN="${SKIN:-1e-4}"
RUN_TIMEOUT="${RUN_TIMEOUT:-3600}"
REPEAT="${REPEAT:-3}"
WARMUP="${WARMUP:-20}"
LOAD_MAX="${LOAD_MAX:-0.5}"
LOAD_WAIT="${LOAD_WAIT:-180}"
ALLOW_LOAD="${ALLOW_LOAD:-0}"
LIGGGHTS_ONLY="${LIGGGHTS_ONLY:-0}"
for d in $DECKS; do
  [[ "$d" == packed || "$d" == agitated ]] || die "DECK must list packed and/or agitated, got '$d'"
done
# pairings "ranks:threads"
pairs=()
if [[ -n "${NP:-}" || -n "${THREADS:-}" ]]; then
  NP="${NP:-${THREADS}}"
  THREADS="${THREADS:-$NP}"
  [[ "$NP" =~ ^[0-9]+$ && "$NP" -ge 1 ]] || die "NP must be a positive integer, got '$NP'"
  [[ "$THREADS" =~ ^[0-9]+$ && "$THREADS" -ge 1 ]] || die "THREADS must be a positive integer, got '$THREADS'"
  pairs=("$NP:$THREADS")
else
  for c in $CORES; do
    [[ "$c" =~ ^[0-9]+$ && "$c" -ge 1 ]] || die "CORES must list positive integers, got '$c'"
    pairs+=("$c:$c")
  done
fi
[[ ${#pairs[@]} -ge 1 ]] || die "no core counts (CORES is empty)"
[[ "$REPEAT" =~ ^[0-9]+$ && "$REPEAT" -ge 1 ]] || die "REPEAT must be a positive integer, got '$REPEAT'"
[[ "$WARMUP" =~ ^[0-9]+$ ]] || die "WARMUP must be a non-negative integer, got '$WARMUP'"
[[ "$LOAD_MAX" =~ ^[0-9]*\.?[0-9]+$ ]] || die "LOAD_MAX must be a number, got '$LOAD_MAX'"
[[ "$LOAD_WAIT" =~ ^[0-9]+$ ]] || die "LOAD_WAIT must be a non-negative integer (seconds), got '$LOAD_WAIT'"

require_peer_tools

ours="$BUILD_DIR/bin/coredem-bench"
ours_missing=""
if [[ "$LIGGGHTS_ONLY" != 1 && ! -x "$ours" ]]; then
  ours_missing="CoReDEM's benchmark binary '$ours' does not exist. Build it with: cmake -S . -B build && cmake --build build -j2 --target coredem-bench (or set BUILD_DIR to the build directory that has bin/coredem-bench). Set LIGGGHTS_ONLY=1 to run LIGGGHTS alone."
  echo "compare.sh: warning: $ours_missing" >&2
  echo "compare.sh: running LIGGGHTS alone; CoReDEM will be reported as missing." >&2
fi

if [[ -n "${KEEP_DIR:-}" ]]; then
  work="$KEEP_DIR"
  mkdir -p "$work"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/coredem-liggghts.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
fi

cpu_model="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
echo "== decks (bench/decks.md): ${DECKS}; N = $N, $WARMUP untimed + $STEPS timed steps; ranks:threads ${pairs[*]}; $REPEAT runs each =="
echo "machine: $(nproc) cores visible, ${cpu_model:-unknown CPU}; load average now: $(cut -d' ' -f1-3 /proc/loadavg)"
[[ "$ALLOW_LOAD" == 1 ]] && echo "ALLOW_LOAD=1: runs started at load >= $LOAD_MAX are labelled LOADED"

ours_status="ok"
[[ "$LIGGGHTS_ONLY" == 1 ]] && ours_status="skipped (LIGGGHTS_ONLY=1)"
[[ -n "$ours_missing" ]] && ours_status="not run. $ours_missing"

run_liggghts() { # $1 = deck dir, $2 = deck, $3 = ranks, $4 = run dir, $5 = repetition
  liggghts_run "$1" "in.$2" "$3" "$4/screen.liggghts.$5" "$4/load.liggghts.$5" "LIGGGHTS run $5" \
    "$([[ "$5" == 1 ]] && echo 1 || echo 0)"
}

run_ours() { # $1 = deck dir, $2 = deck, $3 = threads, $4 = run dir, $5 = repetition
  [[ "$ours_status" == ok ]] || return 0
  local rc=0 cmd
  local skin_factor
  skin_factor="$(python3 -c "print(repr(float('$SKIN') / 1e-3))")"
  cmd=("$ours" dem --case "$2" --particles "$N" --steps "$STEPS" --warmup "$WARMUP"
    --skin "$skin_factor" --backend cpu --threads "$3" --json)
  [[ "$2" == agitated ]] && cmd+=(--velocities "$1/agitated.vel")
  [[ "$5" == 1 ]] && echo "  CoReDEM:  ${cmd[*]}"
  check_load "$4/load.ours.$5" "CoReDEM run $5"
  timeout "$RUN_TIMEOUT" "${cmd[@]}" >"$4/ours.$5.json" 2>"$4/ours.$5.err" || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 30 "$4/ours.$5.err" >&2 || true
    rm -f "$4/ours.$5.json"
    if [[ $rc -eq 124 ]]; then
      ours_status="timed out after RUN_TIMEOUT=$RUN_TIMEOUT s"
    else
      ours_status="failed (exit $rc; its stderr is above)"
    fi
  fi
}

for deck in $DECKS; do
  ddir="$work/$deck"
  mkdir -p "$ddir"
  python3 "$here/make_deck.py" "$N" "$STEPS" "$ddir" --deck "$deck" --warmup "$WARMUP" --contacts \
    --skin "$SKIN" >"$ddir/deck.txt" || die "make_deck.py failed for $deck N=$N STEPS=$STEPS"
  for pair in "${pairs[@]}"; do
    np="${pair%%:*}"
    th="${pair##*:}"
    rdir="$ddir/np${np}_t${th}"
    mkdir -p "$rdir"
    echo "-- $deck: LIGGGHTS $np rank(s), CoReDEM $th thread(s) (deck: $ddir)"
    for ((r = 1; r <= REPEAT; r++)); do
      run_ours "$ddir" "$deck" "$th" "$rdir" "$r"
      run_liggghts "$ddir" "$deck" "$np" "$rdir" "$r"
    done
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"

rc=0
python3 "$here/report.py" "$work" "$N" "$STEPS" "$WARMUP" "$REPEAT" "$DECKS" "${pairs[*]}" "$LOAD_MAX" \
  "$SKIN" || rc=$?
[[ $rc -eq 6 ]] && { echo "compare.sh: a run did not match the intended deck (see CHECK FAILED above)" >&2; exit 6; }
[[ $rc -ne 0 ]] && die "could not parse the runs (kept in KEEP_DIR if set)"

if [[ "$ours_status" == ok ]]; then
  exit 0
fi
echo
if [[ "$ours_status" == "skipped (LIGGGHTS_ONLY=1)" ]]; then
  echo "CoReDEM: $ours_status"
  exit 0
fi
echo "CoReDEM: $ours_status" >&2
exit 3
