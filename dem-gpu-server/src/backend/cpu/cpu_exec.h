#pragma once
/// @file
/// The cpu backend (the reference): OpenMP loops over index ranges. Every parallel loop
/// writes only its own index, so results do not depend on the thread count or on which
/// thread runs which index. Work is handed out by ItemClaims: each thread works through its own
/// contiguous part of the particle order in every pass (what its caches hold stays useful from
/// pass to pass), and takes over the rest of another's part once its own is done (a thread
/// descheduled on a shared machine does not hold the others up).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include <omp.h>

#include "../exec_common.h"
#include "coredem/dem/kernels/lanes.h"

namespace coredem::dem::backend {

/// Work items [0, count) over a team of threads (parallel regions of CpuExec). Thread t owns
/// the contiguous block [count·t/team, count·(t+1)/team) and claims its items from the front, in
/// order; once its block is done it claims items from the back of the others' blocks. A thread
/// thus works on the same part of the particle order in every pass: on a machine whose cores do
/// not share their last-level cache (two chiplets), a thread that roamed over all particles
/// fetched each row from the other core's cache or from memory in every pass (with dynamic
/// chunks the dilute benchmark deck ran 1.8× slower on two threads; docs/performance.md). A
/// claim is one compare-and-swap on the owner's cache line; the counters only hand out
/// indices (the data is ordered by the region's barriers), so relaxed order suffices.
class ItemClaims {
public:
  ItemClaims() = default;
  ItemClaims(const ItemClaims&) {} // a copy gets its own counters
  ItemClaims& operator=(const ItemClaims&) { return *this; }

  /// Sets `sets` independent sets of blocks (e.g. one per colour of a slab pass), set k over
  /// counts[k] items, for `team` threads. Called by one thread before the others claim.
  void init(int team, int sets, const std::uint32_t* counts) {
    const int lines = team * sets;
    if (lines > _capacity) {
      _lines.reset(new Line[static_cast<std::size_t>(lines)]);
      _capacity = lines;
    }
    _team = team;
    for (int k = 0; k < sets; ++k) {
      for (int t = 0; t < team; ++t) {
        const std::uint64_t lo = std::uint64_t{counts[k]} * t / team;
        const std::uint64_t hi = std::uint64_t{counts[k]} * (t + 1) / team;
        _lines[k * team + t].range.store(lo | hi << 32, std::memory_order_relaxed);
      }
    }
  }

  /// Thread t of the team runs body(item) for items of set k until none is left.
  template <class Body>
  void run(int k, int t, Body&& body) {
    Line* set = _lines.get() + static_cast<std::ptrdiff_t>(k) * _team;
    for (std::int64_t item; (item = claim(set[t], true)) >= 0;)
      body(static_cast<std::uint32_t>(item));
    for (int d = 1; d < _team; ++d)
      for (std::int64_t item; (item = claim(set[(t + d) % _team], false)) >= 0;)
        body(static_cast<std::uint32_t>(item));
  }

private:
  struct alignas(64) Line {
    std::atomic<std::uint64_t> range{0}; ///< low 32 bits: next front item; high: end
  };
  /// Takes the front (or back) item of a block; -1 when it is empty.
  static std::int64_t claim(Line& line, bool front) {
    std::uint64_t cur = line.range.load(std::memory_order_relaxed);
    for (;;) {
      const std::uint64_t lo = cur & 0xffffffffu, hi = cur >> 32;
      if (lo >= hi)
        return -1;
      const std::uint64_t next = front ? (lo + 1) | hi << 32 : lo | (hi - 1) << 32;
      if (line.range.compare_exchange_weak(cur, next, std::memory_order_relaxed))
        return static_cast<std::int64_t>(front ? lo : hi - 1);
    }
  }
  std::unique_ptr<Line[]> _lines;
  int _capacity = 0;
  int _team = 1;
};

/// One flag per slab: done (CpuExec::reduceMaxOverSlabRanges).
class SlabFlags {
public:
  SlabFlags() = default;
  SlabFlags(const SlabFlags&) {} // a copy gets its own flags
  SlabFlags& operator=(const SlabFlags&) { return *this; }
  /// slabs flags, all clear (called by one thread before a region).
  void reset(int slabs) {
    const auto n = static_cast<std::size_t>(slabs > 0 ? slabs : 0);
    if (n > _capacity) {
      _flags.reset(new std::atomic<std::uint32_t>[n]);
      _capacity = n;
    }
    for (std::size_t s = 0; s < n; ++s)
      _flags[s].store(0, std::memory_order_relaxed);
  }
  std::atomic<std::uint32_t>* flags() { return _flags.get(); }

private:
  std::unique_ptr<std::atomic<std::uint32_t>[]> _flags;
  std::size_t _capacity = 0;
};

/// A spinning thread's hint to the processor (x86: pause).
inline void spinPause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

struct CpuExec {
  static constexpr bool separateDevice = false;
  static constexpr const char* name = "cpu";
  int threads = 0; ///< 0: OpenMP default
#if defined(COREDEM_DEM_DOUBLE2)
  /// The contact loop evaluates two pairs at once, one in each lane (contacts.h, lanes.h).
  using PairScalar = kernels::Double2;
#endif

  int threadCount() const {
    return threads > 0 ? threads : omp_get_max_threads();
  }

  // Each thread calls its own copy of the body: a local whose address does not escape, so the
  // compiler may keep the captured pointers in registers instead of reloading them from the
  // shared closure after every store the body makes (it cannot rule out that such a store
  // changes the closure). Same calls, same order within a thread: the results are unchanged.
  template <class F>
  void parallelFor(std::size_t n, F f) const {
    const std::int64_t m = static_cast<std::int64_t>(n);
    initChunks(n);
#pragma omp parallel num_threads(threadCount()) if (m > kChunk / 2)
    {
      const F g = f;
      inChunks(n, [&](std::int64_t lo, std::int64_t hi) {
        for (std::int64_t i = lo; i < hi; ++i)
          g(static_cast<std::size_t>(i));
      });
    }
  }

  template <class F>
  double reduceMax(std::size_t n, F f, double init) const {
    const std::int64_t m = static_cast<std::int64_t>(n);
    double r = init;
    initChunks(n);
#pragma omp parallel num_threads(threadCount()) reduction(max : r) if (m > kChunk / 2)
    {
      const F g = f;
      inChunks(n, [&](std::int64_t lo, std::int64_t hi) {
        for (std::int64_t i = lo; i < hi; ++i)
          r = std::max(r, g(static_cast<std::size_t>(i)));
      });
    }
    return r;
  }

  /// reduceMaxInto over [0, n) in ranges: f(lo, hi) returns the max over the indices [lo, hi)
  /// (−∞ for none), so that a body may work on several at a time, e.g. in the lanes of a
  /// register (motion.h). The ranges are the chunks of parallelFor.
  template <class F>
  void reduceMaxOverRangesInto(std::size_t n, F f, double init, double* out) const {
    const std::int64_t m = static_cast<std::int64_t>(n);
    double r = init;
    initChunks(n);
#pragma omp parallel num_threads(threadCount()) reduction(max : r) if (m > kChunk / 2)
    {
      const F g = f;
      inChunks(n, [&](std::int64_t lo, std::int64_t hi) { r = std::max(r, g(lo, hi)); });
    }
    *out = r;
  }

  /// max of f(i) over every index of the slabs [start[s], start[s + 1]), s < slabs, run by
  /// colour (reduceMaxOverSlabRanges), each slab in index order.
  template <class F>
  void reduceMaxOverSlabsWide(const std::uint32_t* start, int slabs, F f, double init,
                              double* out) const {
    reduceMaxOverSlabRanges(
        start, slabs,
        [f](int, std::int64_t lo, std::int64_t hi) {
          double r = -__builtin_inf();
          for (std::int64_t i = lo; i < hi; ++i)
            r = std::max(r, f(static_cast<std::size_t>(i)));
          return r;
        },
        init, out);
  }

  /// max of f(s, lo, hi) over the slabs s < slabs, [lo, hi) = [start[s], start[s + 1]) (f
  /// returns the max over its slab), run by colour: the slabs s ≡ c (mod 3) for c = 0, 1, 2 in
  /// turn, each slab on one thread (pair_lists.h "Slabs": f may then write its pair terms into
  /// both particles). No barrier between colours: slab s writes into slabs s − 1 .. s + 1, so it
  /// shares particles with the slabs within two of it, all of other colours; it starts once
  /// those of lower colours are done, and those of higher colours wait for it. Each particle
  /// thus receives its terms in colour order, as with a barrier, while a thread done with its
  /// slabs of one colour goes on with the next wherever its neighbours allow. (Every slab of a
  /// colour is claimed before any of the next: a slab waits only for slabs being worked on.)
  /// Where the processor has AVX, f is inlined into a copy compiled for AVX, whose three-operand
  /// encoding needs none of the register copies of SSE2's two-operand forms; same operations,
  /// no FMA (not part of AVX): the same results. `start` is host memory.
  template <class F>
  void reduceMaxOverSlabRanges(const std::uint32_t* start, int slabs, F f, double init,
                               double* out) const {
    double r = init;
    const bool avx = hasAvx();
    std::uint32_t counts[3];
    for (int c = 0; c < 3; ++c)
      counts[c] = slabs > c ? static_cast<std::uint32_t>((slabs - c + 2) / 3) : 0u;
    _claims.init(threadCount(), 3, counts);
    _slabDone.reset(slabs);
    std::atomic<std::uint32_t>* done = _slabDone.flags();
#pragma omp parallel num_threads(threadCount()) reduction(max : r) if (slabs > 3)
    {
      const F g = f;
      const int t = omp_get_thread_num();
      for (int c = 0; c < 3; ++c) {
        _claims.run(c, t, [&](std::uint32_t item) {
          const int s = c + 3 * static_cast<int>(item);
          for (int d = -2; d <= 2; ++d) { // the slabs within two of lower colour
            const int q = s + d;
            if (d != 0 && q >= 0 && q < slabs && q % 3 < c)
              while (done[q].load(std::memory_order_acquire) == 0)
                spinPause();
          }
          const auto lo = static_cast<std::int64_t>(start[s]);
          const auto hi = static_cast<std::int64_t>(start[s + 1]);
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__AVX__)
          if (avx)
            r = std::max(r, slabAvx(g, s, lo, hi));
          else
#endif
            r = std::max(r, g(s, lo, hi));
          done[s].store(1, std::memory_order_release);
        });
      }
    }
    (void)avx;
    *out = r;
  }

  /// Whether the processor (and the operating system) support AVX.
  static bool hasAvx() {
#if defined(__x86_64__) && defined(__GNUC__)
    static const bool avx = __builtin_cpu_supports("avx");
    return avx;
#else
    return false;
#endif
  }

  /// reduceMax whose result stays in device memory (*out; here host and device are one): the
  /// device backends leave it there, and the engine reads every such result of a sub-step back
  /// in one transfer at its end (engine_impl.h, SubStepStatus).
  template <class F>
  void reduceMaxInto(std::size_t n, F f, double init, double* out) const {
    *out = reduceMax(n, f, init);
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
    for (std::size_t i = 0; i < n; ++i)
      ++_hist[keys[i]];
    _offsets.resize(_hist.size());
    exclusiveScan(_hist.data(), _offsets.data(), _hist.size());
    for (std::size_t i = 0; i < n; ++i)
      perm[_offsets[keys[i]]++] = static_cast<std::uint32_t>(i);
  }

  /// Stable LSD radix sort (8-bit digits over the bits numKeys needs): the same permutation as
  /// sortByKey, at a cost O(n · bits/8) that does not depend on numKeys (no histogram of
  /// numKeys buckets). For sparse keys, e.g. a few particles on a large coupling grid.
  /// Parallel: each thread counts the digits of its own contiguous block, and scatters it to
  /// offsets ordered by (digit, block): the same stable permutation for any thread count.
  /// @pre keys[i] < numKeys.
  void sortByKeyRadix(const std::uint32_t* keys, std::size_t n, std::uint32_t numKeys,
                      std::uint32_t* perm) const {
    int bits = 1;
    while (bits < 32 && (std::uint64_t{1} << bits) < numKeys)
      ++bits;
    _radixTmp.resize(n);
    std::uint32_t* src = perm;
    std::uint32_t* dst = _radixTmp.data();
    const int blocks =
        n < kParallelSortMin ? 1 : std::min<int>(threadCount(), static_cast<int>(n / 4096) + 1);
    _radixCount.assign(static_cast<std::size_t>(blocks) * 256, 0);
    std::size_t* count = _radixCount.data();
    for (int shift = 0; shift < bits; shift += 8) {
      const bool first = shift == 0;
#pragma omp parallel num_threads(blocks) if (blocks > 1)
      {
        const int b = blocks > 1 ? omp_get_thread_num() : 0;
        const std::size_t lo = n * b / blocks, hi = n * (b + 1) / blocks;
        std::size_t* c = count + 256 * static_cast<std::size_t>(b);
        for (int d = 0; d < 256; ++d)
          c[d] = 0;
        for (std::size_t i = lo; i < hi; ++i) {
          const std::uint32_t idx = first ? static_cast<std::uint32_t>(i) : src[i];
          ++c[(keys[idx] >> shift) & 255u];
        }
#pragma omp barrier
#pragma omp single
        {
          std::size_t sum = 0; // exclusive offsets in (digit, block) order
          for (int d = 0; d < 256; ++d) {
            for (int t = 0; t < blocks; ++t) {
              const std::size_t v = count[256 * static_cast<std::size_t>(t) + d];
              count[256 * static_cast<std::size_t>(t) + d] = sum;
              sum += v;
            }
          }
        }
        for (std::size_t i = lo; i < hi; ++i) {
          const std::uint32_t idx = first ? static_cast<std::uint32_t>(i) : src[i];
          dst[c[(keys[idx] >> shift) & 255u]++] = idx;
        }
      }
      std::swap(src, dst);
    }
    if (src != perm && n)
      std::memcpy(perm, src, n * sizeof(std::uint32_t));
  }

  static void* allocHost(std::size_t bytes) {
    return bytes ? ::operator new (bytes, std::align_val_t{64}) : nullptr;
  }
  static void freeHost(void* p) {
    if (p)
      ::operator delete (p, std::align_val_t{64});
  }
  static void* allocDevice(std::size_t bytes) {
    return allocHost(bytes);
  }
  static void freeDevice(void* p) {
    freeHost(p);
  }
  static void copyToDevice(void* d, const void* h, std::size_t bytes) {
    if (d != h && bytes)
      std::memcpy(d, h, bytes);
  }
  static void copyToHost(void* h, const void* d, std::size_t bytes) {
    if (d != h && bytes)
      std::memcpy(h, d, bytes);
  }
  static void copyDeviceToDevice(void* dst, const void* src, std::size_t bytes) {
    if (dst != src && bytes)
      std::memcpy(dst, src, bytes);
  }
  static void synchronize() {}

  /// Stage timing (engine_impl.h): a mark is the host clock (every loop has finished when the
  /// call that ran it returns).
  struct Mark {
    std::chrono::steady_clock::time_point t;
  };
  static void mark(Mark& m) {
    m.t = std::chrono::steady_clock::now();
  }
  /// Seconds from mark a to mark b.
  static double seconds(const Mark& a, const Mark& b) {
    return std::chrono::duration<double>(b.t - a.t).count();
  }

private:
  /// Indices per work item of parallelFor and reduceMax.
  static constexpr std::int64_t kChunk = 512;
  /// Before a parallel region of inChunks(n, ...): its chunks handed out to a team of
  /// threadCount() (a smaller team takes the missing threads' chunks over as it does a slow
  /// thread's; the end of the last region has joined every thread that claimed from them).
  void initChunks(std::size_t n) const {
    const auto chunks =
        static_cast<std::uint32_t>((static_cast<std::int64_t>(n) + kChunk - 1) / kChunk);
    _claims.init(threadCount(), 1, &chunks);
  }
  /// Inside a parallel region: body(lo, hi) over [0, n) in chunks of kChunk, claimed through
  /// _claims (this thread's contiguous part first; initChunks(n) before the region).
  template <class Body>
  void inChunks(std::size_t n, Body&& body) const {
    const auto m = static_cast<std::int64_t>(n);
    if (omp_get_num_threads() == 1) { // nothing to hand out
      body(std::int64_t{0}, m);
      return;
    }
    _claims.run(0, omp_get_thread_num(), [&](std::uint32_t c) {
      const std::int64_t lo = static_cast<std::int64_t>(c) * kChunk;
      body(lo, std::min(m, lo + kChunk));
    });
  }
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__AVX__)
  /// g(s, lo, hi) inlined into code compiled for AVX (reduceMaxOverSlabRanges).
  template <class F>
  [[gnu::target("avx"), gnu::flatten]] static double slabAvx(const F& g, int s, std::int64_t lo,
                                                             std::int64_t hi) {
    return g(s, lo, hi);
  }
#endif
  /// Below this many keys the radix sort runs on one thread.
  static constexpr std::size_t kParallelSortMin = 16384;
  mutable ItemClaims _claims;  ///< work items of the parallel loops
  mutable SlabFlags _slabDone; ///< slabs done (reduceMaxOverSlabRanges)
  mutable std::vector<std::uint32_t> _hist, _offsets, _radixTmp;
  mutable std::vector<std::size_t> _radixCount;
};

} // namespace coredem::dem::backend
