// Pre-flight: the limits of the DEM server and the participants (preflight_limits.h).
#include "preflight_limits.h"

#include <cmath>
#include <string>
#include <vector>

#include <coredem/common/format.h>
#include <coredem/common/limits.h>

#include "dem_step.h"

namespace coredem::orchestrator {

/// What the DEM server and the participants would refuse, from the same table
/// (coredem/common/limits.h): the counts of coredem-dem's admission control, the sub-steps per
/// CFD step of the plan it will grant, and the gas properties outside the ranges of the gas
/// fields it receives (a constant-property gas sends them as they are given).
void checkServerLimits(const CaseConfig& c, const preflight::Locator& at) {
  const CountLimits limits;
  const auto count = [&](const char* key, std::size_t n, std::uint64_t limit, const char* what) {
    if (n > limit) {
      at.fail({key}, key,
              fmt::format("{} {}: the DEM server admits at most {} ({}); split the case or merge "
                          "entries",
                          n, what, limit, "coredem-dem's admission control"));
    }
  };
  count("materials", c.materials.size(), limits.materials, "materials");
  count("species", c.species.size(), limits.species, "gas species");
  count("solid_species", c.solidSpecies.size(), limits.solidSpecies, "solid species");
  count("particles", c.particles.size(), limits.particleSets, "particle sets");
  count("reactions", c.reactions.size(), limits.reactions, "reactions");
  count("models", c.models.size(), limits.options, "model options");
  // Sub-steps of the largest CFD step (the DEM server refuses a grant of more).
  const bool adaptive = c.dt.kind == DtPolicyConfig::Kind::Courant;
  const double dtMax = adaptive ? c.dt.dtMax : c.dt.dt;
  if (dtMax > 0.0 && std::isfinite(dtMax)) {
    const double dtDem = c.dtDem > 0.0 ? c.dtDem : estimateDtDemMax(c);
    const double nSub = std::ceil(dtMax / dtDem * (1.0 - 1e-12));
    if (!(nSub <= double(limits.subSteps))) {
      const std::vector<std::string> path =
          c.dtDem > 0.0 ? std::vector<std::string>{"time", "dt_dem"}
          : adaptive    ? std::vector<std::string>{"time", "adaptive", "dt_max"}
                        : std::vector<std::string>{"time", "dt"};
      at.fail(path, adaptive ? "time.adaptive.dt_max" : "time.dt",
              fmt::format("{:.6g} s needs {:.6g} DEM sub-steps of {:.6g} s (the contact time of "
                          "the stiffest material pair over dem.dt_factor, or time.dt_dem); the "
                          "DEM server grants at most {} per CFD step: shorten the CFD step or "
                          "soften k_n",
                          dtMax, nSub, dtDem, limits.subSteps));
    }
  }
  // A constant-property gas is sent as given: its values must lie in the DEM's ranges.
  const GasRanges r;
  const GasPropertiesConfig& g = c.gasProperties;
  const auto range = [&](const char* key, double v, double lo, double hi, const char* unit) {
    if (!(v >= lo && v <= hi)) {
      at.fail({"gas_properties", key}, fmt::format("gas_properties.{}", key),
              fmt::format("{:.6g} {} is outside [{:g}, {:g}] {}, the range of the gas state the "
                          "DEM server accepts (docs/protocol.md §3 'Ranges'); check the units",
                          v, unit, lo, hi, unit));
    }
  };
  if (g.model != "ideal_gas") {
    range("density", g.density, r.densityMin, r.densityMax, "kg/m3");
    range("viscosity", g.viscosity, r.viscosityMin, r.viscosityMax, "Pa s");
    range("conductivity", g.conductivity, r.conductivityMin, r.conductivityMax, "W/m/K");
    range("cp", g.cp, r.heatCapacityMin, r.heatCapacityMax, "J/kg/K");
  }
}

} // namespace coredem::orchestrator
