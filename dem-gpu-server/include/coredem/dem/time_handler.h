#pragma once
/// @file
/// Sub-cycling time arithmetic (docs/physics.md §5): Δt_DEM·n_sub = Δt_CFD exactly and
/// simulated time accumulated with Kahan (compensated) summation, so 10^6 tiny steps do
/// not drift.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "coredem/common/compensated_sum.h"
#include "coredem/common/time.h"

namespace coredem::dem {

using coredem::timeEquals;

class TimeHandler {
public:
  explicit TimeHandler(double t0 = 0.0)
      : _time(t0) {}

  /// n_sub = ceil(Δt_CFD/Δt_DEM,max) (at least 1): the plan the orchestrator grants too.
  static int subStepsFor(double dtCfd, double dtDemMax) {
    return coredem::subStepsFor(dtCfd, dtDemMax);
  }

  /// Adds dt to the time with compensated summation.
  void add(double dt) { _time.add(dt); }

  double time() const { return _time.value(); }
  double compensation() const { return _time.compensation(); }
  /// Restores a saved state (time and its Kahan compensation) for bitwise restarts.
  void restore(double time, double compensation) { _time = CompensatedSum(time, compensation); }

private:
  CompensatedSum _time;
};

} // namespace coredem::dem
