#pragma once
// Admission control of coredem-dem (docs/security.md "Admission control"): count limits
// derived from a memory budget, checked on a Configure before anything is allocated.
#include <cstdint>
#include <string>

#include <coredem/common/limits.h>

#include "coredem/v1/configure.pb.h"

namespace coredem::server {

namespace v1 = coredem::v1;

/// Rough memory the DEM server needs (bytes), the figures admission uses.
struct MemoryModel {
  /// Per particle: the particle schema's fields (~60 doubles), 12 tangential-history slots,
  /// neighbour list, host/device mirrors; plus 16 bytes per solid and gas species.
  static constexpr std::uint64_t kParticleBase = 2048;
  static constexpr std::uint64_t kParticlePerSpecies = 16;
  /// Per coupling cell: received GasFields, computed Sources, the message copies; plus 48 bytes
  /// per gas species (Y_g, R_species and their copies).
  static constexpr std::uint64_t kCellBase = 512;
  static constexpr std::uint64_t kCellPerSpecies = 48;
  /// Per material pair (the pair table is n_materials^2).
  static constexpr std::uint64_t kMaterialPair = 64;
  /// Per mesh-wall triangle: the message copy, the DemConfig copy, the engine's triangle with its
  /// edge and vertex ids, the binned search.
  static constexpr std::uint64_t kMeshTriangle = 512;
};

/// The count limits of the project's one table (coredem/common/limits.h, which `coredem check`
/// applies too) and the memory-derived ones of this server's budget.
struct Limits : coredem::CountLimits {
  std::uint64_t memoryBytes = 0; ///< the budget (--max-memory)
  std::uint64_t particles = 0;   ///< derived: budget / bytes per particle
  std::uint64_t cells = 0;       ///< derived: budget / bytes per cell (and <= kMaxCells)
};

/// Half of the physical memory (sysconf), at least 1 GiB.
std::uint64_t defaultMaxMemory();
/// Parses "8G", "512M", "1.5GiB", "1073741824" (bytes; K/M/G/T are powers of 1024). Throws
/// UserError naming the text.
std::uint64_t parseBytes(const std::string& text);
/// "1.5 GiB", "512 MiB", "100 B".
std::string formatBytes(std::uint64_t bytes);

/// The limits of a budget of `memoryBytes` and `subSteps` sub-steps per grant.
Limits limitsFor(std::uint64_t memoryBytes, std::uint64_t subSteps);

/// Estimated bytes for a system of these counts; saturates at UINT64_MAX (never overflows).
std::uint64_t estimateBytes(std::uint64_t particles, std::uint64_t cells, std::uint64_t gasSpecies,
                            std::uint64_t solidSpecies, std::uint64_t materials);

/// Checks a Configure against the limits before anything is built: "" when admitted, else
/// the refusal naming the field, its value and the limit. Counts are summed and multiplied
/// with overflow checks.
std::string admitConfigure(const v1::Configure& configure, const Limits& limits);

} // namespace coredem::server
