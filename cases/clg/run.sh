#!/usr/bin/env bash
# Runs the CLG gasifier and makes its validation plots (scripts/plot/validation_clg.py: dry,
# N2-free outlet composition and solid conversion). Default: the reduced column (reduced.yaml,
# 1 s); --full: the full reactor (case.yaml, 20 s, weeks on 2 cores). The run prints its
# progress with ETA; the script ends by printing where the plots are.
#   cases/clg/run.sh [--full] [OUT_DIR]          (default OUT_DIR runs/clg-reduced or runs/clg)
# Binaries: $COREDEM_BIN (default build/bin); Python: $COREDEM_PYTHON (default /usr/bin/python3).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${COREDEM_BIN:-$root/build/bin}
py=${COREDEM_PYTHON:-/usr/bin/python3}
file=reduced.yaml
out=$root/runs/clg-reduced
if [[ ${1:-} == --full ]]; then
  file=case.yaml
  out=$root/runs/clg
  shift
fi
out=${1:-$out}
"$bin/coredem" run "$here/$file" --out "$out"
"$py" "$root/scripts/plot/validation_clg.py" "$out" --summary "$out/plots/clg_summary.md"
echo "validation plots: $out/plots (clg_outlet.png, clg_conversion.png, clg_summary.md)"
