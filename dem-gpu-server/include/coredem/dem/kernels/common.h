#pragma once
/// @file
/// The one qualifier macro for physics kernels shared by the CPU and CUDA backends
///: `DEM_HD` is `__host__ __device__` under nvcc and `inline` otherwise, so
/// the CPU backend and the GPU backend run the exact same expressions.

#if defined(__CUDACC__)
#define DEM_HD __host__ __device__ inline
#define DEM_HD_FORCEINLINE __host__ __device__ __forceinline__
#else
#define DEM_HD inline
/// DEM_HD for a function the compiler must inline (a hot loop's body called from two places).
#define DEM_HD_FORCEINLINE inline __attribute__((always_inline))
#endif

#include <cstdint>

namespace coredem::dem::kernels {

/// Index of the lowest set bit of x (x ≠ 0): walks a bit set in ascending order with
/// `for (b = bits; b; b &= b - 1) use(lowestBit(b));`.
DEM_HD int lowestBit(std::uint32_t x) {
#if defined(__CUDA_ARCH__)
  return __ffs(static_cast<int>(x)) - 1;
#else
  return __builtin_ctz(x);
#endif
}

} // namespace coredem::dem::kernels
