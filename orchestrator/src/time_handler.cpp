#include <algorithm>
#include <cmath>

#include <coredem/common/check.h>
#include <coredem/common/time.h>
#include <coredem/orchestrator/time_handler.h>

namespace coredem::orchestrator {

bool timeEquals(double a, double b, double tol) {
  return coredem::timeEquals(a, b, tol);
}

TimeHandler::TimeHandler(double time, double compensation)
    : _sum(time, compensation) {}

void TimeHandler::advance(double dt) {
  COREDEM_ASSERT(dt > 0.0 && std::isfinite(dt));
  _sum.add(dt);
}

double TimeHandler::remaining(double tEnd) const {
  return reached(tEnd) ? 0.0 : (tEnd - _sum.value()) + _sum.compensation();
}

bool TimeHandler::reached(double tEnd) const {
  const double t = _sum.value() - _sum.compensation();
  return t >= tEnd || timeEquals(t, tEnd);
}

DtPolicy::DtPolicy(const DtPolicyConfig& config, double lastDt)
    : _config(config)
    , _last(lastDt > 0.0 ? lastDt : config.dt) {}

double DtPolicy::next(double courant, double remaining) {
  COREDEM_ASSERT(remaining > 0.0);
  double dt = _config.dt;
  if (_config.kind == DtPolicyConfig::Kind::Courant) {
    dt = _last;
    if (courant >= 0.0) {
      const double factor = courant > 0.0 ? std::min(_config.courant / courant, _config.maxGrowth)
                                          : _config.maxGrowth;
      dt = _last * factor;
    }
    dt = std::clamp(dt, _config.dtMin, _config.dtMax);
  }
  _last = dt;
  // Land exactly on tEnd: take the remainder when it is shorter than dt, or when the step
  // after this one would be a sliver (< 1e-6 dt).
  if (remaining <= dt * (1.0 + 1e-6)) {
    return remaining;
  }
  // Adaptive steps: split the last two steps evenly instead of leaving a sliver at the end.
  if (_config.kind == DtPolicyConfig::Kind::Courant && remaining < 2.0 * dt) {
    return 0.5 * remaining;
  }
  return dt;
}

SubcyclePlan planSubcycles(double dtCfd, double dtDemMax) {
  COREDEM_ASSERT(dtCfd > 0.0 && std::isfinite(dtCfd));
  COREDEM_ASSERT(dtDemMax > 0.0 && std::isfinite(dtDemMax));
  SubcyclePlan plan;
  plan.nSub = coredem::subStepsFor(dtCfd, dtDemMax); // the same plan the DEM server checks
  plan.dtDem = dtCfd / static_cast<double>(plan.nSub);
  return plan;
}

} // namespace coredem::orchestrator
