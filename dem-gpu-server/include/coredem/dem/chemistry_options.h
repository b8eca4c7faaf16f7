#pragma once
/// @file
/// Chemistry integrated in the DEM step (docs/physics.md §3.5, §4, §6, §8.5;
/// docs/thermochemistry.md): data-defined heterogeneous reactions, the built-in CLG set (R1, R2
/// char gasification; R4, R5 oxygen-carrier reduction; R3 homogeneous water–gas shift per cell),
/// shrinking particles and their removal. Plain data; filled from `Configure.reactions` /
/// `Configure.chemistry` (case.yaml `reactions:` / `chemistry:`) by the server. Species are named
/// by the gas and solid species lists of DemConfig.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "coredem/dem/kernels/clg_char_gasification.h"
#include "coredem/dem/kernels/clg_oc_reduction.h"
#include "coredem/dem/kernels/reaction_generic.h"
#include "coredem/dem/kernels/wgs.h"

namespace coredem::dem {

/// One term of a reaction: a gas or solid species (looked up by name in DemConfig::gasSpecies,
/// then DemConfig::solidSpecies) and its signed coefficient (< 0: reactant), mol per mol of
/// reaction.
struct ReactionTermConfig {
  std::string species;
  double nu = 0.0;
};

/// A heterogeneous reaction defined by data (kernels/reaction_generic.h). Rates are per particle.
struct ReactionConfig {
  std::string name;
  std::vector<ReactionTermConfig> terms; ///< at most kernels::kMaxReactionTerms
  kernels::RateLaw law = kernels::RateLaw::Constant;
  double A = 0.0;              ///< constant: mol/s; arrhenius: mol/s K^-β (m³/mol)^order
  double beta = 0.0;           ///< arrhenius temperature exponent
  double E = 0.0;              ///< arrhenius activation energy, J/mol
  std::string orderSpecies;    ///< gas species whose concentration enters the rate (empty: none)
  double order = 0.0;          ///< its order
  double heatOfReaction = 0.0; ///< J per mol of reaction (> 0 endothermic), when !heatFromNasa7
  bool heatFromNasa7 = false;  ///< ΔH_r(T_p) from NASA-7 data (every species must have data)
};

/// The built-in coal-fuelled chemical-looping set (docs/physics.md §6).
struct ClgOptions {
  bool charGasification = false; ///< R1 + R2: solid C; gas CO, CO2, H2, H2O
  bool ocReduction = false;      ///< R4 + R5: solid Fe2O3, Fe3O4; gas CO, CO2, H2, H2O
  bool wgs = false;              ///< R3 per cell, returned as R_species and Q_hom
  kernels::CharGasificationParams charParams{};
  kernels::OcReductionParams ocParams{};
  kernels::WgsParams wgsParams{}; ///< equilibrium choice and k_f
};

/// Chemistry switches. Chemistry is active when reactions are given or a CLG model is on.
struct ChemistryOptions {
  std::vector<ReactionConfig> reactions;
  ClgOptions clg;
  double removalFraction = 0.1; ///< particles with d < removalFraction · d_0 are removed, in (0, 1)
  bool reactionHeat = true;     ///< Q_rxn = −Σ ΔH_r(T_p) ṅ_r into the particle energy (§3.5)
  double pressure = 101325.0;   ///< Pa, gas pressure for partial pressures (constant gas property)

  bool active() const {
    return !reactions.empty() || clg.charGasification || clg.ocReduction || clg.wgs;
  }
};

/// Names of the CLG kinetic overrides (case.yaml chemistry.clg.<name>): char A_CO2, E_CO2, K_CO2,
/// dH_CO2, K_CO, dH_CO, A_H2O, E_H2O, K_H2O, dH_H2O, K_H2, dH_H2; oxygen carrier rho_m, r_grain,
/// k0_CO, E_CO, n_CO, k0_H2, E_H2, n_H2; WGS kf0, Ef_over_R. Units as in the kernel parameter
/// structs.
const std::vector<std::string>& clgKineticNames();
/// Sets one override; UserError naming the allowed names when `name` is unknown or the value not
/// finite.
void setClgKinetic(ClgOptions& clg, const std::string& name, double value);

/// Chemistry ledgers since construction (kept across writeState/readState).
struct ChemistryTotals {
  std::vector<double> gasProduced; ///< kg per gas species released by particles (< 0: taken up),
                                   ///< DemConfig::gasSpecies order
  std::vector<double> solidChange; ///< kg per solid species gained by particles (< 0: consumed),
                                   ///< DemConfig::solidSpecies order
  std::vector<double>
      removedSolid; ///< kg per solid species in particles removed below the size threshold
  double reactionHeat =
      0.0; ///< J of Q_rxn into the particles (heterogeneous; 0 when reactionHeat off)
  double homogeneousHeat = 0.0; ///< J of Q_hom (WGS) into the gas
  /// J into the gas inside Q_hom: sensible heat of the gas the particles release, Σ ṁ_gas c_p,g
  /// (T_p − T_g) Δt
  double gasSensibleHeat = 0.0;
  /// J: Σ Δm_i c_p,i T_p,i, the change of the particles' Σ m c_p T by mass leaving (< 0) or joining
  /// them at T_p; Δ Σ m c_p T = Q_gas + Q_rad + Q_wall + reactionHeat + this (+ removed particles)
  double sensibleMassEnthalpy = 0.0;
  std::vector<double> homogeneousSource; ///< kg per gas species produced by WGS (sums to ~0)
  /// N s: Σ ṁ_gas,i u_i Δt, the momentum the gas the particles released carried away (their
  /// velocity; negative ṁ: gas taken up), all particles (also outside the coupling grid)
  std::array<double, 3> releasedMomentum{0.0, 0.0, 0.0};
  std::uint64_t removedCount = 0; ///< particles removed
  double removedMass() const {
    double s = 0.0;
    for (double v : removedSolid)
      s += v;
    return s;
  }
};

} // namespace coredem::dem
