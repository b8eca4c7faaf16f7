#pragma once
/// @file
/// Reaction stoichiometry over the NASA-7 species, heats of reaction (PHYSICS §3.5,
/// Eqs. 29–30) and equilibrium constants, and the CLG reaction set R1–R5 (§6).
///
///   ΔH_r(T) = Σ_products ν_n H_n(T) − Σ_reactants ν_n H_n(T)    J per mol of reaction (29)
///   K_p(T)  = exp(−ΔG°_r(T)/(R T)),  ΔG°_r = Σ ν_n G°_n(T)        (p° = 1 bar)
///
/// Here ν_n < 0 for reactants and > 0 for products, so both sums are one signed sum.

#include <cmath>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/nasa7.h>

namespace coredem::dem::kernels {

inline constexpr int kMaxStoichTerms = 6;

/// Reaction written over Species with signed coefficients (mol per mol of reaction).
struct Stoichiometry {
  int n;
  Species species[kMaxStoichTerms];
  double nu[kMaxStoichTerms];
};

/// The CLG reactions (PHYSICS §6, seed Table 1). [C] R1/R2 use pure-carbon char.
enum class ClgReaction : int {
  R1 = 0, ///< C + CO2 → 2 CO                (char–CO2 gasification)
  R2,     ///< C + H2O → CO + H2             (char–steam gasification)
  R3,     ///< CO + H2O → CO2 + H2           (water–gas shift, homogeneous)
  R4,     ///< 3 Fe2O3 + CO → 2 Fe3O4 + CO2  (OC reduction by CO)
  R5,     ///< 3 Fe2O3 + H2 → 2 Fe3O4 + H2O  (OC reduction by H2)
  Count
};

DEM_HD constexpr Stoichiometry clgStoichiometry(ClgReaction r) {
  switch (r) {
  case ClgReaction::R1:
    return {3, {Species::C, Species::CO2, Species::CO}, {-1.0, -1.0, 2.0}};
  case ClgReaction::R2:
    return {4, {Species::C, Species::H2O, Species::CO, Species::H2}, {-1.0, -1.0, 1.0, 1.0}};
  case ClgReaction::R3:
    return {4, {Species::CO, Species::H2O, Species::CO2, Species::H2}, {-1.0, -1.0, 1.0, 1.0}};
  case ClgReaction::R4:
    return {4, {Species::Fe2O3, Species::CO, Species::Fe3O4, Species::CO2}, {-3.0, -1.0, 2.0, 1.0}};
  case ClgReaction::R5:
    return {4, {Species::Fe2O3, Species::H2, Species::Fe3O4, Species::H2O}, {-3.0, -1.0, 2.0, 1.0}};
  default:
    return {0, {}, {}};
  }
}

/// Heat of reaction ΔH_r(T), J per mol of reaction (Eq. 29); > 0 endothermic.
DEM_HD double reactionEnthalpy(const Stoichiometry& s, double T) {
  double dH = 0.0;
  for (int k = 0; k < s.n; ++k) {
    dH += s.nu[k] * nasa7EnthalpyMolar(s.species[k], T);
  }
  return dH;
}
DEM_HD double reactionEnthalpy(ClgReaction r, double T) {
  return reactionEnthalpy(clgStoichiometry(r), T);
}

/// Standard Gibbs energy of reaction ΔG°_r(T), J/mol.
DEM_HD double reactionGibbs(const Stoichiometry& s, double T) {
  double dG = 0.0;
  for (int k = 0; k < s.n; ++k) {
    dG += s.nu[k] * nasa7GibbsMolar(s.species[k], T);
  }
  return dG;
}

/// Equilibrium constant K_p = exp(−ΔG°/(RT)) with partial pressures in bar (dimensionless
/// when Σν_gas = 0, e.g. WGS).
DEM_HD double equilibriumConstant(const Stoichiometry& s, double T) {
  return std::exp(-reactionGibbs(s, T) / (kGasConstant * T));
}

/// Mass imbalance Σ ν_n M_n, kg per mol of reaction (0 to round-off for balanced reactions).
DEM_HD double stoichiometricMassBalance(const Stoichiometry& s) {
  double m = 0.0;
  for (int k = 0; k < s.n; ++k) {
    m += s.nu[k] * molarMass(s.species[k]);
  }
  return m;
}

} // namespace coredem::dem::kernels
