#!/usr/bin/env bash
# bench/coupling/staggered.sh [--build DIR] [--repeat N] [--tiny] [--out DIR]
#                             [--dem-endpoint tcp://HOST:PORT [--dem-server-key FILE]
#                              [--dem-client-key DIR]]
#
# Sequential vs staggered coupling (docs/coupling-schemes.md), interleaved, on two cases made
# from cases/fluidized-bed-cooling:
#   cfd-heavy  coredemFoam on a fine mesh (the blockMesh refined FINE x FINE in x and y; the
#              coupling grid stays 10 x 30 x 2), FEW beads;
#   dem-heavy  the coarse mesh (= the coupling grid) with MANY beads over the whole column.
# One DEM thread (dem.threads: 1) and one CFD process, fixed Δt_CFD = 2.5e-4 s for END s
# simulated. Each (case, scheme) runs REPEAT times, the schemes alternating; before every run the
# 1-minute load average is printed (LOAD_MAX, default 0.5: the script waits up to 240 s for it and
# labels a run started above it LOADED). Reports the median wall seconds per step (median over
# the steps of timeseries.csv's wall_step_s, then the median over the repeats) and the speed-up
# sequential/staggered as a markdown table.
#
# --dem-endpoint EP uses a DEM server that is already running (e.g. the one of
# bench/remote/link.sh in a network namespace behind a delaying relay) instead of starting one:
# the cases get dem.endpoint EP, dem.server_key FILE (its CURVE public key) and dem.client_key DIR
# (a client key pair on its allow-list) when given. That server's own --threads applies.
# Without coredemFoam (COREDEM_OPENFOAM=OFF) both cases use coredem-gas (a prescribed gas: no
# CFD work, so no overlap to gain) and the table says so.
#
# Sizes: default END=0.05 s (200 steps), FINE=4 (9600 cells), FEW=100, MANY=2000, REPEAT=3;
# --tiny: END=0.0025 s (10 steps), FINE=2, FEW=50, MANY=600, REPEAT=1 (a check that it runs).
# Environment overrides: END, FINE, FEW, MANY, REPEAT, LOAD_MAX.
set -euo pipefail
usage() { sed -n '2,31p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$top/build"
out=""
endpoint="" server_key="" client_key=""
tiny=0
repeat_opt=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build="$(cd "$2" && pwd)"; shift 2 ;;
    --repeat) repeat_opt="$2"; shift 2 ;;
    --tiny) tiny=1; shift ;;
    --out) out="$2"; shift 2 ;;
    --dem-endpoint) endpoint="$2"; shift 2 ;;
    --dem-server-key) server_key="$(realpath "$2")"; shift 2 ;;
    --dem-client-key) client_key="$(realpath "$2")"; shift 2 ;;
    -h|--help) usage ;;
    *) echo "staggered.sh: unknown option $1" >&2; usage ;;
  esac
done
if [[ $tiny == 1 ]]; then
  END="${END:-0.0025}" FINE="${FINE:-2}" FEW="${FEW:-50}" MANY="${MANY:-600}" REPEAT="${REPEAT:-1}"
else
  END="${END:-0.05}" FINE="${FINE:-4}" FEW="${FEW:-100}" MANY="${MANY:-2000}" REPEAT="${REPEAT:-3}"
fi
REPEAT="${repeat_opt:-$REPEAT}"
coredem="$build/bin/coredem"
for exe in coredem coredem-dem coredem-gas; do
  [[ -x "$build/bin/$exe" ]] || { echo "staggered.sh: $build/bin/$exe not built" >&2; exit 2; }
done
participant=coredemFoam
[[ -x "$build/bin/coredemFoam" ]] || participant=coredem-gas
[[ -n "$server_key" || -z "$client_key" ]] || { echo "staggered.sh: --dem-client-key needs --dem-server-key" >&2; exit 2; }
python="${COREDEM_PYTHON:-/usr/bin/python3}"
[[ -x "$python" ]] || python=python3
out="${out:-$(mktemp -d "${TMPDIR:-/tmp}/coredem-staggered.XXXXXX")}"
mkdir -p "$out"
echo "staggered.sh: results in $out; $(nproc) cores; participant $participant; END=$END s," \
  "FINE=$FINE, FEW=$FEW, MANY=$MANY, REPEAT=$REPEAT${endpoint:+; DEM server at $endpoint}"

# ---- the cases ------------------------------------------------------------------------------
make_case() { # name scheme beads fine
  local name="$1" scheme="$2" beads="$3" fine="$4" dir="$out/cases/$1-$2"
  rm -rf "$dir"
  mkdir -p "$dir"
  cp -r "$top/cases/fluidized-bed-cooling/openfoam" "$dir/openfoam"
  "$python" - "$top/cases/fluidized-bed-cooling/case.yaml" "$dir" "$name" "$scheme" "$beads" \
    "$fine" "$END" "$participant" "$endpoint" "$server_key" "$client_key" <<'PY'
import re, sys
src, d, name, scheme, beads, fine, end, participant, endpoint, skey, ckey = sys.argv[1:]
t = open(src).read()
t = re.sub(r"(?m)^name: .*$", f"name: bench-{name}-{scheme}", t)
t = re.sub(r"(?ms)^time:.*?(?=^\S)", f"time:\n  end: {end}\n  dt: 2.5e-4\n\n", t)
t = re.sub(r"(?m)^    count: \d+$", f"    count: {beads}", t)
if int(beads) > 400:  # the whole column above the plate: solid fraction stays below 0.35
    t = t.replace("region: {min: [0.0, 0.004, 0.0], max: [0.02, 0.024, 0.004]}",
                  "region: {min: [0.0, 0.004, 0.0], max: [0.02, 0.06, 0.004]}")
t = re.sub(r"(?ms)^checkpoint:.*?(?=^\S)", "checkpoint:\n  every_steps: 0\n\n", t)
t = re.sub(r"(?ms)^output:.*\Z", "output:\n  every: 0\n", t)
dem = "dem:\n  backend: cpu\n  threads: 1\n  timeout_s: 600\n"
if endpoint:
    dem += f"  endpoint: {endpoint}\n"
    if skey:
        dem += f"  server_key: {skey}\n"
    if ckey:
        dem += f"  client_key: {ckey}\n"
t = re.sub(r"(?ms)^dem:.*?(?=^\S)", dem + "\n", t)
if participant == "coredem-gas":
    t = re.sub(r"(?ms)^cfd:.*?(?=^\S)",
               "cfd:\n  timeout_s: 600\n\ngas:\n  u_g: [0.0, 1.5, 0.0]\n  T_g: 293.15\n"
               "  rho_g: 1.204\n  mu_g: 1.81e-5\n\n", t)
else:
    t = t.replace("  timeout_s: 120", "  timeout_s: 600")
t += f"\ncoupling:\n  scheme: {scheme}\n"
open(f"{d}/case.yaml", "w").write(t)
bm = f"{d}/openfoam/system/blockMeshDict"
b = open(bm).read()
b2 = b.replace("(10 30 2) simpleGrading", f"({10 * int(fine)} {30 * int(fine)} 2) simpleGrading")
assert b2 != b or int(fine) == 1, "blockMeshDict: no (10 30 2) block to refine"
open(bm, "w").write(b2)
PY
  [[ $participant == coredemFoam ]] || rm -rf "$dir/openfoam"
  "$coredem" check "$dir" >"$dir/check.log" 2>&1 || { cat "$dir/check.log" >&2; exit 1; }
}
for scheme in sequential staggered; do
  make_case cfd-heavy "$scheme" "$FEW" "$FINE"
  make_case dem-heavy "$scheme" "$MANY" 1
done

# ---- the runs -------------------------------------------------------------------------------
# shellcheck source=bench/quiet.sh
source "$(dirname "${BASH_SOURCE[0]}")/../quiet.sh" # wait_quiet
results="$out/results.csv"
echo "case,scheme,repeat,steps,median_wall_step_s,load" >"$results"
run() { # case scheme repeat
  local c="$1" s="$2" r="$3" run_dir="$out/runs/$1-$2-$3" load
  rm -rf "$run_dir"
  load="$(wait_quiet)"
  printf '%s %-10s %-10s #%s %s\n' "$(date +%H:%M:%S)" "$c" "$s" "$r" "$load"
  if ! "$coredem" run "$out/cases/$c-$s" --out "$run_dir" --no-plots >"$out/$c-$s-$r.log" 2>&1; then
    echo "staggered.sh: run failed, see $out/$c-$s-$r.log" >&2
    tail -20 "$out/$c-$s-$r.log" >&2
    exit 1
  fi
  "$python" - "$run_dir/timeseries.csv" "$c" "$s" "$r" "$load" >>"$results" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
walls = [float(r["wall_step_s"]) for r in rows]
print(f"{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{len(walls)},{statistics.median(walls):.6g},"
      f"{sys.argv[5]}")
PY
  tail -1 "$results" | awk -F, '{printf "   %s steps, median %s s per step\n", $4, $5}'
}
for r in $(seq "$REPEAT"); do
  for c in cfd-heavy dem-heavy; do
    # Alternate which scheme goes first so that a drifting load does not favour one.
    if (( r % 2 )); then order="sequential staggered"; else order="staggered sequential"; fi
    for s in $order; do
      run "$c" "$s" "$r"
    done
  done
done

# ---- the table ------------------------------------------------------------------------------
"$python" - "$results" "$participant" "$endpoint" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
participant, endpoint = sys.argv[2], sys.argv[3]
print()
print(f"CFD participant {participant}; DEM server "
      f"{endpoint if endpoint else 'started by coredem (1 thread)'}; wall s per CFD step "
      "(median over steps, then over repeats)")
if participant == "coredem-gas":
    print("(coredemFoam not built: the prescribed gas does no CFD work, so the staggered scheme "
          "has nothing to overlap)")
print()
print("| case | sequential [s/step] | staggered [s/step] | speed-up | repeats | loaded runs |")
print("|---|---|---|---|---|---|")
for case in ("cfd-heavy", "dem-heavy"):
    m = {}
    loaded = 0
    for scheme in ("sequential", "staggered"):
        v = [float(r["median_wall_step_s"]) for r in rows if r["case"] == case and r["scheme"] == scheme]
        loaded += sum(1 for r in rows if r["case"] == case and r["scheme"] == scheme and "LOADED" in r["load"])
        m[scheme] = statistics.median(v) if v else float("nan")
        n = len(v)
    print(f"| {case} | {m['sequential']:.4g} | {m['staggered']:.4g} | "
          f"{m['sequential'] / m['staggered']:.2f} | {n} | {loaded} |")
PY
echo
echo "staggered.sh: per-run medians in $results"
