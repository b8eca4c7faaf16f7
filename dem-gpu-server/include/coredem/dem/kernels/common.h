#pragma once
/// @file
/// The one qualifier macro for physics kernels shared by the CPU and CUDA backends
///: `DEM_HD` is `__host__ __device__` under nvcc and `inline` otherwise, so
/// the CPU backend and the GPU backend run the exact same expressions.

#if defined(__CUDACC__)
#define DEM_HD __host__ __device__ inline
#else
#define DEM_HD inline
#endif
