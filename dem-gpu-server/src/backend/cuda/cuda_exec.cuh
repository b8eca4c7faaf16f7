#pragma once
/// @file
/// The cuda backend: kernel launch for parallelFor, CUB for sort/scan/reduce, cudaMalloc /
/// pinned host memory. Thin on purpose: the physics is the shared engine_impl.h.

#include <cstddef>
#include <cstdint>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <cuda/functional>
#include <string>

#include <cuda_runtime.h>

#include "../exec_common.h"
#include "../sync_counters.h"

/// Wraps every CUDA runtime call: throws with file:line and a hint.
#define DEM_CUDA_CHECK(expr)                                                                       \
  do {                                                                                             \
    const cudaError_t demCudaErr_ = (expr);                                                        \
    if (demCudaErr_ != cudaSuccess) {                                                              \
      ::coredem::dem::backend::raiseUserError(                                                     \
          std::string("CUDA call '") + #expr + "' failed at " + __FILE__ + ":" +                   \
          std::to_string(__LINE__) + ": " + cudaGetErrorName(demCudaErr_) + ": " +                 \
          cudaGetErrorString(demCudaErr_) +                                                        \
          " (check the GPU and its driver with nvidia-smi, and CUDA_VISIBLE_DEVICES; "             \
          "--backend cpu runs without it)");                                                       \
    }                                                                                              \
  } while (false)

namespace coredem::dem::backend {

template <class F>
__global__ void forEachKernel(std::size_t n, F f) {
  const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n)
    f(i);
}

template <class F>
__global__ void evalKernel(std::size_t n, F f, double* out) {
  const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n)
    out[i] = f(i);
}

/// *out = max(*v, init) (v == nullptr: init): the last step of reduceMaxInto, on the device.
inline __global__ void maxWithInitKernel(const double* v, double init, double* out) {
  const double r = v != nullptr ? *v : init;
  *out = r > init ? r : init;
}

template <class T>
__global__ void iotaKernel(std::size_t n, T* v) {
  static_assert(sizeof(T) == 4, "32-bit indices");
  const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n)
    v[i] = static_cast<T>(i);
}

struct CudaExec {
  static constexpr bool separateDevice = true;
  static constexpr const char* name = "cuda";
  static constexpr unsigned kBlock = 256;
  int threads = 0; ///< unused (kept for a uniform set-up)

  static unsigned blocks(std::size_t n) { return static_cast<unsigned>((n + kBlock - 1) / kBlock); }

  static void checkLaunch() {
    DEM_CUDA_CHECK(cudaGetLastError());
#if !defined(NDEBUG)
    DEM_CUDA_CHECK(cudaDeviceSynchronize());
#endif
  }

  template <class F>
  void parallelFor(std::size_t n, F f) const {
    if (n == 0)
      return;
    ++syncCounters().launches;
    forEachKernel<<<blocks(n), kBlock>>>(n, f);
    checkLaunch();
  }

  template <class F>
  double reduceMax(std::size_t n, F f, double init) const {
    if (n == 0)
      return init;
    double* vals = scratch<double>(_vals, _valsCap, n + 1);
    syncCounters().launches += 2;
    ++syncCounters().hostRoundTrips;
    evalKernel<<<blocks(n), kBlock>>>(n, f, vals);
    checkLaunch();
    std::size_t tmpBytes = 0;
    DEM_CUDA_CHECK(cub::DeviceReduce::Max(nullptr, tmpBytes, vals, vals + n, static_cast<int>(n)));
    void* tmp = scratch<unsigned char>(_tmp, _tmpCap, tmpBytes);
    DEM_CUDA_CHECK(cub::DeviceReduce::Max(tmp, tmpBytes, vals, vals + n, static_cast<int>(n)));
    double r = init;
    DEM_CUDA_CHECK(cudaMemcpy(&r, vals + n, sizeof(double), cudaMemcpyDeviceToHost));
    return r > init ? r : init;
  }

  /// reduceMax whose result stays in device memory (*out, a device pointer): the launches are
  /// queued and the host does not wait (the engine reads the sub-step's results in one copy).
  template <class F>
  void reduceMaxInto(std::size_t n, F f, double init, double* out) const {
    if (n == 0) {
      ++syncCounters().launches;
      maxWithInitKernel<<<1, 1>>>(nullptr, init, out);
      checkLaunch();
      return;
    }
    double* vals = scratch<double>(_vals, _valsCap, n + 1);
    syncCounters().launches += 2;
    evalKernel<<<blocks(n), kBlock>>>(n, f, vals); // f once per index (it may write)
    checkLaunch();
    std::size_t tmpBytes = 0;
    DEM_CUDA_CHECK(cub::DeviceReduce::Reduce(nullptr, tmpBytes, vals, out, static_cast<int>(n),
                                             ::cuda::maximum<>{}, init));
    void* tmp = scratch<unsigned char>(_tmp, _tmpCap, tmpBytes);
    DEM_CUDA_CHECK(cub::DeviceReduce::Reduce(tmp, tmpBytes, vals, out, static_cast<int>(n),
                                             ::cuda::maximum<>{}, init));
  }

  void exclusiveScan(const std::uint32_t* in, std::uint32_t* out, std::size_t n) const {
    ++syncCounters().launches;
    std::size_t tmpBytes = 0;
    DEM_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, tmpBytes, in, out, static_cast<int>(n)));
    void* tmp = scratch<unsigned char>(_tmp, _tmpCap, tmpBytes);
    DEM_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(tmp, tmpBytes, in, out, static_cast<int>(n)));
  }

  /// Stable LSD radix sort of (key, index) pairs; perm receives the indices.
  void sortByKey(const std::uint32_t* keys, std::size_t n, std::uint32_t numKeys,
                 std::uint32_t* perm) const {
    if (n == 0)
      return;
    syncCounters().launches += 2;
    int bits = 1;
    while (bits < 32 && (1ull << bits) < numKeys)
      ++bits;
    std::uint32_t* buf = scratch<std::uint32_t>(_sortBuf, _sortCap, 2 * n);
    std::uint32_t* keysOut = buf;
    std::uint32_t* iota = buf + n;
    iotaKernel<<<blocks(n), kBlock>>>(n, iota);
    checkLaunch();
    std::size_t tmpBytes = 0;
    DEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, tmpBytes, keys, keysOut, iota, perm,
                                                   static_cast<int>(n), 0, bits));
    void* tmp = scratch<unsigned char>(_tmp, _tmpCap, tmpBytes);
    DEM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(tmp, tmpBytes, keys, keysOut, iota, perm,
                                                   static_cast<int>(n), 0, bits));
  }

  /// Same as sortByKey: CUB's radix sort already costs O(n · bits), independent of numKeys.
  void sortByKeyRadix(const std::uint32_t* keys, std::size_t n, std::uint32_t numKeys,
                      std::uint32_t* perm) const {
    sortByKey(keys, n, numKeys, perm);
  }

  static void* allocHost(std::size_t bytes) {
    void* p = nullptr;
    if (bytes)
      DEM_CUDA_CHECK(cudaMallocHost(&p, bytes));
    return p;
  }
  static void freeHost(void* p) {
    if (p)
      cudaFreeHost(p);
  }
  static void* allocDevice(std::size_t bytes) {
    void* p = nullptr;
    if (bytes)
      DEM_CUDA_CHECK(cudaMalloc(&p, bytes));
    return p;
  }
  static void freeDevice(void* p) {
    if (p)
      cudaFree(p);
  }
  static void copyToDevice(void* d, const void* h, std::size_t bytes) {
    if (bytes)
      DEM_CUDA_CHECK(cudaMemcpy(d, h, bytes, cudaMemcpyHostToDevice));
  }
  static void copyToHost(void* h, const void* d, std::size_t bytes) {
    if (bytes)
      ++syncCounters().hostRoundTrips;
    if (bytes)
      DEM_CUDA_CHECK(cudaMemcpy(h, d, bytes, cudaMemcpyDeviceToHost));
  }
  static void copyDeviceToDevice(void* dst, const void* src, std::size_t bytes) {
    if (bytes)
      DEM_CUDA_CHECK(cudaMemcpy(dst, src, bytes, cudaMemcpyDeviceToDevice));
  }
  static void synchronize() {
    ++syncCounters().deviceSyncs;
    DEM_CUDA_CHECK(cudaDeviceSynchronize());
  }

  /// Stage timing without waiting: a mark is a CUDA event recorded in the stream; the engine
  /// reads the differences after the sub-step's status copy, when every mark has completed.
  struct Mark {
    cudaEvent_t e = nullptr;
    Mark() = default;
    Mark(const Mark&) = delete;
    Mark& operator=(const Mark&) = delete;
    ~Mark() {
      if (e)
        cudaEventDestroy(e);
    }
  };
  static void mark(Mark& m) {
    if (!m.e)
      DEM_CUDA_CHECK(cudaEventCreate(&m.e));
    DEM_CUDA_CHECK(cudaEventRecord(m.e));
  }
  static double seconds(const Mark& a, const Mark& b) {
    float ms = 0.0f;
    DEM_CUDA_CHECK(cudaEventElapsedTime(&ms, a.e, b.e));
    return 1e-3 * static_cast<double>(ms);
  }

  CudaExec() = default;
  CudaExec(const CudaExec&) = delete;
  CudaExec& operator=(const CudaExec&) = delete;
  ~CudaExec() {
    freeDevice(_vals);
    freeDevice(_tmp);
    freeDevice(_sortBuf);
  }

private:
  template <class T, class P>
  static T* scratch(P*& ptr, std::size_t& cap, std::size_t n) {
    if (n * sizeof(T) > cap) {
      freeDevice(ptr);
      ptr = static_cast<P*>(allocDevice(n * sizeof(T)));
      cap = n * sizeof(T);
    }
    return reinterpret_cast<T*>(ptr);
  }
  mutable void* _vals = nullptr;
  mutable std::size_t _valsCap = 0;
  mutable void* _tmp = nullptr;
  mutable std::size_t _tmpCap = 0;
  mutable void* _sortBuf = nullptr;
  mutable std::size_t _sortCap = 0;
};

} // namespace coredem::dem::backend
