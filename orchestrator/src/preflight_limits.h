#pragma once
// Pre-flight's check of what the DEM server and the participants would refuse (internal).

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/preflight_locator.h>

namespace coredem::orchestrator {

/// One value of the prescribed gas section: a literal or a table row's value, at the domain
/// level or in a region, with its path below the section (e.g. {"regions", "0", "mu_g"}).
struct PrescribedValue {
  double value;
  std::vector<std::string> path;
};

/// Every value of scalar field `key` (T_g, mu_g, ...) the prescribed gas section `gas` gives.
std::vector<PrescribedValue> prescribedValues(const YAML::Node& gas, const char* key);

/// What the DEM server and the participants would refuse, from the same table
/// (coredem/common/limits.h): the counts of coredem-dem's admission control, the sub-steps per
/// CFD step of the plan it will grant, and constant gas properties outside the ranges of the gas
/// fields it receives. Throws CaseError (Locator::fail) naming the key.
void checkServerLimits(const CaseConfig& c, const preflight::Locator& at);

} // namespace coredem::orchestrator
