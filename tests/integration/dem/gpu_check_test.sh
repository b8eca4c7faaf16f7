#!/usr/bin/env bash
# The decision logic of scripts/gpu-check.sh, with simulated GPU setups (fake probe, nvidia-smi,
# lspci and device nodes): it must fail on every broken CUDA setup and pass only when there is
# really no GPU. No build, no GPU needed.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin" "$work/build"
failures=0

# fake <name> <exit status> <output>: an executable printing output and exiting with status.
fake() {
  printf '#!/usr/bin/env bash\ncat <<"OUT"\n%s\nOUT\nexit %s\n' "$3" "$2" >"$work/bin/$1"
  chmod +x "$work/bin/$1"
}

# expect <expected exit> <text the output must contain> [VAR=value...]: runs gpu-check.
expect() {
  local want="$1" text="$2"
  shift 2
  local out rc=0
  out="$(env GPU_CHECK_SKIP_BUILD=1 GPU_CHECK_PROBE_ONLY=1 NVIDIA_SMI="$work/bin/none" \
    LSPCI="$work/bin/none" NVIDIA_DEV_GLOB="$work/dev/nvidia[0-9]*" "$@" \
    bash "$root/scripts/gpu-check.sh" "$work/build" 2>&1)" || rc=$?
  if [[ "$rc" -ne "$want" ]] || ! grep -qF -- "$text" <<<"$out"; then
    echo "FAIL: $* -> exit $rc (want $want), output:"
    sed 's/^/    /' <<<"$out"
    echo "    (wanted the text: $text)"
    failures=$((failures + 1))
  else
    echo "ok:   exit $rc: $*"
  fi
}

fake probe_error 1 "gpu-probe: error: the CUDA runtime failed: cudaErrorInsufficientDriver: CUDA driver version is insufficient for CUDA runtime version"
fake probe_none 3 "gpu-probe: no GPU: no NVIDIA driver is installed"
fake probe_gpu 0 "gpu-probe: 1 CUDA device(s)"
fake probe_crash 139 "Segmentation fault"
fake smi_lists 0 "GPU 0: NVIDIA H200 (UUID: GPU-0000)"
fake smi_broken 9 "NVIDIA-SMI has failed because it couldn't communicate with the NVIDIA driver."
fake smi_empty 6 "No devices were found"
fake lspci_gpu 0 "17:00.0 3D controller: NVIDIA Corporation GH100 [H200 SXM 141GB] (rev a1)"
fake lspci_none 0 "00:02.0 VGA compatible controller: Intel Corporation Device 9a49"

# A CUDA runtime failure (e.g. a driver older than the runtime) fails, with CUDA's message.
expect 1 "cudaErrorInsufficientDriver" GPU_PROBE="$work/bin/probe_error"
# A probe that crashes fails.
expect 1 "exited 139" GPU_PROBE="$work/bin/probe_crash"
# No device for the runtime, but nvidia-smi lists one: fails.
expect 1 "nvidia-smi lists a GPU" GPU_PROBE="$work/bin/probe_none" NVIDIA_SMI="$work/bin/smi_lists"
# nvidia-smi installed but failing (driver broken): fails.
expect 1 "nvidia-smi is installed but fails" GPU_PROBE="$work/bin/probe_none" NVIDIA_SMI="$work/bin/smi_broken"
# nvidia-smi "No devices were found" (exit 6) still says the driver cannot serve a GPU: fails.
expect 1 "No devices were found" GPU_PROBE="$work/bin/probe_none" NVIDIA_SMI="$work/bin/smi_empty"
# lspci shows an NVIDIA GPU the runtime cannot use (driver not loaded): fails.
expect 1 "lspci shows an NVIDIA GPU" GPU_PROBE="$work/bin/probe_none" LSPCI="$work/bin/lspci_gpu"
# A device node exists: fails.
mkdir -p "$work/dev" && touch "$work/dev/nvidia0"
expect 1 "/dev/nvidia0 exists" GPU_PROBE="$work/bin/probe_none"
rm -f "$work/dev/nvidia0"
# Really no GPU (runtime: no driver; no nvidia-smi, no device node, lspci without NVIDIA): 0.
expect 0 "NO GPU on this machine" GPU_PROBE="$work/bin/probe_none" LSPCI="$work/bin/lspci_none"
# A usable GPU: 0 (the probe-only mode stops before the tests and benchmarks).
expect 0 "a GPU is usable" GPU_PROBE="$work/bin/probe_gpu"

if [[ "$failures" -ne 0 ]]; then
  echo "$failures case(s) failed"
  exit 1
fi
echo "all gpu-check cases behave"
