// The DEM step of a case (dem_step.h).
#include "dem_step.h"

#include <cmath>
#include <limits>
#include <vector>

#include <coredem/common/check.h>
#include <coredem/dem/dem_config.h>
#include <coredem/dem/models.h>

namespace coredem::orchestrator {

namespace {

/// The case's `models:` applied to `d` as the DEM server applies them (validated with the case by
/// validateModels; a value it refuses keeps the default here).
void applyModels(const CaseConfig& c, dem::DemConfig& d) {
  for (const auto& [key, value] : c.models) {
    try {
      dem::applyModelOption(d, key, value);
    } catch (const UserError&) {
    }
  }
}

} // namespace

double dtFactorOf(const CaseConfig& c) {
  dem::DemConfig d;
  applyModels(c, d);
  return d.dtFactor;
}

double estimateDtDemMax(const CaseConfig& c) {
  // The DEM's own function (coredem/dem/models.h) on the case's materials, lightest particle of
  // each material and `models:` (dem.dt_factor, motion).
  dem::DemConfig d;
  d.materials.clear();
  for (const MaterialConfig& m : c.materials) {
    dem::Material dm;
    dm.name = m.name;
    dm.kn = m.kN;
    dm.en = m.eN;
    dm.mu = m.friction;
    d.materials.push_back(dm);
  }
  std::vector<double> minMass(d.materials.size(), std::numeric_limits<double>::infinity());
  for (const auto& p : c.particles) {
    const std::size_t k = std::size_t(materialIndex(c, p.material));
    const double rho = p.density > 0 ? p.density : c.materials[k].density;
    minMass[k] = std::min(minMass[k], dem::particleMass(rho, p.diameter));
  }
  applyModels(c, d);
  const double dtMax = dem::dtDemMax(d, minMass);
  return std::isfinite(dtMax) ? dtMax : c.dt.dt;
}

SubcyclePlan planFor(const CaseConfig& c, double dt, double dtDemMax) {
  if (c.dtDem > 0.0) {
    const double ratio = dt / c.dtDem;
    double n = std::round(ratio);
    if (n < 1.0 || std::abs(ratio - n) > 1e-9 * n) {
      n = std::max(1.0, std::ceil(ratio));
    }
    return SubcyclePlan{std::int64_t(n), dt / n};
  }
  return planSubcycles(dt, dtDemMax);
}

} // namespace coredem::orchestrator
