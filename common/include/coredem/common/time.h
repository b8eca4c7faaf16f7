#pragma once
/// @file
/// Time arithmetic shared by the orchestrator and the DEM server (docs/physics.md §5), so
/// both compute the same sub-cycling plan: n_sub = ceil(Δt_CFD/Δt_DEM,max) with a ratio
/// within 1e-12 of an integer counted as that integer, and tolerant time comparisons.

#include <algorithm>
#include <cmath>

#include "coredem/common/check.h"

namespace coredem {

/// |a − b| <= tol·max(1, |a|, |b|) (times in s).
inline bool timeEquals(double a, double b, double tol = 1e-12) {
  return std::fabs(a - b) <= tol * std::fmax(1.0, std::fmax(std::fabs(a), std::fabs(b)));
}

/// Number of DEM sub-steps of a CFD step: the smallest n >= 1 with Δt_CFD/n <= Δt_DEM,max,
/// where a ratio Δt_CFD/Δt_DEM,max within 1e-12 (relative) of an integer counts as that integer.
inline int subStepsFor(double dtCfd, double dtDemMax) {
  COREDEM_CHECK(dtCfd > 0 && std::isfinite(dtCfd), "dtCfd must be > 0 and finite (got {})", dtCfd);
  COREDEM_CHECK(dtDemMax > 0 && std::isfinite(dtDemMax), "dtDemMax must be > 0 and finite (got {})",
                dtDemMax);
  const double ratio = dtCfd / dtDemMax;
  COREDEM_CHECK(ratio < 2.0e9, "dtCfd/dtDemMax = {} sub-steps is too many; reduce dtCfd", ratio);
  double n = std::ceil(ratio);
  if (n > 1.0 && ratio - (n - 1.0) <= 1e-12 * ratio) {
    n -= 1.0; // the ratio is an integer up to round-off
  }
  return std::max(1, static_cast<int>(n));
}

} // namespace coredem
