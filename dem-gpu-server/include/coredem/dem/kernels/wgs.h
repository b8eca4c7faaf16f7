#pragma once
/// @file
/// Homogeneous water–gas shift R3, CO + H2O ⇌ CO2 + H2, evaluated per CFD cell by the DEM
/// server (docs/physics.md §6.2, §1) and returned as species and heat sources.
///
///   ω = ε_g k_f(T) [C_CO C_H2O − C_CO2 C_H2 / K_eq(T)]     mol/(m³ of cell · s), C_j = ρ_g Y_j/M_j
///   k_f = 2.78e-3 exp(−1510/T) m³/(mol s)   (Yoon, Wei & Denn 1978 / Gururajan 1992 [K])
///   K_eq options: YoonDenn 0.0265 exp(3968/T) (default [C]); Seed exp(−4.33 + 4577.8/T);
///                 Thermodynamic exp(−ΔG°/(RT)) from the NASA-7 data (exactly consistent).
///   R_n = M_n ν_n ω  (kg/(m³ s));  S_h,rxn,g = −ΔH_R3(T_g) ω  (W/m³)
///
/// The seed's extracted rate is not equilibrium-consistent (docs/physics.md §0.3); this form is.
/// ω already contains ε_g: do not multiply by ε_g again (§1).
///
/// The K_eq correlations are a model family (kernels/model_list.h), chosen by
/// `chemistry.clg.wgs_equilibrium`. Adding one: its model struct below (name, doc, Params,
/// params(), `evaluate(const Params&, T)` returning K_eq), its name appended to WgsEquilibria
/// (the others' ids, and so earlier configuration hashes, stay), and its spelling in the
/// `chemistry:` reader and Configure's WgsEquilibrium.

#include <cmath>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/model_list.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/reaction_enthalpy.h>

namespace coredem::dem::kernels {

/// K_eq = 0.0265 exp(3968/T) (Yoon & Denn; the default [C]).
struct YoonDennEquilibrium {
  static constexpr const char* name = "yoon_denn";
  static constexpr const char* doc = "K_eq of Yoon & Denn (seed default)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  DEM_HD static double evaluate(const Params&, double t) { return 0.0265 * std::exp(3968.0 / t); }
};

/// K_eq = exp(−4.33 + 4577.8/T) (the seed's).
struct SeedEquilibrium {
  static constexpr const char* name = "seed";
  static constexpr const char* doc = "K_eq = exp(−4.33 + 4577.8/T) (seed)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  DEM_HD static double evaluate(const Params&, double t) { return std::exp(-4.33 + 4577.8 / t); }
};

/// K_eq = exp(−ΔG°/(R T)) of R3 from the NASA-7 data (exactly consistent with ΔH_R3).
struct ThermodynamicEquilibrium {
  static constexpr const char* name = "thermodynamic";
  static constexpr const char* doc = "K_eq from the NASA-7 data";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  DEM_HD static double evaluate(const Params&, double t) {
    return equilibriumConstant(clgStoichiometry(ClgReaction::R3), t);
  }
};

/// The K_eq correlations, in id order (the registration line).
using WgsEquilibria = ModelList<YoonDennEquilibrium, SeedEquilibrium, ThermodynamicEquilibrium>;

/// A K_eq correlation's id (its position in WgsEquilibria; the configuration hash uses it);
/// case-file names in the registry (coredem/dem/models.h, wgsEquilibriumModels()).
enum class WgsEquilibrium : int { YoonDenn = 0, Seed = 1, Thermodynamic = 2 };

template <class M>
constexpr WgsEquilibrium wgsEquilibrium() {
  return static_cast<WgsEquilibrium>(modelId<M, WgsEquilibria>);
}
static_assert(wgsEquilibrium<YoonDennEquilibrium>() == WgsEquilibrium::YoonDenn);
static_assert(wgsEquilibrium<SeedEquilibrium>() == WgsEquilibrium::Seed);
static_assert(wgsEquilibrium<ThermodynamicEquilibrium>() == WgsEquilibrium::Thermodynamic);

struct WgsParams {
  double kf0 = 2.78e-3;    ///< m³/(mol s)
  double efOverR = 1510.0; ///< K
  WgsEquilibrium equilibrium = WgsEquilibrium::YoonDenn;
  bool enabled = true;
};

/// The family's dispatch: Dispatch<WgsEquilibriumFamily, WgsEquilibria> calls the chosen K_eq
/// (no correlation has parameters: default Params).
struct WgsEquilibriumFamily {
  template <class M>
  DEM_HD static double evaluate(const double& t) {
    return M::evaluate(typename M::Params{}, t);
  }
};

/// K_eq(T) of CO + H2O ⇌ CO2 + H2, −.
DEM_HD double wgsEquilibriumConstant(const WgsParams& p, double t) {
  return Dispatch<WgsEquilibriumFamily, WgsEquilibria>::call(static_cast<int>(p.equilibrium), t);
}

/// Net forward rate ω, mol/(m³ s), from concentrations (mol/m³).
DEM_HD double wgsRate(const WgsParams& p, double t, double epsG, double cCO, double cH2O,
                      double cCO2, double cH2) {
  if (!p.enabled) {
    return 0.0;
  }
  const double kf = p.kf0 * std::exp(-p.efOverR / t);
  return epsG * kf * (cCO * cH2O - cCO2 * cH2 / wgsEquilibriumConstant(p, t));
}

struct WgsCellSources {
  double omega;                        ///< mol/(m³ s)
  double massSource[kGasSpeciesCount]; ///< kg/(m³ s), GasSpecies order
  double heatSource;                   ///< W/m³ into the gas
};

/// Sources of one cell from its molar concentrations c (mol/m³ of gas, GasSpecies order; the
/// cell's gas state, species_particle.h cellGasState). T_g (K), ε_g (−).
/// If dt > 0, ω is limited so that no reactant concentration goes negative within dt.
DEM_HD WgsCellSources wgsCellSourcesFromConcentrations(const WgsParams& p, double tG, double epsG,
                                                       const double* c, double dt = 0.0) {
  WgsCellSources out{};
  double w = wgsRate(p, tG, epsG, c[idx(GasSpecies::CO)], c[idx(GasSpecies::H2O)],
                     c[idx(GasSpecies::CO2)], c[idx(GasSpecies::H2)]);
  if (dt > 0.0) {
    // ω dt ≤ ε_g C of the species consumed (per m³ of cell).
    const double a =
        w > 0.0 ? (c[idx(GasSpecies::CO)] < c[idx(GasSpecies::H2O)] ? c[idx(GasSpecies::CO)]
                                                                    : c[idx(GasSpecies::H2O)])
                : (c[idx(GasSpecies::CO2)] < c[idx(GasSpecies::H2)] ? c[idx(GasSpecies::CO2)]
                                                                    : c[idx(GasSpecies::H2)]);
    const double wMax = epsG * a / dt;
    if (std::fabs(w) > wMax) {
      w = w > 0.0 ? wMax : -wMax;
    }
  }
  out.omega = w;
  out.massSource[idx(GasSpecies::CO)] = -molarMass(Species::CO) * w;
  out.massSource[idx(GasSpecies::H2O)] = -molarMass(Species::H2O) * w;
  out.massSource[idx(GasSpecies::CO2)] = molarMass(Species::CO2) * w;
  out.massSource[idx(GasSpecies::H2)] = molarMass(Species::H2) * w;
  out.massSource[idx(GasSpecies::N2)] = 0.0;
  out.heatSource = -reactionEnthalpy(ClgReaction::R3, tG) * w;
  return out;
}

/// Sources of one cell. T_g (K), ε_g (−), ρ_g (kg/m³), mass fractions Y in GasSpecies order;
/// C_j = ρ_g Y_j/M_j with the molar masses of the species table (nasa7.h).
DEM_HD WgsCellSources wgsCellSources(const WgsParams& p, double tG, double epsG, double rhoG,
                                     const double* y, double dt = 0.0) {
  double c[kGasSpeciesCount];
  for (int k = 0; k < kGasSpeciesCount; ++k) {
    c[k] = rhoG * y[k] / molarMass(static_cast<GasSpecies>(k));
  }
  return wgsCellSourcesFromConcentrations(p, tG, epsG, c, dt);
}

} // namespace coredem::dem::kernels
