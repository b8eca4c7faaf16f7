#pragma once
/// @file
/// Oxygen-carrier reduction R4 (3 Fe2O3 + CO → 2 Fe3O4 + CO2) and R5 (3 Fe2O3 + H2 →
/// 2 Fe3O4 + H2O) (docs/physics.md §6.3; grain / shrinking-core model, reaction control, Abad et
/// al. 2007 form).
///
///   m_eq = m (X_Fe2O3 + X_Fe3O4 · 3 M_Fe2O3/(2 M_Fe3O4))    Fe2O3-equivalent mass (conserved)
///   ξ    = 1 − m X_Fe2O3 / m_eq                               conversion
///   dξ/dt|_j = k_j (1 − ξ)^(2/3),  k_j = 3 b k_s,j C_j^n_j / (ρ_m r_g),
///   k_s,j = k0_j exp(−E_j/(R T_p)),  b = 3 mol Fe2O3 per mol CO or H2
///   ṅ_R4 = (m_eq/(3 M_Fe2O3)) k_CO (1 − ξ)^(2/3)  (mol CO/s);  ṅ_R5 likewise with k_H2
///   solids: ṁ_Fe2O3 = −3 M_Fe2O3 (ṅ_R4 + ṅ_R5),  ṁ_Fe3O4 = 2 M_Fe3O4 (ṅ_R4 + ṅ_R5)
///   gas:    ṁ_CO = −M_CO ṅ_R4, ṁ_CO2 = M_CO2 ṅ_R4, ṁ_H2 = −M_H2 ṅ_R5, ṁ_H2O = M_H2O ṅ_R5
///   heat into the particle: Q = −ΔH_R4(T_p) ṅ_R4 − ΔH_R5(T_p) ṅ_R5
///
/// The seed's prefactor R0/(2 M_O2) is replaced by the mass-balance form above (docs/physics.md
/// §0.3). Defaults: ρ_m = 32811 mol/m³, r_g = 2.6e-7 m (IDAES, citing Abad 2007); CO: k0 = 1e-4
/// m/s, E = 20 kJ/mol, n = 1; H2: k0 = 9e-4 mol^(1−n) m^(3n−2)/s, E = 24 kJ/mol, n = 0.8 ([K], to
/// verify).

#include <cmath>

#include <coredem/dem/kernels/common.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/reaction_enthalpy.h>

namespace coredem::dem::kernels {

struct OcReductionParams {
  double rhoMolar = 32811.0;   ///< ρ_m, mol Fe2O3 per m³
  double grainRadius = 2.6e-7; ///< r_g, m
  double b = 3.0;              ///< mol Fe2O3 per mol reducing gas
  double k0CO = 1.0e-4;        ///< m/s (n = 1)
  double eCO = 20.0e3;         ///< J/mol
  double nCO = 1.0;            ///< −
  double k0H2 = 9.0e-4;        ///< mol^(1−n) m^(3n−2) s⁻¹
  double eH2 = 24.0e3;         ///< J/mol
  double nH2 = 0.8;            ///< −
};

/// Solid species order of an oxygen-carrier particle.
enum class OcSolid : int { Fe2O3 = 0, Fe3O4 = 1, Al2O3 = 2, Count = 3 };
DEM_HD constexpr int idx(OcSolid s) {
  return static_cast<int>(s);
}

struct OcReductionRates {
  double nR4;                       ///< mol/s
  double nR5;                       ///< mol/s
  double conversion;                ///< ξ, −
  double mdotSolid[3];              ///< kg/s, OcSolid order (Al2O3 inert: 0)
  double mdotGas[kGasSpeciesCount]; ///< kg/s, GasSpecies order
  double heat;                      ///< W into the particle
};

/// dξ/dt coefficient k_j = 3 b k0 exp(−E/(R T)) Cⁿ/(ρ_m r_g), s⁻¹. conc in mol/m³.
DEM_HD double ocRateCoefficient(const OcReductionParams& p, double k0, double e, double n,
                                double tP, double conc) {
  if (!(conc > 0.0)) {
    return 0.0;
  }
  const double ks = k0 * std::exp(-e / (kGasConstant * tP));
  return 3.0 * p.b * ks * std::pow(conc, n) / (p.rhoMolar * p.grainRadius);
}

/// Rates of one OC particle: mass m (kg), mass fractions in OcSolid order, T_p (K), and cell
/// concentrations C_CO, C_H2 (mol/m³).
DEM_HD OcReductionRates ocReduction(const OcReductionParams& p, double tP, double m,
                                    const double* massFraction, double cCO, double cH2) {
  OcReductionRates out{};
  const double mFe2O3 = molarMass(Species::Fe2O3);
  const double mFe3O4 = molarMass(Species::Fe3O4);
  const double mHem = m * massFraction[idx(OcSolid::Fe2O3)];
  const double mEq = mHem + m * massFraction[idx(OcSolid::Fe3O4)] * (3.0 * mFe2O3 / (2.0 * mFe3O4));
  if (!(mEq > 0.0) || !(mHem > 0.0)) {
    out.conversion = mEq > 0.0 ? 1.0 : 0.0;
    return out;
  }
  const double unreacted = mHem / mEq; // 1 − ξ
  out.conversion = 1.0 - unreacted;
  const double core = std::cbrt(unreacted * unreacted);
  const double molScale = mEq / (3.0 * mFe2O3);
  out.nR4 = molScale * ocRateCoefficient(p, p.k0CO, p.eCO, p.nCO, tP, cCO) * core;
  out.nR5 = molScale * ocRateCoefficient(p, p.k0H2, p.eH2, p.nH2, tP, cH2) * core;
  const double nTot = out.nR4 + out.nR5;
  out.mdotSolid[idx(OcSolid::Fe2O3)] = -3.0 * mFe2O3 * nTot;
  out.mdotSolid[idx(OcSolid::Fe3O4)] = 2.0 * mFe3O4 * nTot;
  out.mdotSolid[idx(OcSolid::Al2O3)] = 0.0;
  out.mdotGas[idx(GasSpecies::CO)] = -molarMass(Species::CO) * out.nR4;
  out.mdotGas[idx(GasSpecies::CO2)] = molarMass(Species::CO2) * out.nR4;
  out.mdotGas[idx(GasSpecies::H2)] = -molarMass(Species::H2) * out.nR5;
  out.mdotGas[idx(GasSpecies::H2O)] = molarMass(Species::H2O) * out.nR5;
  out.heat = -reactionEnthalpy(ClgReaction::R4, tP) * out.nR4 -
             reactionEnthalpy(ClgReaction::R5, tP) * out.nR5;
  return out;
}

/// ocRateCoefficient() with 1/(R T) given: k0 exp(−E/(RT)) Cⁿ as one exp() (Cⁿ folded in as
/// n ln C, no pow(); n = 1: a multiplication).
DEM_HD double ocRateCoefficientHoisted(const OcReductionParams& p, double k0, double e, double n,
                                       double invRT, double conc) {
  if (!(conc > 0.0)) {
    return 0.0;
  }
  const double ksCn =
      n == 1.0 ? k0 * std::exp(-e * invRT) * conc : k0 * std::exp(n * std::log(conc) - e * invRT);
  return 3.0 * p.b * ksCn / (p.rhoMolar * p.grainRadius);
}

/// ocReduction() for the engine's per-particle loop, same equations: nothing for a particle
/// without Fe2O3 or a cell without CO and H2, 1/(R T_p) once, no pow(), and the heats from the
/// combined ΔH_r polynomials dh[0] (R4) and dh[1] (R5) (combineReactionEnthalpy; dh = nullptr:
/// heat 0). Equals ocReduction() to round-off (tested to 1e-12).
DEM_HD OcReductionRates ocReductionHoisted(const OcReductionParams& p,
                                           const ReactionEnthalpyPoly* dh, double tP, double m,
                                           const double* massFraction, double cCO, double cH2) {
  OcReductionRates out{};
  const double mFe2O3 = molarMass(Species::Fe2O3);
  const double mFe3O4 = molarMass(Species::Fe3O4);
  const double mHem = m * massFraction[idx(OcSolid::Fe2O3)];
  const double mEq = mHem + m * massFraction[idx(OcSolid::Fe3O4)] * (3.0 * mFe2O3 / (2.0 * mFe3O4));
  if (!(mEq > 0.0) || !(mHem > 0.0)) {
    out.conversion = mEq > 0.0 ? 1.0 : 0.0;
    return out;
  }
  const double unreacted = mHem / mEq; // 1 − ξ
  out.conversion = 1.0 - unreacted;
  if (!(cCO > 0.0) && !(cH2 > 0.0)) {
    return out;
  }
  const double invRT = 1.0 / (kGasConstant * tP);
  const double scale = mEq / (3.0 * mFe2O3) * std::cbrt(unreacted * unreacted);
  out.nR4 = scale * ocRateCoefficientHoisted(p, p.k0CO, p.eCO, p.nCO, invRT, cCO);
  out.nR5 = scale * ocRateCoefficientHoisted(p, p.k0H2, p.eH2, p.nH2, invRT, cH2);
  const double nTot = out.nR4 + out.nR5;
  out.mdotSolid[idx(OcSolid::Fe2O3)] = -3.0 * mFe2O3 * nTot;
  out.mdotSolid[idx(OcSolid::Fe3O4)] = 2.0 * mFe3O4 * nTot;
  out.mdotSolid[idx(OcSolid::Al2O3)] = 0.0;
  out.mdotGas[idx(GasSpecies::CO)] = -molarMass(Species::CO) * out.nR4;
  out.mdotGas[idx(GasSpecies::CO2)] = molarMass(Species::CO2) * out.nR4;
  out.mdotGas[idx(GasSpecies::H2)] = -molarMass(Species::H2) * out.nR5;
  out.mdotGas[idx(GasSpecies::H2O)] = molarMass(Species::H2O) * out.nR5;
  if (dh != nullptr) {
    out.heat = -reactionEnthalpy(dh[0], tP) * out.nR4 - reactionEnthalpy(dh[1], tP) * out.nR5;
  }
  return out;
}

/// Scale factor s ∈ [0, 1] so that a step dt does not consume more Fe2O3 than present.
DEM_HD double ocStepLimiter(const OcReductionRates& r, double m, const double* massFraction,
                            double dt) {
  const double loss = -r.mdotSolid[idx(OcSolid::Fe2O3)] * dt;
  const double avail = m * massFraction[idx(OcSolid::Fe2O3)];
  return loss > avail && loss > 0.0 ? avail / loss : 1.0;
}

} // namespace coredem::dem::kernels
