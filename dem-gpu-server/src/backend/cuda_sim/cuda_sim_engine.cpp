// The cuda-sim instantiation of the shared engine (cuda_sim_exec.h): the cpu kernels under the
// cuda backend's memory model, for tests and debugging without a GPU.
#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>
#include <new>
#include <unordered_map>

#include <sys/mman.h>
#include <unistd.h>

#include "../../engine_impl.h"
#include "cuda_sim_exec.h"

namespace coredem::dem {

namespace backend::sim {
namespace {

constexpr std::uint64_t kGarbage = 0x7ff4a5a5a5a5a5a5ull; // signalling NaN as a double

void fillGarbage(void* p, std::size_t bytes) {
  auto* q = static_cast<unsigned char*>(p);
  for (std::size_t k = 0; k < bytes; ++k)
    q[k] = static_cast<unsigned char>(kGarbage >> (8 * (k % 8)));
}

/// Device allocations: bump-allocated from one reserved range (the arena), so that opening and
/// closing a DeviceScope is one mprotect call; the arena restarts when nothing in it is live.
/// Allocations that do not fit get their own mapping (`regions`).
struct Registry {
  std::mutex mutex;
  char* base = nullptr; ///< arena, kArenaBytes of address space (no memory until touched)
  std::size_t top = 0;  ///< bytes handed out since the arena was last empty
  std::size_t live = 0; ///< live allocations in the arena
  std::unordered_map<void*, std::size_t> regions; ///< every live allocation → mapped length
  int depth = 0;                                  ///< open DeviceScopes
};
constexpr std::size_t kArenaBytes = std::size_t{1} << 36; // 64 GiB of address space
Registry& registry() {
  static Registry* r = new Registry; // never destroyed: frees may run at static destruction
  return *r;
}
bool inArena(const Registry& r, const void* p) {
  const char* c = static_cast<const char*>(p);
  return r.base != nullptr && c >= r.base && c < r.base + kArenaBytes;
}

std::size_t pageSize() {
  static const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  return page;
}

void protect(void* p, std::size_t len, bool accessible) {
  if (::mprotect(p, len, accessible ? PROT_READ | PROT_WRITE : PROT_NONE) != 0)
    raiseUserError(std::string("cuda-sim: mprotect failed: ") + std::strerror(errno));
}

/// Device memory accessible or not: the arena's used part in one call, then the others.
void setAccess(Registry& r, bool accessible) {
  const int prot = accessible ? PROT_READ | PROT_WRITE : PROT_NONE;
  // mprotect failures only weaken the check (and DeviceScope's destructor may not throw).
  if (r.top > 0)
    ::mprotect(r.base, r.top, prot);
  for (const auto& [p, len] : r.regions)
    if (!inArena(r, p))
      ::mprotect(p, len, prot);
}

// SIGSEGV: say what the likely cause is, then let the default action run (core dump).
void onSegv(int, siginfo_t* info, void*) {
  static const char msg[] =
      "\ncuda-sim: SIGSEGV in cuda-sim device memory: host code dereferenced a device pointer "
      "(d()) outside a kernel or copy; on the cuda backend this reads garbage or crashes. Use the "
      "host mirror h() after toHost(), or Exec::copyToHost\n";
  // Only the arena is recognised (a plain pointer read: async-signal-safe enough here).
  const Registry& r = registry();
  if (inArena(r, info->si_addr)) {
    ssize_t ignored = ::write(2, msg, sizeof msg - 1);
    (void)ignored;
  }
  std::signal(SIGSEGV, SIG_DFL); // the default action runs when the access repeats
}

void installHandler() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa {};
    sa.sa_sigaction = onSegv;
    sa.sa_flags = SA_SIGINFO | SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    ::sigaction(SIGSEGV, &sa, nullptr);
  });
}

} // namespace

void* allocDevice(std::size_t bytes) {
  if (!bytes)
    return nullptr;
  installHandler();
  const std::size_t len = (bytes + pageSize() - 1) / pageSize() * pageSize();
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (r.base == nullptr) {
    void* a =
        ::mmap(nullptr, kArenaBytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    r.base = a == MAP_FAILED ? nullptr : static_cast<char*>(a);
  }
  void* p = nullptr;
  if (r.base != nullptr && r.top + len <= kArenaBytes) {
    p = r.base + r.top;
    r.top += len;
    ++r.live;
    protect(p, len, true);
  } else {
    p = ::mmap(nullptr, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED)
      throw std::bad_alloc();
  }
  fillGarbage(p, len);
  if (r.depth == 0)
    protect(p, len, false);
  r.regions.emplace(p, len);
  return p;
}

void freeDevice(void* p) {
  if (!p)
    return;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.regions.find(p);
  if (it == r.regions.end())
    raiseUserError("cuda-sim: freeDevice of a pointer that allocDevice did not return");
  if (inArena(r, p)) {
    ::madvise(p, it->second, MADV_DONTNEED); // give the pages back; the range is not reused
    if (--r.live == 0)
      r.top = 0; // ... until the arena is empty
  } else {
    ::munmap(p, it->second);
  }
  r.regions.erase(it);
}

void* allocHost(std::size_t bytes) {
  if (!bytes)
    return nullptr;
  void* p = ::operator new (bytes, std::align_val_t{64});
  fillGarbage(p, bytes);
  return p;
}

void freeHost(void* p) {
  if (p)
    ::operator delete (p, std::align_val_t{64});
}

DeviceScope::DeviceScope() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (r.depth++ == 0)
    setAccess(r, true);
}

DeviceScope::~DeviceScope() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (--r.depth == 0)
    setAccess(r, false);
}

} // namespace backend::sim

template class EngineImpl<backend::CudaSimExec>;

std::unique_ptr<Engine> makeCudaSimEngine(const EngineSetup& setup) {
  return std::make_unique<EngineImpl<backend::CudaSimExec>>(setup);
}

} // namespace coredem::dem
