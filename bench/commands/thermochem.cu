// The CUDA side of `coredem-bench thermochem`: the chemistry stages of thermochem.h as one
// kernel launch each (one thread per particle), timed with CUDA events. Built only with
// COREDEM_CUDA_ENABLED (bench/commands/thermochem.cmake).
#include <stdexcept>
#include <string>

#include <cuda_runtime.h>

#include "thermochem.h"

namespace coredem::bench::thermochem {

namespace {

void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) {
    throw std::runtime_error(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(e));
  }
}

template <class T>
T* upload(const std::vector<T>& v) {
  T* d = nullptr;
  check(cudaMalloc(&d, v.size() * sizeof(T) + 1), "cudaMalloc");
  if (!v.empty())
    check(cudaMemcpy(d, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy");
  return d;
}

template <class T>
T* scratch(std::size_t n) {
  T* d = nullptr;
  check(cudaMalloc(&d, n * sizeof(T) + 1), "cudaMalloc");
  return d;
}

__global__ void chemKernel(int stage, ChemArrays a,
                           coredem::dem::kernels::HeterogeneousReaction gen) {
  const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < a.n)
    chemBody(stage, a, gen, i);
}

} // namespace

ChemTimes runChemistryCuda(const ChemInput& in, int reps) {
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    throw std::runtime_error(
        "no CUDA device is visible (cudaGetDeviceCount); run with --backend cpu");
  }
  const std::size_t n = in.n;
  double* T = upload(in.T);
  double* mass0 = upload(in.mass);
  std::int32_t* cell = upload(in.cell);
  double* pBar = upload(in.pBar);
  double* conc = upload(in.conc);
  double* m = upload(in.mass);
  double* y = upload(in.Y);
  double* mdot = scratch<double>(n * kSolids);
  double* mg = scratch<double>(n * kGas);
  double* q = scratch<double>(n);
  double* d = scratch<double>(n);
  std::int32_t* removed = scratch<std::int32_t>(n);
  const ChemArrays a{n,    T,  mass0, cell, pBar,    conc,  m,         y,
                     mdot, mg, q,     d,    removed, in.dt, in.density};
  const auto gen = genericReaction();
  cudaEvent_t start, stop;
  check(cudaEventCreate(&start), "cudaEventCreate");
  check(cudaEventCreate(&stop), "cudaEventCreate");
  const unsigned block = 256;
  const unsigned grid = static_cast<unsigned>((n + block - 1) / block);
  // Warm-up, untimed: the first launch of each stage loads the module (and JIT-compiles PTX
  // when the build has no machine code for this GPU); that is not the stage's cost.
  for (int s = 0; s < kChemStageCount; ++s) {
    if (grid > 0)
      chemKernel<<<grid, block>>>(s, a, gen);
    check(cudaGetLastError(), "chemKernel warm-up launch");
  }
  check(cudaDeviceSynchronize(), "warm-up cudaDeviceSynchronize");
  ChemTimes t;
  t.reps = reps;
  for (int r = 0; r < reps; ++r) {
    for (int s = 0; s < kChemStageCount; ++s) {
      check(cudaEventRecord(start), "cudaEventRecord");
      if (grid > 0)
        chemKernel<<<grid, block>>>(s, a, gen);
      check(cudaGetLastError(), "chemKernel launch");
      check(cudaEventRecord(stop), "cudaEventRecord");
      check(cudaEventSynchronize(stop), "cudaEventSynchronize");
      float ms = 0.0f;
      check(cudaEventElapsedTime(&ms, start, stop), "cudaEventElapsedTime");
      t.seconds[s] += 1e-3 * ms;
    }
  }
  cudaEventDestroy(start);
  cudaEventDestroy(stop);
  for (void* p : {static_cast<void*>(T), static_cast<void*>(mass0), static_cast<void*>(cell),
                  static_cast<void*>(pBar), static_cast<void*>(conc), static_cast<void*>(m),
                  static_cast<void*>(y), static_cast<void*>(mdot), static_cast<void*>(mg),
                  static_cast<void*>(q), static_cast<void*>(d), static_cast<void*>(removed)}) {
    cudaFree(p);
  }
  return t;
}

} // namespace coredem::bench::thermochem
