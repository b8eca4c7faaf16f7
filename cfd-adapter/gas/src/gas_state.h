#pragma once
// coredem-gas's checkpoint: time, step and the cumulative ledgers in HDF5 (docs/client.md).
#include <cstdint>
#include <string>
#include <vector>

namespace coredem::gas {

struct GasState {
  double time = 0.0;     ///< s, end of the step
  std::int64_t step = 0; ///< last completed step
  std::string caseKey;   ///< e.g. "case.yaml:gas"
  std::vector<std::string> names;
  std::vector<double> values;       ///< cumulative sums
  std::vector<double> compensation; ///< Kahan compensation of each sum
};

/// Writes `path` via a temp file + rename (a reader never sees a partial file).
void writeGasState(const std::string& path, const GasState& s);
GasState readGasState(const std::string& path);

} // namespace coredem::gas
