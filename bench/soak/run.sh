#!/usr/bin/env bash
# Soak: STEPS coupled steps (default 10^5) of a small case against a real coredem-dem, with
# injected peer faults (CFD participant killed and restarted every 1000 steps, session ended
# by Shutdown every 5000 and by a dropped orchestrator connection every 10000, malformed
# messages from every peer every ~100 steps, delayed GasFields and grants), printing the
# server's RSS every REPORT steps. Exit 1 if a step fails, a fault is not answered as
# documented, the server does not stop on SIGTERM, or its RSS grows by more than
# MAX_GROWTH_MIB after the first tenth of the run. Not a timing benchmark.
#
#   bench/soak/run.sh [STEPS] [REPORT]          (BUILD=build by default; MAX_GROWTH_MIB=64)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${BUILD:-$root/build}"
steps="${1:-100000}"
report="${2:-5000}"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCOREDEM_CUDA=OFF -DCOREDEM_OPENFOAM=OFF
fi
cmake --build "$build" -j"${JOBS:-2}" --target coredem-dem coredem-soak
exec "$build/bin/coredem-soak" --dem "$build/bin/coredem-dem" --steps "$steps" \
  --report-every "$report" --max-growth-mib "${MAX_GROWTH_MIB:-64}" \
  --work-dir "${WORK_DIR:-$build/soak}"
