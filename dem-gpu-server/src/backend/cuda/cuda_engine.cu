// The cuda instantiation of the shared engine (the same engine_impl.h as the cpu backend,
// compiled by nvcc with extended lambdas). Compiled when COREDEM_CUDA_ENABLED; it is never
// run on machines without a GPU.
#include "../../engine_impl.h"
#include "cuda_exec.cuh"

namespace coredem::dem {

template class EngineImpl<backend::CudaExec>;

std::unique_ptr<Engine> makeCudaEngine(const EngineSetup& setup) {
  return std::make_unique<EngineImpl<backend::CudaExec>>(setup);
}

int cudaDevices() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError(); // clear the sticky "no driver / no device" error
    return 0;
  }
  return n;
}

} // namespace coredem::dem
