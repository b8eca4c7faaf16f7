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

namespace {

/// What of the walls the DEM's Δt_DEM,max reads: the material pairs, and one wall per contact
/// material the walls have (−1: a wall without one, each particle's own material).
void addContactWalls(const CaseConfig& c, dem::DemConfig& d) {
  for (const auto& p : c.materialPairs) {
    dem::MaterialPair mp;
    mp.a = materialIndex(c, p.a);
    mp.b = materialIndex(c, p.b);
    mp.en = p.eN.value_or(mp.en);
    mp.mu = p.friction.value_or(mp.mu);
    d.materialPairs.push_back(mp);
  }
  std::vector<std::string> names;
  if (c.walls.box) {
    names.push_back(c.walls.boxMaterial);
  }
  for (const auto& p : c.walls.planes) {
    names.push_back(p.material);
  }
  for (const auto& w : c.walls.revolved) {
    names.push_back(w.material);
  }
  for (const auto& w : c.walls.meshes) {
    names.push_back(w.material);
  }
  for (const std::string& n : names) {
    dem::Wall w;
    w.material = n.empty() ? -1 : materialIndex(c, n);
    d.walls.push_back(w);
  }
}

} // namespace

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
    dm.ktFactor = m.ktFactor.value_or(dm.ktFactor);
    dm.etatFactor = m.etatFactor.value_or(dm.etatFactor);
    dm.youngsModulus = m.youngsModulus.value_or(dm.youngsModulus);
    dm.poissonRatio = m.poissonRatio.value_or(dm.poissonRatio);
    d.materials.push_back(dm);
  }
  addContactWalls(c, d);
  std::vector<double> minMass(d.materials.size(), std::numeric_limits<double>::infinity());
  std::vector<double> minRadius(d.materials.size(), 1.0); // of the lightest particle
  for (const auto& p : c.particles) {
    const std::size_t k = std::size_t(materialIndex(c, p.material));
    const double rho = p.density > 0 ? p.density : c.materials[k].density;
    const double mass = dem::particleMass(rho, p.diameter);
    if (mass < minMass[k]) {
      minMass[k] = mass;
      minRadius[k] = 0.5 * p.diameter;
    }
  }
  applyModels(c, d);
  const double dtMax = dem::dtDemMax(d, minMass, minRadius);
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
