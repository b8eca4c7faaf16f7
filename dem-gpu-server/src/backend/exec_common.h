#pragma once
/// @file
/// Shared backend vocabulary: the lambda qualifier for parallel_for bodies and the error
/// hook. A backend ("Exec") is a small type providing (see cpu/cpu_exec.h):
///   parallelFor(n, f)            f(i) for i in [0, n), any order, no two i alias
///   reduceMax(n, f, init)        max(init, max_i f(i)); exact, so order-independent. f may
///                                write outputs of its own index i (fused kernel + reduction)
///   sortByKey(keys, n, numKeys, perm)   stable permutation sorting keys ascending
///   sortByKeyRadix(keys, n, numKeys, perm)   same permutation, cost independent of numKeys
///   exclusiveScan(in, out, n)    out[i] = Σ_{k<i} in[k]
///   allocHost/freeHost (pinned for CUDA), allocDevice/freeDevice, copyToDevice/copyToHost,
///   synchronize(); separateDevice tells whether device memory differs from host memory.

#include <string>

#if defined(__CUDACC__)
#define DEM_LAMBDA __host__ __device__
#else
#define DEM_LAMBDA
#endif

namespace coredem::dem::backend {

/// Cache hint for memory a loop body will touch a few iterations later (CPU: the compiler's
/// prefetch; CUDA device code: nothing). Never changes results.
#if defined(__CUDACC__)
__host__ __device__
#endif
    inline void
    prefetch(const void* p) {
#if defined(__CUDA_ARCH__)
  (void)p;
#else
  __builtin_prefetch(p, 1, 3);
#endif
}

/// Throws coredem::UserError(message) (defined out of line so that nvcc-compiled code does
/// not need the fmt-based check macros).
[[noreturn]] void raiseUserError(const std::string& message);

} // namespace coredem::dem::backend
