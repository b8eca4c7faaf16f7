#!/usr/bin/env bash
# scripts/gpu-check.sh [BUILD_DIR]
#
# GPU readiness of the DEM core (docs/performance.md "GPU check"):
#   1. configures BUILD_DIR (default: build-gpu) with -DCOREDEM_CUDA=ON and builds the DEM
#      library with its cuda backend, coredem-bench and the backend-templated tests;
#   2. looks for a GPU (nvidia-smi, then the CUDA runtime's device count through coredem-bench);
#   3. without a GPU: says so and exits 0 after the build (CI only compiles the CUDA code);
#      with a GPU: runs the backend-templated tests with the cuda backend (a skipped cuda test
#      is a failure there), then `coredem-bench dem` and `coredem-bench thermochem` on both
#      backends, and prints particle-steps/s and the cuda/cpu speed-ups.
#
# Environment (all optional):
#   N_DEM        particles of the dem benchmark           (default: 100000)
#   STEPS_DEM    its measured steps                       (default: 200)
#   N_THERMO     particles of the thermochem benchmark    (default: 100000)
#   CPU_THREADS  threads of the cpu runs (the "1 core" reference of the seed's figures is
#                CPU_THREADS=1)                           (default: 1)
#   JOBS         build parallelism                        (default: 2)
#   CUDA_ARCH    CMAKE_CUDA_ARCHITECTURES                 (default: CMake's / nvcc's choice)
#
# Exit status: 0 built (and, with a GPU, every check passed); 1 build or a check failed;
# 2 bad usage or no CUDA compiler.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
[[ $# -le 1 ]] || { sed -n '2,25p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
build="${1:-$root/build-gpu}"
N_DEM="${N_DEM:-100000}"
STEPS_DEM="${STEPS_DEM:-200}"
N_THERMO="${N_THERMO:-100000}"
CPU_THREADS="${CPU_THREADS:-1}"
JOBS="${JOBS:-2}"

nvcc="${CUDACXX:-}"
[[ -z "$nvcc" ]] && nvcc="$(command -v nvcc || true)"
[[ -z "$nvcc" && -x /usr/local/cuda/bin/nvcc ]] && nvcc=/usr/local/cuda/bin/nvcc
if [[ -z "$nvcc" ]]; then
  echo "gpu-check: no CUDA compiler found (nvcc not on PATH, not in /usr/local/cuda/bin); install the" >&2
  echo "CUDA toolkit or set CUDACXX=/path/to/nvcc" >&2
  exit 2
fi
echo "== gpu-check: CUDA compiler $nvcc ($("$nvcc" --version | tail -1))"

# ---- 1. configure + build ----
cmake_args=(-S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCOREDEM_CUDA=ON
            -DCMAKE_CUDA_COMPILER="$nvcc")
command -v ccache >/dev/null && cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
[[ -n "${CUDA_ARCH:-}" ]] && cmake_args+=(-DCMAKE_CUDA_ARCHITECTURES="$CUDA_ARCH")
mkdir -p "$build"
logs="$build/gpu-check"   # log files: $logs.configure.log, .build.log, .probe.log, .tests.log
echo "== configure: cmake ${cmake_args[*]}"
cmake "${cmake_args[@]}" >"$logs.configure.log" 2>&1 || { tail -40 "$logs.configure.log" >&2; echo "gpu-check: configure failed (log: $logs.configure.log)" >&2; exit 1; }
grep -q "CUDA backend ON" "$logs.configure.log" ||
  { grep -i cuda "$logs.configure.log" >&2 || true; echo "gpu-check: CMake did not enable the CUDA backend (see above)" >&2; exit 1; }
targets=(coredem_dem coredem-bench dem_unit_tests)
echo "== build: ${targets[*]} (-j$JOBS)"
cmake --build "$build" -j"$JOBS" --target "${targets[@]}" >"$logs.build.log" 2>&1 ||
  { grep -E "error" "$logs.build.log" | head -40 >&2; echo "gpu-check: build failed (log: $logs.build.log)" >&2; exit 1; }
echo "   built: $build/bin/coredem-bench, dem_unit_tests (cuda backend compiled)"

# ---- 2. is there a GPU? ----
gpus=0
if command -v nvidia-smi >/dev/null && nvidia-smi -L >/dev/null 2>&1; then
  gpus="$(nvidia-smi -L | grep -c '^GPU' || true)"
  nvidia-smi -L
fi
if [[ "$gpus" -eq 0 ]]; then
  # nvidia-smi missing or silent: ask the CUDA runtime (cudaGetDeviceCount) via the backend.
  if "$build/bin/coredem-bench" dem --case packed --particles 1000 --steps 1 --warmup 0 --backend cuda --json \
      >/dev/null 2>"$logs.probe.log"; then
    gpus=1
  fi
fi
if [[ "$gpus" -eq 0 ]]; then
  echo
  echo "gpu-check: NO GPU on this machine (nvidia-smi found none and cudaGetDeviceCount reports 0:"
  echo "  $(tail -1 "$logs.probe.log" 2>/dev/null || true))."
  echo "The CUDA backend, the cuda instantiations of the tests and the cuda benchmark kernels were"
  echo "compiled; nothing was run on a GPU. Run this script on a machine with an NVIDIA GPU for the"
  echo "tests and the cuda/cpu speed-ups."
  exit 0
fi

# ---- 3. tests with the cuda backend ----
echo
echo "== backend-templated tests (cpu and cuda instantiations)"
tests_log="$logs.tests.log"
tests_bin="$(find "$build" -name dem_unit_tests -type f -perm -u+x | head -1)"
[[ -n "$tests_bin" ]] || { echo "gpu-check: dem_unit_tests not found under $build" >&2; exit 1; }
if ! "$tests_bin" --gtest_filter='BackendConformance*' >"$tests_log" 2>&1; then
  tail -40 "$tests_log" >&2
  echo "gpu-check: backend tests failed (log: $tests_log)" >&2
  exit 1
fi
# Only the cuda instantiation can skip (not built / no device): with a GPU, a skip is a failure.
if grep -q '^\[  SKIPPED \]' "$tests_log"; then
  grep -B1 '^\[  SKIPPED \]' "$tests_log" >&2
  echo "gpu-check: cuda instantiations were skipped although a GPU is present" >&2
  exit 1
fi
grep -E "^\[  (PASSED|FAILED) " "$tests_log"

# ---- 4. benchmarks on both backends ----
field() { python3 -c 'import json,sys; d=json.loads(sys.stdin.read().strip().splitlines()[-1]); print(eval("d"+sys.argv[1]))' "$1"; }
bench() { OMP_WAIT_POLICY=PASSIVE "$build/bin/coredem-bench" "$@"; }

echo
echo "== coredem-bench dem --case packed --particles $N_DEM --steps $STEPS_DEM (cpu: $CPU_THREADS thread(s))"
for c in packed agitated; do
  cpu_json="$(bench dem --case "$c" --particles "$N_DEM" --steps "$STEPS_DEM" --backend cpu --threads "$CPU_THREADS" --json)"
  gpu_json="$(bench dem --case "$c" --particles "$N_DEM" --steps "$STEPS_DEM" --backend cuda --json)"
  cpu_rate="$(field '["particle_steps_per_s"]' <<<"$cpu_json")"
  gpu_rate="$(field '["particle_steps_per_s"]' <<<"$gpu_json")"
  python3 - "$c" "$cpu_rate" "$gpu_rate" <<'EOF'
import sys
c, cpu, gpu = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
print(f"  {c:9s} cpu {cpu:11.4e} particle-steps/s   cuda {gpu:11.4e}   speed-up cuda/cpu {gpu/cpu:7.2f}x")
EOF
done

echo
echo "== coredem-bench thermochem --particles $N_THERMO (ns per particle per sub-step; cpu: $CPU_THREADS thread(s))"
cpu_json="$(bench thermochem --particles "$N_THERMO" --threads "$CPU_THREADS" --json)"
gpu_json="$(bench thermochem --particles "$N_THERMO" --backend cuda --json)"
python3 - "$cpu_json" "$gpu_json" <<'EOF'
import json, sys
cpu = json.loads(sys.argv[1].strip().splitlines()[-1])
gpu = json.loads(sys.argv[2].strip().splitlines()[-1])
print(f"  {'sub-model':30s} {'cpu ns':>10s} {'cuda ns':>10s} {'cuda/cpu':>9s}")
for k, v in cpu["sub_models"].items():
    g = gpu["sub_models"].get(k)
    sp = f"{v / g:8.1f}x" if g and g > 0 and v > 0 else "     n/a"
    print(f"  {k:30s} {v:10.2f} {g:10.2f} {sp}")
for k in ("whole_step_mechanics", "whole_step_all_heat"):
    v, g = cpu["context"][k], gpu["context"][k]
    print(f"  {k:30s} {v:10.2f} {g:10.2f} {v / g:8.1f}x")
print("  (seed headline: up to 289x per sub-routine against one core, about 6x for the whole particle step)")
EOF
echo
echo "gpu-check: done"
