#pragma once
/// @file
/// The cuda-sim backend: the cpu kernels under the cuda backend's memory model, so that a
/// missing host↔device synchronisation fails on a machine without a GPU (tests, CI).
///
/// What it shares with backend/cuda/cuda_exec.cuh:
///   - separateDevice = true: every DualArray has a host mirror and a separate device copy,
///     moved only by toDevice()/toHost() under the same modify/sync flags;
///   - allocations are not zeroed: device and host memory start as garbage (the 8-byte pattern
///     0x7ff4a5a5a5a5a5a5, a signalling NaN as a double, large integers otherwise), so a read
///     of a copy that was never written or never synchronised shows up as NaN or nonsense;
///   - device memory is reachable only from kernels and copies: outside parallelFor,
///     reduceMax, exclusiveScan, sortByKey* and the copy functions it is mapped PROT_NONE, so
///     host code dereferencing a device pointer stops with SIGSEGV (a message names the
///     likely cause) where the cuda backend would read garbage or crash;
///   - CUB-like primitives: stable LSD radix sort, max by a pairwise tree, loops run in
///     reverse index order (a body that depends on the iteration order differs from cpu).
/// What it does not model: asynchronous launches (every call here is synchronous, as the
/// cuda backend's results are after its cudaMemcpy), device math (FMA contraction) and
/// kernels that read pinned host memory (legal, slow, on a GPU).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "../cpu/cpu_exec.h"
#include "../exec_common.h"
#include "../sync_counters.h"

namespace coredem::dem::backend {

namespace sim {
/// Page-granular device allocation filled with the garbage pattern; PROT_NONE outside
/// DeviceScope. Thread-safe.
void* allocDevice(std::size_t bytes);
void freeDevice(void* p);
/// Host allocation filled with the garbage pattern (pinned memory is not zeroed either).
void* allocHost(std::size_t bytes);
void freeHost(void* p);
/// Device memory readable and writable while at least one scope is alive (nesting allowed).
struct DeviceScope {
  DeviceScope();
  ~DeviceScope();
  DeviceScope(const DeviceScope&) = delete;
  DeviceScope& operator=(const DeviceScope&) = delete;
};
inline void countLaunch() {
  ++syncCounters().launches;
}
inline void countRoundTrip() {
  ++syncCounters().hostRoundTrips;
}
} // namespace sim

struct CudaSimExec {
  static constexpr bool separateDevice = true;
  static constexpr const char* name = "cuda-sim";
  /// Ignored: cuda-sim runs on one thread. Changing page protections (DeviceScope) in a
  /// process whose OpenMP threads spin between loops costs a TLB shootdown on every core
  /// (20× slower on a loaded machine), and thread-count independence is the cpu backend's test.
  int threads = 0;

  /// f(i) for every i, in reverse index order (any order is allowed; cpu runs ascending).
  template <class F>
  void parallelFor(std::size_t n, F f) const {
    sim::DeviceScope scope;
    sim::countLaunch();
    for (std::size_t k = 0; k < n; ++k)
      f(n - 1 - k);
  }

  /// Evaluates f into a buffer (as evalKernel does), then reduces it by a pairwise tree (the
  /// order of a CUB block reduction rather than the cpu's chunked loop); the result is read
  /// back to the host (a round trip).
  template <class F>
  double reduceMax(std::size_t n, F f, double init) const {
    if (n == 0)
      return init;
    sim::DeviceScope scope;
    sim::countRoundTrip();
    return std::max(treeMax(n, f), init);
  }

  /// reduceMax whose result stays in device memory (*out, a device pointer): no round trip.
  template <class F>
  void reduceMaxInto(std::size_t n, F f, double init, double* out) const {
    sim::DeviceScope scope;
    sim::countLaunch();
    *out = n == 0 ? init : std::max(treeMax(n, f), init);
  }

  void exclusiveScan(const std::uint32_t* in, std::uint32_t* out, std::size_t n) const {
    sim::DeviceScope scope;
    sim::countLaunch();
    _cpu.exclusiveScan(in, out, n);
  }

  /// Stable LSD radix sort (CUB's algorithm; the same permutation as cpu's counting sort).
  void sortByKey(const std::uint32_t* keys, std::size_t n, std::uint32_t numKeys,
                 std::uint32_t* perm) const {
    sim::DeviceScope scope;
    sim::countLaunch();
    _cpu.sortByKeyRadix(keys, n, numKeys, perm);
  }
  void sortByKeyRadix(const std::uint32_t* keys, std::size_t n, std::uint32_t numKeys,
                      std::uint32_t* perm) const {
    sortByKey(keys, n, numKeys, perm);
  }

  static void* allocHost(std::size_t bytes) { return sim::allocHost(bytes); }
  static void freeHost(void* p) { sim::freeHost(p); }
  static void* allocDevice(std::size_t bytes) { return sim::allocDevice(bytes); }
  static void freeDevice(void* p) { sim::freeDevice(p); }
  static void copyToDevice(void* d, const void* h, std::size_t bytes) { copy(d, h, bytes); }
  static void copyToHost(void* h, const void* d, std::size_t bytes) {
    if (bytes)
      sim::countRoundTrip();
    copy(h, d, bytes);
  }
  static void copyDeviceToDevice(void* dst, const void* src, std::size_t bytes) {
    copy(dst, src, bytes);
  }
  static void synchronize() { ++syncCounters().deviceSyncs; }

  /// Stage timing: the host clock, as on the cpu (cuda uses events that do not wait).
  using Mark = CpuExec::Mark;
  static void mark(Mark& m) { CpuExec::mark(m); }
  static double seconds(const Mark& a, const Mark& b) { return CpuExec::seconds(a, b); }

private:
  template <class F>
  double treeMax(std::size_t n, F f) const {
    _vals.resize(n);
    double* vals = _vals.data();
    parallelFor(n, [=](std::size_t i) { vals[i] = f(i); });
    for (std::size_t stride = 1; stride < n; stride *= 2)
      for (std::size_t i = 0; i + stride < n; i += 2 * stride)
        vals[i] = std::max(vals[i], vals[i + stride]);
    return vals[0];
  }

  static void copy(void* dst, const void* src, std::size_t bytes) {
    if (!bytes)
      return;
    sim::DeviceScope scope;
    std::memcpy(dst, src, bytes);
  }
  CpuExec _cpu; ///< serial scan and radix sort
  mutable std::vector<double> _vals;
};

} // namespace coredem::dem::backend
