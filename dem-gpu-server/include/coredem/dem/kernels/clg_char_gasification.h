#pragma once
/// @file
/// Char gasification R1 (C + CO2 → 2 CO) and R2 (C + H2O → CO + H2) for coal-fuelled
/// chemical-looping gasification (docs/physics.md §6.1; Langmuir–Hinshelwood, shrinking core).
///
///   r_CO2 = k_CO2 K_CO2 P_CO2 / (1 + K_CO2 P_CO2 + K_CO P_CO)      s⁻¹
///   r_H2O = k_H2O K_H2O P_H2O / (1 + K_H2O P_H2O + K_H2 P_H2)      s⁻¹
///   k_j = A_j exp(−E_j/(R T_p)),  K_j = K0_j exp(−ΔH_ads,j/(R T_p))   (P in bar)
///   per particle [C]:  X = 1 − m_C/m_C0,
///     ṅ_R1 = (m_C0/M_C) r_CO2 (1 − X)^(2/3),  ṅ_R2 = (m_C0/M_C) r_H2O (1 − X)^(2/3)   mol/s
///   solid: ṁ_C = −M_C (ṅ_R1 + ṅ_R2)
///   gas:   ṁ_CO2 = −M_CO2 ṅ_R1, ṁ_CO = M_CO (2 ṅ_R1 + ṅ_R2), ṁ_H2O = −M_H2O ṅ_R2, ṁ_H2 = M_H2 ṅ_R2
///   heat into the particle: Q = −ΔH_R1(T_p) ṅ_R1 − ΔH_R2(T_p) ṅ_R2  (NASA-7, §3.5)
///
/// [C] pure-carbon char (the seed's pseudo-char stoichiometry is inconsistent, §6.1).
/// Kinetic defaults are the [C]/[K] values of docs/physics.md §6.1 (Yu et al.'s own values were not
/// found): A = 1e7 s⁻¹, E_H2O = 210 kJ/mol, E_CO2 = 230 kJ/mol, K_H2O = K_CO2 = 1 bar⁻¹,
/// K_H2 = K_CO = 10 bar⁻¹ (temperature independent).

#include <cmath>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/reaction_enthalpy.h>

namespace coredem::dem::kernels {

/// Adsorption constant K = K0 exp(−ΔH_ads/(R T)), bar⁻¹.
struct AdsorptionConstant {
  double k0;    ///< bar⁻¹
  double dHads; ///< J/mol (0: temperature independent)
};

struct CharGasificationParams {
  double aCO2 = 1.0e7;   ///< s⁻¹
  double eCO2 = 230.0e3; ///< J/mol
  AdsorptionConstant kCO2{1.0, 0.0};
  AdsorptionConstant kCO{10.0, 0.0};
  double aH2O = 1.0e7;   ///< s⁻¹
  double eH2O = 210.0e3; ///< J/mol
  AdsorptionConstant kH2O{1.0, 0.0};
  AdsorptionConstant kH2{10.0, 0.0};
};

DEM_HD double adsorption(const AdsorptionConstant& k, double t) {
  return k.k0 * std::exp(-k.dHads / (kGasConstant * t));
}

/// Intrinsic L-H rate of char–CO2 gasification, s⁻¹ (pressures in bar).
DEM_HD double charRateCO2(const CharGasificationParams& p, double tP, double pCO2, double pCO) {
  const double k = p.aCO2 * std::exp(-p.eCO2 / (kGasConstant * tP));
  const double kc = adsorption(p.kCO2, tP);
  return k * kc * pCO2 / (1.0 + kc * pCO2 + adsorption(p.kCO, tP) * pCO);
}

/// Intrinsic L-H rate of char–steam gasification, s⁻¹ (pressures in bar).
DEM_HD double charRateH2O(const CharGasificationParams& p, double tP, double pH2O, double pH2) {
  const double k = p.aH2O * std::exp(-p.eH2O / (kGasConstant * tP));
  const double kw = adsorption(p.kH2O, tP);
  return k * kw * pH2O / (1.0 + kw * pH2O + adsorption(p.kH2, tP) * pH2);
}

struct CharGasificationRates {
  double nR1;                       ///< mol/s of R1
  double nR2;                       ///< mol/s of R2
  double mdotC;                     ///< kg/s of solid carbon (< 0)
  double mdotGas[kGasSpeciesCount]; ///< kg/s, GasSpecies order
  double heat;                      ///< W into the particle
};

/// Rates of one char particle. tP K; partial pressures (bar) of the cell indexed by GasSpecies
/// (P_j = x_j p); mC, mC0: current and initial carbon mass, kg.
DEM_HD CharGasificationRates charGasification(const CharGasificationParams& p, double tP,
                                              const double* pBar, double mC, double mC0) {
  CharGasificationRates out{};
  if (!(mC > 0.0) || !(mC0 > 0.0)) {
    return out;
  }
  const double unreacted = mC / mC0; // 1 − X
  const double core = std::cbrt(unreacted * unreacted);
  const double molC0 = mC0 / molarMass(Species::C);
  out.nR1 =
      molC0 * charRateCO2(p, tP, pBar[idx(GasSpecies::CO2)], pBar[idx(GasSpecies::CO)]) * core;
  out.nR2 =
      molC0 * charRateH2O(p, tP, pBar[idx(GasSpecies::H2O)], pBar[idx(GasSpecies::H2)]) * core;
  out.mdotC = -molarMass(Species::C) * (out.nR1 + out.nR2);
  out.mdotGas[idx(GasSpecies::CO2)] = -molarMass(Species::CO2) * out.nR1;
  out.mdotGas[idx(GasSpecies::CO)] = molarMass(Species::CO) * (2.0 * out.nR1 + out.nR2);
  out.mdotGas[idx(GasSpecies::H2O)] = -molarMass(Species::H2O) * out.nR2;
  out.mdotGas[idx(GasSpecies::H2)] = molarMass(Species::H2) * out.nR2;
  out.heat = -reactionEnthalpy(ClgReaction::R1, tP) * out.nR1 -
             reactionEnthalpy(ClgReaction::R2, tP) * out.nR2;
  return out;
}

/// adsorption() with 1/(R T) given; no exp() for a temperature-independent constant.
DEM_HD double adsorptionHoisted(const AdsorptionConstant& k, double invRT) {
  return k.dHads == 0.0 ? k.k0 : k.k0 * std::exp(-k.dHads * invRT);
}

/// charGasification() for the engine's per-particle loop, same equations: 1/(R T_p) computed
/// once, no exp() for temperature-independent adsorption constants or for a rate whose gas
/// reactant is absent, nothing for a particle without carbon, and the heats from the combined
/// ΔH_r polynomials dh[0] (R1) and dh[1] (R2) (combineReactionEnthalpy; dh = nullptr: heat 0,
/// for runs without reaction heat). Equals charGasification() to round-off (tested to 1e-12).
DEM_HD CharGasificationRates charGasificationHoisted(const CharGasificationParams& p,
                                                     const ReactionEnthalpyPoly* dh, double tP,
                                                     const double* pBar, double mC, double mC0) {
  CharGasificationRates out{};
  const double pCO2 = pBar[idx(GasSpecies::CO2)], pH2O = pBar[idx(GasSpecies::H2O)];
  if (!(mC > 0.0) || !(mC0 > 0.0) || !(pCO2 > 0.0 || pH2O > 0.0)) {
    return out;
  }
  const double invRT = 1.0 / (kGasConstant * tP);
  const double unreacted = mC / mC0; // 1 − X
  const double scale = mC0 / molarMass(Species::C) * std::cbrt(unreacted * unreacted);
  if (pCO2 > 0.0) {
    const double kc = adsorptionHoisted(p.kCO2, invRT);
    const double r =
        p.aCO2 * std::exp(-p.eCO2 * invRT) * kc * pCO2 /
        (1.0 + kc * pCO2 + adsorptionHoisted(p.kCO, invRT) * pBar[idx(GasSpecies::CO)]);
    out.nR1 = scale * r;
  }
  if (pH2O > 0.0) {
    const double kw = adsorptionHoisted(p.kH2O, invRT);
    const double r =
        p.aH2O * std::exp(-p.eH2O * invRT) * kw * pH2O /
        (1.0 + kw * pH2O + adsorptionHoisted(p.kH2, invRT) * pBar[idx(GasSpecies::H2)]);
    out.nR2 = scale * r;
  }
  out.mdotC = -molarMass(Species::C) * (out.nR1 + out.nR2);
  out.mdotGas[idx(GasSpecies::CO2)] = -molarMass(Species::CO2) * out.nR1;
  out.mdotGas[idx(GasSpecies::CO)] = molarMass(Species::CO) * (2.0 * out.nR1 + out.nR2);
  out.mdotGas[idx(GasSpecies::H2O)] = -molarMass(Species::H2O) * out.nR2;
  out.mdotGas[idx(GasSpecies::H2)] = molarMass(Species::H2) * out.nR2;
  if (dh != nullptr) {
    out.heat = -reactionEnthalpy(dh[0], tP) * out.nR1 - reactionEnthalpy(dh[1], tP) * out.nR2;
  }
  return out;
}

/// Scale factor s ∈ [0, 1] so that a step dt does not consume more carbon than present
/// (multiply every rate of `r` by s).
DEM_HD double charStepLimiter(const CharGasificationRates& r, double mC, double dt) {
  const double loss = -r.mdotC * dt;
  return loss > mC && loss > 0.0 ? (mC > 0.0 ? mC / loss : 0.0) : 1.0;
}

} // namespace coredem::dem::kernels
