#!/usr/bin/env bash
# bench/gas-model/run.sh [--build DIR] [--repeat N] [--tiny] [--out DIR]
#
# Cost per CFD step of coredemFoam's two gas models (docs/coredemFoam.md): the constant-property
# gas (constant/transportProperties) and the variable-density ideal-gas mixture
# (case.yaml gas_properties.model: ideal_gas, pure N2: coredem writes the JANAF + Sutherland
# dictionary that OpenFOAM's rhoReactionThermo evaluates), on the same empty column at CELLS mesh
# cells each.
#
# The case: the 1 x 4 x 1 cm column of tests/e2e/openfoam/cases/column with its blockMesh refined
# to (n, 4n, n) cells (n = round((cells/4)^(1/3))) over the 5 x 20 x 5 coupling grid (overlap
# map), gas entering at 0.3 m/s and 400 K into gas at 293.15 K (the temperature front keeps the
# energy equation and, in the variable path, the properties busy), one frozen 0.1 mm bead with
# heat exchange off (the DEM does nearly nothing), fixed dt = 2e-4 s, STEPS steps, no output or
# checkpoints. coredemFoam runs with -timers; the figure per run is from RUN/timers-cfd.json:
#   gas   = (UEqn + pEqn + TEqn + YEqn + rest)/steps   the gas solve (rest: properties, ledgers)
#   step  = (step_seconds - wait_dem - advance)/steps  everything coredemFoam does per step
# Each (size, model) runs REPEAT times, the models alternating (the first of a pair swaps every
# repeat); before each run the 1-minute load average is printed (bench/quiet.sh: waits up to
# 240 s for it to fall below LOAD_MAX, default 0.5, and labels a run started above it LOADED).
# Prints a markdown table of the medians over the repeats and the ratio variable/constant.
#
# Sizes: default CELLS="10000 100000", STEPS=40, REPEAT=3; --tiny: CELLS="500 2000", STEPS=4,
# REPEAT=1 (a check that it runs). Environment overrides: CELLS, STEPS, REPEAT, LOAD_MAX.
set -euo pipefail
usage() { sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$top/build"
out=""
tiny=0
repeat_opt=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build="$(cd "$2" && pwd)"; shift 2 ;;
    --repeat) repeat_opt="$2"; shift 2 ;;
    --tiny) tiny=1; shift ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) usage ;;
    *) echo "gas-model/run.sh: unknown option $1" >&2; usage ;;
  esac
done
if [[ $tiny == 1 ]]; then
  CELLS="${CELLS:-500 2000}" STEPS="${STEPS:-4}" REPEAT="${REPEAT:-1}"
else
  CELLS="${CELLS:-10000 100000}" STEPS="${STEPS:-40}" REPEAT="${REPEAT:-3}"
fi
REPEAT="${repeat_opt:-$REPEAT}"
for exe in coredem coredem-dem coredemFoam; do
  [[ -x "$build/bin/$exe" ]] || {
    echo "gas-model/run.sh: $build/bin/$exe not built (configure with -DCOREDEM_OPENFOAM=ON)" >&2
    exit 2
  }
done
coredem="$build/bin/coredem"
python="${COREDEM_PYTHON:-/usr/bin/python3}"
[[ -x "$python" ]] || python=python3
template="$top/tests/e2e/openfoam/cases/column"
out="${out:-$(mktemp -d "${TMPDIR:-/tmp}/coredem-gas-model.XXXXXX")}"
mkdir -p "$out"
echo "gas-model/run.sh: results in $out; $(nproc) cores; CELLS=$CELLS, STEPS=$STEPS," \
  "REPEAT=$REPEAT"

# ---- the cases ------------------------------------------------------------------------------
make_case() { # cells model
  local dir="$out/cases/$1-$2"
  rm -rf "$dir"
  mkdir -p "$dir"
  cp -r "$template" "$dir/openfoam"
  "$python" - "$dir" "$1" "$2" "$STEPS" <<'PY'
import os, re, sys
d, cells, model, steps = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
of = f"{d}/openfoam"
n = max(1, round((cells / 4) ** (1 / 3)))
def sub(path, f):
    t = open(path).read()
    t2 = f(t)
    open(path, "w").write(t2)
for root, _, files in os.walk(of):
    for name in files:
        sub(os.path.join(root, name),
            lambda t: t.replace("@U_IN@", "0.3").replace("@T_IN@", "400"))
sub(f"{of}/system/blockMeshDict",
    lambda t: t.replace("(5 20 5) simpleGrading", f"({n} {4 * n} {n}) simpleGrading"))
header = ("FoamFile\n{\n    version 2.0;\n    format ascii;\n    class %s;\n"
          "    location \"%s\";\n    object %s;\n}\n")
if model == "variable":
    # coredem writes constant/thermophysicalProperties (pure N2) from case.yaml's ideal_gas; the
    # template's zero gauge kinematic p is taken as Pa.
    open(f"{of}/0/N2", "w").write(header % ("volScalarField", "0", "N2") + """
dimensions [0 0 0 0 0 0 0];
internalField uniform 1;
boundaryField
{
    inlet  { type fixedValue; value uniform 1; }
    outlet { type inletOutlet; inletValue uniform 1; value uniform 1; }
    walls  { type zeroGradient; }
}
""")
    gas = ("gas_properties: {model: ideal_gas, temperature: 293.15, pressure: 101325.0}\n"
           "species: [{name: N2, molar_mass: 0.028014}]")
else:
    gas = ("gas_properties: {density: 1.204, viscosity: 1.81e-5, conductivity: 0.0257, "
           "cp: 1006.0,\n                 temperature: 293.15, pressure: 101325.0}")
dt = 2e-4
open(f"{d}/case.yaml", "w").write(f"""name: bench-gas-model-{cells}-{model}
grid: {{origin: [0, 0, 0], spacing: [0.002, 0.002, 0.002], cells: [5, 20, 5]}}
gravity: [0.0, -9.81, 0.0]
{gas}
walls:
  box: {{min: [0.0, 0.0, 0.0], max: [0.01, 0.04, 0.01]}}
cfd: {{participant: coredemFoam, case: openfoam, timeout_s: 600}}
dem: {{backend: cpu, threads: 1, timeout_s: 600}}
time: {{end: {steps * dt!r}, dt: {dt}, dt_dem: {dt}}}
checkpoint: {{every_steps: 0}}
output: {{every: 0}}
models: {{heat: "off", motion: frozen}}
materials:
  - {{name: glass, density: 2500.0, k_n: 100.0, e_n: 0.5, friction: 0.3}}
particles:
  - {{name: bead, material: glass, count: 1, diameter: 1.0e-4, packing: lattice,
     region: {{min: [0.0, 0.0042, 0.0], max: [0.0004, 0.0046, 0.0004]}}}}
""")
print(f"{n} x {4 * n} x {n} = {n * n * 4 * n}")
PY
}
declare -A mesh
for cells in $CELLS; do
  for model in constant variable; do
    mesh[$cells]="$(make_case "$cells" "$model")"
    "$coredem" check "$out/cases/$cells-$model" >"$out/cases/$cells-$model/check.log" 2>&1 || {
      cat "$out/cases/$cells-$model/check.log" >&2
      exit 1
    }
  done
done

# ---- the runs -------------------------------------------------------------------------------
# shellcheck source=bench/quiet.sh
source "$(dirname "${BASH_SOURCE[0]}")/../quiet.sh" # wait_quiet
results="$out/results.csv"
echo "cells,mesh,model,repeat,steps,gas_s_per_step,step_s_per_step,load" >"$results"
run() { # cells model repeat
  local c="$1" m="$2" r="$3" run_dir="$out/runs/$1-$2-$3" load
  rm -rf "$run_dir"
  load="$(wait_quiet)"
  printf '%s %8s cells %-8s #%s %s\n' "$(date +%H:%M:%S)" "$c" "$m" "$r" "$load"
  if ! "$coredem" run "$out/cases/$c-$m" --out "$run_dir" --no-plots --timers \
    >"$out/$c-$m-$r.log" 2>&1; then
    echo "gas-model/run.sh: run failed, see $out/$c-$m-$r.log and $run_dir/logs/cfd.log" >&2
    tail -20 "$out/$c-$m-$r.log" >&2
    exit 1
  fi
  "$python" - "$run_dir/timers-cfd.json" "$c" "${mesh[$c]}" "$m" "$r" "$load" >>"$results" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
s, n = t["stages"], t["steps"]
gas = sum(s[k]["seconds"] for k in ("UEqn", "pEqn", "TEqn", "YEqn", "rest")) / n
step = (t["step_seconds"] - s["wait_dem"]["seconds"] - s["advance"]["seconds"]) / n
print(f"{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{sys.argv[5]},{n},{gas:.6g},{step:.6g},"
      f"{sys.argv[6]}")
PY
  tail -1 "$results" | awk -F, '{printf "   %s steps, gas %s s/step, coredemFoam %s s/step\n", $5, $6, $7}'
}
for r in $(seq "$REPEAT"); do
  for c in $CELLS; do
    if (( r % 2 )); then order="constant variable"; else order="variable constant"; fi
    for m in $order; do
      run "$c" "$m" "$r"
    done
  done
done

# ---- the table ------------------------------------------------------------------------------
"$python" - "$results" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print()
print("coredemFoam wall s per CFD step (median over repeats); gas = UEqn + pEqn + TEqn + YEqn + "
      "rest, step = all but the wait for the DEM and the next grant")
print()
print("| mesh cells | constant gas [s] | variable gas [s] | variable/constant | "
      "constant step [s] | variable step [s] | repeats | loaded runs |")
print("|---|---|---|---|---|---|---|---|")
for cells in dict.fromkeys(r["cells"] for r in rows):
    sel = [r for r in rows if r["cells"] == cells]
    med = {}
    for m in ("constant", "variable"):
        for k in ("gas_s_per_step", "step_s_per_step"):
            v = [float(r[k]) for r in sel if r["model"] == m]
            med[m, k] = statistics.median(v) if v else float("nan")
    loaded = sum(1 for r in sel if "LOADED" in r["load"])
    n = len(sel) // 2
    print(f"| {sel[0]['mesh']} | {med['constant', 'gas_s_per_step']:.4g} | "
          f"{med['variable', 'gas_s_per_step']:.4g} | "
          f"{med['variable', 'gas_s_per_step'] / med['constant', 'gas_s_per_step']:.2f} | "
          f"{med['constant', 'step_s_per_step']:.4g} | {med['variable', 'step_s_per_step']:.4g} | "
          f"{n} | {loaded} |")
PY
echo
echo "gas-model/run.sh: per-run figures in $results"
