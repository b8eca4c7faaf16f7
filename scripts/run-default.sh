#!/usr/bin/env bash
# Runs the default case (cases/settling-heated, DEM-only: particles settling in a box of
# prescribed hot gas) with the binaries of BUILD_DIR (default: build) and prints where the
# results and the plots are.
#   scripts/run-default.sh [BUILD_DIR]
set -euo pipefail
build=${1:-build}
top=$(cd "$(dirname "$0")/.." && pwd)
coredem="$build/bin/coredem"
for exe in coredem coredem-dem coredem-gas; do
  if [[ ! -x $build/bin/$exe ]]; then
    echo "run-default: $build/bin/$exe not found; build first (make run does it)" >&2
    exit 1
  fi
done

run_dir="$top/runs/settling-heated-$(date +%Y%m%d-%H%M%S)"
# coredem makes the plots itself at the end (scripts/plot/plot_run.py with COREDEM_PYTHON).
"$coredem" run "$top/cases/settling-heated" --out "$run_dir"
echo
echo "run-default: results in $run_dir"
echo "  timeseries : $run_dir/timeseries.csv"
echo "  particles  : $run_dir/particles.xdmf (open in ParaView), snapshots in $run_dir/snapshots/"
echo "  checkpoints: $run_dir/checkpoints/ (continue with: $coredem resume $run_dir)"
echo "  plots      : $run_dir/plots/timeseries.png, $run_dir/plots/particles.png"
