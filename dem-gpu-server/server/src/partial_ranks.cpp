#include "partial_ranks.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;

Combined combinePartialGasFields(const std::vector<StepReply>& to, const GridShape& grid,
                                 double cellVolume, std::uint32_t rankCount) {
  namespace f = proto::fields;
  const std::uint64_t cells = grid.cells;
  const std::uint32_t species = grid.species;
  const auto& first = to.front().request->message.envelope();
  const auto n = static_cast<std::size_t>(cells);
  Combined out;
  std::vector<double> volume(n, 0.0);
  for (const StepReply& t : to) {
    const auto fv = t.request->message.values<double>(f::kFluidVolume);
    for (std::size_t i = 0; i < t.cells.size(); ++i) {
      volume[static_cast<std::size_t>(t.cells[i])] += fv[i];
    }
  }
  double totalVolume = 0.0;
  for (std::size_t g = 0; g < n; ++g) {
    totalVolume += volume[g];
  }
  if (!(totalVolume > 0.0)) {
    out.failure = {CombineFailure::Kind::Volumes, v1::ERROR_CODE_INVALID_CONFIGURATION,
                   fmt::format("step {}: the {} CFD ranks' GasFields touch no coupling cell",
                               first.step(), rankCount),
                   "the ranks touch no coupling cell"};
    return out;
  }
  auto gas =
      proto::makeGasFields(first.step(), first.time(), first.gas_fields().dt(), cells, species);
  for (const auto& spec : f::gasFields()) {
    const std::size_t q = f::componentsOf(spec.extent, species);
    std::vector<double> sum(n * q, 0.0), all(q, 0.0);
    for (const StepReply& t : to) {
      const auto v = t.request->message.values<double>(spec.name);
      for (std::size_t i = 0; i < t.cells.size(); ++i) {
        const std::size_t g = static_cast<std::size_t>(t.cells[i]);
        for (std::size_t c = 0; c < q; ++c) {
          sum[g * q + c] += v[i * q + c];
        }
      }
    }
    for (std::size_t g = 0; g < n; ++g) {
      for (std::size_t c = 0; c < q; ++c) {
        all[c] += sum[g * q + c];
      }
    }
    for (std::size_t g = 0; g < n; ++g) {
      for (std::size_t c = 0; c < q; ++c) {
        sum[g * q + c] = volume[g] > 0.0 ? sum[g * q + c] / volume[g] : all[c] / totalVolume;
      }
    }
    gas.addArray<double>(spec.name, std::span<const double>(sum),
                         f::shapeOf(spec.extent, cells, species));
  }
  std::vector<double> fraction(n, 1.0);
  bool partFluid = false;
  for (std::size_t g = 0; g < n; ++g) {
    const double v = volume[g];
    if (v > cellVolume * (1.0 + 1e-6)) {
      out.failure = {CombineFailure::Kind::Volumes, v1::ERROR_CODE_INVALID_CONFIGURATION,
                     fmt::format("step {}: the CFD ranks' fluid volume in coupling cell {} is {} "
                                 "m3, more than the cell's {} m3 (overlapping decomposition?)",
                                 first.step(), g, v, cellVolume),
                     "overlapping fluid volumes"};
      return out;
    }
    fraction[g] = std::abs(v - cellVolume) <= 1e-12 * cellVolume ? 1.0
                  : v <= 1e-12 * cellVolume                      ? 0.0
                                                                 : std::min(1.0, v / cellVolume);
    partFluid = partFluid || fraction[g] != 1.0;
  }
  if (partFluid) {
    gas.addArray<double>(f::kFluidFraction, std::span<const double>(fraction), {cells});
  }
  // Q_split (v1.5) is extensive: each rank sends its own contribution per coupling-cell volume,
  // and a cell's heat is the sum of the ranks' (in rank order), not a fluid-volume average.
  // Sent on when any rank sent it.
  std::vector<double> split(n, 0.0);
  bool anySplit = false;
  for (const StepReply& t : to) {
    const auto q = t.request->message.findArray(f::kHeatToParticles);
    if (!q) {
      continue;
    }
    anySplit = true;
    const auto v = q->as<double>();
    for (std::size_t i = 0; i < t.cells.size(); ++i) {
      split[static_cast<std::size_t>(t.cells[i])] += v[i];
    }
  }
  if (anySplit) {
    gas.addArray<double>(f::kHeatToParticles, std::span<const double>(split), {cells});
  }
  if (const auto st = proto::validateGasRanges(gas); !st.ok()) {
    out.failure = {CombineFailure::Kind::Ranges, st.code,
                   "the combined GasFields of the CFD ranks: " + st.message, std::string()};
    return out;
  }
  out.gas = std::move(gas);
  return out;
}

} // namespace coredem::server
