#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include <coredem/common/yaml_section.h>
#include <coredem/dem/models.h>
#include <coredem/dem/triangle_mesh.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/foam_patches.h>
#include <coredem/orchestrator/gas_data.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/preflight.h>
#include <coredem/orchestrator/sha256.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

using yaml::describe;
using yaml::join;
using yaml::Section;

constexpr double kBig = std::numeric_limits<double>::max();

const std::vector<std::string> kWallKeys = {"box",    "planes",   "cylinders", "cones",
                                            "meshes", "material", "thermal",   "temperature"};

// ---------------------------------------------------------------- chemistry (protocol v1.1)
/// Kinetic overrides of chemistry.clg (same names as coredem::dem::clgKineticNames(), which the
/// DEM server checks again).
const std::vector<std::string> kClgKinetics = {
    "A_CO2", "E_CO2",  "K_CO2", "dH_CO2", "K_CO",  "dH_CO",    "A_H2O", "E_H2O",
    "K_H2O", "dH_H2O", "K_H2",  "dH_H2",  "rho_m", "r_grain",  "k0_CO", "E_CO",
    "n_CO",  "k0_H2",  "E_H2",  "n_H2",   "kf0",   "Ef_over_R"};

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

/// solid_species, reactions, chemistry (docs/case-schema.md). Called after species and particles.
void parseChemistry(const Section& top, CaseConfig& c) {
  if (top.has("solid_species")) {
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
  if (top.has("reactions")) {
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
                      fmt::format("'{}' must be a gas species among the terms of '{}'",
                                  rc.orderSpecies, rc.name));
          }
          rc.order = rate.number("order", 1.0, -kBig, kBig, "reaction order");
        } else if (rate.has("order")) {
          rate.fail(rate.markOf("order"), rate.full("order"), "needs order_species");
        }
      }
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
      c.reactions.push_back(rc);
    }
  }
  if (top.has("chemistry")) {
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
        g.fail(
            g.markOf("char_stoichiometry"), g.full("char_stoichiometry"),
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
}

/// gas_properties.model ideal_gas: a participant that solves the gas (coredemFoam), gas species
/// with thermo and transport data (gas_data.h) whose molar masses are the table's, and the
/// initial gas state (density, viscosity, conductivity, cp at temperature and pressure).
void checkIdealGas(const Section& top, CaseConfig& c) {
  const ParticipantDescriptor& part = participant(c.cfd.participant);
  const Section g = top.section("gas_properties",
                                {"model", "temperature", "pressure", "diffusivity", "alphac_min"});
  if (part.caseFolder.empty()) {
    g.fail(g.markOf("model"), "gas_properties.model",
           fmt::format("ideal_gas needs a CFD participant that solves the gas (cfd.participant: "
                       "coredemFoam); {} prescribes the gas from the '{}' section with constant "
                       "properties; use model: constant with it",
                       c.cfd.participant, c.cfd.gasKey));
  }
  std::vector<std::string> names;
  if (top.has("species")) {
    const auto list = top.list("species", {"name", "molar_mass"}, "gas species");
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
  // The initial gas: air, or the species' uniform initial mass fractions in the OpenFOAM case
  // (equal fractions when they cannot be read; pre-flight checks them).
  if (names.empty()) {
    names.emplace_back(kAirSpecies);
  }
  std::vector<double> Y(names.size(), 1.0 / double(names.size()));
  if (!c.species.empty()) {
    std::vector<double> read;
    double sum = 0.0;
    for (const auto& n : names) {
      const FoamFieldValues f = readFoamField(c.caseDir / c.cfd.caseFolder / "0" / n);
      if (!f.found || f.values.empty() || f.values.front().patch != "internalField" ||
          !f.values.front().uniform || !(f.values.front().value >= 0.0)) {
        break;
      }
      read.push_back(f.values.front().value);
      sum += read.back();
    }
    if (read.size() == names.size() && std::abs(sum - 1.0) <= 1e-9) {
      Y = read;
    }
  }
  auto& p = c.gasProperties;
  const GasState s = idealGasState(names, Y, p.temperature, p.pressure);
  p.density = s.density;
  p.viscosity = s.viscosity;
  p.conductivity = s.conductivity;
  p.cp = s.cp;
}

/// The axis of a cylinder or cone: nonzero, returned normalised.
Vec3 wallAxis(const Section& s) {
  Vec3 a = s.vec3("axis", std::nullopt, "axis direction, e.g. [0, 0, 1]");
  const double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  if (!(len > 0.0) || !std::isfinite(len)) {
    s.fail(s.markOf("axis"), s.full("axis"), "must be a nonzero direction, e.g. [0, 0, 1]");
  }
  for (double& x : a) {
    x /= len;
  }
  return a;
}

/// side and caps of a cylinder or cone (caps need a finite extent).
void wallSideAndCaps(const Section& s, RevolvedWallConfig& r) {
  r.side = s.choice("side", std::string("inside"), {"inside", "outside", "both"});
  if (!s.has("caps")) {
    return;
  }
  const YAML::Node caps = s.raw("caps");
  if (!caps.IsSequence()) {
    s.fail(s.markOf("caps"), s.full("caps"),
           fmt::format("expected a list of the ends to close: [], [start], [end] or [start, end]; "
                       "got {}",
                       describe(caps)));
  }
  for (std::size_t k = 0; k < caps.size(); ++k) {
    const std::string key = fmt::format("{}[{}]", s.full("caps"), k);
    if (!caps[k].IsScalar() || (caps[k].Scalar() != "start" && caps[k].Scalar() != "end")) {
      s.fail(caps[k].Mark(), key,
             fmt::format("{} is not an end; allowed: start, end", describe(caps[k])));
    }
    bool& cap = caps[k].Scalar() == "start" ? r.capStart : r.capEnd;
    if (cap) {
      s.fail(caps[k].Mark(), key, fmt::format("'{}' is listed twice", caps[k].Scalar()));
    }
    cap = true;
  }
  if ((r.capStart || r.capEnd) && !r.finite) {
    s.fail(s.markOf("caps"), s.full("caps"),
           "an infinite cylinder has no ends to cap; give 'from' and 'to' (m along the axis) or "
           "remove 'caps'");
  }
}

/// The axial extent from/to of a cylinder (both or neither) or a cone (both required).
void wallExtent(const Section& s, RevolvedWallConfig& r) {
  if (r.cone) {
    s.require("from", "m along the axis from 'point' where the cone starts");
    s.require("to", "m along the axis from 'point' where the cone ends, > from");
  } else if (s.has("from") != s.has("to")) {
    const std::string given = s.has("from") ? "from" : "to";
    s.fail(s.markOf(given), s.full(given),
           "give both 'from' and 'to' (a finite cylinder) or neither (an infinite cylinder)");
  }
  r.finite = s.has("from");
  if (!r.finite) {
    return;
  }
  r.from = s.number("from", std::nullopt, -kBig, kBig, "m along the axis from 'point'");
  r.to = s.number("to", std::nullopt, -kBig, kBig, "m along the axis from 'point', > from");
  if (!(r.to > r.from)) {
    s.fail(s.markOf("to"), s.full("to"),
           fmt::format("{} m must exceed from = {} m (the axis points from 'from' to 'to')", r.to,
                       r.from));
  }
}

/// walls.cylinders, walls.cones (protocol v1.4; docs/case-schema.md "walls").
void parseWallShapes(const Section& w, CaseConfig& c) {
  if (w.has("cylinders")) {
    for (const auto& s :
         w.list("cylinders", {"point", "axis", "radius", "from", "to", "side", "caps"},
                "cylinder walls")) {
      RevolvedWallConfig r;
      r.index = c.walls.revolved.size();
      r.point = s.vec3("point", std::nullopt, "m, a point on the axis");
      r.axis = wallAxis(s);
      r.radiusFrom = r.radiusTo = s.number("radius", std::nullopt, 0.0, kBig, "m, > 0", true);
      wallExtent(s, r);
      wallSideAndCaps(s, r);
      c.walls.revolved.push_back(r);
    }
  }
  if (w.has("cones")) {
    std::size_t index = 0;
    for (const auto& s : w.list(
             "cones", {"point", "axis", "from", "to", "radius_from", "radius_to", "side", "caps"},
             "cone (frustum) walls")) {
      RevolvedWallConfig r;
      r.cone = true;
      r.index = index++;
      r.point = s.vec3("point", std::nullopt, "m, a point on the axis");
      r.axis = wallAxis(s);
      wallExtent(s, r);
      r.radiusFrom = s.number("radius_from", std::nullopt, 0.0, kBig, "m at 'from', >= 0");
      r.radiusTo = s.number("radius_to", std::nullopt, 0.0, kBig, "m at 'to', >= 0");
      if (!(r.radiusFrom > 0.0 || r.radiusTo > 0.0)) {
        s.fail(s.markOf("radius_to"), s.full("radius_to"),
               "a cone needs a radius > 0 at one end at least (radius_from or radius_to)");
      }
      wallSideAndCaps(s, r);
      c.walls.revolved.push_back(r);
    }
  }
}

/// The patch names of walls.meshes[i].from_cfd: a list of names (or one name).
std::vector<std::string> patchNames(const Section& s) {
  const YAML::Node n = s.raw("from_cfd");
  std::vector<std::string> names;
  if (n.IsScalar()) {
    names.push_back(n.Scalar());
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) {
      if (!n[i].IsScalar() || n[i].Scalar().empty()) {
        s.fail(n[i].Mark(), fmt::format("{}[{}]", s.full("from_cfd"), i),
               fmt::format("expected a patch name, found {}", describe(n[i])));
      }
      names.push_back(n[i].Scalar());
    }
  }
  if (names.empty()) {
    s.fail(s.markOf("from_cfd"), s.full("from_cfd"),
           fmt::format("expected a list of patch names of the CFD mesh, e.g. [walls], found {}",
                       describe(n)));
  }
  return names;
}

/// walls.meshes[i].from_cfd: the wall from patches of the OpenFOAM case's mesh (cfd.case).
void meshFromCfd(const Section& s, const CaseConfig& c, bool cfdSection, MeshWallConfig& m) {
  const std::string key = s.full("from_cfd");
  const ParticipantDescriptor& p = participant(c.cfd.participant);
  if (!p.openFoamCase) {
    std::vector<std::string> foam;
    for (const auto& q : participantTable()) {
      if (q.openFoamCase) {
        foam.push_back(q.name);
      }
    }
    s.fail(s.markOf("from_cfd"), key,
           fmt::format("from_cfd takes the walls from the mesh of the OpenFOAM case in cfd.case, "
                       "but the CFD participant is {} ({}), which has no mesh; use "
                       "cfd: {{participant: {}, case: <OpenFOAM case folder>}}, or give the wall "
                       "as an STL file (walls.meshes[].file)",
                       p.name, cfdSection ? "cfd.participant" : "the default: no cfd section",
                       join(foam)));
  }
  m.fromCfd = patchNames(s);
  const fs::path foamCase = fs::absolute(c.caseDir / c.cfd.caseFolder).lexically_normal();
  m.path = foamCase / "constant" / "polyMesh";
  m.name = fmt::format("{}/constant/polyMesh:{}", c.cfd.caseFolder, join(m.fromCfd));
  if (m.name.size() > 200) { // the DEM server's limit on names is 256 bytes
    m.name = fmt::format("{}... ({} patches)", m.name.substr(0, 170), m.fromCfd.size());
  }
  FoamPatchSurface surface;
  try {
    surface = readFoamPatches(foamCase, m.fromCfd);
  } catch (const FoamMeshError& e) {
    s.fail(s.markOf("from_cfd"), key, e.what());
  }
  dem::TriangleMesh mesh;
  mesh.name = m.name;
  mesh.vertices = std::move(surface.vertices);
  mesh.triangles = std::move(surface.triangles);
  try {
    // No domain: the mesh is in metres (OpenFOAM's points are); the pre-flight compares it with
    // the coupling grid.
    dem::checkMesh(mesh, dem::MeshCheckOptions{m.closed, std::nullopt});
  } catch (const dem::MeshError& e) {
    std::string what = e.what();
    // Triangle numbers mean nothing to the user: name the mesh face it comes from.
    std::string face;
    static const std::regex triangle("triangle ([0-9]+)");
    std::smatch hit;
    if (std::regex_search(what, hit, triangle)) {
      const std::size_t t = std::stoul(hit[1].str()) - 1;
      if (t < surface.sourceFace.size()) {
        face = fmt::format(" (triangle {} is part of face {} of patch '{}')", t + 1,
                           surface.sourceFace[t], m.fromCfd[surface.sourcePatch[t]]);
      }
    }
    // The STL checker's advice (export the surface again) does not fit a CFD mesh.
    const auto advice = what.find("; a closed wall is required");
    if (advice != std::string::npos && what.find("not closed") != std::string::npos) {
      what = fmt::format("{}{}; a closed wall is required ({}: true): name every patch around "
                         "the fluid in {}, or set {}: false for an open wall",
                         what.substr(0, advice), face, s.full("closed"), key, s.full("closed"));
    } else {
      what += face + "; check the CFD mesh (checkMesh)";
    }
    s.fail(s.markOf("from_cfd"), key, what);
  }
  m.vertices = std::move(mesh.vertices);
  m.triangles = std::move(mesh.triangles);
}

/// walls.meshes (protocol v1.4; docs/case-schema.md "walls"): STL files or patches of the CFD
/// mesh. Called after the cfd section (from_cfd reads cfd.case).
void parseMeshWalls(const Section& w, CaseConfig& c, bool cfdSection) {
  if (!w.has("meshes")) {
    return;
  }
  // The walls are expected inside the coupling grid (pre-flight checks that too): a mesh far
  // larger than the grid is probably in millimetres. The grid is required in every case, so it is
  // always the domain (a DEM-only case still has one, covering its walls).
  std::array<double, 6> domain{};
  for (int d = 0; d < 3; ++d) {
    domain[std::size_t(d)] = c.grid.origin[std::size_t(d)];
    domain[std::size_t(d) + 3] =
        c.grid.origin[std::size_t(d)] +
        c.grid.spacing[std::size_t(d)] * double(c.grid.cells[std::size_t(d)]);
  }
  for (const auto& s :
       w.list("meshes", {"file", "from_cfd", "scale", "closed"}, "triangle-mesh walls")) {
    MeshWallConfig m;
    m.closed = s.onOff("closed", false);
    if (s.has("file") && s.has("from_cfd")) {
      s.fail(s.markOf("from_cfd"), s.full("from_cfd"),
             "give either 'file' (an STL file) or 'from_cfd' (patches of the CFD mesh), not both");
    }
    if (s.has("from_cfd")) {
      if (s.has("scale")) {
        s.fail(s.markOf("scale"), s.full("scale"),
               "not used with from_cfd: the CFD mesh's points are in metres already; remove it");
      }
      meshFromCfd(s, c, cfdSection, m);
      c.walls.meshes.push_back(std::move(m));
      continue;
    }
    m.file = s.string("file", std::nullopt,
                      "STL file, relative to the case folder (or from_cfd: patches of the CFD "
                      "mesh)");
    m.name = m.file;
    m.scale = s.number("scale", 1.0, 0.0, kBig,
                       "factor to metres, > 0 (1: file in m, 0.001: file in mm)", true);
    // Relative to the case folder, like initial_state and cfd.case: a resumed run finds the file
    // through run.json's case_dir, a campaign member through the links to the base case's files.
    m.path = fs::absolute(c.caseDir / m.file);
    if (!fs::is_regular_file(m.path)) {
      s.fail(s.markOf("file"), s.full("file"),
             fmt::format("file '{}' not found (looked for {}); give an STL file (ASCII or binary) "
                         "relative to the case folder",
                         m.file, m.path.string()));
    }
    try {
      dem::TriangleMesh mesh = dem::readStl(m.path, dem::StlOptions{m.scale});
      mesh.name = m.file;
      dem::checkMesh(mesh, dem::MeshCheckOptions{m.closed, domain});
      m.vertices = std::move(mesh.vertices);
      m.triangles = std::move(mesh.triangles);
    } catch (const dem::MeshError& e) {
      std::string what = e.what();
      if (m.closed && what.find("not closed") != std::string::npos) {
        what += fmt::format(" (or set {}: false for an open wall)", s.full("closed"));
      }
      s.fail(s.markOf("file"), s.full("file"), what);
    }
    c.walls.meshes.push_back(std::move(m));
  }
}

} // namespace

std::string RevolvedWallConfig::key() const {
  return fmt::format("walls.{}[{}]", cone ? "cones" : "cylinders", index);
}

int materialIndex(const CaseConfig& config, const std::string& name) {
  for (std::size_t i = 0; i < config.materials.size(); ++i) {
    if (config.materials[i].name == name) {
      return int(i);
    }
  }
  return -1;
}

CaseConfig parseCase(const std::string& text, const fs::path& file, const fs::path& caseDir) {
  const std::string fileName = file.string();
  const YAML::Node root = yaml::parse(text, fileName);
  CaseConfig c;
  c.caseDir = caseDir;
  c.caseFile = fs::absolute(file);
  c.text = text;
  c.configHash = sha256Hex(text);

  const Section top(root, fileName, "",
                    {"name",       "description",    "time",          "grid",      "gravity",
                     "species",    "gas_properties", "materials",     "particles", "initial_state",
                     "walls",      "models",         "dem",           "cfd",       "gas",
                     "checkpoint", "output",         "solid_species", "reactions", "chemistry",
                     "coupling"},
                    YAML::Mark());
  c.name = top.string("name", std::nullopt, "the case name, used for the run folder");
  if (c.name.empty() || c.name.find('/') != std::string::npos) {
    top.fail(top.markOf("name"), "name", "must be a non-empty name without '/'");
  }
  c.description = top.string("description", std::string(), "free text");

  // time
  top.require("time", "end time and time step");
  {
    const Section t = top.section("time", {"end", "dt", "adaptive", "dt_dem"});
    c.endTime = t.number("end", std::nullopt, 0.0, kBig, "simulated end time in s, > 0", true);
    c.dt.dt = t.number("dt", std::nullopt, 0.0, kBig,
                       "CFD time step in s, > 0 (the first step when adaptive)", true);
    if (t.has("adaptive")) {
      const Section a = t.section("adaptive", {"courant", "dt_min", "dt_max", "max_growth"});
      c.dt.kind = DtPolicyConfig::Kind::Courant;
      c.dt.courant = a.number("courant", std::nullopt, 0.0, 100.0, "target Courant number", true);
      c.dt.dtMin = a.number("dt_min", std::nullopt, 0.0, kBig, "smallest CFD step in s", true);
      c.dt.dtMax = a.number("dt_max", std::nullopt, 0.0, kBig, "largest CFD step in s", true);
      c.dt.maxGrowth = a.number("max_growth", 1.2, 1.0, 10.0, "largest step-to-step growth factor");
      if (c.dt.dtMin > c.dt.dtMax) {
        a.fail(a.markOf("dt_min"), "time.adaptive.dt_min",
               fmt::format("{} is larger than dt_max = {}; need dt_min <= dt_max", c.dt.dtMin,
                           c.dt.dtMax));
      }
      if (c.dt.dt < c.dt.dtMin || c.dt.dt > c.dt.dtMax) {
        t.fail(t.markOf("dt"), "time.dt",
               fmt::format("{} must lie in [dt_min, dt_max] = [{}, {}] when adaptive", c.dt.dt,
                           c.dt.dtMin, c.dt.dtMax));
      }
    }
    if (t.has("dt_dem")) {
      c.dtDem = t.number("dt_dem", std::nullopt, 0.0, kBig,
                         "forced DEM step in s, > 0; time.dt must be an integer multiple", true);
      if (t.has("adaptive")) {
        t.fail(t.markOf("dt_dem"), "time.dt_dem",
               "a forced DEM step needs a fixed time.dt; remove 'adaptive' or 'dt_dem'");
      }
      const double ratio = c.dt.dt / c.dtDem;
      const double n = std::round(ratio);
      if (n < 1.0 || std::abs(ratio - n) > 1e-9 * n) {
        t.fail(t.markOf("dt_dem"), "time.dt_dem",
               fmt::format("time.dt / time.dt_dem = {} / {} = {:.12g} is not an integer >= 1; "
                           "choose dt_dem = dt / n_sub for an integer n_sub (e.g. {:.6g})",
                           c.dt.dt, c.dtDem, ratio, c.dt.dt / std::max(1.0, std::ceil(ratio))));
      }
    }
  }

  // coupling grid
  top.require("grid", "the coupling grid");
  {
    const Section g = top.section("grid", {"origin", "spacing", "cells"});
    c.grid.origin = g.vec3("origin", Vec3{0, 0, 0}, "m, lower corner");
    c.grid.spacing = g.vec3("spacing", std::nullopt, "cell size in m, > 0", 0.0, kBig, true);
    const Vec3 cells = g.vec3("cells", std::nullopt, "cells per axis, integers >= 1", 1.0, 1e6);
    for (int i = 0; i < 3; ++i) {
      if (cells[i] != std::floor(cells[i])) {
        g.fail(g.markOf("cells"), "grid.cells", "cell counts must be integers >= 1");
      }
      c.grid.cells[i] = std::uint64_t(cells[i]);
    }
  }
  c.gravity = top.vec3("gravity", Vec3{0.0, 0.0, -9.81}, "m/s2");

  if (top.has("species")) {
    std::set<std::string> seen;
    for (const auto& s : top.list("species", {"name", "molar_mass"}, "gas species")) {
      SpeciesConfig sp;
      sp.name = s.string("name", std::nullopt, "species name, e.g. CO2");
      sp.molarMass = s.number("molar_mass", std::nullopt, 0.0, kBig, "kg/mol, > 0", true);
      if (!seen.insert(sp.name).second) {
        s.fail(s.markOf("name"), "species", fmt::format("species '{}' is listed twice", sp.name));
      }
      c.species.push_back(sp);
    }
  }

  if (top.has("gas_properties")) {
    const Section g =
        top.section("gas_properties", {"model", "density", "viscosity", "conductivity", "cp",
                                       "temperature", "pressure", "diffusivity", "alphac_min"});
    auto& p = c.gasProperties;
    p.model = g.choice("model", std::string("constant"), {"constant", "ideal_gas"});
    if (p.idealGas()) {
      // One source of truth: the ideal-gas model computes these from T, p and the composition.
      for (const char* key : {"density", "viscosity", "conductivity", "cp"}) {
        if (g.has(key)) {
          g.fail(g.markOf(key), g.full(key),
                 fmt::format("not with model: ideal_gas, which computes the {} from temperature, "
                             "pressure and composition (perfect gas, NASA-7 cp, Sutherland "
                             "viscosity); remove the key, or use model: constant",
                             key == std::string("cp") ? "heat capacity" : key));
        }
      }
      p.diffusivity = g.number("diffusivity", p.diffusivity, 0.0, kBig,
                               "species diffusivity in m2/s, > 0", true);
      p.alphacMin = g.number("alphac_min", p.alphacMin, 0.0, 1.0,
                             "smallest gas fraction the gas equations accept, in (0, 1)", true);
    } else {
      for (const char* key : {"diffusivity", "alphac_min"}) {
        if (g.has(key)) {
          g.fail(g.markOf(key), g.full(key),
                 "only with model: ideal_gas (with model constant, the OpenFOAM case's "
                 "constant/transportProperties gives D and alphacMin)");
        }
      }
      p.density = g.number("density", p.density, 0.0, kBig, "kg/m3, > 0", true);
      p.viscosity = g.number("viscosity", p.viscosity, 0.0, kBig, "Pa s, > 0", true);
      p.conductivity = g.number("conductivity", p.conductivity, 0.0, kBig, "W/m/K, > 0", true);
      p.cp = g.number("cp", p.cp, 0.0, kBig, "J/kg/K, > 0", true);
    }
    p.temperature = g.number("temperature", p.temperature, 0.0, kBig, "K, > 0", true);
    p.pressure = g.number("pressure", p.pressure, 0.0, kBig, "Pa, > 0", true);
  }

  top.require("materials", "a list of solid materials");
  for (const auto& m : top.list("materials",
                                {"name", "density", "k_n", "e_n", "friction", "kt_factor",
                                 "etat_factor", "cp", "conductivity", "emissivity"},
                                "solid materials")) {
    MaterialConfig mc;
    mc.name = m.string("name", std::nullopt, "material name");
    mc.density = m.number("density", std::nullopt, 0.0, kBig, "kg/m3, > 0", true);
    mc.kN = m.number("k_n", std::nullopt, 0.0, kBig, "normal spring stiffness in N/m, > 0", true);
    mc.eN =
        m.number("e_n", std::nullopt, 0.0, 1.0, "normal restitution coefficient in (0, 1]", true);
    mc.friction = m.number("friction", 0.3, 0.0, kBig, "Coulomb friction coefficient, >= 0");
    if (m.has("kt_factor")) {
      mc.ktFactor = m.number("kt_factor", std::nullopt, 0.0, kBig, "k_t/k_n (default 2/7)", true);
    }
    if (m.has("etat_factor")) {
      mc.etatFactor = m.number("etat_factor", std::nullopt, 0.0, kBig, "eta_t/eta_n (default 1/2)");
    }
    mc.cp = m.number("cp", 840.0, 0.0, kBig, "specific heat in J/kg/K, > 0", true);
    mc.conductivity = m.number("conductivity", 1.0, 0.0, kBig, "W/m/K, > 0", true);
    mc.emissivity = m.number("emissivity", 0.0, 0.0, 1.0, "emissivity in [0, 1]");
    if (materialIndex(c, mc.name) >= 0) {
      m.fail(m.markOf("name"), "materials", fmt::format("material '{}' is defined twice", mc.name));
    }
    c.materials.push_back(mc);
  }
  if (c.materials.empty()) {
    top.fail(top.markOf("materials"), "materials", "needs at least one material");
  }

  if (top.has("initial_state")) {
    const std::string rel =
        top.string("initial_state", std::nullopt, "HDF5 state file, relative to the case folder");
    c.initialState = fs::absolute(caseDir / rel);
    if (!fs::is_regular_file(c.initialState)) {
      top.fail(top.markOf("initial_state"), "initial_state",
               fmt::format("file '{}' not found (looked for {}); give an HDF5 state file relative "
                           "to the case folder",
                           rel, c.initialState.string()));
    }
  }
  if (top.has("particles")) {
    for (const auto& p :
         top.list("particles",
                  {"name", "material", "count", "diameter", "density", "temperature", "composition",
                   "packing", "region", "seed", "velocity", "positions"},
                  "particle sets")) {
      ParticleSetConfig ps;
      ps.name = p.string("name", std::string("set") + std::to_string(c.particles.size()),
                         "label for outputs");
      ps.material = p.string("material", std::nullopt, "name of a material in 'materials'");
      if (materialIndex(c, ps.material) < 0) {
        std::vector<std::string> names;
        for (const auto& m : c.materials) {
          names.push_back(m.name);
        }
        p.fail(p.markOf("material"), p.full("material"),
               fmt::format("unknown material '{}'; allowed: {}", ps.material, join(names)));
      }
      if (p.has("positions")) { // explicit packing: one centre per particle
        const YAML::Node pos = p.raw("positions");
        if (!pos.IsSequence() || pos.size() == 0) {
          p.fail(p.markOf("positions"), p.full("positions"),
                 "expected a non-empty list of particle centres [[x, y, z], ...] in m");
        }
        for (std::size_t k = 0; k < pos.size(); ++k) {
          const std::string key = fmt::format("{}[{}]", p.full("positions"), k);
          if (!pos[k].IsSequence() || pos[k].size() != 3) {
            p.fail(pos[k].Mark(), key,
                   fmt::format("expected a centre [x, y, z] in m, got {}", describe(pos[k])));
          }
          Vec3 x{};
          for (std::size_t d = 0; d < 3; ++d) {
            x[d] = p.numberOf(pos[k][d], fmt::format("{}[{}]", key, d), -kBig, kBig, "m");
          }
          ps.positions.push_back(x);
        }
      }
      ps.count =
          ps.positions.empty()
              ? std::uint64_t(p.integer("count", std::nullopt, 1, 100000000, "number of particles"))
              : std::uint64_t(p.integer("count", std::int64_t(ps.positions.size()), 1, 100000000,
                                        "number of particles"));
      if (!ps.positions.empty() && ps.count != ps.positions.size()) {
        p.fail(p.markOf("count"), p.full("count"),
               fmt::format("{} particles but {} positions; with 'positions' leave 'count' out "
                           "(it is the number of positions)",
                           ps.count, ps.positions.size()));
      }
      ps.diameter = p.number("diameter", std::nullopt, 0.0, kBig, "m, > 0", true);
      ps.density = p.number("density", 0.0, 0.0, kBig, "kg/m3 (0 = the material's)");
      ps.temperature = p.number("temperature", 293.15, 0.0, kBig, "initial temperature in K", true);
      if (p.has("composition")) {
        const YAML::Node comp = p.raw("composition");
        if (!comp.IsMap()) {
          p.fail(p.markOf("composition"), p.full("composition"),
                 "expected a mapping species -> mass fraction, e.g. {Fe2O3: 1.0}");
        }
        double sum = 0.0;
        for (const auto& kv : comp) {
          const double f = p.numberOf(kv.second, p.full("composition." + kv.first.Scalar()), 0.0,
                                      1.0, "mass fraction in [0, 1]");
          ps.composition.emplace_back(kv.first.Scalar(), f);
          sum += f;
        }
        if (std::abs(sum - 1.0) > 1e-9) {
          p.fail(p.markOf("composition"), p.full("composition"),
                 fmt::format("mass fractions sum to {}, must sum to 1", sum));
        }
      }
      if (!ps.positions.empty()) {
        ps.packing = p.choice("packing", std::string("explicit"), {"explicit"});
        if (p.has("region")) {
          p.fail(p.markOf("region"), p.full("region"),
                 "not used with 'positions' (explicit packing); remove one of them");
        }
      } else {
        ps.packing = p.choice("packing", std::string("lattice"), {"lattice", "random"});
        p.require("region", "box {min: [x,y,z], max: [x,y,z]} in m to fill, or 'positions'");
        const Section r = p.section("region", {"min", "max"});
        ps.regionMin = r.vec3("min", std::nullopt, "m");
        ps.regionMax = r.vec3("max", std::nullopt, "m");
        for (int i = 0; i < 3; ++i) {
          if (ps.regionMax[i] <= ps.regionMin[i]) {
            r.fail(r.markOf("max"), r.full("max"), "every component must exceed the one of 'min'");
          }
        }
      }
      ps.seed = std::uint64_t(
          p.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max(), "random seed"));
      ps.velocity = p.vec3("velocity", Vec3{0, 0, 0}, "initial velocity in m/s");
      c.particles.push_back(ps);
    }
  }
  if (c.particles.empty() && c.initialState.empty()) {
    top.fail(top.mark(), "particles",
             "the case needs 'particles' (a list of particle sets) or 'initial_state'");
  }

  if (top.has("walls")) {
    const Section w = top.section("walls", kWallKeys);
    if (w.has("box")) {
      const Section b = w.section("box", {"min", "max"});
      c.walls.box =
          std::make_pair(b.vec3("min", std::nullopt, "m"), b.vec3("max", std::nullopt, "m"));
    }
    if (w.has("planes")) {
      for (const auto& pl : w.list("planes", {"point", "normal"}, "planar walls")) {
        c.walls.planes.push_back({pl.vec3("point", std::nullopt, "m"),
                                  pl.vec3("normal", std::nullopt, "into the domain")});
      }
    }
    parseWallShapes(w, c);
    c.walls.material = w.string("material", c.materials.front().name, "material of the walls");
    if (materialIndex(c, c.walls.material) < 0) {
      w.fail(w.markOf("material"), "walls.material",
             fmt::format("unknown material '{}'", c.walls.material));
    }
    // Thermal condition (docs/heat-coupling.md "Walls"): adiabatic (default) or every wall held
    // at `temperature` with particle–wall conduction. Configure carries it as temperature (0 =
    // adiabatic).
    const std::string thermal =
        w.choice("thermal", std::string("adiabatic"), {"adiabatic", "fixed_temperature"});
    if (thermal == "fixed_temperature") {
      c.walls.temperature = w.number("temperature", std::nullopt, 0.0, kBig,
                                     "K, > 0 (the temperature the walls are held at)", true);
    } else {
      if (w.has("temperature")) {
        w.fail(w.markOf("temperature"), "walls.temperature",
               "walls are adiabatic (walls.thermal: adiabatic, the default), so a wall temperature "
               "has no effect; add 'thermal: fixed_temperature' to hold the walls at it, or remove "
               "it");
      }
      c.walls.temperature = 0.0;
    }
  } else {
    c.walls.material = c.materials.front().name;
  }

  if (top.has("models")) {
    const YAML::Node m = top.raw("models");
    if (!m.IsMap()) {
      top.fail(top.markOf("models"), "models",
               "expected a mapping name -> model, e.g. {drag: gidaspow}");
    }
    std::vector<YAML::Mark> keyMarks, valueMarks;
    for (const auto& kv : m) {
      if (!kv.second.IsScalar()) {
        top.fail(kv.second.Mark(), "models." + kv.first.Scalar(), "expected a model name");
      }
      c.models.emplace_back(kv.first.Scalar(), kv.second.Scalar());
      keyMarks.push_back(kv.first.Mark());
      valueMarks.push_back(kv.second.Mark());
    }
    // The DEM server's model registry (coredem/dem/models.h): every key and value it would refuse
    // or ignore fails here, before anything starts.
    const std::vector<dem::ModelIssue> issues = dem::validateModels(c.models);
    if (!issues.empty()) {
      const dem::ModelIssue& bad = issues.front();
      top.fail(bad.unknownKey ? keyMarks[bad.index] : valueMarks[bad.index], "models." + bad.key,
               bad.message);
    }
  }

  if (top.has("dem")) {
    const Section d = top.section("dem", {"endpoint", "backend", "threads", "timeout_s",
                                          "server_key", "client_key", "timers"});
    c.dem.endpoint = d.string("endpoint", std::string(),
                              "endpoint of a running coredem-dem, e.g. tcp://127.0.0.1:5555");
    if (!c.dem.endpoint.empty() && c.dem.endpoint.rfind("tcp://", 0) != 0 &&
        c.dem.endpoint.rfind("ipc://", 0) != 0) {
      d.fail(d.markOf("endpoint"), "dem.endpoint", "must start with tcp:// or ipc://");
    }
    c.dem.backend = d.choice("backend", std::string("cpu"), {"cpu", "cuda", "auto"});
    c.dem.threads = int(d.integer("threads", 0, 0, 4096, "OpenMP threads, 0 = default"));
    c.dem.timeoutSeconds = d.number("timeout_s", 60.0, 0.0, kBig, "deadline in s", true);
    c.dem.timers = d.onOff("timers", false);
    if (d.has("server_key")) {
      const std::string rel =
          d.string("server_key", std::nullopt,
                   "file with the DEM server's CURVE public key (server.public)");
      c.dem.serverKey = fs::absolute(caseDir / rel);
      if (!fs::is_regular_file(c.dem.serverKey)) {
        d.fail(d.markOf("server_key"), "dem.server_key",
               fmt::format("file '{}' not found (looked for {}); give the server.public file that "
                           "'coredem-dem --generate-curve-keys DIR' wrote",
                           rel, c.dem.serverKey.string()));
      }
      if (c.dem.endpoint.empty()) {
        d.fail(d.markOf("server_key"), "dem.server_key",
               "only used with dem.endpoint (a server started elsewhere with --curve-keys)");
      }
    }
    if (d.has("client_key")) {
      const std::string rel = d.string(
          "client_key", std::nullopt,
          "this client's secret key file (client.secret) or the folder holding it, written by "
          "'coredem-dem --generate-client-key DIR'");
      c.dem.clientKey = fs::absolute(caseDir / rel);
      if (!fs::exists(c.dem.clientKey)) {
        d.fail(d.markOf("client_key"), "dem.client_key",
               fmt::format("'{}' not found (looked for {}); give the client.secret file (or its "
                           "folder) that 'coredem-dem --generate-client-key DIR' wrote",
                           rel, c.dem.clientKey.string()));
      }
      if (!d.has("server_key")) {
        d.fail(d.markOf("client_key"), "dem.client_key",
               "only used with dem.server_key (a server started with --curve-keys and "
               "--client-keys)");
      }
    }
  }
  if (top.has("cfd")) {
    const Section f =
        top.section("cfd", {"participant", "gas_key", "case", "timeout_s", "timers", "ranks"});
    // What a participant takes and allows comes from its row of the participant table.
    c.cfd.participant = f.choice("participant", c.cfd.participant, participantNames());
    const ParticipantDescriptor& p = participant(c.cfd.participant);
    if (!p.caseFolder.empty()) {
      c.cfd.caseFolder =
          f.string("case", std::nullopt,
                   fmt::format("{} of {}, relative to the case folder", p.caseFolder, p.name));
    }
    c.cfd.gasKey = f.string("gas_key", std::string("gas"), "key of the prescribed-gas section");
    c.cfd.timeoutSeconds = f.number("timeout_s", 60.0, 0.0, kBig, "deadline in s", true);
    c.cfd.timers = f.onOff("timers", false);
    c.cfd.ranks = int(f.integer("ranks", 1, 1, 4096, "MPI ranks of the CFD participant"));
    if (c.cfd.ranks > 1 && p.parallelArgs.empty()) {
      f.fail(f.markOf("ranks"), "cfd.ranks",
             fmt::format("{} runs on one process; a decomposed run (ranks > 1) needs a "
                         "participant that runs under MPI (coredemFoam)",
                         p.name));
    }
    if (c.cfd.timers && !p.hasTimers()) {
      std::vector<std::string> withTimers;
      for (const auto& q : participantTable()) {
        if (q.hasTimers()) {
          withTimers.push_back(q.name);
        }
      }
      f.fail(f.markOf("timers"), "cfd.timers",
             fmt::format("stage timers exist in {} only; remove the key", join(withTimers)));
    }
  }
  if (top.has("walls")) { // after cfd: walls.meshes[].from_cfd reads cfd.case
    parseMeshWalls(top.section("walls", kWallKeys), c, top.has("cfd"));
  }
  c.hasGasSection = top.has("gas");
  if (c.gasProperties.idealGas()) {
    checkIdealGas(top, c);
  }
  if (top.has("coupling")) {
    const Section k = top.section("coupling", {"scheme"});
    c.coupling.scheme = k.choice("scheme", c.coupling.scheme, {"sequential", "staggered"});
    if (c.coupling.scheme == "staggered" && c.gasProperties.idealGas()) {
      k.fail(k.markOf("scheme"), "coupling.scheme",
             "staggered is not available with gas_properties.model: ideal_gas yet: the "
             "variable-density gas books the particle heat exchange for the sequential scheme "
             "(docs/coredemFoam.md); use scheme: sequential or model: constant");
    }
  }

  if (top.has("checkpoint")) {
    const Section k = top.section("checkpoint", {"every_steps", "every_seconds", "keep"});
    c.checkpoint.everySteps =
        k.integer("every_steps", 0, 0, std::numeric_limits<std::int64_t>::max(),
                  "steps between checkpoints, 0 = off");
    c.checkpoint.everySeconds = k.number("every_seconds", 0.0, 0.0, kBig,
                                         "wall-clock seconds between checkpoints, 0 = off");
    c.checkpoint.keep = int(k.integer("keep", 3, 1, 1000000, "checkpoints to keep"));
  }
  if (top.has("output")) {
    const Section o = top.section("output", {"every", "every_seconds", "timeseries_every"});
    c.output.snapshotEvery =
        o.integer("every", 0, 0, std::numeric_limits<std::int64_t>::max(),
                  "steps between outputs (particle snapshot and CFD fields), 0 = none");
    c.output.everySeconds =
        o.number("every_seconds", 0.0, 0.0, kBig,
                 "simulated seconds between outputs (particle snapshot and CFD fields), 0 = none");
    c.output.timeseriesEvery =
        o.integer("timeseries_every", 1, 1, std::numeric_limits<std::int64_t>::max(),
                  "steps between timeseries.csv rows");
  }
  parseChemistry(top, c);
  return c;
}

CaseConfig loadCase(const fs::path& caseDirOrFile) {
  fs::path file = caseDirOrFile;
  if (fs::is_directory(file)) {
    file /= "case.yaml";
  }
  if (!fs::is_regular_file(file)) {
    throw CaseError(fmt::format("{}: case file not found; give a case folder that contains "
                                "case.yaml (or the path of a case file)",
                                file.string()));
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) {
    throw CaseError(fmt::format("{}: cannot read the case file", file.string()));
  }
  return parseCase(text.str(), file, fs::absolute(file).parent_path());
}

} // namespace coredem::orchestrator
