#!/usr/bin/env bash
# Builds the libFuzzer target for envelope decoding + validation (bench/fuzz/envelope_fuzz.cpp)
# with clang, ASan and coverage on the protocol library, in its own build folder, and runs
# EXECS executions (default 10^7) in one process, seeded with protocol/golden/ (a second run
# goes on from the corpus the first one grew).
#
#   bench/fuzz/run.sh [EXECS] [MAX_SECONDS]
#
# Environment: FUZZ_BUILD (build folder, default build-fuzz), FUZZ_CORPUS (working corpus,
# default FUZZ_BUILD/corpus; the golden messages are copied in first), CLANG (default
# clang++-14 if present, else clang++). Exit status: libFuzzer's (0: no crash in EXECS runs or
# MAX_SECONDS; a crash leaves crash-* in FUZZ_BUILD and exits non-zero). Not a benchmark: the
# figures that matter are the execution count and the crash count.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
execs="${1:-10000000}"
maxSeconds="${2:-3600}"
build="${FUZZ_BUILD:-$root/build-fuzz}"
corpus="${FUZZ_CORPUS:-$build/corpus}"
cxx="${CLANG:-$(command -v clang++-14 || command -v clang++)}"
cc="${cxx/clang++/clang}"
[ -x "$cxx" ] || { echo "run.sh: clang++ not found (set CLANG)" >&2; exit 2; }

mkdir -p "$build"
flags="-fsanitize=fuzzer-no-link,address -fno-omit-frame-pointer -g"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOREDEM_FUZZ=ON \
  -DCOREDEM_CUDA=OFF -DCOREDEM_OPENFOAM=OFF -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_C_COMPILER="$cc" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" > "$build/configure.log" 2>&1 ||
  { cat "$build/configure.log" >&2; exit 2; }
cmake --build "$build" -j"${JOBS:-2}" --target coredem-fuzz-envelope

mkdir -p "$corpus"
# The golden messages of every version, named apart.
for v in "$root"/protocol/golden/v1.*; do
  for f in "$v"/*.cdmf; do cp -n "$f" "$corpus/$(basename "$v")-$(basename "$f")"; done
done
cd "$build"
start=$(date +%s)
set +e
ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}" "$build/bin/coredem-fuzz-envelope" \
  -runs="$execs" -max_total_time="$maxSeconds" -rss_limit_mb=2048 \
  -max_len=65536 -print_final_stats=1 "$corpus" 2>&1 | tee "$build/fuzz.log" | grep -v "^#[0-9]*.*\(NEW\|REDUCE\|pulse\)"
rc=${PIPESTATUS[0]}
set -e
end=$(date +%s)
runs=$(grep -o "stat::number_of_executed_units: *[0-9]*" "$build/fuzz.log" | grep -o "[0-9]*$" || echo "?")
crashes=$(find "$build" -maxdepth 1 \( -name 'crash-*' -o -name 'leak-*' -o -name 'oom-*' -o -name 'timeout-*' \) | wc -l)
echo "fuzz: $runs executions, $crashes crash/leak/oom/timeout files, $((end - start)) s, exit $rc"
exit "$rc"
