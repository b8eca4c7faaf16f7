#!/usr/bin/env bash
# Runs the drag-law fluidization curves (sweep.yaml: 9 laws x 9 superficial velocities, 81 short
# coupled runs of bed/case.yaml, about 20 min on 2 cores), collects them and writes the minimum
# fluidization velocity of each law against Wen & Yu's correlation and Ergun's equation
# (analyse.py: fluidization_curves.png and umf.md in OUT_DIR/plots).
#   cases/drag-law-fluidization/run.sh [OUT_DIR]        (default runs/drag-law-fluidization)
# An interrupted campaign continues where it stopped when run.sh is run again.
# Binaries: $COREDEM_BIN (default build/bin); Python: $COREDEM_PYTHON (default /usr/bin/python3).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${COREDEM_BIN:-$root/build/bin}
py=${COREDEM_PYTHON:-/usr/bin/python3}
out=${1:-$root/runs/drag-law-fluidization}
if [[ -f $out/campaign.db ]]; then
  "$bin/coredem" campaign resume "$out"
else
  "$bin/coredem" check "$here/sweep.yaml"
  "$bin/coredem" campaign run "$here/sweep.yaml" --out "$out"
fi
"$bin/coredem" campaign collect "$out"
mkdir -p "$out/plots"
"$py" "$here/analyse.py" "$out/summary.csv" --case "$here/bed/case.yaml" --out "$out/plots"
echo "fluidization curves: $out/plots (fluidization_curves.png, umf.md); summary: $out/summary.csv"
