#pragma once
/// @file
/// What the engine's chemistry module needs besides the particles (plain data, filled by
/// DemSystem from ChemistryOptions with every species name resolved to an index).

#include <vector>

#include "coredem/dem/kernels/clg_char_gasification.h"
#include "coredem/dem/kernels/clg_oc_reduction.h"
#include "coredem/dem/kernels/reaction_enthalpy.h"
#include "coredem/dem/kernels/reaction_generic.h"
#include "coredem/dem/kernels/wgs.h"

namespace coredem::dem {

/// Local-array bounds of the per-particle chemistry kernel (checked by DemSystem).
inline constexpr int kChemMaxSolids = 8;
inline constexpr int kChemMaxGas = 16;

/// Scalars passed by value into the kernels.
struct ChemParams {
  int nGas = 0;
  int nSolid = 0;
  int nReactions = 0;
  bool charOn = false;
  bool ocOn = false;
  bool wgsOn = false;
  bool reactionHeat = true;
  int gasIndex[kernels::kGasSpeciesCount] = {-1, -1, -1, -1,
                                             -1};    ///< case gas index of CO, CO2, H2, H2O, N2
  int solidC = -1, solidFe2O3 = -1, solidFe3O4 = -1; ///< case solid indices
  double removalFraction = 0.1;
  double pressure = 101325.0; ///< Pa
  kernels::CharGasificationParams charParams{};
  kernels::OcReductionParams ocParams{};
  kernels::WgsParams wgsParams{};
};

struct ChemistrySetup {
  bool enabled = false;
  ChemParams params;
  std::vector<kernels::HeterogeneousReaction> reactions;
  std::vector<kernels::Stoichiometry> reactionNasa7; ///< per reaction; n = 0: constant dH
  std::vector<double> gasMolarMass;                  ///< kg/mol per case gas species
  std::vector<double> materialCp;                    ///< J/kg/K per material
};

} // namespace coredem::dem
