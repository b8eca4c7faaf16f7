// Pre-flight: the limits of the DEM server and the participants (preflight_limits.h).
#include "preflight_limits.h"

#include <cctype>
#include <cmath>
#include <string>
#include <vector>

#include <coredem/common/format.h>
#include <coredem/common/limits.h>

#include "dem_step.h"

namespace coredem::orchestrator {

std::vector<PrescribedValue> prescribedValues(const YAML::Node& gas, const char* key) {
  std::vector<PrescribedValue> out;
  auto take = [&](const YAML::Node& n, std::vector<std::string> path) {
    try {
      if (n && n.IsScalar()) {
        out.push_back({n.as<double>(), path});
      } else if (n && n.IsMap() && n["table"] && n["table"].IsSequence()) {
        std::size_t i = 0;
        for (const YAML::Node& row : n["table"]) {
          if (row.IsSequence() && row.size() == 2 && row[1].IsScalar()) {
            std::vector<std::string> p = path;
            p.insert(p.end(), {"table", std::to_string(i), "1"});
            out.push_back({row[1].as<double>(), p});
          }
          ++i;
        }
      }
    } catch (const YAML::Exception&) {
      // not a number: the participant's own reader names it
    }
  };
  if (!gas || !gas.IsMap()) {
    return out;
  }
  take(gas[key], {key});
  if (gas["regions"] && gas["regions"].IsSequence()) {
    std::size_t i = 0;
    for (const YAML::Node& r : gas["regions"]) {
      if (r.IsMap()) {
        take(r[key], {"regions", std::to_string(i), key});
      }
      ++i;
    }
  }
  return out;
}

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
  // A prescribed gas (coredem-gas) is sent as given too: every literal and table value of its
  // section and regions in the DEM's ranges (μ_g = 1e-320 Pa s ran until the first exchange).
  {
    const YAML::Node gas = at.root()[c.cfd.gasKey];
    const GasRanges r;
    struct Range {
      const char* key;
      double lo, hi;
      const char* unit;
    };
    // (T_g is warned about below 200 K by warnPrescribedGasTemperature, not refused here yet:
    // the campaign e2e tests use a member with T_g = -5 K that must fail at its start.)
    const Range ranges[] = {{"rho_g", r.densityMin, r.densityMax, "kg/m3"},
                            {"mu_g", r.viscosityMin, r.viscosityMax, "Pa s"},
                            {"kappa_g", r.conductivityMin, r.conductivityMax, "W/m/K"},
                            {"cp_g", r.heatCapacityMin, r.heatCapacityMax, "J/kg/K"}};
    for (const Range& g : ranges) {
      for (const PrescribedValue& v : prescribedValues(gas, g.key)) {
        if (!(v.value >= g.lo && v.value <= g.hi)) {
          std::vector<std::string> path = {c.cfd.gasKey};
          path.insert(path.end(), v.path.begin(), v.path.end());
          std::string key = c.cfd.gasKey;
          for (const std::string& part : v.path) {
            key +=
                (std::isdigit(static_cast<unsigned char>(part[0])) ? "[" + part + "]" : "." + part);
          }
          at.fail(path, key,
                  fmt::format("{:.6g} {} is outside [{:g}, {:g}] {}, the range of the gas state "
                              "the DEM server accepts (docs/protocol.md §3 'Ranges'); check the "
                              "units",
                              v.value, g.unit, g.lo, g.hi, g.unit));
        }
      }
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
