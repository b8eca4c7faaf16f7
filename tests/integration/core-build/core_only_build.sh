#!/usr/bin/env bash
# core_only_build.sh SOURCE_DIR BUILD_DIR NVCC|OFF [COMPILER_LAUNCHER]
#
# Configures and builds the DEM core alone (-DCOREDEM_CORE_ONLY=ON) with every third-party
# package but OpenMP made unavailable (CMAKE_DISABLE_FIND_PACKAGE_<Pkg>, pkg-config seeing no
# modules), then checks that
#   1. no object of the core included a header of those packages (the compilers' depfiles list
#      every header a translation unit read: /usr/include holds them even when CMake finds none);
#   2. no executable of the core needs one of their libraries (readelf's NEEDED entries);
#   3. the core's tests pass: dem_unit_tests with the backend and stage conformance suite on cpu
#      and cuda-sim; only the cuda instantiations may skip, and only without a GPU;
#   4. coredem-bench runs the dem deck on the cpu and answers gpu-probe.
# GoogleTest comes from its source tree (Debian's googletest: /usr/src/googletest), as on a
# machine where it is carried.
set -euo pipefail
src="$1"
build="$2"
nvcc="${3:-OFF}"
launcher="${4:-}"
fail() { echo "core_only_build: FAILED: $*" >&2; exit 1; }

packages=(Protobuf HDF5 yaml-cpp spdlog fmt CLI11 GTest cppzmq ZeroMQ benchmark SQLite3 PkgConfig
          Python3 Python)
args=(-S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCOREDEM_CORE_ONLY=ON
      -DCOREDEM_GTEST_SOURCE_DIR=/usr/src/googletest)
for p in "${packages[@]}"; do args+=("-DCMAKE_DISABLE_FIND_PACKAGE_$p=ON"); done
if [[ "$nvcc" != OFF ]]; then
  # One architecture keeps the test short; which one does not matter for what it proves.
  args+=(-DCOREDEM_CUDA=ON "-DCMAKE_CUDA_COMPILER=$nvcc" -DCOREDEM_CUDA_ARCHITECTURES=90)
else
  args+=(-DCOREDEM_CUDA=OFF)
  echo "core_only_build: the parent build has no CUDA: the core is built without it here"
fi
if [[ -n "$launcher" ]]; then
  args+=("-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher" "-DCMAKE_CUDA_COMPILER_LAUNCHER=$launcher")
fi
empty="$build/no-pkg-config-modules"
mkdir -p "$empty"
echo "== configure: cmake ${args[*]}"
PKG_CONFIG_LIBDIR="$empty" PKG_CONFIG_PATH="$empty" cmake "${args[@]}" >"$build/configure.log" 2>&1 ||
  { tail -30 "$build/configure.log" >&2; fail "configure (log: $build/configure.log)"; }
grep -E "CoReDEM .*core only" "$build/configure.log"
if [[ "$nvcc" != OFF ]]; then
  grep -q "CUDA backend ON" "$build/configure.log" || fail "the CUDA backend was not enabled"
fi
grep -q "tests ON" "$build/configure.log" || fail "the core's tests were not configured"

echo "== build"
cmake --build "$build" -j 2 >"$build/build.log" 2>&1 ||
  { grep -E "error" "$build/build.log" | head -30 >&2; fail "build (log: $build/build.log)"; }

echo "== 1. headers read by the core's translation units"
forbidden='/(spdlog|fmt|yaml-cpp|hdf5|zmq|google/protobuf|CLI|benchmark)/|/(H5[A-Za-z]*|hdf5[a-z_]*|zmq[a-z_]*|sqlite3|yaml)\.h(pp)?$'
depfiles=$(find "$build" -path "$build/_deps" -prune -o -name '*.d' -print)
[[ -n "$depfiles" ]] || fail "no depfiles under $build (the generator writes none?)"
leaks=$(xargs cat <<<"$depfiles" | tr ' \\' '\n\n' | grep -E '^/' | grep -E "$forbidden" | sort -u || true)
# GoogleTest's headers must come from the source tree, not from an installed package.
gtest_installed=$(xargs cat <<<"$depfiles" | tr ' \\' '\n\n' | grep -E '^/usr/include/(gtest|gmock)/' | sort -u || true)
[[ -z "$leaks$gtest_installed" ]] ||
  fail "the core read headers of packages it must not need:
$leaks$gtest_installed"
echo "   $(wc -l <<<"$depfiles") depfiles: no header of ${packages[*]}"

echo "== 2. libraries the core's executables need"
for exe in "$build/bin/coredem-bench" "$build/tests/dem_unit_tests"; do
  [[ -x "$exe" ]] || fail "$exe was not built"
  needed=$(readelf -d "$exe" | sed -n 's/.*NEEDED.*\[\(.*\)\]/\1/p' | tr '\n' ' ')
  echo "   $(basename "$exe"): $needed"
  if grep -qE 'spdlog|fmt|yaml|hdf5|zmq|protobuf|gtest|gmock|benchmark|sqlite' <<<"$needed"; then
    fail "$exe needs a library the core must not need"
  fi
done

echo "== 3. the core's tests (dem_unit_tests)"
log="$build/dem_unit_tests.log"
xml="$build/dem_unit_tests.xml"
"$build/tests/dem_unit_tests" --gtest_output="xml:$xml" >"$log" 2>&1 ||
  { grep -E "Failure|FAILED|Which is" "$log" | head -40 >&2; fail "dem_unit_tests (log: $log)"; }
grep -E '^\[  (PASSED|SKIPPED) +\] [0-9]' "$log"
grep -q '^\[ *OK \] StageConformance/0\.' "$log" || fail "the cpu stage conformance tests did not run"
grep -q '^\[ *OK \] StageConformance/1\.' "$log" || fail "the cuda-sim stage conformance tests did not run"
# A skip is allowed only where CUDA is missing (a cuda instantiation or a CUDA-device test).
bad_skips=$(grep -o '<skipped message="[^"]*"' "$xml" | grep -v 'CUDA' || true)
[[ -z "$bad_skips" ]] || fail "tests skipped for another reason than a missing GPU:
$bad_skips"

echo "== 4. coredem-bench"
"$build/bin/coredem-bench" dem --case packed --particles 2000 --steps 10 --warmup 2 --threads 2 --json |
  grep -q '"particle_steps_per_s"' || fail "coredem-bench dem printed no figure"
probe_rc=0
"$build/bin/coredem-bench" gpu-probe || probe_rc=$?
[[ $probe_rc -eq 0 || $probe_rc -eq 3 ]] || fail "coredem-bench gpu-probe exited $probe_rc"
echo "core_only_build: OK"
