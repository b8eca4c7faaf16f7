#pragma once
// The DEM step of a case as the DEM server will plan it (internal to the orchestrator): used by
// the session's Configure and by pre-flight (coredem check), which refuses a case whose plan
// the server would refuse.

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/time_handler.h>

namespace coredem::orchestrator {

/// Δt_DEM,max of the case from the DEM's own function (coredem::dem::dtDemMax: the undamped
/// contact duration / dem.dt_factor and the integrator's stability limit over the material pairs
/// of the particle sets, docs/physics.md). The DEM server's reply is authoritative (with an
/// initial state file its particles may differ from the sets).
double estimateDtDemMax(const CaseConfig& c);

/// The case's `models: {dem.dt_factor}` (default 50).
double dtFactorOf(const CaseConfig& c);

/// The sub-cycling plan of a step: from the forced DEM step time.dt_dem when given (n_sub =
/// dt/dt_dem; a step shortened to land on time.end gets n_sub = ceil), else from Δt_DEM,max.
SubcyclePlan planFor(const CaseConfig& c, double dt, double dtDemMax);

} // namespace coredem::orchestrator
