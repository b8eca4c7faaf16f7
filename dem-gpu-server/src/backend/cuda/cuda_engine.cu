// The cuda instantiation of the shared engine (the same engine_impl.h as the cpu backend,
// compiled by nvcc with extended lambdas). Compiled when COREDEM_CUDA_ENABLED; it is never
// run on machines without a GPU.
#include <cstdlib>

#include "../../engine_impl.h"
#include "../cuda_probe.h"
#include "cuda_exec.cuh"

namespace coredem::dem {

template class EngineImpl<backend::CudaExec>;

std::unique_ptr<Engine> makeCudaEngine(const EngineSetup& setup) {
  return std::make_unique<EngineImpl<backend::CudaExec>>(setup);
}

static_assert(backend::kCudaSuccess == cudaSuccess);
static_assert(backend::kCudaErrorInsufficientDriver == cudaErrorInsufficientDriver);
static_assert(backend::kCudaErrorNoDevice == cudaErrorNoDevice);

CudaProbe cudaProbe() {
  backend::CudaRuntimeAnswer a;
  int n = 0;
  const cudaError_t e = cudaGetDeviceCount(&n);
  a.error = static_cast<int>(e);
  a.errorName = cudaGetErrorName(e);
  a.errorString = cudaGetErrorString(e);
  a.deviceCount = e == cudaSuccess ? n : 0;
  if (cudaDriverGetVersion(&a.driverVersion) != cudaSuccess)
    a.driverVersion = 0;
  if (cudaRuntimeGetVersion(&a.runtimeVersion) != cudaSuccess)
    a.runtimeVersion = CUDART_VERSION;
  if (const char* v = std::getenv("CUDA_VISIBLE_DEVICES"))
    a.visibleDevices = v;
  cudaGetLastError(); // clear a sticky error of the probe
  return backend::interpretCudaRuntime(a);
}

} // namespace coredem::dem
