#!/usr/bin/env bash
# Runs the liquid-fluidized bed's expansion campaign (sweep.yaml: 3 drag laws x 5 water
# velocities, 15 coupled runs of case.yaml, about 12 min on 2 cores), collects it and compares
# the bed voidage with Richardson & Zaki (analyse.py: expansion.md and bed_expansion.png in
# OUT_DIR/plots).
#   cases/liquid-fluidized-bed/run.sh [OUT_DIR]        (default runs/liquid-fluidized-bed-expansion)
# An interrupted campaign continues where it stopped when run.sh is run again.
# Binaries: $COREDEM_BIN (default build/bin); Python: $COREDEM_PYTHON (default /usr/bin/python3).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${COREDEM_BIN:-$root/build/bin}
py=${COREDEM_PYTHON:-/usr/bin/python3}
out=${1:-$root/runs/liquid-fluidized-bed-expansion}
if [[ -f $out/campaign.db ]]; then
  "$bin/coredem" campaign resume "$out"
else
  "$bin/coredem" check "$here/sweep.yaml"
  "$bin/coredem" campaign run "$here/sweep.yaml" --out "$out"
fi
"$bin/coredem" campaign collect "$out"
"$py" "$here/analyse.py" "$out" --case "$here/case.yaml" --out "$out/plots"
echo "bed expansion: $out/plots (bed_expansion.png, expansion.md); summary: $out/summary.csv"
