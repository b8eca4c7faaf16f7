#pragma once
/// @file
/// Process-wide counts of what makes a GPU sub-step wait (read by backendSyncCounts() in
/// dem_system.h, reported per sub-step by coredem-bench dem). The backends with a separate
/// device (cuda, cuda-sim) count; the cpu backend has nothing to wait for and counts nothing.

#include <atomic>
#include <cstdint>

namespace coredem::dem::backend {

struct SyncCounters {
  /// Device → host transfers the host waits for (copyToHost, a reduceMax result): each one a
  /// host round trip that drains the device queue.
  std::atomic<std::uint64_t> hostRoundTrips{0};
  /// Explicit device-wide synchronisations (Exec::synchronize: the stage timers).
  std::atomic<std::uint64_t> deviceSyncs{0};
  /// Kernel-like launches (parallelFor, reduceMax, exclusiveScan, sorts).
  std::atomic<std::uint64_t> launches{0};
};

inline SyncCounters& syncCounters() {
  static SyncCounters c;
  return c;
}

} // namespace coredem::dem::backend
