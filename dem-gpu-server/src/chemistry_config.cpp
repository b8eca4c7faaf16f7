// ChemistryOptions (names) -> ChemistrySetup (indices), its validation, hash text and the
// per-particle references. Called by DemSystem (dem_system.cpp).
#include "chemistry_config.h"

#include <cmath>
#include <cstdio>

#include "coredem/common/check.h"
#include "coredem/common/log.h"
#include "coredem/dem/kernels/pressure_gradient.h"

namespace coredem::dem {
namespace {

int find(const std::vector<Species>& list, const std::string& name) {
  for (std::size_t k = 0; k < list.size(); ++k)
    if (list[k].name == name)
      return static_cast<int>(k);
  return -1;
}

std::string names(const std::vector<Species>& list) {
  std::string s;
  for (const Species& sp : list)
    s += (s.empty() ? "" : ", ") + sp.name;
  return s.empty() ? "(none)" : s;
}

/// NASA-7 species of a name (CO, CO2, H2, H2O, N2, C, Fe2O3, Fe3O4, Al2O3), or Count.
kernels::Species nasaSpecies(const std::string& name) {
  static const char* const kNames[] = {"CO", "CO2",   "H2",    "H2O",  "N2",
                                       "C",  "Fe2O3", "Fe3O4", "Al2O3"};
  for (int k = 0; k < kernels::kSpeciesCount; ++k)
    if (name == kNames[k])
      return static_cast<kernels::Species>(k);
  return kernels::Species::Count;
}

void needGas(const DemConfig& c, const char* model, std::initializer_list<const char*> list) {
  for (const char* n : list)
    COREDEM_CHECK(
        find(c.gasSpecies, n) >= 0,
        "chemistry: {} needs gas species {} in 'species' (have: {}); add it or turn the model off",
        model, n, names(c.gasSpecies));
}

/// Checks one data-defined reaction and adds it (with its NASA-7 stoichiometry for ΔH(T)) to s.
void addReaction(const DemConfig& c, const ReactionConfig& r,
                 const decltype(coredem::logger(""))& log, ChemistrySetup& s) {
  COREDEM_CHECK(
      !r.terms.empty() && r.terms.size() <= static_cast<std::size_t>(kernels::kMaxReactionTerms),
      "reaction '{}': {} terms; give 1 to {}", r.name, r.terms.size(), kernels::kMaxReactionTerms);
  kernels::HeterogeneousReaction h;
  kernels::Stoichiometry st{0, {}, {}};
  bool nasaOk = true;
  h.n = static_cast<int>(r.terms.size());
  for (int k = 0; k < h.n; ++k) {
    const ReactionTermConfig& t = r.terms[static_cast<std::size_t>(k)];
    COREDEM_CHECK(t.nu != 0.0 && std::isfinite(t.nu),
                  "reaction '{}': species {} has nu = {}; give a nonzero "
                  "coefficient (< 0 reactant, > 0 product)",
                  r.name, t.species, t.nu);
    const int gi = find(c.gasSpecies, t.species);
    const int si = find(c.solidSpecies, t.species);
    COREDEM_CHECK(gi >= 0 || si >= 0,
                  "reaction '{}': unknown species '{}'; gas species: {}; solid species: {}", r.name,
                  t.species, names(c.gasSpecies), names(c.solidSpecies));
    COREDEM_CHECK(gi < 0 || si < 0,
                  "reaction '{}': species '{}' is both a gas and a solid species; rename one",
                  r.name, t.species);
    h.phase[k] = gi >= 0 ? kernels::ReactionPhase::Gas : kernels::ReactionPhase::Solid;
    h.index[k] = gi >= 0 ? gi : si;
    h.nu[k] = t.nu;
    h.molarMass[k] = gi >= 0 ? c.gasSpecies[static_cast<std::size_t>(gi)].molarMass
                             : c.solidSpecies[static_cast<std::size_t>(si)].molarMass;
    const kernels::Species ns = nasaSpecies(t.species);
    if (ns == kernels::Species::Count)
      nasaOk = false;
    else if (st.n < kernels::kMaxStoichTerms)
      st.species[st.n] = ns, st.nu[st.n++] = t.nu;
  }
  h.law = r.law;
  COREDEM_CHECK(std::isfinite(r.A) && r.A >= 0.0, "reaction '{}': rate A = {} must be >= 0", r.name,
                r.A);
  COREDEM_CHECK(std::isfinite(r.beta) && std::isfinite(r.E) && r.E >= 0.0,
                "reaction '{}': arrhenius beta = {} and E = {} J/mol must be finite, E >= 0",
                r.name, r.beta, r.E);
  h.A = r.A;
  h.beta = r.beta;
  h.E = r.E;
  if (!r.orderSpecies.empty()) {
    int term = -1;
    for (int k = 0; k < h.n; ++k)
      if (r.terms[static_cast<std::size_t>(k)].species == r.orderSpecies)
        term = k;
    COREDEM_CHECK(term >= 0 && h.phase[term] == kernels::ReactionPhase::Gas,
                  "reaction '{}': order_species '{}' must be a gas species among its terms", r.name,
                  r.orderSpecies);
    h.orderTerm = term;
    h.order = r.order;
  }
  if (r.heatFromNasa7) {
    COREDEM_CHECK(nasaOk,
                  "reaction '{}': heat_of_reaction nasa7 needs NASA-7 data for every species "
                  "(available: CO, CO2, H2, H2O, N2, C, Fe2O3, Fe3O4, Al2O3); give a number in "
                  "J/mol instead",
                  r.name);
    h.dH = 0.0;
  } else {
    COREDEM_CHECK(std::isfinite(r.heatOfReaction), "reaction '{}': heat_of_reaction is not finite",
                  r.name);
    h.dH = r.heatOfReaction;
    st = kernels::Stoichiometry{0, {}, {}};
  }
  bool hasSolidReactant = false;
  for (int k = 0; k < h.n; ++k)
    hasSolidReactant =
        hasSolidReactant || (h.phase[k] == kernels::ReactionPhase::Solid && h.nu[k] < 0.0);
  COREDEM_CHECK(hasSolidReactant,
                "reaction '{}' has no solid reactant; a heterogeneous reaction consumes a solid "
                "species (nu < 0) of the particle",
                r.name);
  const double imbalance = kernels::heterogeneousMassImbalance(h);
  double scale = 0.0;
  for (int k = 0; k < h.n; ++k)
    scale += std::fabs(h.nu[k] * h.molarMass[k]);
  if (std::fabs(imbalance) > 1e-9 * scale) {
    log->warn(
        "reaction '{}' does not conserve mass: sum nu M = {:.6g} kg/mol ({:.3g} of sum |nu M|); "
        "mass is created or destroyed at that rate",
        r.name, imbalance, imbalance / scale);
  }
  s.reactions.push_back(h);
  s.reactionNasa7.push_back(st);
}

} // namespace

ChemistrySetup makeChemistrySetup(const DemConfig& c) {
  const ChemistryOptions& o = c.chemistry;
  ChemistrySetup s;
  s.enabled = o.active();
  ChemParams& p = s.params;
  p.nGas = static_cast<int>(c.gasSpecies.size());
  p.nSolid = static_cast<int>(c.solidSpecies.size());
  for (const Material& m : c.materials)
    s.materialCp.push_back(m.cp);
  for (const Species& sp : c.gasSpecies)
    s.gasMolarMass.push_back(sp.molarMass);
  if (!s.enabled)
    return s;

  COREDEM_CHECK(o.removalFraction > 0.0 && o.removalFraction < 1.0,
                "chemistry: removal_fraction = {} must be in (0, 1) (docs/physics.md §1.1: 0.1)",
                o.removalFraction);
  COREDEM_CHECK(o.pressure > 0.0 && std::isfinite(o.pressure),
                "chemistry: gas pressure {} Pa must be > 0", o.pressure);
  const bool particleChemistry =
      !o.reactions.empty() || o.clg.charGasification || o.clg.ocReduction;
  COREDEM_CHECK(p.nSolid <= kChemMaxSolids && (p.nSolid >= 1 || !particleChemistry),
                "chemistry: {} solid species; particle reactions need 1 to {} solid species "
                "('solid_species')",
                p.nSolid, kChemMaxSolids);
  COREDEM_CHECK(p.nGas <= kChemMaxGas,
                "chemistry: {} gas species; at most {} are supported with chemistry", p.nGas,
                kChemMaxGas);
  p.removalFraction = o.removalFraction;
  p.pressure = o.pressure;
  p.reactionHeat = o.reactionHeat;

  static const char* const kGasNames[] = {"CO", "CO2", "H2", "H2O", "N2"};
  for (int g = 0; g < kernels::kGasSpeciesCount; ++g)
    p.gasIndex[g] = find(c.gasSpecies, kGasNames[g]);
  p.solidC = find(c.solidSpecies, "C");
  p.solidFe2O3 = find(c.solidSpecies, "Fe2O3");
  p.solidFe3O4 = find(c.solidSpecies, "Fe3O4");

  const ClgOptions& clg = o.clg;
  p.charOn = clg.charGasification;
  p.ocOn = clg.ocReduction;
  p.wgsOn = clg.wgs;
  p.charParams = clg.charParams;
  p.ocParams = clg.ocParams;
  p.wgsParams = clg.wgsParams;
  p.wgsParams.enabled = clg.wgs;
  if (p.charOn) {
    COREDEM_CHECK(
        p.solidC >= 0,
        "chemistry.clg.char_gasification needs solid species C in 'solid_species' (have: {})",
        names(c.solidSpecies));
    needGas(c, "clg.char_gasification (R1, R2)", {"CO", "CO2", "H2", "H2O"});
  }
  if (p.ocOn) {
    COREDEM_CHECK(p.solidFe2O3 >= 0 && p.solidFe3O4 >= 0,
                  "chemistry.clg.oc_reduction needs solid species Fe2O3 and Fe3O4 in "
                  "'solid_species' (have: {})",
                  names(c.solidSpecies));
    needGas(c, "clg.oc_reduction (R4, R5)", {"CO", "CO2", "H2", "H2O"});
  }
  if (p.wgsOn) {
    needGas(c, "clg.wgs (R3)", {"CO", "CO2", "H2", "H2O"});
    COREDEM_CHECK(c.grid.cellCount() > 0,
                  "chemistry.clg.wgs is evaluated per coupling cell; the case has no grid");
  }

  auto log = coredem::logger("dem.chemistry");
  for (const ReactionConfig& r : o.reactions)
    addReaction(c, r, log, s);
  return s;
}

std::string chemistryHashText(const DemConfig& c) {
  const ChemistryOptions& o = c.chemistry;
  if (!o.active())
    return {}; // no chemistry: hashes of earlier configurations unchanged
  std::string t = "|chem:";
  auto num = [&](double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g;", v);
    t += b;
  };
  num(o.removalFraction), num(o.pressure), num(o.reactionHeat ? 1 : 0);
  for (const ReactionConfig& r : o.reactions) {
    t += r.name + "{";
    for (const ReactionTermConfig& term : r.terms)
      t += term.species + ":", num(term.nu);
    num(static_cast<int>(r.law)), num(r.A), num(r.beta), num(r.E);
    t += r.orderSpecies + ":";
    num(r.order), num(r.heatOfReaction), num(r.heatFromNasa7 ? 1 : 0);
    t += "}";
  }
  const ClgOptions& g = o.clg;
  t += "clg:";
  num(g.charGasification), num(g.ocReduction), num(g.wgs);
  const auto& ch = g.charParams;
  for (double v : {ch.aCO2, ch.eCO2, ch.kCO2.k0, ch.kCO2.dHads, ch.kCO.k0, ch.kCO.dHads, ch.aH2O,
                   ch.eH2O, ch.kH2O.k0, ch.kH2O.dHads, ch.kH2.k0, ch.kH2.dHads})
    num(v);
  const auto& oc = g.ocParams;
  for (double v :
       {oc.rhoMolar, oc.grainRadius, oc.b, oc.k0CO, oc.eCO, oc.nCO, oc.k0H2, oc.eH2, oc.nH2})
    num(v);
  const auto& w = g.wgsParams;
  num(w.kf0), num(w.efOverR), num(static_cast<int>(w.equilibrium));
  return t;
}

void initChemistryReferences(const DemConfig& c, HostState& st) {
  const std::size_t n = st.n;
  const int ns = st.nSpecies;
  st.d0.resize(n);
  st.chemRef.assign(2 * n, 0.0);
  const int iC = find(c.solidSpecies, "C");
  const int iHem = find(c.solidSpecies, "Fe2O3");
  const int iMag = find(c.solidSpecies, "Fe3O4");
  const double mHem = kernels::molarMass(kernels::Species::Fe2O3);
  const double mMag = kernels::molarMass(kernels::Species::Fe3O4);
  for (std::size_t i = 0; i < n; ++i) {
    st.d0[i] = 2.0 * st.radius[i];
    const double m = st.mass[i];
    const double* x = ns > 0 ? &st.species[i * static_cast<std::size_t>(ns)] : nullptr;
    if (iC >= 0)
      st.chemRef[2 * i] = m * x[iC];
    if (iHem >= 0 && iMag >= 0)
      st.chemRef[2 * i + 1] = m * (x[iHem] + x[iMag] * (3.0 * mHem / (2.0 * mMag)));
  }
}

} // namespace coredem::dem

namespace coredem::dem {

std::size_t removeSmallParticles(double removalFraction, HostState& st, ChemistryTotals& totals) {
  const std::size_t n = st.n;
  const int ns = st.nSpecies;
  std::vector<std::size_t> keep;
  keep.reserve(n);
  if (totals.removedSolid.size() < static_cast<std::size_t>(ns))
    totals.removedSolid.resize(static_cast<std::size_t>(ns), 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (2.0 * st.radius[i] < removalFraction * st.d0[i]) {
      for (int k = 0; k < ns; ++k)
        totals.removedSolid[static_cast<std::size_t>(k)] += st.mass[i] * st.species[i * ns + k];
    } else {
      keep.push_back(i);
    }
  }
  const std::size_t removed = n - keep.size();
  if (removed == 0)
    return 0;
  compactParticles(st, keep); // every schema field; neighbour lists invalidated
  totals.removedCount += removed;
  return removed;
}

} // namespace coredem::dem

namespace coredem::dem {
namespace {

struct KineticEntry {
  const char* name;
  double* (*field)(ClgOptions&);
};

const KineticEntry kKinetics[] = {
    {"A_CO2", [](ClgOptions& c) { return &c.charParams.aCO2; }},
    {"E_CO2", [](ClgOptions& c) { return &c.charParams.eCO2; }},
    {"K_CO2", [](ClgOptions& c) { return &c.charParams.kCO2.k0; }},
    {"dH_CO2", [](ClgOptions& c) { return &c.charParams.kCO2.dHads; }},
    {"K_CO", [](ClgOptions& c) { return &c.charParams.kCO.k0; }},
    {"dH_CO", [](ClgOptions& c) { return &c.charParams.kCO.dHads; }},
    {"A_H2O", [](ClgOptions& c) { return &c.charParams.aH2O; }},
    {"E_H2O", [](ClgOptions& c) { return &c.charParams.eH2O; }},
    {"K_H2O", [](ClgOptions& c) { return &c.charParams.kH2O.k0; }},
    {"dH_H2O", [](ClgOptions& c) { return &c.charParams.kH2O.dHads; }},
    {"K_H2", [](ClgOptions& c) { return &c.charParams.kH2.k0; }},
    {"dH_H2", [](ClgOptions& c) { return &c.charParams.kH2.dHads; }},
    {"rho_m", [](ClgOptions& c) { return &c.ocParams.rhoMolar; }},
    {"r_grain", [](ClgOptions& c) { return &c.ocParams.grainRadius; }},
    {"k0_CO", [](ClgOptions& c) { return &c.ocParams.k0CO; }},
    {"E_CO", [](ClgOptions& c) { return &c.ocParams.eCO; }},
    {"n_CO", [](ClgOptions& c) { return &c.ocParams.nCO; }},
    {"k0_H2", [](ClgOptions& c) { return &c.ocParams.k0H2; }},
    {"E_H2", [](ClgOptions& c) { return &c.ocParams.eH2; }},
    {"n_H2", [](ClgOptions& c) { return &c.ocParams.nH2; }},
    {"kf0", [](ClgOptions& c) { return &c.wgsParams.kf0; }},
    {"Ef_over_R", [](ClgOptions& c) { return &c.wgsParams.efOverR; }},
};

} // namespace

const std::vector<std::string>& clgKineticNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const KineticEntry& e : kKinetics)
      v.emplace_back(e.name);
    return v;
  }();
  return names;
}

void setClgKinetic(ClgOptions& clg, const std::string& name, double value) {
  for (const KineticEntry& e : kKinetics) {
    if (name == e.name) {
      COREDEM_CHECK(std::isfinite(value), "chemistry.clg.{} = {} is not a finite number", name,
                    value);
      *e.field(clg) = value;
      return;
    }
  }
  std::string all;
  for (const std::string& n : clgKineticNames())
    all += (all.empty() ? "" : ", ") + n;
  throw UserError("chemistry.clg." + name + ": unknown kinetic parameter; allowed: " + all);
}

} // namespace coredem::dem
