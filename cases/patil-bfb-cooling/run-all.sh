#!/usr/bin/env bash
# Runs the four Patil variants (75 g / 125 g, adiabatic / cold walls) one after the other and
# makes the validation plots (scripts/plot/validation_patil.py). Default: the reduced 8 mm
# slices (slice-*.yaml, ~1-2 h on 2 cores); --full: the full beds (*.yaml, weeks on 2 cores).
# Each run prints its progress with ETA; the script ends by printing where the plots are.
#   cases/patil-bfb-cooling/run-all.sh [--full] [OUT_DIR]     (default OUT_DIR runs/patil[-full])
# Binaries: $COREDEM_BIN (default build/bin); Python: $COREDEM_PYTHON (default /usr/bin/python3).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${COREDEM_BIN:-$root/build/bin}
py=${COREDEM_PYTHON:-/usr/bin/python3}
prefix=slice-
out=$root/runs/patil
if [[ ${1:-} == --full ]]; then
  prefix=
  out=$root/runs/patil-full
  shift
fi
out=${1:-$out}
mkdir -p "$out"
args=()
for inv in 75g 125g; do
  for w in adiabatic cold-walls; do
    name=${prefix}$inv-$w
    "$bin/coredem" run "$here/$name.yaml" --out "$out/$name"
    args+=(--run "$inv-$w=$out/$name")
  done
done
"$py" "$root/scripts/plot/validation_patil.py" "${args[@]}" --out "$out/plots" --summary "$out/plots/summary.md"
echo "validation plots: $out/plots (patil_temperature.png, patil_ledger.png, summary.md)"
