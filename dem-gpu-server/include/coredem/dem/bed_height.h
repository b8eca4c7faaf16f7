#pragma once
/// @file
/// Bed height of a particle bed, reported by the DEM server as the diagnostic `bed_height_m`
/// (timeseries.csv, docs/orchestrator.md "Outputs").

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace coredem::dem {

/// Height of the bed along −g: from the lowest particle bottom to the top of the bed, taken as
/// the 95th percentile of the centres' elevations plus the mean radius (so a packed bed of L
/// layers of diameter d gives L·d; the 5 % highest particles, splashed or elutriated, do not
/// count). `pos` holds n centres (x, y, z), `radius` n radii; 0 for no particles or no gravity.
inline double bedHeight(const std::vector<double>& pos, const std::vector<double>& radius,
                        std::size_t n, const std::array<double, 3>& gravity) {
  const double g =
      std::sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]);
  if (n == 0 || !(g > 0.0) || pos.size() < 3 * n || radius.size() < n) {
    return 0.0;
  }
  std::vector<double> elevation(n);
  double bottom = 0.0, meanRadius = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    elevation[i] =
        -(pos[3 * i] * gravity[0] + pos[3 * i + 1] * gravity[1] + pos[3 * i + 2] * gravity[2]) / g;
    bottom = i == 0 ? elevation[i] - radius[i] : std::min(bottom, elevation[i] - radius[i]);
    meanRadius += radius[i];
  }
  meanRadius /= static_cast<double>(n);
  const std::size_t k = std::min(n - 1, static_cast<std::size_t>(std::ceil(0.95 * double(n))) - 1);
  std::nth_element(elevation.begin(), elevation.begin() + static_cast<std::ptrdiff_t>(k),
                   elevation.end());
  return elevation[k] + meanRadius - bottom;
}

} // namespace coredem::dem
