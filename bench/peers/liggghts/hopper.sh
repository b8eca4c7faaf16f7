#!/usr/bin/env bash
# bench/peers/liggghts/hopper.sh N STEPS
#
# The `hopper` deck of bench/decks.md (a 30-degree conical hopper discharging N glass beads
# through an outlet of 8 d_p into a bin) in CoReDEM (`coredem-bench dem --case hopper`) and in
# LIGGGHTS 3.8 (make_hopper.py), both starting from the same settled bed and reading the same
# STL files. CoReDEM settles the bed once (untimed, outlet closed) and writes the deck
# directory; then, for each wall variant and core count, REPEAT interleaved runs of WARMUP
# untimed + STEPS timed steps from the opening (CoReDEM, LIGGGHTS, CoReDEM, ...), the load
# average printed before each. The table gives the median particle-steps/s of both codes, the
# discharged fraction and particles touching walls; below it the discharge rate of both codes
# (linear fit of the discharged mass between FIT_LO and FIT_HI of N) against Beverloo's band,
# and with WALL_COST=1 the cost of the walls (the bed at rest in the closed hopper vs the same
# bed without walls). Every run is checked against the intended deck first (hopper_report.py).
#
# The rate needs the run to reach FIT_HI: about FIT_HI N m / W_Beverloo / dt steps (the script
# prints the estimate; 2000 particles: ~1.6e5 steps). A throughput comparison can use fewer
# steps (the rate is then n/a).
#
# Environment (all optional):
#   VARIANTS       wall variants: primitive, stl, primitive_closed, stl_closed, none
#                  (default "primitive stl"; WALL_COST=1 adds "primitive_closed stl_closed none";
#                  VARIANTS= WALL_COST=1: those three alone)
#   WALL_COST      1: add the closed-outlet and no-wall variants (cost of the walls)
#   OUTLET         outlet diameter in d_p (default 8)
#   SAMPLE         count the discharged particles every SAMPLE steps, both codes (default 500)
#   FIT_LO, FIT_HI discharged fractions bounding the rate fit (default 0.2, 0.8)
#   DECK_DIR       keep the settled bed (and decks) here and reuse it (default: in the work dir)
#   CORES, NP, THREADS, REPEAT, WARMUP, LOAD_MAX, LOAD_WAIT, ALLOW_LOAD, BUILD_DIR, LIGGGHTS,
#   MPIRUN, MPI_FLAGS, SKIN, RUN_TIMEOUT, KEEP_DIR: as compare.sh (README.md)
#
# Exit status: 0 all ran and passed the checks; 2 bad usage or LIGGGHTS missing/failed;
# 3 CoReDEM's binary missing or failed (without it there is no deck, unless DECK_DIR holds one);
# 5 the load average was >= LOAD_MAX before a run (without ALLOW_LOAD=1); 6 a run did not match
# the intended deck.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"

usage() {
  sed -n '2,35p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
SCRIPT=hopper.sh
# shellcheck source=common.sh
source "$here/common.sh" # die, require_peer_tools, check_load, liggghts_run

[[ $# -eq 2 ]] || usage
N="$1"
STEPS="$2"
[[ "$N" =~ ^[0-9]+$ && "$N" -ge 1 ]] || die "N must be a positive integer (particle count), got '$N'"
[[ "$STEPS" =~ ^[0-9]+$ && "$STEPS" -ge 1 ]] || die "STEPS must be a positive integer, got '$STEPS'"

WALL_COST="${WALL_COST:-0}"
VARIANTS="${VARIANTS-primitive stl}"
[[ "$WALL_COST" == 1 ]] && VARIANTS="$VARIANTS primitive_closed stl_closed none"
read -r -a _variants <<<"$VARIANTS" # trim and squeeze the list
VARIANTS="${_variants[*]:-}"
[[ -n "$VARIANTS" ]] || die "no variants (VARIANTS is empty and WALL_COST is not 1)"
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
OUTLET="${OUTLET:-8}"
SAMPLE="${SAMPLE:-500}"
FIT_LO="${FIT_LO:-0.2}"
FIT_HI="${FIT_HI:-0.8}"
for v in $VARIANTS; do
  case "$v" in primitive | stl | primitive_closed | stl_closed | none) ;;
  *) die "VARIANTS must list primitive, stl, primitive_closed, stl_closed and/or none, got '$v'" ;;
  esac
done
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
[[ "$SAMPLE" =~ ^[0-9]+$ && "$SAMPLE" -ge 1 ]] || die "SAMPLE must be a positive integer, got '$SAMPLE'"
[[ "$LOAD_MAX" =~ ^[0-9]*\.?[0-9]+$ ]] || die "LOAD_MAX must be a number, got '$LOAD_MAX'"
[[ "$LOAD_WAIT" =~ ^[0-9]+$ ]] || die "LOAD_WAIT must be a non-negative integer (seconds), got '$LOAD_WAIT'"
python3 -c "import sys; lo, hi = float('$FIT_LO'), float('$FIT_HI'); sys.exit(0 if 0 <= lo < hi <= 1 else 1)" 2>/dev/null ||
  die "FIT_LO and FIT_HI must satisfy 0 <= FIT_LO < FIT_HI <= 1, got '$FIT_LO', '$FIT_HI'"
require_peer_tools

ours="$BUILD_DIR/bin/coredem-bench"
if [[ -n "${KEEP_DIR:-}" ]]; then
  work="$KEEP_DIR"
  mkdir -p "$work"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/coredem-hopper.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
fi
deck="$work/deck"
if [[ -n "${DECK_DIR:-}" ]]; then
  mkdir -p "$DECK_DIR"
  deck="$(cd "$DECK_DIR" && pwd)"
  [[ -e "$work/deck" && ! -L "$work/deck" ]] && die "$work/deck exists and is not a link to DECK_DIR"
  ln -sfn "$deck" "$work/deck"
fi
mkdir -p "$deck"
skin_factor="$(python3 -c "print(repr(float('$SKIN') / 1e-3))")"

cpu_model="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
echo "== hopper deck (bench/decks.md): N = $N, outlet $OUTLET d_p, variants ${VARIANTS}; $WARMUP untimed + $STEPS timed steps; ranks:threads ${pairs[*]}; $REPEAT runs each =="
echo "machine: $(nproc) cores visible, ${cpu_model:-unknown CPU}; load average now: $(cut -d' ' -f1-3 /proc/loadavg)"
[[ "$ALLOW_LOAD" == 1 ]] && echo "ALLOW_LOAD=1: runs started at load >= $LOAD_MAX are labelled LOADED"

# The settled bed: CoReDEM writes it (untimed), or DECK_DIR already holds it for this N/outlet.
if [[ -x "$ours" ]]; then
  max_threads=1
  for p in "${pairs[@]}"; do [[ "${p##*:}" -gt $max_threads ]] && max_threads="${p##*:}"; done
  echo "-- settling the bed (untimed; reused if $deck holds it): $ours dem --case hopper --particles $N --outlet $OUTLET --deck-dir $deck --settle-only --threads $max_threads"
  rc=0
  timeout "$RUN_TIMEOUT" "$ours" dem --case hopper --particles "$N" --outlet "$OUTLET" --deck-dir "$deck" \
    --settle-only --threads "$max_threads" --skin "$skin_factor" >"$work/settle.txt" 2>&1 || rc=$?
  cat "$work/settle.txt"
  [[ $rc -eq 0 ]] || { echo "$SCRIPT: coredem-bench could not settle the bed (exit $rc)" >&2; exit 3; }
elif [[ -f "$deck/hopper.deck" ]]; then
  echo "$SCRIPT: warning: CoReDEM's binary '$ours' does not exist; using the deck in $deck for LIGGGHTS alone" >&2
else
  echo "$SCRIPT: error: CoReDEM's benchmark binary '$ours' does not exist and $deck holds no deck: it writes the settled bed both codes start from. Build it with: cmake -S . -B build && cmake --build build -j2 --target coredem-bench (or set BUILD_DIR)" >&2
  exit 3
fi
python3 - "$deck/hopper.deck" "$N" "$FIT_HI" "$STEPS" "$WARMUP" <<'EOF'
import math, sys
kv = dict(l.strip().split(" = ", 1) for l in open(sys.argv[1]) if " = " in l and l[0] != "#")
n, hi, steps, warm = int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
if int(kv["n"]) != n:
    sys.exit(f"hopper.sh: the deck in {sys.argv[1]} has n = {kv['n']}, not {n}")
rho = float(kv["rho_bulk"]) or 0.6 * float(kv["rho_p"])
w = 0.58 * rho * math.sqrt(float(kv["gravity"])) * (float(kv["outlet_d"]) - 1.5 * float(kv["d_p"])) ** 2.5
need = hi * n * float(kv["mass"]) / w / float(kv["dt"])
print(f"   rho_b = {rho:.1f} kg/m^3; Beverloo {w:.4e} kg/s: reaching {100 * hi:.0f} % discharged takes ~{need:.3g} steps"
      + ("" if warm + steps >= need else f" (this run: {warm + steps}; the discharge rate will be n/a or partial)"))
EOF

ours_status="ok"
[[ -x "$ours" ]] || ours_status="not run: '$ours' does not exist"

run_ours() { # $1 = variant, $2 = threads, $3 = run dir, $4 = repetition
  [[ "$ours_status" == ok ]] || return 0
  local rc=0 cmd walls="${1%_closed}"
  cmd=("$ours" dem --case hopper --walls "$walls" --particles "$N" --outlet "$OUTLET" --deck-dir "$deck"
    --steps "$STEPS" --warmup "$WARMUP" --sample "$SAMPLE" --fit-lo "$FIT_LO" --fit-hi "$FIT_HI"
    --skin "$skin_factor" --backend cpu --threads "$2" --json --samples-out "$3/ours.$4.samples")
  [[ "$1" == *_closed ]] && cmd+=(--closed)
  [[ "$4" == 1 ]] && echo "  CoReDEM:  ${cmd[*]}"
  check_load "$3/load.ours.$4" "CoReDEM run $4"
  timeout "$RUN_TIMEOUT" "${cmd[@]}" >"$3/ours.$4.json" 2>"$3/ours.$4.err" || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 30 "$3/ours.$4.err" >&2 || true
    rm -f "$3/ours.$4.json"
    if [[ $rc -eq 124 ]]; then
      ours_status="timed out after RUN_TIMEOUT=$RUN_TIMEOUT s"
    else
      ours_status="failed (exit $rc; its stderr is above)"
    fi
  fi
}

for variant in $VARIANTS; do
  vdir="$work/$variant"
  mkdir -p "$vdir"
  walls="${variant%_closed}"
  closed=()
  [[ "$variant" == *_closed ]] && closed=(--closed)
  python3 "$here/make_hopper.py" "$deck" "$STEPS" --walls "$walls" "${closed[@]}" --warmup "$WARMUP" \
    --skin "$SKIN" --sample "$SAMPLE" --contacts >"$vdir/params.txt" ||
    die "make_hopper.py failed for $variant"
  for pair in "${pairs[@]}"; do
    np="${pair%%:*}"
    th="${pair##*:}"
    rdir="$vdir/np${np}_t${th}"
    mkdir -p "$rdir"
    echo "-- hopper $variant: LIGGGHTS $np rank(s), CoReDEM $th thread(s) (deck: $deck)"
    for ((r = 1; r <= REPEAT; r++)); do
      run_ours "$variant" "$th" "$rdir" "$r"
      liggghts_run "$deck" "in.hopper_$variant" "$np" "$rdir/screen.liggghts.$r" "$rdir/load.liggghts.$r" \
        "LIGGGHTS run $r" "$([[ "$r" == 1 ]] && echo 1 || echo 0)"
    done
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"

rc=0
python3 "$here/hopper_report.py" "$work" "$N" "$STEPS" "$WARMUP" "$REPEAT" "$VARIANTS" "${pairs[*]}" \
  "$LOAD_MAX" "$SKIN" "$SAMPLE" "$FIT_LO" "$FIT_HI" || rc=$?
[[ $rc -eq 6 ]] && { echo "$SCRIPT: a run did not match the intended deck (see CHECK FAILED above)" >&2; exit 6; }
[[ $rc -ne 0 ]] && die "could not parse the runs (kept in KEEP_DIR if set)"

[[ "$ours_status" == ok ]] && exit 0
echo
echo "CoReDEM: $ours_status" >&2
exit 3
