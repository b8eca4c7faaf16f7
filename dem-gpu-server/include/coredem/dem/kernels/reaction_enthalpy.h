#pragma once
/// @file
/// Reaction stoichiometry over the NASA-7 species, heats of reaction (docs/physics.md §3.5,
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

/// The CLG reactions (docs/physics.md §6, seed Table 1). [C] R1/R2 use pure-carbon char.
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

/// ΔH_r(T) of one reaction as one NASA-7-form polynomial per temperature piece: on a piece
/// where every species uses one interval, Σ ν_n H_n(T) = R [T (c0 + T (c1 + T (c2 + T (c3 +
/// T c4)))) + c5] with c_m = Σ ν_n a_m,n/(m+1) (m < 5) and c5 = Σ ν_n a_6,n. The pieces are split
/// at every interval break of every species (the union of their T_mid values), so the form
/// equals the species sum up to round-off at every T, including the extrapolated ends
/// (reactionEnthalpy(Stoichiometry) is the reference; tests/unit/thermochem/nasa7_test.cpp).
/// Built once per reaction on the host (combineReactionEnthalpy); one polynomial per call.
inline constexpr int kMaxEnthalpyPieces = 8;

struct ReactionEnthalpyPoly {
  int n = 0;                              ///< pieces (0: none; −1: too many breaks)
  double tUpper[kMaxEnthalpyPieces] = {}; ///< upper end of piece k, K (k < n − 1)
  double c[kMaxEnthalpyPieces][6] = {};   ///< coefficients of piece k (see above)
};

/// Combined coefficients of a reaction (pieces at every species interval break; n = −1 if
/// there are more than kMaxEnthalpyPieces pieces). Same interval rule as nasa7IntervalIndex: at
/// a break the upper piece is used.
DEM_HD constexpr ReactionEnthalpyPoly combineReactionEnthalpy(const Stoichiometry& s) {
  ReactionEnthalpyPoly out{};
  double breaks[kMaxStoichTerms * 2 + 1] = {};
  int nb = 0;
  for (int k = 0; k < s.n; ++k) {
    const Nasa7Data d = nasa7Data(s.species[k]);
    for (int i = 0; i + 1 < d.n; ++i) {
      const double b = d.iv[i].tMax;
      bool seen = false;
      for (int j = 0; j < nb; ++j)
        seen = seen || breaks[j] == b;
      if (seen)
        continue;
      if (nb >= kMaxEnthalpyPieces - 1) {
        out.n = -1;
        return out;
      }
      int j = nb++;
      for (; j > 0 && breaks[j - 1] > b; --j)
        breaks[j] = breaks[j - 1]; // keep sorted
      breaks[j] = b;
    }
  }
  out.n = nb + 1;
  for (int p = 0; p < out.n; ++p) {
    out.tUpper[p] = p < nb ? breaks[p] : 0.0;
    // Every species' interval on this piece: the one at the piece's lower end (piece 0: the
    // first interval of every species, extrapolated below the data as nasa7EnthalpyMolar does).
    const double tLow = p == 0 ? -1.0 : breaks[p - 1];
    for (int k = 0; k < s.n; ++k) {
      const Nasa7Data d = nasa7Data(s.species[k]);
      const double* a = d.iv[nasa7IntervalIndex(d, tLow)].a;
      for (int m = 0; m < 5; ++m)
        out.c[p][m] += s.nu[k] * (a[m] / (m + 1.0));
      out.c[p][5] += s.nu[k] * a[5];
    }
  }
  return out;
}

/// Heat of reaction ΔH_r(T) from the combined coefficients, J per mol of reaction (Eq. 29).
DEM_HD double reactionEnthalpy(const ReactionEnthalpyPoly& h, double T) {
  int p = 0;
  while (p + 1 < h.n && T >= h.tUpper[p])
    ++p;
  const double* c = h.c[p];
  return kGasConstant * (T * (c[0] + T * (c[1] + T * (c[2] + T * (c[3] + T * c[4])))) + c[5]);
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
