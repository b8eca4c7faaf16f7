// solid_species, reactions, chemistry (protocol v1.1; docs/case-schema.md): after species and
// particles (compositions name solid species; reactions name gas and solid species).
#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>

#include "case_read.h"

namespace coredem::orchestrator::caseread {
namespace {

using yaml::join;

/// Kinetic overrides of chemistry.clg (same names as coredem::dem::clgKineticNames(), which the
/// DEM server checks again).
const std::vector<std::string> kClgKinetics = {
    "A_CO2", "E_CO2",  "K_CO2", "dH_CO2", "K_CO",  "dH_CO",    "A_H2O", "E_H2O",
    "K_H2O", "dH_H2O", "K_H2",  "dH_H2",  "rho_m", "r_grain",  "k0_CO", "E_CO",
    "n_CO",  "k0_H2",  "E_H2",  "n_H2",   "kf0",   "Ef_over_R"};

/// The terms of reactions[i]: known species, 1 to 6 terms, a solid reactant, mass balance.
void readTerms(const Section& r, const CaseConfig& c, ReactionConfig& rc) {
  r.require("terms", "list of {species, nu}, nu < 0 for reactants");
  double imbalance = 0.0, scale = 0.0;
  bool solidReactant = false;
  for (const auto& t : r.list("terms", {"species", "nu"}, "reaction terms")) {
    ReactionTermConfig term;
    term.species = t.string("species", std::nullopt, "a gas or solid species name");
    term.nu = t.number("nu", std::nullopt, -kBig, kBig,
                       "mol per mol of reaction, < 0 reactant, > 0 product");
    if (term.nu == 0.0) {
      t.fail(t.markOf("nu"), t.full("nu"), "must be nonzero (< 0 reactant, > 0 product)");
    }
    const SpeciesConfig* gas = findSpecies(c.species, term.species);
    const SpeciesConfig* solid = findSpecies(c.solidSpecies, term.species);
    if (gas == nullptr && solid == nullptr) {
      t.fail(t.markOf("species"), t.full("species"),
             fmt::format("unknown species '{}'; allowed: gas species {}; solid species {}",
                         term.species, speciesNames(c.species), speciesNames(c.solidSpecies)));
    }
    const double molar = gas != nullptr ? gas->molarMass : solid->molarMass;
    imbalance += term.nu * molar;
    scale += std::abs(term.nu * molar);
    solidReactant = solidReactant || (solid != nullptr && term.nu < 0.0);
    rc.terms.push_back(term);
  }
  if (rc.terms.empty() || rc.terms.size() > 6) {
    r.fail(r.markOf("terms"), r.full("terms"),
           fmt::format("{} terms; give 1 to 6", rc.terms.size()));
  }
  if (!solidReactant) {
    r.fail(r.markOf("terms"), r.full("terms"),
           "no solid reactant: a heterogeneous reaction consumes a solid species (nu < 0)");
  }
  // Mass balance: Σ ν M = 0. More than 1e-3 of Σ|ν M| is a wrong coefficient (error);
  // smaller residuals come from rounded molar masses (the DEM server logs a warning).
  if (std::abs(imbalance) > 1e-3 * scale) {
    r.fail(r.markOf("terms"), r.full("terms"),
           fmt::format("the terms do not balance mass: sum nu M = {:.6g} kg/mol ({:.3g} of sum "
                       "|nu M|); check the coefficients and molar masses",
                       imbalance, imbalance / scale));
  }
}

/// The rate law of reactions[i] (after its terms: order_species must be one of them).
void readRate(const Section& r, const CaseConfig& c, ReactionConfig& rc) {
  r.require("rate", "{law: constant, A: ...} or {law: arrhenius, A, beta, E, ...}");
  const Section rate = r.section("rate", {"law", "A", "beta", "E", "order_species", "order"});
  rc.law = rate.choice("law", std::nullopt, {"constant", "arrhenius"});
  rc.A = rate.number("A", std::nullopt, 0.0, kBig,
                     rc.law == "constant" ? "mol of reaction per s per particle, >= 0"
                                          : "pre-exponential factor, >= 0");
  if (rc.law == "constant") {
    for (const char* k : {"beta", "E", "order_species", "order"}) {
      if (rate.has(k)) {
        rate.fail(rate.markOf(k), rate.full(k), "only with law: arrhenius");
      }
    }
  } else {
    rc.beta = rate.number("beta", 0.0, -kBig, kBig, "temperature exponent");
    rc.E = rate.number("E", 0.0, 0.0, kBig, "activation energy in J/mol, >= 0");
    if (rate.has("order_species")) {
      rc.orderSpecies = rate.string("order_species", std::nullopt, "gas species of the rate");
      bool ok = findSpecies(c.species, rc.orderSpecies) != nullptr;
      bool inTerms = false;
      for (const auto& t : rc.terms) {
        inTerms = inTerms || t.species == rc.orderSpecies;
      }
      if (!ok || !inTerms) {
        rate.fail(rate.markOf("order_species"), rate.full("order_species"),
                  fmt::format("'{}' must be a gas species among the terms of '{}'", rc.orderSpecies,
                              rc.name));
      }
      rc.order = rate.number("order", 1.0, -kBig, kBig, "reaction order");
    } else if (rate.has("order")) {
      rate.fail(rate.markOf("order"), rate.full("order"), "needs order_species");
    }
  }
}

/// heat_of_reaction of reactions[i]: J/mol, or nasa7 (every species with NASA-7 data).
void readHeatOfReaction(const Section& r, ReactionConfig& rc) {
  if (r.has("heat_of_reaction")) {
    const YAML::Node h = r.raw("heat_of_reaction");
    if (h.IsScalar() && h.Scalar() == "nasa7") {
      rc.heatFromNasa7 = true;
      static const std::set<std::string> nasa = {"CO", "CO2",   "H2",    "H2O",  "N2",
                                                 "C",  "Fe2O3", "Fe3O4", "Al2O3"};
      for (const auto& t : rc.terms) {
        if (nasa.count(t.species) == 0) {
          r.fail(r.markOf("heat_of_reaction"), r.full("heat_of_reaction"),
                 fmt::format("nasa7 needs NASA-7 data for every species; '{}' has none "
                             "(available: {}); give a number in J/mol",
                             t.species, join({nasa.begin(), nasa.end()})));
        }
      }
    } else {
      rc.heatOfReaction = r.number("heat_of_reaction", std::nullopt, -kBig, kBig,
                                   "J per mol of reaction (> 0 endothermic), or nasa7");
    }
  }
}

} // namespace

const SpeciesConfig* findSpecies(const std::vector<SpeciesConfig>& list, const std::string& name) {
  for (const auto& sp : list) {
    if (sp.name == name) {
      return &sp;
    }
  }
  return nullptr;
}

std::string speciesNames(const std::vector<SpeciesConfig>& list) {
  std::vector<std::string> names;
  for (const auto& sp : list) {
    names.push_back(sp.name);
  }
  return names.empty() ? std::string("(none)") : join(names);
}

void readSolidSpecies(CaseReading& rd) {
  const Section& top = rd.top;
  CaseConfig& c = rd.c;
  if (!top.has("solid_species")) {
    return;
  }
  std::set<std::string> seen;
  for (const auto& s : top.list("solid_species", {"name", "molar_mass"}, "particle species")) {
    SpeciesConfig sp;
    sp.name = s.string("name", std::nullopt, "solid species name, e.g. Fe2O3");
    sp.molarMass = s.number("molar_mass", std::nullopt, 0.0, kBig, "kg/mol, > 0", true);
    if (!seen.insert(sp.name).second) {
      s.fail(s.markOf("name"), "solid_species",
             fmt::format("solid species '{}' is listed twice", sp.name));
    }
    if (findSpecies(c.species, sp.name) != nullptr) {
      s.fail(s.markOf("name"), "solid_species",
             fmt::format("'{}' is also a gas species; give solid and gas species distinct names",
                         sp.name));
    }
    c.solidSpecies.push_back(sp);
  }
  // Compositions name solid species.
  const YAML::Node parts = top.raw("particles");
  for (std::size_t i = 0; i < c.particles.size(); ++i) {
    for (const auto& [name, f] : c.particles[i].composition) {
      if (findSpecies(c.solidSpecies, name) == nullptr) {
        const YAML::Node comp = parts && parts.IsSequence() && i < parts.size()
                                    ? parts[i]["composition"]
                                    : YAML::Node();
        top.fail(comp ? comp.Mark() : top.mark(), fmt::format("particles[{}].composition", i),
                 fmt::format("unknown solid species '{}'; allowed: {}", name,
                             speciesNames(c.solidSpecies)));
      }
    }
  }
}

void readReactions(CaseReading& rd) {
  const Section& top = rd.top;
  CaseConfig& c = rd.c;
  if (!top.has("reactions")) {
    return;
  }
  if (c.solidSpecies.empty()) {
    top.fail(top.markOf("reactions"), "reactions",
             "reactions need 'solid_species' (the particle species they consume or produce)");
  }
  std::set<std::string> names;
  for (const auto& r :
       top.list("reactions", {"name", "terms", "rate", "heat_of_reaction"}, "reactions")) {
    ReactionConfig rc;
    rc.name = r.string("name", std::nullopt, "reaction name");
    if (!names.insert(rc.name).second) {
      r.fail(r.markOf("name"), r.full("name"),
             fmt::format("reaction '{}' is defined twice", rc.name));
    }
    readTerms(r, c, rc);
    readRate(r, c, rc);
    readHeatOfReaction(r, rc);
    c.reactions.push_back(rc);
  }
}

void readChemistry(CaseReading& rd) {
  const Section& top = rd.top;
  CaseConfig& c = rd.c;
  if (!top.has("chemistry")) {
    return;
  }
  ChemistryConfig& ch = c.chemistry;
  ch.present = true;
  const Section s = top.section("chemistry", {"clg", "removal_fraction", "reaction_heat"});
  if (s.has("clg")) {
    std::vector<std::string> allowed = {"char_gasification", "char_stoichiometry", "oc_reduction",
                                        "wgs", "wgs_equilibrium"};
    allowed.insert(allowed.end(), kClgKinetics.begin(), kClgKinetics.end());
    const Section g = s.section("clg", allowed);
    ch.charGasification = g.onOff("char_gasification", false);
    ch.charStoichiometry =
        g.choice("char_stoichiometry", std::string("carbon"), {"carbon", "seed"});
    if (ch.charStoichiometry == "seed") {
      g.fail(g.markOf("char_stoichiometry"), g.full("char_stoichiometry"),
             "seed is not implemented: the seed's pseudo-char lines of R1 and R2 are not mutually "
             "consistent (docs/physics.md §6.1); use carbon");
    }
    ch.ocReduction = g.onOff("oc_reduction", false);
    ch.wgs = g.onOff("wgs", false);
    ch.wgsEquilibrium = g.choice("wgs_equilibrium", std::string("yoon_denn"),
                                 {"yoon_denn", "seed", "thermodynamic"});
    for (const auto& k : kClgKinetics) {
      if (g.has(k)) {
        ch.kinetics.emplace_back(k, g.number(k, std::nullopt, -kBig, kBig, "kinetic parameter"));
      }
    }
    auto need = [&](const std::string& key, std::vector<std::string> gas,
                    std::vector<std::string> solid) {
      for (const auto& n : gas) {
        if (findSpecies(c.species, n) == nullptr) {
          g.fail(g.markOf(key), g.full(key),
                 fmt::format("needs gas species {} in 'species' (have: {})", n,
                             speciesNames(c.species)));
        }
      }
      for (const auto& n : solid) {
        if (findSpecies(c.solidSpecies, n) == nullptr) {
          g.fail(g.markOf(key), g.full(key),
                 fmt::format("needs solid species {} in 'solid_species' (have: {})", n,
                             speciesNames(c.solidSpecies)));
        }
      }
    };
    if (ch.charGasification) {
      need("char_gasification", {"CO", "CO2", "H2", "H2O"}, {"C"});
    }
    if (ch.ocReduction) {
      need("oc_reduction", {"CO", "CO2", "H2", "H2O"}, {"Fe2O3", "Fe3O4"});
    }
    if (ch.wgs) {
      need("wgs", {"CO", "CO2", "H2", "H2O"}, {});
    }
  }
  if (s.has("removal_fraction")) {
    ch.removalFraction = s.number("removal_fraction", std::nullopt, 0.0, 1.0,
                                  "fraction of the initial diameter, in (0, 1)", true);
    if (*ch.removalFraction >= 1.0) {
      s.fail(s.markOf("removal_fraction"), s.full("removal_fraction"), "must be < 1");
    }
  }
  if (s.has("reaction_heat")) {
    ch.reactionHeat = s.onOff("reaction_heat", true);
  }
}

} // namespace coredem::orchestrator::caseread
