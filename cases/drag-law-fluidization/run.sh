#!/usr/bin/env bash
# Runs the drag-law fluidization curves (sweep.yaml: 9 laws x 9 superficial velocities, 81 short
# coupled runs of bed/case.yaml, about 20 min on 2 cores), collects them and writes the minimum
# fluidization velocity of each law against Wen & Yu's correlation and Ergun's equation
# (analyse.py: fluidization_curves.png and umf.md in OUT_DIR/plots).
#   cases/drag-law-fluidization/run.sh [OUT_DIR]        (default runs/drag-law-fluidization)
#   cases/drag-law-fluidization/run.sh --calibrated [OUT_DIR]
#       the Syamlal-O'Brien law calibrated to U_mf (sweep-syamlal-calibrated.yaml, 9 runs, ~3 min;
#       default OUT_DIR runs/drag-law-fluidization-syamlal-calibrated)
# An interrupted campaign continues where it stopped when run.sh is run again.
# Binaries: $COREDEM_BIN (default build/bin); Python: $COREDEM_PYTHON (default /usr/bin/python3).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${COREDEM_BIN:-$root/build/bin}
py=${COREDEM_PYTHON:-/usr/bin/python3}
sweep=sweep.yaml
base=bed
label=()
out=$root/runs/drag-law-fluidization
if [[ ${1:-} == --calibrated ]]; then
  sweep=sweep-syamlal-calibrated.yaml
  base=bed-syamlal-calibrated
  label=(--label "syamlal-obrien calibrated")
  out=$root/runs/drag-law-fluidization-syamlal-calibrated
  shift
fi
out=${1:-$out}
if [[ -f $out/campaign.db ]]; then
  "$bin/coredem" campaign resume "$out"
else
  "$bin/coredem" check "$here/$sweep"
  "$bin/coredem" campaign run "$here/$sweep" --out "$out"
fi
"$bin/coredem" campaign collect "$out"
mkdir -p "$out/plots"
"$py" "$here/analyse.py" "$out/summary.csv" --case "$here/$base/case.yaml" --out "$out/plots" \
  "${label[@]}"
echo "fluidization curves: $out/plots (fluidization_curves.png, umf.md); summary: $out/summary.csv"
