#!/usr/bin/env bash
# bench/remote/overhead.sh [CELLS] [RTTS_MS] [STEPS] [REPEATS]
#
# Coupling overhead per CFD step against the round trip to the DEM server (docs/performance.md,
# "DEM on a remote node"). For each coupling-cell count in CELLS (default "10000 100000
# 1000000") a case of that many cells with 100 particles (the DEM's work is small, so the
# exchange is as large a share as it gets; coredem-gas as the CFD participant) runs STEPS
# (default 10) fixed 1 ms steps by `coredem run`, against
#   local    the coredem-dem that `coredem run` starts itself on loopback (no CURVE), and
#   RTT      a coredem-dem on an emulated remote node (bench/remote/link.sh: network namespace,
#            veth, CURVE with a client allow-list), for each round trip in RTTS_MS (default
#            "0 0.1 1 10"; 0 = the bare veth, no delay).
# Configurations run interleaved (the order rotates every repeat), REPEATS (default 3) times;
# the load average is printed before each run. At the end a markdown table of medians, per CFD
# step:
#   step          wall time of a step (the orchestrator's overhead.json)
#   DEM compute   the DEM server's advance: its sub-steps (coredem-dem --timers)
#   overhead      step - DEM compute
#   copies        serialisation and copies: coredem-gas's serialise + receive (client library)
#                 + the server's validate + unpack + pack_send (building and handing Sources and
#                 StepDone to ZeroMQ)
#   wire          the data's time on the link both ways: coredem-gas's wait for D - the
#                 server's validate + unpack + advance + ledgers + pack_send (transfer + latency)
#   control       overhead - copies - wire: grants and StepDone of both participants, the
#                 ledgers of both, the gas evaluation, the orchestrator's bookkeeping
#   +vs 0         overhead - overhead of RTT 0 (the same cells), and that in round trips
#
# Before each run it waits up to 240 s for the load average to fall below LOAD_MAX (default 0.5;
# a run started above it is labelled LOADED). Needs root and iproute2 (network namespaces).
# Environment: BUILD_DIR (default
# <project>/build: coredem, coredem-dem, coredem-gas, coredem-relay), THREADS (DEM threads,
# default 2), MBIT (bandwidth limit of the emulated link, default 0 = none), KEEP_DIR (keep
# cases, runs and results.jsonl there).
# Tiny check: bench/remote/overhead.sh 1000 "0 1" 3 1
set -euo pipefail
# shellcheck source=bench/quiet.sh
source "$(dirname "${BASH_SOURCE[0]}")/../quiet.sh" # wait_quiet (LOAD_MAX)
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
die() { echo "overhead.sh: error: $*" >&2; exit 2; }
[[ "${1:-}" == "-h" || "${1:-}" == "--help" || $# -gt 4 ]] && { sed -n '2,33p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
CELLS_LIST="${1:-10000 100000 1000000}"
RTTS="${2:-0 0.1 1 10}"
STEPS="${3:-10}"
REPEATS="${4:-3}"
[[ "$STEPS" =~ ^[0-9]+$ && "$STEPS" -ge 1 ]] || die "STEPS must be a positive integer, got '$STEPS'"
[[ "$REPEATS" =~ ^[0-9]+$ && "$REPEATS" -ge 1 ]] || die "REPEATS must be a positive integer, got '$REPEATS'"
for c in $CELLS_LIST; do [[ "$c" =~ ^[0-9]+$ && "$c" -ge 8 ]] || die "cell counts must be integers >= 8, got '$c'"; done
for r in $RTTS; do [[ "$r" =~ ^[0-9]+([.][0-9]+)?$ ]] || die "round trips must be numbers >= 0 (ms), got '$r'"; done
export BUILD_DIR="${BUILD_DIR:-$root/build}"
THREADS="${THREADS:-2}"
MBIT="${MBIT:-0}"
for p in coredem coredem-dem coredem-gas coredem-relay; do
  [[ -x "$BUILD_DIR/bin/$p" ]] || die "$BUILD_DIR/bin/$p not found (build it, or set BUILD_DIR)"
done
[[ $(id -u) -eq 0 ]] || die "the emulated remote node (network namespaces) needs root"

if [[ -n "${KEEP_DIR:-}" ]]; then work="$KEEP_DIR"; mkdir -p "$work"
else work="$(mktemp -d "${TMPDIR:-/tmp}/coredem-remote-overhead.XXXXXX")"; fi
export LINK_DIR="$work/links"
links=()
cleanup() {
  for l in "${links[@]}"; do "$here/link.sh" down "$l" >/dev/null 2>&1 || true; done
  [[ -z "${KEEP_DIR:-}" ]] && rm -rf "$work"
  return 0
}
trap cleanup EXIT
trap 'exit 130' INT TERM

echo "machine: $(nproc) cores, $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1); DEM threads $THREADS; link bandwidth ${MBIT} Mbit/s (0 = unlimited); $STEPS steps x $REPEATS repeats"
configs=(local)
i=0
for rtt in $RTTS; do
  l="ov$i"
  i=$((i + 1))
  links+=("$l")
  mkdir -p "$LINK_DIR"
  DEM_ARGS="--threads $THREADS --backend cpu --timeout-s 7200" "$here/link.sh" up "$l" "$rtt" "$MBIT" >"$LINK_DIR/$l.up"
  head -1 "$LINK_DIR/$l.up"
  configs+=("$l")
done

# One case per cell count and configuration: a cube of n^3 cells of 5 mm, 100 beads of 1 mm at
# the bottom, air rising at 0.1 m/s, fixed 1 ms steps, no checkpoints or snapshots.
make_case() { # CELLS DIR [DEM_YAML]
  python3 - "$1" "$STEPS" "$2" "$THREADS" "${3:-}" <<'PY'
import os, sys
cells, steps, out, threads, dem_yaml = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5]
n = max(2, round(cells ** (1.0 / 3.0)))
h = 0.005
side = n * h
dem = open(dem_yaml).read().rstrip("\n") + "\n" if dem_yaml else "dem:\n  timers: on\n"
dem += f"  backend: cpu\n  threads: {threads}\n  timeout_s: 3600\n"
os.makedirs(out, exist_ok=True)
open(os.path.join(out, "case.yaml"), "w").write(f"""# bench/remote/overhead.sh: {n}^3 coupling cells, 100 particles
name: remote-overhead-{n**3}
time: {{end: {steps * 1.0e-3!r}, dt: 1.0e-3}}
grid: {{origin: [0.0, 0.0, 0.0], spacing: [{h}, {h}, {h}], cells: [{n}, {n}, {n}]}}
gravity: [0.0, 0.0, -9.81]
materials:
  - {{name: glass, density: 2500.0, k_n: 100.0, e_n: 0.9, friction: 0.3}}
particles:
  - name: beads
    material: glass
    count: 100
    diameter: 1.0e-3
    temperature: 300.0
    packing: random
    region: {{min: [0.0006, 0.0006, 0.0006], max: [{side - 0.0006!r}, {side - 0.0006!r}, {min(side, 0.01) - 0.0006!r}]}}
    seed: 3
walls:
  box: {{min: [0.0, 0.0, 0.0], max: [{side!r}, {side!r}, {side!r}]}}
gas: {{u_g: [0.0, 0.0, 0.1], T_g: 300.0, rho_g: 1.2, mu_g: 1.8e-5}}
{dem}cfd:
  timeout_s: 3600
""")
PY
}
for cells in $CELLS_LIST; do
  make_case "$cells" "$work/cases/$cells-local"
  for l in "${links[@]}"; do make_case "$cells" "$work/cases/$cells-$l" "$LINK_DIR/$l/dem.yaml"; done
done

results="$work/results.jsonl"
: >"$results"
ncfg=${#configs[@]}
for rep in $(seq "$REPEATS"); do
  for cells in $CELLS_LIST; do
    for k in $(seq 0 $((ncfg - 1))); do
      cfg="${configs[$(((k + rep - 1) % ncfg))]}"
      rtt="local"
      timers="$work/runs/$cells-$cfg-$rep/timers-dem.json"
      if [[ "$cfg" != local ]]; then
        # shellcheck disable=SC1090
        source "$LINK_DIR/$cfg/env"
        rtt="$LINK_RTT_MS"
        timers="$LINK_TIMERS_FILE"
        rm -f "$timers"
      fi
      run="$work/runs/$cells-$cfg-$rep"
      rm -rf "$run"
      mkdir -p "$work/runs"
      echo "repeat $rep, $cells cells, $([[ $rtt == local ]] && echo "local DEM (loopback)" || echo "round trip $rtt ms"): $(wait_quiet) (before: $(cut -d' ' -f1-3 /proc/loadavg))"
      "$BUILD_DIR/bin/coredem" run "$work/cases/$cells-$cfg" --out "$run" --no-plots >"$run.log" 2>&1 ||
        { tail -20 "$run.log" >&2; die "coredem run failed ($cells cells, $cfg): $run.log"; }
      for _ in $(seq 100); do [[ -s "$timers" ]] && break; sleep 0.1; done
      [[ -s "$timers" ]] || die "no DEM timers in $timers"
      python3 - "$run" "$timers" "$cells" "$rtt" "$rep" "$(cut -d' ' -f1 /proc/loadavg)" >>"$results" <<'PY'
import json, re, sys
run, timers, cells, rtt, rep, load = sys.argv[1:]
ov = json.load(open(f"{run}/logs/overhead.json"))
dem = json.load(open(timers))
cfd = open(f"{run}/logs/cfd.log").read()
m = re.search(r"exchange per step: serialise ([\d.]+) ms, send ([\d.]+) ms, wait for D ([\d.]+) ms.*receive ([\d.]+) ms", cfd)
if not m:
    sys.exit(f"overhead.sh: no exchange split in {run}/logs/cfd.log (coredem-gas too old?)")
ser, send, wait, recv = (float(v) for v in m.groups())
n = dem["steps"]
d = {k: v / n * 1e3 for k, v in dem["exchange_s"].items()}
adv = dem["advance_s"] / n * 1e3
step = ov["step_wall_s"] * 1e3
compute = ov["dem_compute_s"] * 1e3
copies = ser + recv + d["validate"] + d["unpack"] + d["pack_send"]
wire = wait - (d["validate"] + d["unpack"] + adv + d["ledgers"] + d["pack_send"])
print(json.dumps({"cells": int(cells), "rtt": rtt, "rep": int(rep), "load": float(load),
                  "step": step, "compute": adv, "dem_wall": compute, "overhead": step - adv,
                  "copies": copies, "wire": wire, "control": step - adv - copies - wire,
                  "serialise": ser, "send": send, "wait": wait, "receive": recv,
                  "d_validate": d["validate"], "d_unpack": d["unpack"], "d_pack_send": d["pack_send"]}))
PY
    done
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
python3 - "$results" "$STEPS" "$REPEATS" "$MBIT" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
steps, repeats, mbit = sys.argv[2], sys.argv[3], sys.argv[4]
med = {}
for r in rows:
    med.setdefault((r["cells"], r["rtt"]), []).append(r)
def m(key, rs):
    return statistics.median(r[key] for r in rs)
bw = "unlimited" if float(mbit) == 0 else f"{mbit} Mbit/s"
print(f"Medians of {repeats} runs of {steps} steps, ms per CFD step (bandwidth {bw}; "
      f"load average {min(r['load'] for r in rows):.1f}-{max(r['load'] for r in rows):.1f}):")
print()
print("| cells | round trip | step | DEM compute | **overhead** | copies | wire | control | +vs 0 (round trips) |")
print("|---|---|---|---|---|---|---|---|---|")
order = lambda k: (k[0], -1.0 if k[1] == "local" else float(k[1]))
for key in sorted(med, key=order):
    cells, rtt = key
    rs = med[key]
    extra = ""
    base = med.get((cells, "0"))
    if rtt not in ("local", "0") and base:
        e = m("overhead", rs) - m("overhead", base)
        extra = f"{e:+.2f} ({e / float(rtt):.1f})"
    label = "loopback (local D)" if rtt == "local" else f"{rtt} ms" + (" (bare veth)" if rtt == "0" else "")
    print(f"| {cells:,} | {label} | {m('step', rs):.2f} | {m('compute', rs):.2f} | **{m('overhead', rs):.2f}** | "
          f"{m('copies', rs):.2f} | {m('wire', rs):.2f} | {m('control', rs):.2f} | {extra} |")
PY
