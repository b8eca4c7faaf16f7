#pragma once
/// @file
/// Simulated time of a coupled run: compensated (Kahan) summation of the
/// granted Δt_CFD, window-end comparison with a tolerance, the Δt_CFD policy (fixed or
/// CFL-adaptive within [dt_min, dt_max]) and the DEM sub-cycling plan.

#include <cstdint>

#include <coredem/common/compensated_sum.h>

namespace coredem::orchestrator {

/// Tolerant comparison of two times in seconds: |a - b| <= tol * max(1, |a|, |b|).
bool timeEquals(double a, double b, double tol = 1e-12);

/// Accumulates time with Kahan summation so that 10^6 tiny steps do not drift.
class TimeHandler {
public:
  /// @param time start time [s]; @param compensation the Kahan carry (restored from a checkpoint).
  explicit TimeHandler(double time = 0.0, double compensation = 0.0);

  /// Advances by dt > 0 [s].
  void advance(double dt);
  /// Current time [s].
  double time() const { return _sum.value(); }
  /// The Kahan compensation term (store it in checkpoints for a bitwise-identical resume).
  double compensation() const { return _sum.compensation(); }
  /// Time still to go until tEnd (0 if reached).
  double remaining(double tEnd) const;
  /// True when time() has reached tEnd within the tolerance of timeEquals.
  bool reached(double tEnd) const;

private:
  CompensatedSum _sum;
};

/// How Δt_CFD is chosen each step.
struct DtPolicyConfig {
  enum class Kind { Fixed, Courant };
  Kind kind = Kind::Fixed;
  double dt = 1e-4;       ///< fixed Δt_CFD, and the first Δt of the adaptive policy [s]
  double dtMin = 0.0;     ///< lower bound of the adaptive policy [s]
  double dtMax = 0.0;     ///< upper bound of the adaptive policy [s]
  double courant = 0.5;   ///< target Courant number of the adaptive policy
  double maxGrowth = 1.2; ///< largest step-to-step increase factor of the adaptive policy
};

/// Chooses Δt_CFD step by step. Fixed: always dt. Courant: dt·C_target/C_reported, growth
/// limited to maxGrowth per step (no limit on decrease), clamped to [dtMin, dtMax].
/// Each step is finally shortened so that the run lands exactly on tEnd (adaptive: when less
/// than two steps remain, the rest is split into two equal steps, so no sliver step is left).
class DtPolicy {
public:
  explicit DtPolicy(const DtPolicyConfig& config, double lastDt = 0.0);

  /// Δt for the next step. @param courant the Courant number the CFD reported for the
  /// previous step (ignored by the fixed policy; negative = none reported yet).
  /// @param remaining time left to tEnd (> 0).
  double next(double courant, double remaining);
  /// The Δt before the end-of-run clipping (part of the resumable state).
  double lastDt() const { return _last; }

private:
  DtPolicyConfig _config;
  double _last;
};

/// The DEM sub-cycling plan for one CFD step: nSub sub-steps of dtDem, nSub·dtDem = dtCfd.
struct SubcyclePlan {
  std::int64_t nSub = 1;
  double dtDem = 0.0;
};

/// n_sub = ceil(Δt_CFD / Δt_DEM,max) (ratios within 1e-12 of an integer are not rounded up),
/// Δt_DEM = Δt_CFD / n_sub ≤ Δt_DEM,max. @pre both > 0 and finite.
SubcyclePlan planSubcycles(double dtCfd, double dtDemMax);

} // namespace coredem::orchestrator
