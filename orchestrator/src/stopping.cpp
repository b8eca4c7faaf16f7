// Stopping a run early (session.h): the --walltime decision and the hint for a diverged CFD
// participant. Pure functions, unit-tested without participants.
#include <algorithm>

#include <fmt/format.h>

#include <coredem/orchestrator/session.h>

namespace coredem::orchestrator {

bool walltimeStopDue(double elapsed, double walltime, double stepEst, double checkpointStepEst) {
  return elapsed + stepEst + std::max(stepEst, checkpointStepEst) + walltimeReserve(walltime) >
         walltime;
}

std::string divergenceHint(std::int64_t step, double dt, double courant) {
  if (courant > 0.0) {
    const double suggested = dt * std::min(0.5, 0.5 / courant);
    return fmt::format("floating-point exception: the CFD solution probably diverged in step {} "
                       "(dt_CFD = {:.4g} s; last reported Courant number {:.3g}). Try time.dt <= "
                       "{:.3g} s, or time.adaptive with courant <= 0.5",
                       step, dt, courant, suggested);
  }
  return fmt::format("floating-point exception: the CFD solution probably diverged in step {} "
                     "(dt_CFD = {:.4g} s; no Courant number reported yet). Try time.dt <= {:.3g} "
                     "s, or time.adaptive with courant <= 0.5",
                     step, dt, 0.5 * dt);
}

} // namespace coredem::orchestrator
