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

struct Registry {
  std::mutex mutex;
  std::unordered_map<void*, std::size_t> regions; ///< device allocations → mapped length
  int depth = 0;                                  ///< open DeviceScopes
};
Registry& registry() {
  static Registry* r = new Registry; // never destroyed: frees may run at static destruction
  return *r;
}
std::atomic<std::uint64_t> gLaunches{0}, gRoundTrips{0};

std::size_t pageSize() {
  static const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  return page;
}

void protect(void* p, std::size_t len, bool accessible) {
  if (::mprotect(p, len, accessible ? PROT_READ | PROT_WRITE : PROT_NONE) != 0)
    raiseUserError(std::string("cuda-sim: mprotect failed: ") + std::strerror(errno));
}

// SIGSEGV: say what the likely cause is, then let the default action run (core dump).
void onSegv(int, siginfo_t* info, void*) {
  static const char msg[] =
      "\ncuda-sim: SIGSEGV: host code touched memory it may not (most likely a device pointer, "
      "d(), dereferenced outside a kernel or copy: on the cuda backend this reads garbage or "
      "crashes; use the host mirror h() after toHost(), or Exec::copyToHost)\n";
  (void)info;
  ssize_t ignored = ::write(2, msg, sizeof msg - 1);
  (void)ignored;
  std::signal(SIGSEGV, SIG_DFL);
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
  void* p = ::mmap(nullptr, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED)
    throw std::bad_alloc();
  fillGarbage(p, len);
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
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
  ::munmap(p, it->second);
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
    for (const auto& [p, len] : r.regions)
      protect(p, len, true);
}

DeviceScope::~DeviceScope() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (--r.depth == 0)
    for (const auto& [p, len] : r.regions)
      ::mprotect(p, len, PROT_NONE); // no throw from a destructor; failure only weakens a check
}

std::uint64_t launches() {
  return gLaunches.load();
}
void countLaunch() {
  ++gLaunches;
}
std::uint64_t hostRoundTrips() {
  return gRoundTrips.load();
}
void countRoundTrip() {
  ++gRoundTrips;
}

} // namespace backend::sim

template class EngineImpl<backend::CudaSimExec>;

std::unique_ptr<Engine> makeCudaSimEngine(const EngineSetup& setup) {
  return std::make_unique<EngineImpl<backend::CudaSimExec>>(setup);
}

} // namespace coredem::dem
