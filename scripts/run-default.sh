#!/usr/bin/env bash
# Runs the default case with the binaries of BUILD_DIR (default: build) and prints where the
# results and the plots are:
#   cases/fluidized-bed-cooling  coupled OpenFOAM (coredemFoam) + DEM: hot glass beads fluidized
#                                and cooled by air (about 1-2 min on 2 cores);
#   cases/settling-heated        DEM-only fallback when coredemFoam was not built
#                                (COREDEM_OPENFOAM=OFF, or Debian's openfoam not installed).
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

if [[ -x $build/bin/coredemFoam ]]; then
  case_name=fluidized-bed-cooling
else
  case_name=settling-heated
  echo "run-default: $build/bin/coredemFoam was not built (COREDEM_OPENFOAM=OFF or OpenFOAM not" >&2
  echo "  installed: scripts/install-deps.sh installs Debian's openfoam); running the DEM-only case" >&2
  echo "  cases/settling-heated instead of the coupled cases/fluidized-bed-cooling." >&2
fi

run_dir="$top/runs/$case_name-$(date +%Y%m%d-%H%M%S)"
echo "run-default: coredem run cases/$case_name --out $run_dir"
start=$(date +%s)
# coredem makes the plots itself at the end (scripts/plot/plot_run.py with COREDEM_PYTHON).
"$coredem" run "$top/cases/$case_name" --out "$run_dir"
echo
echo "run-default: cases/$case_name finished in $(($(date +%s) - start)) s; results in $run_dir"
echo "  timeseries : $run_dir/timeseries.csv"
echo "  particles  : $run_dir/particles.xdmf (open in ParaView), snapshots in $run_dir/snapshots/"
if [[ $case_name == fluidized-bed-cooling ]]; then
  echo "  gas fields : $run_dir/openfoam/<time>/ (OpenFOAM case: paraFoam -case $run_dir/openfoam)"
fi
echo "  checkpoints: $run_dir/checkpoints/ (continue with: $coredem resume $run_dir)"
echo "  plots      : $run_dir/plots/timeseries.png (top left: mean, min, max particle temperature vs time),"
echo "               $run_dir/plots/particles.png"
