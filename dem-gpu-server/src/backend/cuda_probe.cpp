#include "cuda_probe.h"

namespace coredem::dem::backend {

namespace {
std::string version(int v) {
  return std::to_string(v / 1000) + "." + std::to_string((v % 1000) / 10);
}
} // namespace

CudaProbe interpretCudaRuntime(const CudaRuntimeAnswer& a) {
  CudaProbe p;
  p.built = true;
  const std::string visible = a.visibleDevices
                                  ? "CUDA_VISIBLE_DEVICES=\"" + *a.visibleDevices + "\""
                                  : std::string("CUDA_VISIBLE_DEVICES not set");
  const std::string hideHint =
      a.visibleDevices ? "; CUDA_VISIBLE_DEVICES may hide the GPUs: unset it or list valid "
                         "device indices/UUIDs (nvidia-smi -L)"
                       : "";
  if (a.error == kCudaSuccess) {
    p.devices = a.deviceCount;
    if (a.deviceCount <= 0)
      p.note = "cudaGetDeviceCount found no device (" + visible + ")" + hideHint;
    return p;
  }
  const std::string cuda = a.errorName + ": " + a.errorString;
  if (a.error == kCudaErrorNoDevice) {
    p.note = "no CUDA-capable device (" + cuda + "; " + visible + ")" + hideHint;
    return p;
  }
  if (a.error == kCudaErrorInsufficientDriver && a.driverVersion == 0) {
    p.note = "no NVIDIA driver is installed (" + cuda + ")";
    return p;
  }
  p.error = "the CUDA runtime failed: " + cuda + " (this build's CUDA runtime " +
            version(a.runtimeVersion) + ", the driver " +
            (a.driverVersion > 0 ? "supports CUDA up to " + version(a.driverVersion)
                                 : std::string("was not found")) +
            "; " + visible + "). ";
  if (a.error == kCudaErrorInsufficientDriver) {
    p.error += "The NVIDIA driver is too old for this build: install a driver that supports CUDA " +
               version(a.runtimeVersion) +
               " or newer (nvidia-smi prints the CUDA version the driver supports), or rebuild "
               "with a CUDA toolkit no newer than the driver's.";
  } else {
    p.error += "Check the GPU and its driver with nvidia-smi (driver loaded, GPU not in an error "
               "state, compute mode not prohibited) and CUDA_VISIBLE_DEVICES; --backend cpu runs "
               "without it.";
  }
  return p;
}

} // namespace coredem::dem::backend
