// coredem-bench gpu-probe: what the CUDA runtime says on this machine (scripts/gpu-check.sh).
// Not a benchmark: one line and an exit status a script can act on.
#include <cstdio>
#include <cstring>

#include "commands.h"
#include "coredem/dem/dem_system.h"

namespace coredem::bench {
namespace {

/// Exit 0: n ≥ 1 usable devices; 3: no GPU (not built, no driver, no device); 1: the CUDA
/// runtime failed (CUDA's message and what to do on stderr).
int runGpuProbe(int argc, char** argv) {
  if (argc > 1) {
    const bool help = !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h");
    std::fprintf(help ? stdout : stderr,
                 "usage: coredem-bench gpu-probe\n"
                 "Asks the CUDA runtime for devices. Prints one line; exit 0 = devices found, "
                 "3 = no GPU (reason printed), 1 = CUDA failed (its message printed).\n");
    return help ? 0 : 2;
  }
  const dem::CudaProbe p = dem::probeCuda();
  if (!p.error.empty()) {
    std::fprintf(stderr, "gpu-probe: error: %s\n", p.error.c_str());
    return 1;
  }
  if (p.devices == 0) {
    std::printf("gpu-probe: no GPU: %s\n", p.note.c_str());
    return 3;
  }
  std::printf("gpu-probe: %d CUDA device(s)\n", p.devices);
  return 0;
}

} // namespace

COREDEM_BENCH_COMMAND("gpu-probe", "what the CUDA runtime reports (devices, or its error)",
                      runGpuProbe);

} // namespace coredem::bench
