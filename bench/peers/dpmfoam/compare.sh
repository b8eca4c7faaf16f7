#!/usr/bin/env bash
# bench/peers/dpmfoam/compare.sh N SIM_SECONDS
#
# Runs the same fluidized bed (bench/peers/dpmfoam/README.md) with N particles for SIM_SECONDS
# simulated seconds, first with OpenFOAM's DPMFoam (Debian's openfoam, serial) and then with
# CoReDEM (`coredem run`: coredemFoam + coredem-dem, cpu backend, 2 threads), one after the
# other on this machine, and prints for both the wall seconds per simulated second (and CPU
# seconds per simulated second), the ratio DPMFoam/CoReDEM, and the time-averaged pressure
# drop and bed height over the second half of the run (from the fields both write 20 times).
# The meshes are made by blockMesh before the timed runs (excluded from both times).
#
# Environment (all optional):
#   BUILD_DIR      where bin/coredem, coredem-dem, coredemFoam live (default: <project>/build)
#   RUN_TIMEOUT    seconds allowed for each run                      (default: 7200)
#   KEEP_DIR       keep both cases, runs and logs here               (default: a temp dir, removed)
#   SEED           seed of the start positions' jitter               (default: 1)
#   ONLY           dpmfoam or coredem: run one code only             (default: both)
#   TIMERS         1: `coredem run --timers` (per-stage timers of both participants,
#                  timers-cfd.json / timers-dem.json in the run folder)
#   SUBSTEP_VELOCITY  fastest-particle speed (m/s) at which DPMFoam's collision sub-step
#                  equals CoReDEM's dt_DEM (make_case.py --substep-velocity; default 0.025)
#   SUBSTEP_TOL    allowed relative difference of DPMFoam's logged collision sub-cycles
#                  from the intended ceil(deltaT/dt_DEM) (report.py; default 0.10)
#
# Exit status: 0 both ran; 2 bad usage, a program missing or DPMFoam failed; 3 CoReDEM failed;
# 4 DPMFoam's logged sub-cycle count is off the intended one by more than SUBSTEP_TOL (the
# figures are printed, marked as not like-for-like).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"

usage() { sed -n '2,27p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
die() { echo "compare.sh: error: $*" >&2; exit 2; }

[[ $# -eq 2 ]] || usage
N="$1"
SIM="$2"
[[ "$N" =~ ^[0-9]+$ && "$N" -ge 1 ]] || die "N must be a positive integer (particle count), got '$N'"
[[ "$SIM" =~ ^[0-9]*\.?[0-9]+([eE]-?[0-9]+)?$ ]] || die "SIM_SECONDS must be a positive number, got '$SIM'"
BUILD_DIR="${BUILD_DIR:-$root/build}"
RUN_TIMEOUT="${RUN_TIMEOUT:-7200}"
SEED="${SEED:-1}"
ONLY="${ONLY:-}"
TIMERS="${TIMERS:-0}"
[[ -z "$ONLY" || "$ONLY" == dpmfoam || "$ONLY" == coredem ]] || die "ONLY must be dpmfoam or coredem, got '$ONLY'"

export WM_PROJECT_DIR="${WM_PROJECT_DIR:-/usr/share/openfoam}"
command -v python3 >/dev/null || die "python3 not found (it writes the cases)"
command -v timeout >/dev/null || die "timeout (coreutils) not found"
[[ -x /usr/bin/time ]] || die "/usr/bin/time not found (Debian package time)"
command -v blockMesh >/dev/null || die "blockMesh not found: install Debian's openfoam (scripts/install-deps.sh)"
if [[ "$ONLY" != coredem ]]; then
  command -v DPMFoam >/dev/null || die "DPMFoam not found: install Debian's openfoam (scripts/install-deps.sh)"
fi
if [[ "$ONLY" != dpmfoam ]]; then
  for p in coredem coredem-dem coredemFoam; do
    [[ -x "$BUILD_DIR/bin/$p" ]] ||
      die "$BUILD_DIR/bin/$p not found. Build with: cmake -S . -B build -DCOREDEM_OPENFOAM=ON && cmake --build build -j2 --target coredem coredem-dem coredemFoam (or set BUILD_DIR)"
  done
fi

if [[ -n "${KEEP_DIR:-}" ]]; then
  work="$KEEP_DIR"
  mkdir -p "$work"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/coredem-dpmfoam.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
fi

cpu_model="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
echo "== fluidized bed (bench/peers/dpmfoam/README.md): N = $N, $SIM s simulated =="
echo "machine: $(nproc) cores visible, ${cpu_model:-unknown CPU}; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

timer_flag=()
[[ "$TIMERS" == 1 ]] && timer_flag=(--timers)
substep_flag=()
[[ -n "${SUBSTEP_VELOCITY:-}" ]] && substep_flag=(--substep-velocity "$SUBSTEP_VELOCITY")
python3 "$here/make_case.py" "$N" "$SIM" "$work" --seed "$SEED" "${substep_flag[@]}" >"$work/parameters.txt" ||
  die "make_case.py failed for N=$N SIM_SECONDS=$SIM"
sed 's/^/  /' "$work/parameters.txt"
(cd "$work/dpmfoam" && blockMesh >log.blockMesh 2>&1) || die "blockMesh failed: $work/dpmfoam/log.blockMesh"
(cd "$work/coredem/openfoam" && blockMesh >log.blockMesh 2>&1) || die "blockMesh failed: $work/coredem/openfoam/log.blockMesh"

status=0
if [[ "$ONLY" != coredem ]]; then
  echo "DPMFoam: (cd $work/dpmfoam && DPMFoam)"
  rc=0
  (cd "$work/dpmfoam" && /usr/bin/time -f '%e %U %S' -o time.txt timeout "$RUN_TIMEOUT" DPMFoam >log.DPMFoam 2>&1) || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 20 "$work/dpmfoam/log.DPMFoam" >&2 || true
    [[ $rc -eq 124 ]] && die "DPMFoam did not finish within RUN_TIMEOUT=$RUN_TIMEOUT s"
    die "DPMFoam failed (exit $rc); its last output is above"
  fi
fi
if [[ "$ONLY" != dpmfoam ]]; then
  echo "CoReDEM: $BUILD_DIR/bin/coredem run $work/coredem --out $work/coredem-run --no-plots"
  rm -rf "$work/coredem-run"
  rc=0
  /usr/bin/time -f '%e %U %S' -o "$work/coredem.time.txt" timeout "$RUN_TIMEOUT" \
    "$BUILD_DIR/bin/coredem" run "$work/coredem" --out "$work/coredem-run" --no-plots "${timer_flag[@]}" \
    >"$work/coredem.log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 20 "$work/coredem.log" >&2 || true
    tail -n 20 "$work/coredem-run/logs/cfd.log" >&2 2>/dev/null || true
    echo "compare.sh: CoReDEM failed (exit $rc); logs in $work (set KEEP_DIR to keep them)" >&2
    status=3
  fi
fi
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
rc=0
python3 "$here/report.py" "$work" "$N" "$SIM" || rc=$?
if [[ $rc -eq 4 ]]; then
  echo "compare.sh: DPMFoam did not run the intended collision sub-step (see SUB-STEP MISMATCH above)" >&2
  [[ $status -eq 0 ]] && status=4
elif [[ $rc -ne 0 ]]; then
  die "could not read the runs (set KEEP_DIR to keep them)"
fi
exit $status
