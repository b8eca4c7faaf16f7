#!/bin/sh
# Cost of coredemFoam's mesh <-> coupling-grid map (docs/coredemFoam.md "Any mesh"): the one-off
# cost of the volume-overlap weights and the share of a CFD step spent in mapping and exchange,
# at about 1e5 and 1e6 CFD cells (a 4 x 20 x 4 cm column graded towards the walls, coupling grid
# of 2 mm cells). Not part of `make test`; run it on a quiet machine:
#
#   bench/mesh-map/run.sh BUILD_DIR [OUT_DIR]
#   SIZES="10 20 10" END=0.002 bench/mesh-map/run.sh BUILD_DIR /tmp/mm   # a tiny check that it runs
#
# For each mesh it writes OUT_DIR/<cells>/mapcheck.log (line "map: ... weights in S s": the
# one-off cost; mapcheck-2.log: the decomposed map on 2 processors) and coupled runs with
# --timers on 1 and 2 ranks (cfd.ranks, M:1: RUN/timers-cfd.json is rank 0's, the others'
# RUN/timers-cfd-processorN.json) whose pack / unpack (mapping) and serialise / send / wait /
# receive (exchange) give the shares of the step.
# SIZES: ';'-separated cell counts "nx ny nz" (default "46 48 46;100 100 100"); END: simulated
# seconds of each coupled run (default 0.02: 20 steps).
set -eu
BUILD=${1:?usage: run.sh BUILD_DIR [OUT_DIR]}
OUT=${2:-bench-mesh-map}
SRC=$(cd "$(dirname "$0")/../.." && pwd)
export WM_PROJECT_DIR="${WM_PROJECT_DIR:-/usr/share/openfoam}"
SIZES=${SIZES:-46 48 46;100 100 100}
END=${END:-0.02}
MPI_ARGS="--oversubscribe"
[ "$(id -u)" = 0 ] && MPI_ARGS="$MPI_ARGS --allow-run-as-root"
mkdir -p "$OUT"
# cells per axis (x y z; y vertical): 46 x 48 x 46 ~ 1.0e5, 100 x 100 x 100 = 1.0e6
# (every command in the loop reads /dev/null: mpirun would otherwise eat the remaining sizes)
echo "$SIZES" | tr ';' '\n' | while read -r n; do
  [ -n "$n" ] || continue
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
  sed -i "s/cells: \[5, 20, 5\]/cells: [20, 100, 20]/; s/max: \[0.01, 0.04, 0.01\]/max: [0.04, 0.2, 0.04]/; s/max: \[0.01, 0.020, 0.01\]/max: [0.04, 0.020, 0.04]/; s/count: 1600/count: 25600/; s/end: 0.012 .*/end: $END/" \
    "$d/case/case.yaml"
  blockMesh -case "$d/case/openfoam" > "$d/blockMesh.log" 2>&1
  "$BUILD/bin/coredemMapCheck" -case "$d/case/openfoam" -origin '(0 0 0)' \
    -spacing '(0.002 0.002 0.002)' -counts '(20 100 20)' > "$d/mapcheck.log" 2>&1
  grep "map:" "$d/mapcheck.log"
  printf 'FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }\nnumberOfSubdomains 2;\nmethod simple;\nsimpleCoeffs { n (2 1 1); delta 0.001; }\n' \
    > "$d/case/openfoam/system/decomposeParDict"
  decomposePar -case "$d/case/openfoam" -force > "$d/decomposePar.log" 2>&1
  # shellcheck disable=SC2086
  mpirun $MPI_ARGS -np 2 "$BUILD/bin/coredemMapCheck" -parallel -case "$d/case/openfoam" \
    -origin '(0 0 0)' -spacing '(0.002 0.002 0.002)' -counts '(20 100 20)' \
    > "$d/mapcheck-2.log" 2>&1 < /dev/null
  grep "map:" "$d/mapcheck-2.log"
  rm -rf "$d/case/openfoam/processor"* "$d/case/openfoam/system/decomposeParDict"
  for ranks in 1 2; do
    sed -i "s/^  ranks: .*//; s/^  case: openfoam.*/  case: openfoam\n  ranks: $ranks/" "$d/case/case.yaml"
    "$BUILD/bin/coredem" run "$d/case" --out "$d/run-$ranks" --timers --no-plots \
      > "$d/run-$ranks.log" 2>&1 < /dev/null
    echo "$tag cells, $ranks rank(s):"
    grep -E '"(pack|unpack|serialise|send|wait_dem|receive|step_seconds|exchange_share)"' \
      "$d/run-$ranks/timers-cfd.json" || true
  done
done
