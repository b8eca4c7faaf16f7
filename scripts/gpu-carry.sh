#!/usr/bin/env bash
# scripts/gpu-carry.sh: prepares .carry/ (ignored by git) with what scripts/gpu-check.sh needs on
# a GPU machine where nothing can be installed and that is reached with a copy of this tree:
# GoogleTest's source tree (Debian's googletest package, /usr/src/googletest, about 4 MB), for
# the DEM core's conformance tests. Copy .carry/ along with the tree.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
src="${GTEST_SOURCE:-/usr/src/googletest}"
[[ -f "$src/CMakeLists.txt" ]] ||
  { echo "gpu-carry: no GoogleTest source tree at $src (Debian: apt-get install googletest)" >&2; exit 1; }
mkdir -p "$root/.carry"
rm -rf "$root/.carry/googletest"
cp -r "$src" "$root/.carry/googletest"
echo "gpu-carry: $root/.carry/googletest ($(du -sh "$root/.carry/googletest" | cut -f1)) from $src"
