#pragma once
/// @file
/// The cpu backend (the reference): OpenMP loops over index ranges. Every parallel loop
/// writes only its own index, so results do not depend on the thread count or on which
/// thread runs which index. Dynamic scheduling in chunks of 512 lets a running thread take
/// over the work of a descheduled one (shared/oversubscribed machines).

#include "../exec_common.h"

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

namespace coredem::dem::backend {

struct CpuExec {
  static constexpr bool separateDevice = false;
  static constexpr const char* name = "cpu";
  int threads = 0;  ///< 0: OpenMP default

  int threadCount() const { return threads > 0 ? threads : omp_get_max_threads(); }

  template <class F>
  void parallelFor(std::size_t n, F f) const {
    const std::int64_t m = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(dynamic, 512) num_threads(threadCount()) if (m > 256)
    for (std::int64_t i = 0; i < m; ++i) f(static_cast<std::size_t>(i));
  }

  template <class F>
  double reduceMax(std::size_t n, F f, double init) const {
    const std::int64_t m = static_cast<std::int64_t>(n);
    double r = init;
#pragma omp parallel for schedule(dynamic, 512) num_threads(threadCount()) reduction(max : r) if (m > 256)
    for (std::int64_t i = 0; i < m; ++i) r = std::max(r, f(static_cast<std::size_t>(i)));
    return r;
  }

  /// out[i] = Σ_{k<i} in[k] (serial: it is O(n) and runs on small histograms).
  void exclusiveScan(const std::uint32_t* in, std::uint32_t* out, std::size_t n) const {
    std::uint32_t s = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t v = in[i];
      out[i] = s;
      s += v;
    }
  }

  /// Stable counting sort: perm lists indices in ascending key order (ties keep index order).
  /// @pre keys[i] < numKeys.
  void sortByKey(const std::uint32_t* keys, std::size_t n, std::uint32_t numKeys,
                 std::uint32_t* perm) const {
    _hist.assign(static_cast<std::size_t>(numKeys) + 1, 0u);
    for (std::size_t i = 0; i < n; ++i) ++_hist[keys[i]];
    _offsets.resize(_hist.size());
    exclusiveScan(_hist.data(), _offsets.data(), _hist.size());
    for (std::size_t i = 0; i < n; ++i) perm[_offsets[keys[i]]++] = static_cast<std::uint32_t>(i);
  }

  static void* allocHost(std::size_t bytes) { return bytes ? ::operator new(bytes, std::align_val_t{64}) : nullptr; }
  static void freeHost(void* p) { if (p) ::operator delete(p, std::align_val_t{64}); }
  static void* allocDevice(std::size_t bytes) { return allocHost(bytes); }
  static void freeDevice(void* p) { freeHost(p); }
  static void copyToDevice(void* d, const void* h, std::size_t bytes) { if (d != h && bytes) std::memcpy(d, h, bytes); }
  static void copyToHost(void* h, const void* d, std::size_t bytes) { if (d != h && bytes) std::memcpy(h, d, bytes); }
  static void copyDeviceToDevice(void* dst, const void* src, std::size_t bytes) { if (dst != src && bytes) std::memcpy(dst, src, bytes); }
  static void synchronize() {}

private:
  mutable std::vector<std::uint32_t> _hist, _offsets;
};

} // namespace coredem::dem::backend
