#!/usr/bin/env bash
# bench/peers/liggghts/compare.sh N STEPS
#
# Runs the `packed` deck of bench/decks.md with N particles for STEPS steps, first in LIGGGHTS
# (Debian's liggghts 3.8, NP MPI ranks) and then in CoReDEM
# (`coredem-bench dem --case packed ... --backend cpu --threads THREADS --json`), one after the
# other on this machine (REPEAT times, interleaved), and prints both median throughputs
# (particle-steps/s over the timed loop only: LIGGGHTS' "Loop time", CoReDEM's own timed loop;
# setup, reading and the first force evaluation are excluded from both) and the ratio
# ours/LIGGGHTS.
#
# Environment (all optional):
#   BUILD_DIR      where bin/coredem-bench lives        (default: <project>/build)
#   NP             LIGGGHTS MPI ranks                    (default: 2)
#   THREADS        CoReDEM CPU threads                   (default: 2)
#   LIGGGHTS       LIGGGHTS executable                   (default: liggghts)
#   MPIRUN         MPI launcher                          (default: mpirun)
#   MPI_FLAGS      extra launcher flags                  (default: none)
#   SKIN           LIGGGHTS neighbour skin in metres     (default: 1e-4 = 0.1 d_p)
#   RUN_TIMEOUT    seconds allowed for each run          (default: 3600)
#   REPEAT         runs of each code, interleaved; the   (default: 3)
#                  median throughput is compared
#   KEEP_DIR       keep the generated deck and logs here (default: a temp dir, removed)
#   LIGGGHTS_ONLY  set to 1 to skip CoReDEM
#
# Exit status: 0 both ran; 2 bad usage or LIGGGHTS missing/failed; 3 LIGGGHTS ran but
# CoReDEM's binary is missing or failed (the LIGGGHTS figures are still printed).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"

usage() {
  sed -n '2,27p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
die() { echo "compare.sh: error: $*" >&2; exit 2; }

[[ $# -eq 2 ]] || usage
N="$1"
STEPS="$2"
[[ "$N" =~ ^[0-9]+$ && "$N" -ge 1 ]] || die "N must be a positive integer (particle count), got '$N'"
[[ "$STEPS" =~ ^[0-9]+$ && "$STEPS" -ge 1 ]] || die "STEPS must be a positive integer, got '$STEPS'"

NP="${NP:-2}"
THREADS="${THREADS:-2}"
BUILD_DIR="${BUILD_DIR:-$root/build}"
LIGGGHTS="${LIGGGHTS:-liggghts}"
MPIRUN="${MPIRUN:-mpirun}"
MPI_FLAGS="${MPI_FLAGS:-}"
SKIN="${SKIN:-1e-4}"
RUN_TIMEOUT="${RUN_TIMEOUT:-3600}"
REPEAT="${REPEAT:-3}"
LIGGGHTS_ONLY="${LIGGGHTS_ONLY:-0}"
[[ "$NP" =~ ^[0-9]+$ && "$NP" -ge 1 ]] || die "NP must be a positive integer, got '$NP'"
[[ "$THREADS" =~ ^[0-9]+$ && "$THREADS" -ge 1 ]] || die "THREADS must be a positive integer, got '$THREADS'"
[[ "$REPEAT" =~ ^[0-9]+$ && "$REPEAT" -ge 1 ]] || die "REPEAT must be a positive integer, got '$REPEAT'"

command -v python3 >/dev/null || die "python3 not found (it generates the deck)"
command -v timeout >/dev/null || die "timeout (coreutils) not found"
command -v "$LIGGGHTS" >/dev/null ||
  die "LIGGGHTS executable '$LIGGGHTS' not found. Install it with: scripts/install-deps.sh --with-peers (Debian packages liggghts, openmpi-bin), or point LIGGGHTS= at it."
command -v "$MPIRUN" >/dev/null ||
  die "MPI launcher '$MPIRUN' not found. Install it with: scripts/install-deps.sh --with-peers (Debian package openmpi-bin), or point MPIRUN= at it."

ours="$BUILD_DIR/bin/coredem-bench"
ours_missing=""
if [[ "$LIGGGHTS_ONLY" != 1 && ! -x "$ours" ]]; then
  ours_missing="CoReDEM's benchmark binary '$ours' does not exist. Build it with: cmake -S . -B build && cmake --build build -j2 --target coredem-bench (or set BUILD_DIR to the build directory that has bin/coredem-bench). Set LIGGGHTS_ONLY=1 to run LIGGGHTS alone."
  echo "compare.sh: warning: $ours_missing" >&2
  echo "compare.sh: running LIGGGHTS alone first; CoReDEM will be reported as missing." >&2
fi

if [[ -n "${KEEP_DIR:-}" ]]; then
  work="$KEEP_DIR"
  mkdir -p "$work"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/coredem-liggghts.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
fi

# ---- machine ----
cpu_model="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
echo "== packed deck (bench/decks.md): N = $N, $STEPS steps =="
echo "machine: $(nproc) cores visible, ${cpu_model:-unknown CPU}; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

# ---- runs ----
python3 "$here/make_deck.py" "$N" "$STEPS" "$work" --contacts --skin "$SKIN" >"$work/deck.txt" ||
  die "make_deck.py failed for N=$N STEPS=$STEPS"
mpi_args=(-np "$NP")
[[ "$(id -u)" == 0 ]] && mpi_args+=(--allow-run-as-root)
[[ "$NP" -gt "$(nproc)" ]] && mpi_args+=(--oversubscribe)
# shellcheck disable=SC2206
[[ -n "$MPI_FLAGS" ]] && mpi_args+=($MPI_FLAGS)
ours_cmd=("$ours" dem --case packed --particles "$N" --steps "$STEPS" --backend cpu --threads "$THREADS" --json)
echo "LIGGGHTS: $MPIRUN ${mpi_args[*]} $LIGGGHTS -in in.packed   (deck: $work)"
[[ "$LIGGGHTS_ONLY" != 1 && -z "$ours_missing" ]] && echo "CoReDEM:  ${ours_cmd[*]}"

run_liggghts() { # $1 = repetition
  local rc=0
  (cd "$work" && timeout "$RUN_TIMEOUT" "$MPIRUN" "${mpi_args[@]}" "$LIGGGHTS" -in in.packed -log none \
    >"screen.liggghts.$1" 2>&1) || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 30 "$work/screen.liggghts.$1" >&2 || true
    [[ $rc -eq 124 ]] && die "LIGGGHTS did not finish within RUN_TIMEOUT=$RUN_TIMEOUT s"
    die "LIGGGHTS failed (exit $rc); its last output is above"
  fi
}

ours_status="ok"
[[ "$LIGGGHTS_ONLY" == 1 ]] && ours_status="skipped (LIGGGHTS_ONLY=1)"
[[ -n "$ours_missing" ]] && ours_status="not run. $ours_missing"
run_ours() { # $1 = repetition
  [[ "$ours_status" == ok ]] || return 0
  local rc=0
  timeout "$RUN_TIMEOUT" "${ours_cmd[@]}" >"$work/ours.$1.json" 2>"$work/ours.$1.err" || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 30 "$work/ours.$1.err" >&2 || true
    rm -f "$work/ours.$1.json"
    if [[ $rc -eq 124 ]]; then
      ours_status="timed out after RUN_TIMEOUT=$RUN_TIMEOUT s"
    else
      ours_status="failed (exit $rc; its stderr is above)"
    fi
  fi
}

for ((r = 1; r <= REPEAT; r++)); do
  run_liggghts "$r"
  run_ours "$r"
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 "$here/report.py" "$work" "$N" "$STEPS" "$NP" "$THREADS" "$REPEAT" ||
  die "could not parse the runs (kept in KEEP_DIR if set)"

if [[ "$ours_status" == ok ]]; then
  if ! ls "$work"/ours.*.json >/dev/null 2>&1; then
    echo "CoReDEM: its output had no JSON" >&2
    exit 3
  fi
  exit 0
fi
echo
if [[ "$ours_status" == "skipped (LIGGGHTS_ONLY=1)" ]]; then
  echo "CoReDEM: $ours_status"
  exit 0
fi
echo "CoReDEM: $ours_status" >&2
exit 3
