// species, gas_properties and the ideal-gas check (docs/case-schema.md, docs/gas-model.md).
#include <algorithm>
#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>

#include <coredem/orchestrator/gas_data.h>
#include <coredem/orchestrator/participants.h>

#include "case_read.h"

namespace coredem::orchestrator::caseread {

using yaml::join;

/// species: the gas species
void readSpecies(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (top.has("species")) {
    std::set<std::string> seen;
    r.species = top.list("species", {"name", "molar_mass"}, "gas species");
    for (const auto& s : r.species) {
      SpeciesConfig sp;
      sp.name = s.string("name", std::nullopt, "species name, e.g. CO2");
      sp.molarMass = s.number("molar_mass", std::nullopt, 0.0, kBig, "kg/mol, > 0", true);
      if (!seen.insert(sp.name).second) {
        s.fail(s.markOf("name"), "species", fmt::format("species '{}' is listed twice", sp.name));
      }
      c.species.push_back(sp);
    }
  }
}

/// gas_properties: constant or ideal_gas. Without `model`, the model is chosen by
/// resolveGasModel once the particles, walls, models and chemistry are read; the keys given are
/// read here and checked against the model there.
void readGasProperties(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (!top.has("gas_properties")) {
    return;
  }
  const Section& g = r.gasProperties.emplace(
      top.section("gas_properties", {"model", "density", "viscosity", "conductivity", "cp",
                                     "temperature", "pressure", "diffusivity", "alphac_min"}));
  auto& p = c.gasProperties;
  if (g.has("alphac_min")) {
    g.fail(g.markOf("alphac_min"), g.full("alphac_min"),
           "replaced by models: {eps_min: ...}, one clip of the gas fraction for the gas "
           "equations and the DEM's drag and convection (docs/physics.md §1.1)");
  }
  if (g.has("model")) {
    p.model = g.choice("model", std::string("constant"), {"constant", "ideal_gas"});
    r.gasModelGiven = true;
  }
  p.density = g.number("density", p.density, 0.0, kBig, "kg/m3, > 0", true);
  p.viscosity = g.number("viscosity", p.viscosity, 0.0, kBig, "Pa s, > 0", true);
  p.conductivity = g.number("conductivity", p.conductivity, 0.0, kBig, "W/m/K, > 0", true);
  p.cp = g.number("cp", p.cp, 0.0, kBig, "J/kg/K, > 0", true);
  p.diffusivity =
      g.number("diffusivity", p.diffusivity, 0.0, kBig, "species diffusivity in m2/s, > 0", true);
  p.temperature = g.number("temperature", p.temperature, 0.0, kBig, "K, > 0", true);
  p.pressure = g.number("pressure", p.pressure, 0.0, kBig, "Pa, > 0", true);
}

namespace {

/// What the gas exchanges with the particles and walls: the largest temperature difference
/// of a particle set or fixed-temperature walls to the gas (K, 0 with models.heat off), and
/// whether the case has reactions.
struct GasExchange {
  double dT = 0.0;
  bool reactions = false;
};

GasExchange gasExchange(const CaseConfig& c) {
  const ChemistryConfig& ch = c.chemistry;
  return {largestGasTemperatureDifference(c),
          !c.reactions.empty() || ch.charGasification || ch.ocReduction || ch.wgs};
}

std::string describe(const GasExchange& e) {
  if (e.dT > 0.0 && e.reactions) {
    return fmt::format("exchanges heat (up to {:.4g} K from the gas) and reactions", e.dT);
  }
  return e.reactions ? std::string("has reactions")
                     : fmt::format("exchanges heat (up to {:.4g} K from the gas)", e.dT);
}

} // namespace

/// The gas model: `model` as given; without it, ideal_gas where heat or reactions are exchanged
/// and the participant solves the gas, constant otherwise. Constant-property keys are refused
/// with ideal_gas (one source of truth), diffusivity with constant; a constant gas
/// more than kConstantGasWarnDeltaT from the particles or walls is warned about.
void resolveGasModel(CaseReading& r) {
  CaseConfig& c = r.c;
  auto& p = c.gasProperties;
  const GasExchange e = gasExchange(c);
  const bool exchanges = e.dT > 0.0 || e.reactions;
  const bool solves = participant(c.cfd.participant).solvesGas;
  if (!r.gasModelGiven) {
    p.model = exchanges && solves ? "ideal_gas" : "constant";
  }
  if (!r.gasProperties) {
    return;
  }
  const Section& g = *r.gasProperties;
  if (p.idealGas()) {
    // One source of truth: the ideal-gas model computes these from T, p and the composition.
    for (const char* key : {"density", "viscosity", "conductivity", "cp"}) {
      if (!g.has(key)) {
        continue;
      }
      const std::string what = key == std::string("cp") ? "heat capacity" : key;
      if (r.gasModelGiven) {
        g.fail(g.markOf(key), g.full(key),
               fmt::format("not with model: ideal_gas, which computes the {} from temperature, "
                           "pressure and composition (perfect gas, NASA-7 cp, Sutherland "
                           "viscosity); remove the key, or use model: constant",
                           what));
      }
      g.fail(g.markOf(key), g.full(key),
             fmt::format("the case {} with {}, so its gas model is ideal_gas (the default), which "
                         "computes the {} from temperature, pressure and composition: remove "
                         "the key, or write gas_properties.model: constant to keep constant "
                         "properties",
                         describe(e), c.cfd.participant, what));
    }
    return;
  }
  if (g.has("diffusivity")) {
    g.fail(g.markOf("diffusivity"), g.full("diffusivity"),
           "only with model: ideal_gas (with model constant, the OpenFOAM case's "
           "constant/transportProperties gives D)");
  }
}

/// gas: the prescribed-gas section (coredem-gas), read by the participant
void readGasSection(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  c.hasGasSection = top.has("gas");
}

/// gas_properties.model ideal_gas: a participant that solves the gas (coredemFoam), gas species
/// with thermo and transport data (gas_data.h) whose molar masses are the table's, and the
/// initial gas state (density, viscosity, conductivity, cp at temperature and pressure).
void checkIdealGas(CaseReading& r) {
  CaseConfig& c = r.c;
  if (!c.gasProperties.idealGas()) {
    return;
  }
  const ParticipantDescriptor& part = participant(c.cfd.participant);
  const Section& g = *r.gasProperties;
  if (!part.solvesGas) {
    g.fail(g.markOf("model"), "gas_properties.model",
           fmt::format("ideal_gas needs a CFD participant that solves the gas (cfd.participant: "
                       "coredemFoam); {} prescribes the gas from the '{}' section with constant "
                       "properties; use model: constant with it",
                       c.cfd.participant, c.cfd.gasKey));
  }
  std::vector<std::string> names;
  if (r.top.has("species")) {
    const auto& list = r.species;
    for (std::size_t i = 0; i < list.size() && i < c.species.size(); ++i) {
      const Section& s = list[i];
      const SpeciesConfig& sp = c.species[i];
      if (sp.name == kAirSpecies) {
        s.fail(s.markOf("name"), s.full("name"),
               "'air' is the gas of a case without species (model ideal_gas): remove 'species' "
               "for an air case, or list the gas species");
      }
      const auto d = gasSpeciesData(sp.name);
      if (!d) {
        std::vector<std::string> known = gasSpeciesWithData();
        known.erase(std::remove(known.begin(), known.end(), std::string(kAirSpecies)), known.end());
        s.fail(s.markOf("name"), s.full("name"),
               fmt::format("gas species '{}' has no thermo (NASA-7) or transport (Sutherland) data "
                           "for gas_properties.model ideal_gas; species with data: {} (a case "
                           "without species is air)",
                           sp.name, join(known)));
      }
      if (std::abs(sp.molarMass - d->molarMass) > kIdealGasMolarMassRelTol * d->molarMass) {
        s.fail(s.markOf("molar_mass"), s.full("molar_mass"),
               fmt::format("{} kg/mol, but the ideal-gas data (the DEM's NASA-7 table) give {:.6g} "
                           "kg/mol for {}; give the same value (relative tolerance {:.0e})",
                           sp.molarMass, d->molarMass, sp.name, kIdealGasMolarMassRelTol));
      }
      names.push_back(sp.name);
    }
  }
  // The initial gas: air, or the species' uniform initial mass fractions in the participant's
  // input (the OpenFOAM case's 0/; equal fractions when they cannot be read; pre-flight checks
  // them).
  if (names.empty()) {
    names.emplace_back(kAirSpecies);
  }
  std::vector<double> Y(names.size(), 1.0 / double(names.size()));
  if (!c.species.empty() && part.initialMassFractions != nullptr) {
    if (auto read = part.initialMassFractions(c, names)) {
      Y = std::move(*read);
    }
  }
  auto& p = c.gasProperties;
  const GasState s = idealGasState(names, Y, p.temperature, p.pressure);
  p.density = s.density;
  p.viscosity = s.viscosity;
  p.conductivity = s.conductivity;
  p.cp = s.cp;
}

} // namespace coredem::orchestrator::caseread

namespace coredem::orchestrator {

double largestGasTemperatureDifference(const CaseConfig& c) {
  for (const auto& [name, value] : c.models) {
    if (name == "heat" && (value == "off" || value == "false")) {
      return 0.0;
    }
  }
  const double tg = c.gasProperties.temperature;
  double dT = 0.0;
  for (const auto& p : c.particles) {
    dT = std::max(dT, std::abs(p.temperature - tg));
  }
  if (c.walls.temperature > 0.0) {
    dT = std::max(dT, std::abs(c.walls.temperature - tg));
  }
  return dT;
}

} // namespace coredem::orchestrator
