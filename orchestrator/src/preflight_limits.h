#pragma once
// Pre-flight's check of what the DEM server and the participants would refuse (internal).

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/preflight_locator.h>

namespace coredem::orchestrator {

/// What the DEM server and the participants would refuse, from the same table
/// (coredem/common/limits.h): the counts of coredem-dem's admission control, the sub-steps per
/// CFD step of the plan it will grant, and constant gas properties outside the ranges of the gas
/// fields it receives. Throws CaseError (Locator::fail) naming the key.
void checkServerLimits(const CaseConfig& c, const preflight::Locator& at);

} // namespace coredem::orchestrator
