#!/bin/sh
# Cost of coredemFoam's mesh <-> coupling-grid map (docs/coredemFoam.md "Any mesh"): the one-off
# cost of the volume-overlap weights and the share of a CFD step spent in mapping and exchange,
# at about 1e5 and 1e6 CFD cells (a 4 x 20 x 4 cm column graded towards the walls, coupling grid
# of 2 mm cells). Not part of `make test`; run it on a quiet machine:
#
#   bench/mesh-map/run.sh BUILD_DIR [OUT_DIR]
#
# For each mesh it writes OUT_DIR/<cells>/mapcheck.log (line "map: ... weights in S s": the
# one-off cost) and a 20-step coupled run with --timers whose RUN/timers-cfd.json gives the
# pack / unpack (mapping) and serialise / send / wait / receive (exchange) shares of the step.
# Decomposed runs (2 ranks) need the M:1 exchange, which is not built yet: only the decomposed
# map's cost is measured (coredemMapCheck -parallel on 2 processors).
set -eu
BUILD=${1:?usage: run.sh BUILD_DIR [OUT_DIR]}
OUT=${2:-bench-mesh-map}
SRC=$(cd "$(dirname "$0")/../.." && pwd)
export WM_PROJECT_DIR="${WM_PROJECT_DIR:-/usr/share/openfoam}"
mkdir -p "$OUT"
# cells per axis (x z y): 46 x 46 x 48 ~ 1.0e5, 100 x 100 x 100 = 1.0e6
for n in "46 48 46" "100 100 100"; do
  set -- $n
  tag=$(( $1 * $2 * $3 ))
  d="$OUT/$tag"
  rm -rf "$d" && mkdir -p "$d"
  cp -r "$SRC/cases/packed-bed-graded" "$d/case"
  cat > "$d/case/openfoam/system/blockMeshDict" <<DICT
FoamFile { version 2.0; format ascii; class dictionary; object blockMeshDict; }
scale 1;
vertices
(
    (0 0 0) (0.04 0 0) (0.04 0.2 0) (0 0.2 0)
    (0 0 0.04) (0.04 0 0.04) (0.04 0.2 0.04) (0 0.2 0.04)
);
blocks ( hex (0 1 2 3 4 5 6 7) ($1 $2 $3)
         simpleGrading (((0.5 0.5 4) (0.5 0.5 0.25)) 1 ((0.5 0.5 4) (0.5 0.5 0.25))) );
boundary
(
    inlet  { type patch; faces ((0 1 5 4)); }
    outlet { type patch; faces ((3 7 6 2)); }
    walls  { type wall;  faces ((0 4 7 3) (1 2 6 5) (0 3 2 1) (4 5 6 7)); }
);
DICT
  sed -i "s/cells: \[5, 20, 5\]/cells: [20, 100, 20]/; s/max: \[0.01, 0.04, 0.01\]/max: [0.04, 0.2, 0.04]/; s/max: \[0.01, 0.020, 0.01\]/max: [0.04, 0.020, 0.04]/; s/count: 1600/count: 25600/; s/end: 0.012/end: 0.02/" \
    "$d/case/case.yaml"
  blockMesh -case "$d/case/openfoam" > "$d/blockMesh.log" 2>&1
  "$BUILD/bin/coredemMapCheck" -case "$d/case/openfoam" -origin '(0 0 0)' \
    -spacing '(0.002 0.002 0.002)' -counts '(20 100 20)' > "$d/mapcheck.log" 2>&1
  grep "map:" "$d/mapcheck.log"
  printf 'FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }\nnumberOfSubdomains 2;\nmethod simple;\nsimpleCoeffs { n (2 1 1); delta 0.001; }\n' \
    > "$d/case/openfoam/system/decomposeParDict"
  decomposePar -case "$d/case/openfoam" -force > "$d/decomposePar.log" 2>&1
  mpirun --oversubscribe -np 2 "$BUILD/bin/coredemMapCheck" -parallel -case "$d/case/openfoam" \
    -origin '(0 0 0)' -spacing '(0.002 0.002 0.002)' -counts '(20 100 20)' \
    > "$d/mapcheck-2.log" 2>&1
  grep "map:" "$d/mapcheck-2.log"
  rm -rf "$d/case/openfoam/processor"*
  "$BUILD/bin/coredem" run "$d/case" --out "$d/run" --timers --no-plots > "$d/run.log" 2>&1
  grep -E '"(pack|unpack|serialise|send|wait_dem|receive|step_seconds|exchange_share)"' \
    "$d/run/timers-cfd.json" || true
done
