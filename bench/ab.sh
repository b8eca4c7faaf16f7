#!/usr/bin/env bash
# bench/ab.sh BASE_BUILD_DIR NEW_BUILD_DIR [REPEAT]
#
# Interleaved A/B of two builds of coredem-bench on a quiet machine (docs/performance.md):
# `thermochem` (1 thread) and `dem` on the packed and agitated decks (bench/decks.md) at 1 and
# 2 threads, N = 100,000, REPEAT (default 3) runs of each build, base and new alternating.
# Before every run it waits (up to 240 s) for the 1-minute load average to fall below
# LOAD_MAX (default 0.5) and prints it; a run started above it is labelled LOADED.
# Prints one line per run; report medians. Output JSON files are kept in OUT (default: a
# temporary folder, printed).
set -euo pipefail
[[ $# -ge 2 ]] || { sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
base="$1/bin/coredem-bench"
new="$2/bin/coredem-bench"
repeat="${3:-3}"
for b in "$base" "$new"; do
  [[ -x "$b" ]] || { echo "ab.sh: $b not found; build the target coredem-bench in that build directory" >&2; exit 2; }
done
out="${OUT:-$(mktemp -d "${TMPDIR:-/tmp}/coredem-ab.XXXXXX")}"
mkdir -p "$out"
echo "ab.sh: results in $out; $(nproc) cores; load now $(cut -d' ' -f1-3 /proc/loadavg)"
python3 "$here/peers/liggghts/make_deck.py" 100000 300 "$out/deck" --deck agitated --warmup 20 \
  --contacts --skin 1e-4 >/dev/null
vel="$out/deck/agitated.vel"

# shellcheck source=bench/quiet.sh
source "$here/quiet.sh" # wait_quiet
run() { # tag binary args...
  local tag="$1" bin="$2"; shift 2
  printf '%s %-28s %s\n' "$(date +%H:%M:%S)" "$tag" "$(wait_quiet)"
  "$bin" "$@" >"$out/$tag.json" 2>"$out/$tag.err"
  python3 - "$out/$tag.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
if d["command"] == "thermochem":
    s, c = d["sub_models"], d["context"]
    print("   ns/particle/sub-step: gas lens %.1f, contact conduction %.1f, convection %.1f; "
          "whole step all heat / mechanics %.2f" % (s["gas_lens_conduction"], s["contact_conduction"],
          s["convection"], c["whole_step_all_heat"] / c["whole_step_mechanics"]))
else:
    print("   %.4e particle-steps/s, rebuilds %s, %.1f B/particle" % (d["particle_steps_per_s"],
          d["rebuilds"], d["bytes_per_particle"]))
PY
}
for r in $(seq "$repeat"); do
  run "thermochem.base.$r" "$base" thermochem --particles 100000 --threads 1 --json
  run "thermochem.new.$r" "$new" thermochem --particles 100000 --threads 1 --json
done
for cfg in "packed 1 200" "packed 2 300" "agitated 1 300" "agitated 2 300"; do
  read -r deck threads steps <<<"$cfg"
  extra=()
  [[ "$deck" == agitated ]] && extra=(--velocities "$vel")
  for r in $(seq "$repeat"); do
    for v in base new; do
      bin="$base"; [[ $v == new ]] && bin="$new"
      run "dem.$deck.t$threads.$v.$r" "$bin" dem --case "$deck" --particles 100000 --steps "$steps" \
        --warmup 20 --skin 0.1 --backend cpu --threads "$threads" --json "${extra[@]}"
    done
  done
done
