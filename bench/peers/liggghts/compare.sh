#!/usr/bin/env bash
# bench/peers/liggghts/compare.sh N STEPS
#
# Runs the `packed` deck of bench/decks.md with N particles for STEPS steps, first in LIGGGHTS
# (Debian's liggghts 3.8, NP MPI ranks) and then in CoReDEM
# (`coredem-bench dem --case packed ... --backend cpu --threads THREADS --json`), one after the
# other on this machine, and prints both throughputs (particle-steps/s over the timed loop
# only: LIGGGHTS' "Loop time", CoReDEM's own timed loop; setup, reading and the first force
# evaluation are excluded from both) and the ratio ours/LIGGGHTS.
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
#   KEEP_DIR       keep the generated deck and logs here (default: a temp dir, removed)
#   LIGGGHTS_ONLY  set to 1 to skip CoReDEM
#
# Exit status: 0 both ran; 2 bad usage or LIGGGHTS missing/failed; 3 LIGGGHTS ran but
# CoReDEM's binary is missing or failed (the LIGGGHTS figures are still printed).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"

usage() {
  sed -n '2,24p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
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
LIGGGHTS_ONLY="${LIGGGHTS_ONLY:-0}"
[[ "$NP" =~ ^[0-9]+$ && "$NP" -ge 1 ]] || die "NP must be a positive integer, got '$NP'"
[[ "$THREADS" =~ ^[0-9]+$ && "$THREADS" -ge 1 ]] || die "THREADS must be a positive integer, got '$THREADS'"

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

# ---- LIGGGHTS ----
python3 "$here/make_deck.py" "$N" "$STEPS" "$work" --contacts --skin "$SKIN" >"$work/deck.txt" ||
  die "make_deck.py failed for N=$N STEPS=$STEPS"
mpi_args=(-np "$NP")
[[ "$(id -u)" == 0 ]] && mpi_args+=(--allow-run-as-root)
[[ "$NP" -gt "$(nproc)" ]] && mpi_args+=(--oversubscribe)
# shellcheck disable=SC2206
[[ -n "$MPI_FLAGS" ]] && mpi_args+=($MPI_FLAGS)

echo "LIGGGHTS: $MPIRUN ${mpi_args[*]} $LIGGGHTS -in in.packed  (in $work)"
set +e
(cd "$work" && timeout "$RUN_TIMEOUT" "$MPIRUN" "${mpi_args[@]}" "$LIGGGHTS" -in in.packed -log log.liggghts \
  >screen.liggghts 2>&1)
rc=$?
set -e
if [[ $rc -ne 0 ]]; then
  tail -n 30 "$work/screen.liggghts" >&2 || true
  [[ $rc -eq 124 ]] && die "LIGGGHTS did not finish within RUN_TIMEOUT=$RUN_TIMEOUT s"
  die "LIGGGHTS failed (exit $rc); its last output is above"
fi

lig_report="$(python3 - "$work/screen.liggghts" "$N" "$STEPS" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
n, steps = int(sys.argv[2]), int(sys.argv[3])
loops = re.findall(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms", text)
if not loops or int(loops[0][2]) != steps or int(loops[0][3]) != n:
    sys.exit(f"could not find 'Loop time ... for {steps} steps with {n} atoms' in the LIGGGHTS output")
loop = float(loops[0][0])
grid = re.search(r"(\d+) by (\d+) by (\d+) MPI processor grid", text)
builds = re.search(r"Neighbor list builds = (\d+)", text)
mem = re.search(r"Memory usage per processor = (\S+) Mbytes", text)
# the untimed `run 0` after the timed run prints c_csum (sum over particles of their
# particle-particle contact counts)
csum = None
m = re.search(r"Step\s+Atoms\s+KinEng\s+csum\s*\n\s*\d+\s+\d+\s+\S+\s+(\S+)", text)
if m:
    csum = float(m.group(1))
print(f"loop={loop!r}")
print(f"pss={n * steps / loop!r}")
print(f"grid={'x'.join(grid.groups()) if grid else '?'}")
print(f"builds={builds.group(1) if builds else '?'}")
print(f"mem_mb={mem.group(1) if mem else '?'}")
print(f"cpp={csum / n if csum is not None else float('nan')!r}")
EOF
)" || die "could not parse the LIGGGHTS output ($work/screen.liggghts)"
eval "$lig_report"
lig_loop="$loop"; lig_pss="$pss"; lig_cpp="$cpp"

# ---- CoReDEM ----
ours_status="skipped (LIGGGHTS_ONLY=1)"
ours_pss=""
if [[ "$LIGGGHTS_ONLY" != 1 ]]; then
  if [[ -n "$ours_missing" ]]; then
    ours_status="missing"
  else
    ours_cmd=("$ours" dem --case packed --particles "$N" --steps "$STEPS" --backend cpu --threads "$THREADS" --json)
    echo "CoReDEM:  ${ours_cmd[*]}"
    set +e
    timeout "$RUN_TIMEOUT" "${ours_cmd[@]}" >"$work/ours.json" 2>"$work/ours.err"
    rc=$?
    set -e
    if [[ $rc -ne 0 ]]; then
      tail -n 30 "$work/ours.err" >&2 || true
      if [[ $rc -eq 124 ]]; then
        ours_status="timed out after RUN_TIMEOUT=$RUN_TIMEOUT s"
      else
        ours_status="failed (exit $rc; its stderr is above)"
      fi
    elif ours_report="$(python3 - "$work/ours.json" <<'EOF'
import json, math, sys
text = open(sys.argv[1]).read()
dec = json.JSONDecoder()
found = None
for i, c in enumerate(text):
    if c == "{":
        try:
            obj, _ = dec.raw_decode(text[i:])
        except ValueError:
            continue
        if isinstance(obj, dict) and "particle_steps_per_s" in obj:
            found = obj
if found is None:
    sys.exit("no JSON object with 'particle_steps_per_s' in coredem-bench's output")
def num(keys):
    for k in keys:
        v = found.get(k)
        if isinstance(v, (int, float)):
            return float(v)
    return float("nan")
print(f"pss={float(found['particle_steps_per_s'])!r}")
print(f"cpp={num(['contacts_per_particle', 'contacts_per_particle_pp']) !r}")
print(f"bpp={num(['bytes_per_particle', 'memory_bytes_per_particle']) !r}")
print(f"loop={num(['loop_seconds', 'loop_time_s', 'seconds', 'elapsed_s', 'wall_s']) !r}")
EOF
)"; then
      eval "$ours_report"
      ours_pss="$pss"; ours_cpp="$cpp"; ours_bpp="$bpp"; ours_loop="$loop"
      ours_status="ok"
    else
      ours_status="its output had no parsable JSON with particle_steps_per_s (see $work/ours.json)"
    fi
  fi
fi

# ---- report ----
python3 - "$N" "$STEPS" "$NP" "$THREADS" "$grid" "$builds" "$mem_mb" "$lig_loop" "$lig_pss" "$lig_cpp" \
  "${ours_pss:-}" "${ours_cpp:-nan}" "${ours_bpp:-nan}" "${ours_loop:-nan}" <<'EOF'
import math, sys
(n, steps, np_, threads, grid, builds, mem_mb, lig_loop, lig_pss, lig_cpp,
 ours_pss, ours_cpp, ours_bpp, ours_loop) = sys.argv[1:]
n = int(n)
def f(x, fmt):
    try:
        v = float(x)
    except ValueError:
        return "n/a"
    return "n/a" if math.isnan(v) else format(v, fmt)
try:
    lig_bpp = float(mem_mb) * 1048576 * int(np_) / n
except ValueError:
    lig_bpp = float("nan")
print()
print(f"{'code':10s} {'parallelism':>14s} {'loop time [s]':>14s} {'particle-steps/s':>17s} "
      f"{'contacts/particle':>18s} {'bytes/particle':>15s}")
print(f"{'LIGGGHTS':10s} {np_ + ' MPI (' + grid + ')':>14s} {f(lig_loop, '.3f'):>14s} "
      f"{f(lig_pss, '.4e'):>17s} {f(lig_cpp, '.3f'):>18s} {f(lig_bpp, '.0f'):>15s}")
if ours_pss:
    print(f"{'CoReDEM':10s} {threads + ' threads':>14s} {f(ours_loop, '.3f'):>14s} "
          f"{f(ours_pss, '.4e'):>17s} {f(ours_cpp, '.3f'):>18s} {f(ours_bpp, '.0f'):>15s}")
    print(f"\nratio ours/LIGGGHTS (particle-steps/s): {float(ours_pss) / float(lig_pss):.3f}")
print()
print("Timed loops only: LIGGGHTS' 'Loop time' of the run (read_data, setup, the first neighbour")
print("build and force evaluation excluded); CoReDEM's own timed step loop (its setup excluded).")
print(f"LIGGGHTS: neighbour list builds during the loop = {builds}; contacts/particle = particle-")
print("particle contacts per particle (each pair counted at both ends, walls not counted) after the")
print("last step; bytes/particle = LIGGGHTS' 'Memory usage per processor' x ranks / N (its own estimate).")
EOF

case "$ours_status" in
  ok) exit 0 ;;
  "skipped (LIGGGHTS_ONLY=1)") echo "CoReDEM: skipped (LIGGGHTS_ONLY=1)"; exit 0 ;;
  missing) echo; echo "CoReDEM: not run. $ours_missing" >&2; exit 3 ;;
  *) echo; echo "CoReDEM: $ours_status" >&2; exit 3 ;;
esac
