#pragma once
/// @file
/// Sub-cycling time arithmetic (STYLE §9, PHYSICS §5): Δt_DEM·n_sub = Δt_CFD exactly and
/// simulated time accumulated with Kahan (compensated) summation, so 10^6 tiny steps do
/// not drift.

#include "coredem/common/check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace coredem::dem {

/// |a - b| <= tol·max(1, |a|, |b|).
inline bool timeEquals(double a, double b, double tol = 1e-12) {
  return std::fabs(a - b) <= tol * std::fmax(1.0, std::fmax(std::fabs(a), std::fabs(b)));
}

class TimeHandler {
public:
  explicit TimeHandler(double t0 = 0.0) : _sum(t0) {}

  /// n_sub = ceil(Δt_CFD/Δt_DEM,max) (at least 1), so that Δt_CFD/n_sub <= Δt_DEM,max.
  /// A ratio within 1e-12 of an integer counts as that integer.
  static int subStepsFor(double dtCfd, double dtDemMax) {
    COREDEM_CHECK(dtCfd > 0 && std::isfinite(dtCfd), "dtCfd must be > 0 and finite (got {})", dtCfd);
    COREDEM_CHECK(dtDemMax > 0 && std::isfinite(dtDemMax),
                  "dtDemMax must be > 0 and finite (got {})", dtDemMax);
    const double ratio = dtCfd / dtDemMax;
    COREDEM_CHECK(ratio < 2.0e9, "dtCfd/dtDemMax = {} sub-steps is too many; reduce dtCfd", ratio);
    double n = std::ceil(ratio);
    if (n - ratio > 1.0 - 1e-12 * ratio && n > 1) n -= 1;  // ratio is an integer up to round-off
    return std::max(1, static_cast<int>(n));
  }

  /// Adds dt to the time with compensated summation.
  void add(double dt) {
    const double y = dt - _c;
    const double t = _sum + y;
    _c = (t - _sum) - y;
    _sum = t;
  }

  double time() const { return _sum; }
  double compensation() const { return _c; }
  /// Restores a saved state (time and its Kahan compensation) for bitwise restarts.
  void restore(double time, double compensation) {
    _sum = time;
    _c = compensation;
  }

private:
  double _sum = 0.0;
  double _c = 0.0;
};

} // namespace coredem::dem
