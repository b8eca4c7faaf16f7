#!/usr/bin/env bash
# scripts/gpu-check.sh [BUILD_DIR]
#
# GPU readiness of the DEM core (docs/performance.md "GPU check"), one prepared script that fits
# in 10 minutes on a machine with one GPU:
#   1. configures BUILD_DIR (default: build-gpu) with -DCOREDEM_CUDA=ON and builds the DEM
#      library with its cuda backend, coredem-bench and the backend-templated tests;
#   2. asks the CUDA runtime (`coredem-bench gpu-probe`) and, when it sees no device, looks for
#      GPU hardware (nvidia-smi, /dev/nvidia*, lspci): a CUDA runtime failure, a failing
#      nvidia-smi or a GPU the runtime cannot see is a failure (exit 1); only a machine with no
#      NVIDIA GPU and no driver exits 0 here ("NO GPU": CI compiles the CUDA code only);
#   3. with a GPU: the backend conformance suite with the cuda backend (a skipped cuda test is a
#      failure there), compute-sanitizer (memcheck) on a short cuda run, then `coredem-bench dem`
#      and `coredem-bench thermochem` on both backends with particle-steps/s and the cuda/cpu
#      speed-ups.
#
# Environment (all optional):
#   N_DEM        particles of the dem benchmark           (default: 100000)
#   STEPS_DEM    its measured steps                       (default: 200)
#   N_THERMO     particles of the thermochem benchmark    (default: 100000)
#   CPU_THREADS  threads of the cpu runs (the "1 core" reference of the seed's figures is
#                CPU_THREADS=1)                           (default: 1)
#   JOBS         build parallelism                        (default: 2)
#   CUDA_ARCH    COREDEM_CUDA_ARCHITECTURES               (default: the CMake option's
#                75-real;80-real;90; `native` builds for this machine's GPU only, faster)
#   GPU_CHECK_SKIP_BUILD=1   use BUILD_DIR as it is (no configure/build)
#   GPU_CHECK_PROBE_ONLY=1   stop after step 2 (0: a GPU is usable)
#   GPU_PROBE, NVIDIA_SMI, LSPCI, NVIDIA_DEV_GLOB   the probe command (default: BUILD_DIR's
#                `coredem-bench gpu-probe`), nvidia-smi, lspci and the device-node glob
#                (default /dev/nvidia[0-9]*): tests replace them to simulate broken setups
#
# Exit status: 0 built (and, with a GPU, every check passed; without one, none exists); 1 build,
# CUDA or a check failed; 2 bad usage or no CUDA compiler.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
[[ $# -le 1 ]] || { sed -n '2,33p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
build="${1:-$root/build-gpu}"
N_DEM="${N_DEM:-100000}"
STEPS_DEM="${STEPS_DEM:-200}"
N_THERMO="${N_THERMO:-100000}"
CPU_THREADS="${CPU_THREADS:-1}"
JOBS="${JOBS:-2}"
NVIDIA_SMI="${NVIDIA_SMI:-nvidia-smi}"
LSPCI="${LSPCI:-lspci}"
NVIDIA_DEV_GLOB="${NVIDIA_DEV_GLOB:-/dev/nvidia[0-9]*}"
mkdir -p "$build"
logs="$build/gpu-check"   # log files: $logs.configure.log, .build.log, .probe.log, .tests.log
fail() { echo "gpu-check: FAILED: $*" >&2; exit 1; }

# ---- 1. configure + build ----
if [[ "${GPU_CHECK_SKIP_BUILD:-0}" != 1 ]]; then
  nvcc="${CUDACXX:-}"
  [[ -z "$nvcc" ]] && nvcc="$(command -v nvcc || true)"
  [[ -z "$nvcc" && -x /usr/local/cuda/bin/nvcc ]] && nvcc=/usr/local/cuda/bin/nvcc
  if [[ -z "$nvcc" ]]; then
    echo "gpu-check: no CUDA compiler found (nvcc not on PATH, not in /usr/local/cuda/bin); install the" >&2
    echo "CUDA toolkit or set CUDACXX=/path/to/nvcc" >&2
    exit 2
  fi
  echo "== gpu-check: CUDA compiler $nvcc ($("$nvcc" --version | tail -1))"
  cmake_args=(-S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCOREDEM_CUDA=ON
              -DCMAKE_CUDA_COMPILER="$nvcc")
  command -v ccache >/dev/null && cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  [[ -n "${CUDA_ARCH:-}" ]] && cmake_args+=(-DCOREDEM_CUDA_ARCHITECTURES="$CUDA_ARCH")
  echo "== configure: cmake ${cmake_args[*]}"
  cmake "${cmake_args[@]}" >"$logs.configure.log" 2>&1 || { tail -40 "$logs.configure.log" >&2; fail "configure (log: $logs.configure.log)"; }
  grep -q "CUDA backend ON" "$logs.configure.log" ||
    { grep -i cuda "$logs.configure.log" >&2 || true; fail "CMake did not enable the CUDA backend (see above)"; }
  grep "CUDA architectures" "$logs.configure.log" || true
  targets=(coredem_dem coredem-bench dem_unit_tests)
  echo "== build: ${targets[*]} (-j$JOBS)"
  cmake --build "$build" -j"$JOBS" --target "${targets[@]}" >"$logs.build.log" 2>&1 ||
    { grep -E "error" "$logs.build.log" | head -40 >&2; fail "build (log: $logs.build.log)"; }
  echo "   built: $build/bin/coredem-bench, dem_unit_tests (cuda backend compiled)"
fi

# ---- 2. is there a GPU? ----
# The CUDA runtime first: exit 0 devices, 3 no GPU (no driver / no device), 1 CUDA failed.
probe_rc=0
if [[ -n "${GPU_PROBE:-}" ]]; then
  ${GPU_PROBE} >"$logs.probe.log" 2>&1 || probe_rc=$?
else
  "$build/bin/coredem-bench" gpu-probe >"$logs.probe.log" 2>&1 || probe_rc=$?
fi
cat "$logs.probe.log"
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
         fail "nvidia-smi lists a GPU but the CUDA runtime sees none ($(tail -1 "$logs.probe.log")):
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
     echo "gpu-check: NO GPU on this machine (the CUDA runtime, nvidia-smi, /dev/nvidia* and lspci"
     echo "  agree). The CUDA backend, the cuda instantiations of the tests and the cuda benchmark"
     echo "  kernels were compiled; nothing was run on a GPU. Run this script on a machine with an"
     echo "  NVIDIA GPU for the conformance suite on cuda, compute-sanitizer and the speed-ups."
     exit 0 ;;
  1) fail "the CUDA runtime failed (see above)" ;;
  *) fail "the GPU probe exited $probe_rc (crashed?; log: $logs.probe.log)" ;;
esac
if [[ "${GPU_CHECK_PROBE_ONLY:-0}" == 1 ]]; then
  echo "gpu-check: a GPU is usable (GPU_CHECK_PROBE_ONLY: stopping here)"
  exit 0
fi
"$NVIDIA_SMI" -L 2>/dev/null || true

# ---- 3. tests with the cuda backend ----
echo
echo "== backend conformance suite (cpu, cuda-sim and cuda instantiations; every stage)"
tests_log="$logs.tests.log"
tests_bin="$(find "$build" -name dem_unit_tests -type f -perm -u+x | head -1)"
[[ -n "$tests_bin" ]] || fail "dem_unit_tests not found under $build"
if ! "$tests_bin" --gtest_filter='BackendConformance*:StageConformance*:CudaProbe*:CudaSim*' >"$tests_log" 2>&1; then
  grep -E "Failure|FAILED|error|Which is|\]: " "$tests_log" | head -60 >&2
  fail "conformance tests (log: $tests_log)"
fi
# Only the cuda instantiations can skip (not built / no device): with a GPU, a skip is a failure.
if grep -q '^\[  SKIPPED \]' "$tests_log"; then
  grep -B1 '^\[  SKIPPED \]' "$tests_log" >&2
  fail "cuda instantiations were skipped although a GPU is present"
fi
grep -E "^\[  (PASSED|FAILED) " "$tests_log"

echo
echo "== compute-sanitizer (memcheck) on a short cuda run"
sanitizer="$(command -v compute-sanitizer || true)"
[[ -z "$sanitizer" && -x /usr/local/cuda/bin/compute-sanitizer ]] && sanitizer=/usr/local/cuda/bin/compute-sanitizer
if [[ -n "$sanitizer" ]]; then
  for c in packed agitated; do
    "$sanitizer" --tool memcheck --error-exitcode 1 --print-limit 20 \
      "$build/bin/coredem-bench" dem --case "$c" --particles 2000 --steps 20 --warmup 2 --backend cuda \
      >"$logs.sanitizer.$c.log" 2>&1 || { tail -40 "$logs.sanitizer.$c.log" >&2; fail "compute-sanitizer on the $c deck (log: $logs.sanitizer.$c.log)"; }
    echo "   $c: $(grep -E 'ERROR SUMMARY' "$logs.sanitizer.$c.log" || echo 'no errors')"
  done
else
  echo "   compute-sanitizer not found (CUDA toolkit's bin not on PATH): skipped" >&2
fi

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
