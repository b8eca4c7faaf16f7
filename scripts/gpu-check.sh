#!/usr/bin/env bash
# scripts/gpu-check.sh [BUILD_DIR]
#
# GPU readiness of the DEM core (docs/performance.md "GPU check"): one prepared script for a
# machine with one GPU where nothing can be installed (CUDA, CMake and a C++ compiler only). It
# fits in about 5 minutes there:
#   1. configures BUILD_DIR (default: build-gpu) as the DEM core alone (-DCOREDEM_CORE_ONLY=ON:
#      no protobuf, ZeroMQ, HDF5, yaml-cpp, spdlog, CLI11 needed) with the CUDA backend for this
#      machine's GPU, and builds coredem-bench and dem_unit_tests with every core; GoogleTest
#      comes from a source tree (GTEST_SOURCE);
#   2. asks the CUDA runtime (`coredem-bench gpu-probe`) and, when it sees no device, looks for
#      GPU hardware (nvidia-smi, /dev/nvidia*, lspci): a CUDA runtime failure, a failing
#      nvidia-smi or a GPU the runtime cannot see is a failure (exit 1); only a machine with no
#      NVIDIA GPU and no driver exits 0 here, printing "NO GPU";
#   3. with a GPU: the DEM core's unit tests with the backend and stage conformance suite on
#      cpu, cuda-sim and cuda (a skipped test is a failure there); compute-sanitizer memcheck on
#      a short cuda run where the runtime supports it (said so where it does not, e.g. gVisor);
#      `coredem-bench dem` (packed, agitated) and `coredem-bench thermochem` on both backends at
#      each of N_LIST particles with the cuda/cpu speed-ups;
#   4. prints a short table last; the table, every JSON figure and all logs go to LOG_DIR.
#
# Environment (all optional):
#   N_LIST       particle counts of the benchmarks      (default: "100000 1000000")
#   DEM_WORK     particle-steps per dem run; steps = DEM_WORK / N, 20 at least (default: 2e7)
#   CPU_THREADS  threads of the cpu runs                 (default: all cores)
#   JOBS         build parallelism                       (default: all cores)
#   CUDA_ARCH    COREDEM_CUDA_ARCHITECTURES              (default: the GPU's compute capability
#                from nvidia-smi, e.g. 90; 90 where none is found)
#   GTEST_SOURCE GoogleTest source tree                  (default: .carry/googletest in the
#                source tree when present, else /usr/src/googletest; scripts/gpu-carry.sh
#                prepares the first)
#   LOG_DIR      where summary.txt, bench.jsonl and logs.tar.gz are written
#                                                        (default: BUILD_DIR/gpu-check)
#   GPU_CHECK_SKIP_BUILD=1   use BUILD_DIR as it is (no configure/build)
#   GPU_CHECK_PROBE_ONLY=1   stop after step 2 (0: a GPU is usable)
#   GPU_CHECK_REHEARSE=1     rehearse steps 3-4 on a machine without a GPU before spending GPU
#                time: no probe, cuda-sim stands in for cuda in the dem runs and the cpu in the
#                thermochem runs, cuda tests may skip, no sanitizer (the figures mean nothing)
#   GPU_PROBE, NVIDIA_SMI, LSPCI, NVIDIA_DEV_GLOB   the probe command (default: BUILD_DIR's
#                `coredem-bench gpu-probe`), nvidia-smi, lspci and the device-node glob
#                (default /dev/nvidia[0-9]*): tests replace them to simulate broken setups
#
# Exit status: 0 built (and, with a GPU, every check passed; without one, none exists); 1 build,
# CUDA or a check failed; 2 bad usage or no CUDA compiler.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
[[ $# -le 1 ]] || { sed -n '2,46p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
build="${1:-$root/build-gpu}"
cores="$(nproc 2>/dev/null || echo 2)"
N_LIST="${N_LIST:-100000 1000000}"
DEM_WORK="${DEM_WORK:-2e7}"
CPU_THREADS="${CPU_THREADS:-$cores}"
JOBS="${JOBS:-$cores}"
NVIDIA_SMI="${NVIDIA_SMI:-nvidia-smi}"
LSPCI="${LSPCI:-lspci}"
NVIDIA_DEV_GLOB="${NVIDIA_DEV_GLOB:-/dev/nvidia[0-9]*}"
mkdir -p "$build"
# The logs are written under $build/gpu-check/logs; LOG_DIR receives three files only (a folder
# that comes back from a lent machine may be limited to a few files): summary.txt, bench.jsonl
# and logs.tar.gz (the logs folder, packed at the end or on a failure).
logs="$build/gpu-check"
mkdir -p "$logs/logs"
out="${LOG_DIR:-$logs}"
mkdir -p "$out"
summary="$out/summary.txt"
: >"$summary"
started=$SECONDS
fail() { echo "gpu-check: FAILED: $*" >&2; echo "FAILED: $*" >>"$summary"; pack; exit 1; }
note() { echo "$*"; echo "$*" >>"$summary"; }
pack() { tar -C "$logs" -czf "$out/logs.tar.gz" logs 2>/dev/null || true; }

# ---- 1. configure + build the DEM core alone ----
if [[ "${GPU_CHECK_SKIP_BUILD:-0}" != 1 ]]; then
  nvcc="${CUDACXX:-}"
  [[ -z "$nvcc" ]] && nvcc="$(command -v nvcc || true)"
  [[ -z "$nvcc" && -x /usr/local/cuda/bin/nvcc ]] && nvcc=/usr/local/cuda/bin/nvcc
  if [[ -z "$nvcc" ]]; then
    echo "gpu-check: no CUDA compiler found (nvcc not on PATH, not in /usr/local/cuda/bin); install the" >&2
    echo "CUDA toolkit or set CUDACXX=/path/to/nvcc" >&2
    exit 2
  fi
  arch="${CUDA_ARCH:-}"
  if [[ -z "$arch" ]] && command -v "$NVIDIA_SMI" >/dev/null 2>&1; then
    arch="$("$NVIDIA_SMI" --query-gpu=compute_cap --format=csv,noheader 2>/dev/null | head -1 | tr -d ' .')" || arch=""
    [[ "$arch" =~ ^[0-9]+$ ]] || arch=""
  fi
  arch="${arch:-90}"
  gtest="${GTEST_SOURCE:-}"
  if [[ -z "$gtest" ]]; then
    for cand in "$root/.carry/googletest" /usr/src/googletest; do
      [[ -f "$cand/CMakeLists.txt" ]] && { gtest="$cand"; break; }
    done
  fi
  [[ -n "$gtest" && -f "$gtest/CMakeLists.txt" ]] ||
    { echo "gpu-check: no GoogleTest source tree (GTEST_SOURCE, .carry/googletest, /usr/src/googletest):" >&2
      echo "  run scripts/gpu-carry.sh on a machine with Debian's googletest and carry .carry/ along" >&2
      exit 2; }
  note "== gpu-check: $(date -u '+%Y-%m-%d %H:%M UTC'), $cores cores, CUDA compiler $nvcc ($("$nvcc" --version | tail -1)), architecture $arch"
  cmake_args=(-S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCOREDEM_CORE_ONLY=ON
              -DCOREDEM_CUDA=ON -DCMAKE_CUDA_COMPILER="$nvcc" -DCOREDEM_CUDA_ARCHITECTURES="$arch"
              -DCOREDEM_GTEST_SOURCE_DIR="$gtest")
  command -v ninja >/dev/null && cmake_args+=(-G Ninja)
  command -v ccache >/dev/null && cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_CUDA_COMPILER_LAUNCHER=ccache)
  echo "== configure: cmake ${cmake_args[*]}"
  cmake "${cmake_args[@]}" >"$logs/logs/configure.log" 2>&1 || { tail -40 "$logs/logs/configure.log" >&2; fail "configure (log: logs/configure.log)"; }
  grep -q "CUDA backend ON" "$logs/logs/configure.log" ||
    { grep -i cuda "$logs/logs/configure.log" >&2 || true; fail "CMake did not enable the CUDA backend (see above)"; }
  grep -q "tests ON" "$logs/logs/configure.log" || fail "the DEM core's tests were not configured (GoogleTest: $gtest)"
  targets=(coredem-bench dem_unit_tests)
  t0=$SECONDS
  echo "== build: ${targets[*]} (-j$JOBS)"
  cmake --build "$build" -j"$JOBS" --target "${targets[@]}" >"$logs/logs/build.log" 2>&1 ||
    { grep -E "error" "$logs/logs/build.log" | head -40 >&2; fail "build (log: logs/build.log)"; }
  note "   built the DEM core alone in $((SECONDS - t0)) s: coredem-bench, dem_unit_tests (cuda backend compiled)"
fi
bench_bin="$build/bin/coredem-bench"
tests_bin="$build/tests/dem_unit_tests"

rehearse="${GPU_CHECK_REHEARSE:-0}"
dem_gpu_backend=cuda
thermo_gpu_backend=cuda
if [[ "$rehearse" == 1 ]]; then
  dem_gpu_backend=cuda-sim
  thermo_gpu_backend=cpu
  note "   REHEARSAL (GPU_CHECK_REHEARSE=1): no GPU used; cuda-sim / cpu stand in for cuda"
fi

# ---- 2. is there a GPU? ----
# The CUDA runtime first: exit 0 devices, 3 no GPU (no driver / no device), 1 CUDA failed.
probe_rc=0
probe_log="$logs/logs/probe.log"
if [[ "$rehearse" == 1 ]]; then
  echo "gpu-probe: not asked (rehearsal)" >"$probe_log"
elif [[ -n "${GPU_PROBE:-}" ]]; then
  ${GPU_PROBE} >"$probe_log" 2>&1 || probe_rc=$?
else
  "$bench_bin" gpu-probe >"$probe_log" 2>&1 || probe_rc=$?
fi
cat "$probe_log"
case "$probe_rc" in
  0) ;;
  3) # The runtime sees no GPU: make sure there really is none.
     if command -v "$NVIDIA_SMI" >/dev/null 2>&1; then
       smi_rc=0
       smi_out="$("$NVIDIA_SMI" -L 2>&1)" || smi_rc=$?
       [[ "$smi_rc" -eq 0 ]] ||
         fail "nvidia-smi is installed but fails (exit $smi_rc): the driver is not working:
  $smi_out"
       if grep -q '^GPU' <<<"$smi_out"; then
         fail "nvidia-smi lists a GPU but the CUDA runtime sees none ($(tail -1 "$probe_log")):
  $smi_out
  check CUDA_VISIBLE_DEVICES and the driver version against this build's CUDA runtime"
       fi
     fi
     # shellcheck disable=SC2086
     for node in $NVIDIA_DEV_GLOB; do
       [[ -e "$node" ]] && fail "$node exists (an NVIDIA GPU with its driver) but the CUDA runtime sees no device"
     done
     if command -v "$LSPCI" >/dev/null 2>&1 && "$LSPCI" 2>/dev/null | grep -iE '(3D|VGA|display).*nvidia' >/dev/null; then
       fail "lspci shows an NVIDIA GPU but the CUDA runtime sees none (driver missing or not loaded?)"
     fi
     echo
     note "gpu-check: NO GPU on this machine (the CUDA runtime, nvidia-smi, /dev/nvidia* and lspci"
     note "  agree). The DEM core was built alone with its CUDA backend; nothing was run on a GPU. Run"
     note "  this script on a machine with an NVIDIA GPU for the conformance suite on cuda,"
     note "  compute-sanitizer and the speed-ups."
     pack
     exit 0 ;;
  1) fail "the CUDA runtime failed (see above)" ;;
  *) fail "the GPU probe exited $probe_rc (crashed?; log: logs/probe.log)" ;;
esac
if [[ "${GPU_CHECK_PROBE_ONLY:-0}" == 1 ]]; then
  echo "gpu-check: a GPU is usable (GPU_CHECK_PROBE_ONLY: stopping here)"
  exit 0
fi
note "   GPU: $("$NVIDIA_SMI" --query-gpu=name,memory.total,driver_version,compute_cap --format=csv,noheader 2>/dev/null || echo '(nvidia-smi not available)')"
note "   kernel: $(uname -r)"

# ---- 3a. the DEM core's tests, the conformance suite on cpu, cuda-sim and cuda ----
echo
echo "== dem_unit_tests (backend and stage conformance on cpu, cuda-sim, cuda; kernels; probe)"
tests_log="$logs/logs/dem_unit_tests.log"
t0=$SECONDS
tests_rc=0
"$tests_bin" --gtest_output="xml:$logs/logs/dem_unit_tests.xml" >"$tests_log" 2>&1 || tests_rc=$?
if [[ "$tests_rc" -ne 0 ]]; then
  # The differences found are the first measurement of the cuda drift: keep them in the summary.
  grep -E "Failure|FAILED|Which is|Expected|actual|\]: " "$tests_log" | head -60 | tee -a "$summary" >&2
fi
# With a GPU nothing may skip: a skipped cuda test did not run.
if [[ "$rehearse" != 1 ]] && grep -q '^\[  SKIPPED \]' "$tests_log"; then
  grep -A2 '^\[ RUN' "$tests_log" | grep -B2 '^\[  SKIPPED \]' | head -20 >&2 || true
  fail "tests were skipped although a GPU is present (log: logs/dem_unit_tests.log)"
fi
[[ "$tests_rc" -eq 0 ]] || fail "dem_unit_tests (log: logs/dem_unit_tests.log)"
note "   dem_unit_tests: $(grep -E '^\[  PASSED  \]' "$tests_log") in $((SECONDS - t0)) s; skipped: $(grep -oE '^\[  SKIPPED \] [0-9]+' "$tests_log" | grep -oE '[0-9]+$' || echo 0)"

# ---- 3b. compute-sanitizer ----
echo
echo "== compute-sanitizer (memcheck) on a short cuda run"
sanitizer="$(command -v compute-sanitizer || true)"
[[ -z "$sanitizer" && -x /usr/local/cuda/bin/compute-sanitizer ]] && sanitizer=/usr/local/cuda/bin/compute-sanitizer
if [[ "$rehearse" == 1 ]]; then
  note "   compute-sanitizer: not run (rehearsal)"
elif [[ -z "$sanitizer" ]]; then
  note "   compute-sanitizer: not found (CUDA toolkit's bin not on PATH): not run"
else
  for c in packed agitated; do
    slog="$logs/logs/sanitizer.$c.log"
    src=0
    timeout 150 "$sanitizer" --tool memcheck --error-exitcode 1 --print-limit 20 \
      "$bench_bin" dem --case "$c" --particles 2000 --steps 20 --warmup 2 --backend cuda \
      >"$slog" 2>&1 || src=$?
    if grep -qiE "device not supported|not supported on this (platform|device)|unable to (find|initialize) .*(device|driver)" "$slog"; then
      note "   compute-sanitizer ($c): the runtime refuses it here ($(grep -m1 -iE 'not supported|unable to' "$slog" | tr -s ' ' | cut -c1-120); kernel $(uname -r): gVisor-like sandbox) — not a failure"
      break
    fi
    [[ "$src" -eq 124 ]] && fail "compute-sanitizer on the $c deck ran past 150 s (log: logs/sanitizer.$c.log)"
    [[ "$src" -eq 0 ]] || { tail -40 "$slog" >&2; fail "compute-sanitizer on the $c deck (log: logs/sanitizer.$c.log)"; }
    note "   compute-sanitizer ($c): $(grep -E 'ERROR SUMMARY' "$slog" || echo 'no errors')"
  done
fi

# ---- 3c. benchmarks on both backends ----
jsonl="$out/bench.jsonl"
: >"$jsonl"
last_json() { grep -E '^\{' | tail -1; }
field() { sed -n "s/.*\"$1\":\([-0-9.e+]*\).*/\1/p"; }
bench() { # bench <log name> <coredem-bench args...>: the run's JSON line (also in bench.jsonl)
  local name="$1"
  shift
  local out
  out="$(OMP_WAIT_POLICY=PASSIVE OMP_PROC_BIND=close "$bench_bin" "$@" --json 2>"$logs/logs/bench.$name.err")" ||
    { tail -20 "$logs/logs/bench.$name.err" >&2; fail "coredem-bench $* (log: logs/bench.$name.err)"; }
  out="$(last_json <<<"$out")"
  echo "$out" >>"$jsonl"
  echo "$out"
}
table=()
echo
for n in $N_LIST; do
  steps="$(awk -v w="$DEM_WORK" -v n="$n" 'BEGIN { s = int(w / n); print (s < 20 ? 20 : s) }')"
  for c in packed agitated; do
    echo "== coredem-bench dem --case $c --particles $n --steps $steps (cpu: $CPU_THREADS threads)"
    cpu="$(bench "dem.$c.$n.cpu" dem --case "$c" --particles "$n" --steps "$steps" --backend cpu --threads "$CPU_THREADS")"
    gpu="$(bench "dem.$c.$n.cuda" dem --case "$c" --particles "$n" --steps "$steps" --backend "$dem_gpu_backend")"
    rc="$(field particle_steps_per_s <<<"$cpu")"
    rg="$(field particle_steps_per_s <<<"$gpu")"
    table+=("$(awk -v c="dem $c" -v n="$n" -v a="$rc" -v b="$rg" 'BEGIN { printf "  %-26s %9d %13.4e %13.4e %9.2fx", c, n, a, b, b / a }')")
    echo "${table[-1]}"
  done
  # thermochem times 14 variants (the CLG rates alone are ~5 µs per particle and sub-step on
  # one core): fewer sub-steps and one repeat from 10^6 particles keep the cpu side short.
  tsteps=(--steps 10 --warmup 5 --repeat 3)
  [[ "$n" -ge 1000000 ]] && tsteps=(--steps 4 --warmup 2 --repeat 1)
  echo "== coredem-bench thermochem --particles $n ${tsteps[*]} (cpu: $CPU_THREADS threads)"
  cpu="$(bench "thermochem.$n.cpu" thermochem --particles "$n" "${tsteps[@]}" --threads "$CPU_THREADS")"
  gpu="$(bench "thermochem.$n.cuda" thermochem --particles "$n" "${tsteps[@]}" --backend "$thermo_gpu_backend")"
  for k in whole_step_mechanics whole_step_all_heat; do
    a="$(field "$k" <<<"$cpu")"
    b="$(field "$k" <<<"$gpu")"
    label="thermochem: mechanics"
    [[ "$k" == whole_step_all_heat ]] && label="thermochem: all heat"
    # ns per particle per sub-step: the speed-up is cpu / cuda; shown as particle-steps/s.
    table+=("$(awk -v c="$label" -v n="$n" -v a="$a" -v b="$b" 'BEGIN { printf "  %-26s %9d %13.4e %13.4e %9.2fx", c, n, 1e9 / a, 1e9 / b, a / b }')")
    echo "${table[-1]}"
  done
done

# ---- 4. the table ----
{
  echo
  echo "== GPU check: particle-steps/s (cpu: $CPU_THREADS threads of $cores cores; cuda: one GPU)"
  printf "  %-26s %9s %13s %13s %10s\n" "benchmark" "particles" "cpu" "cuda" "cuda/cpu"
  printf "%s\n" "${table[@]}"
  echo "  per-sub-model ns (thermochem): bench.jsonl; logs: logs.tar.gz; whole check: $((SECONDS - started)) s"
} | tee -a "$summary"
pack
echo
echo "gpu-check: done"
