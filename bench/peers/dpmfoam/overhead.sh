#!/usr/bin/env bash
# bench/peers/dpmfoam/overhead.sh "CELLS..." STEPS
#
# The coupling overhead inside a coupled run (docs/performance.md, "Coupling overhead"): for each
# cell count, a cube of that many cells with 100 particles (make_overhead_case.py; the exchange
# dominates) run by `coredem run --timers` for STEPS fixed 1 ms steps; prints per CFD step the
# coredemFoam stages, the DEM server's advance, and the exchange share of the step:
#   exchange = pack + serialise + send + receive + unpack (coredemFoam)
#            + wait for the DEM - the DEM's advance (transfer + the server's own exchange work).
#
# Environment: BUILD_DIR (default <project>/build), KEEP_DIR (keep cases and runs),
#   COREDEM_FOAM_EXCHANGE=copy (coredemFoam gathers/scatters through its own copies instead of
#   sending from and receiving into its fields: the "before" of docs/performance.md).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
die() { echo "overhead.sh: error: $*" >&2; exit 2; }
[[ $# -eq 2 ]] || { sed -n '2,14p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
CELLS_LIST="$1"
STEPS="$2"
[[ "$STEPS" =~ ^[0-9]+$ && "$STEPS" -ge 1 ]] || die "STEPS must be a positive integer, got '$STEPS'"
BUILD_DIR="${BUILD_DIR:-$root/build}"
export WM_PROJECT_DIR="${WM_PROJECT_DIR:-/usr/share/openfoam}"
for p in coredem coredem-dem coredemFoam; do
  [[ -x "$BUILD_DIR/bin/$p" ]] || die "$BUILD_DIR/bin/$p not found (build with -DCOREDEM_OPENFOAM=ON, or set BUILD_DIR)"
done
command -v blockMesh >/dev/null || die "blockMesh not found: install Debian's openfoam"
if [[ -n "${KEEP_DIR:-}" ]]; then work="$KEEP_DIR"; mkdir -p "$work"
else work="$(mktemp -d "${TMPDIR:-/tmp}/coredem-overhead.XXXXXX")"; trap 'rm -rf "$work"' EXIT; fi
echo "machine: $(nproc) cores, $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1); load before: $(cut -d' ' -f1-3 /proc/loadavg); exchange mode: ${COREDEM_FOAM_EXCHANGE:-in place}"
for cells in $CELLS_LIST; do
  [[ "$cells" =~ ^[0-9]+$ ]] || die "cell counts must be integers, got '$cells'"
  c="$work/case-$cells"
  rm -rf "$c" "$work/run-$cells"
  python3 "$here/make_overhead_case.py" "$cells" "$STEPS" "$c" >/dev/null
  (cd "$c/openfoam" && blockMesh >log.blockMesh 2>&1) || die "blockMesh failed ($c/openfoam/log.blockMesh)"
  "$BUILD_DIR/bin/coredem" run "$c" --out "$work/run-$cells" --no-plots --timers >"$work/log-$cells" 2>&1 ||
    { tail -20 "$work/log-$cells" >&2; die "coredem run failed for $cells cells"; }
  python3 - "$work/run-$cells" <<'PY'
import json, sys
run = sys.argv[1]
cfd = json.load(open(f"{run}/timers-cfd.json"))
dem = json.load(open(f"{run}/timers-dem.json"))
n = cfd["steps"]
st = {k: v["seconds"] / n * 1e3 for k, v in cfd["stages"].items()}
step = cfd["step_seconds"] / n * 1e3
dem_adv = dem["advance_s"] / dem["steps"] * 1e3
own = st["pack"] + st["serialise"] + st["send"] + st["receive"] + st["unpack"]
transfer = st["wait_dem"] - dem_adv
ex = own + transfer
print(f"cells {cfd['cells']:>8}  steps {n}  step {step:8.1f} ms | pack {st['pack']:.2f} serialise {st['serialise']:.2f} "
      f"send {st['send']:.2f} wait {st['wait_dem']:.1f} (DEM advance {dem_adv:.1f}) receive {st['receive']:.2f} "
      f"unpack {st['unpack']:.2f} | UEqn {st['UEqn']:.1f} pEqn {st['pEqn']:.1f} TEqn {st['TEqn']:.1f} "
      f"advance {st['advance']:.1f} rest {st['rest']:.1f} ms | exchange {ex:.1f} ms = {100 * ex / step:.1f} % "
      f"(coredemFoam side {100 * own / step:.1f} %)")
PY
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
