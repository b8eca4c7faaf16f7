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

namespace {

/// "time.adaptive.dt_max", "gas.regions[0].mu_g" for messages from a case path.
std::string keyOf(const std::vector<std::string>& path) {
  std::string key;
  for (const std::string& part : path) {
    const bool index = !part.empty() && std::isdigit(static_cast<unsigned char>(part[0]));
    key += index ? "[" + part + "]" : (key.empty() ? "" : ".") + part;
  }
  return key;
}

/// The counts of coredem-dem's admission control.
void checkCounts(const CaseConfig& c, const preflight::Locator& at, const CountLimits& limits) {
  const auto count = [&](const char* key, std::size_t n, std::uint64_t limit, const char* what) {
    if (n > limit) {
      at.fail({key}, key,
              fmt::format("{} {}: the DEM server admits at most {} (coredem-dem's admission "
                          "control); split the case or merge entries",
                          n, what, limit));
    }
  };
  count("materials", c.materials.size(), limits.materials, "materials");
  count("species", c.species.size(), limits.species, "gas species");
  count("solid_species", c.solidSpecies.size(), limits.solidSpecies, "solid species");
  count("particles", c.particles.size(), limits.particleSets, "particle sets");
  count("reactions", c.reactions.size(), limits.reactions, "reactions");
  count("models", c.models.size(), limits.options, "model options");
}

/// The sub-steps of the largest CFD step (the DEM server refuses a grant of more).
void checkSubSteps(const CaseConfig& c, const preflight::Locator& at, const CountLimits& limits) {
  const bool adaptive = c.dt.kind == DtPolicyConfig::Kind::Courant;
  const double dtMax = adaptive ? c.dt.dtMax : c.dt.dt;
  if (!(dtMax > 0.0 && std::isfinite(dtMax))) {
    return;
  }
  const double dtDem = c.dtDem > 0.0 ? c.dtDem : estimateDtDemMax(c);
  const double nSub = std::ceil(dtMax / dtDem * (1.0 - 1e-12));
  if (nSub <= double(limits.subSteps)) {
    return;
  }
  const std::vector<std::string> path = c.dtDem > 0.0 ? std::vector<std::string>{"time", "dt_dem"}
                                        : adaptive
                                            ? std::vector<std::string>{"time", "adaptive", "dt_max"}
                                            : std::vector<std::string>{"time", "dt"};
  at.fail(path, keyOf(path),
          fmt::format("{:.6g} s needs {:.6g} DEM sub-steps of {:.6g} s (the contact time of the "
                      "stiffest material pair over dem.dt_factor, or time.dt_dem); the DEM server "
                      "grants at most {} per CFD step: shorten the CFD step, soften the contact "
                      "(materials[].k_n), lower dem.dt_factor or raise time.dt_dem",
                      dtMax, nSub, dtDem, limits.subSteps));
}

/// A gas value the DEM receives as given: the prescribed gas's field and the constant-property
/// gas's property, with the range of the one table.
struct GasRange {
  const char* field;    ///< the prescribed gas section's key (GasFields array)
  const char* property; ///< gas_properties' key
  double GasPropertiesConfig::*value;
  double GasRanges::*lo;
  double GasRanges::*hi;
  const char* unit;
};
constexpr GasRange kGasRanges[] = {
    {"T_g", "temperature", &GasPropertiesConfig::temperature, &GasRanges::temperatureMin,
     &GasRanges::temperatureMax, "K"},
    {"rho_g", "density", &GasPropertiesConfig::density, &GasRanges::densityMin,
     &GasRanges::densityMax, "kg/m3"},
    {"mu_g", "viscosity", &GasPropertiesConfig::viscosity, &GasRanges::viscosityMin,
     &GasRanges::viscosityMax, "Pa s"},
    {"kappa_g", "conductivity", &GasPropertiesConfig::conductivity, &GasRanges::conductivityMin,
     &GasRanges::conductivityMax, "W/m/K"},
    {"cp_g", "cp", &GasPropertiesConfig::cp, &GasRanges::heatCapacityMin,
     &GasRanges::heatCapacityMax, "J/kg/K"}};

/// The gas values the DEM receives as given inside its ranges: every literal and table value of
/// the prescribed gas (coredem-gas; μ_g = 1e-320 Pa s ran until the first exchange) and the
/// properties of a constant-property gas.
void checkGasRanges(const CaseConfig& c, const preflight::Locator& at) {
  const GasRanges r;
  const YAML::Node gas = at.root()[c.cfd.gasKey];
  const auto inside = [&](const GasRange& g, double v, const std::vector<std::string>& path) {
    if (!(v >= r.*g.lo && v <= r.*g.hi)) {
      at.fail(path, keyOf(path),
              fmt::format("{:.6g} {} is outside [{:g}, {:g}] {}, the range of the gas state the "
                          "DEM server accepts (docs/protocol.md §3 'Ranges'); check the units",
                          v, g.unit, r.*g.lo, r.*g.hi, g.unit));
    }
  };
  for (const GasRange& g : kGasRanges) {
    for (const PrescribedValue& v : prescribedValues(gas, g.field)) {
      std::vector<std::string> path = {c.cfd.gasKey};
      path.insert(path.end(), v.path.begin(), v.path.end());
      inside(g, v.value, path);
    }
    if (c.gasProperties.model != "ideal_gas") {
      inside(g, c.gasProperties.*g.value, {"gas_properties", g.property});
    }
  }
}

} // namespace

void checkServerLimits(const CaseConfig& c, const preflight::Locator& at) {
  const CountLimits limits;
  checkCounts(c, at, limits);
  checkSubSteps(c, at, limits);
  checkGasRanges(c, at);
}

} // namespace coredem::orchestrator
