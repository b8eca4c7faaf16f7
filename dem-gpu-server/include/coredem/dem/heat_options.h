#pragma once
/// @file
/// Model switches of the particle heat transfer integrated in the DEM step (docs/heat-coupling.md).
/// Plain data; set from `Configure.options` (case.yaml `models:`) through the model registry
/// (coredem/dem/models.h, applyModelOption).

#include "coredem/dem/kernels/convection.h"

namespace coredem::dem {

/// Which heat-transfer terms the DEM step evaluates (Eq. 18). The material properties
/// (c_p, k_p, emissivity) are in `Material`; the gas properties come per cell with the gas fields.
struct HeatOptions {
  bool enabled = true;    ///< `heat: on|off` — off: temperatures stay constant, H = H_Tp = 0
  bool convection = true; ///< particle–gas convection (Eqs. 19–21); needs T_g, κ_g, c_p,g
  kernels::NusseltModel nusselt =
      kernels::NusseltModel::LiMason; ///< `convection: li-mason|ranz-marshall`
  bool reynoldsWithVoidage = true;    ///< `convection_reynolds: with-voidage|without-voidage`
  double voidageExponent = 3.5;       ///< `nusselt_exponent`: n of ε^n in Li–Mason (Eq. 21)
  bool contactConduction = true;      ///< `contact_conduction: on|off` (Eqs. 22–23)
  bool lensConduction = true;         ///< `lens_conduction: on|off` (Eqs. 24–26); needs κ_g
  double lensFraction = 0.2;          ///< `flpc`: lens radius (1 + FLPC) R_L
  double minSeparation = 1.0e-6;      ///< `s_min` (m): minimum conduction distance in the lens
  double lensRelTol = 1.0e-8;         ///< `lens_rel_tol`: quadrature tolerance of the lens integral
  bool radiation = true; ///< `radiation: on|off`; only particles with emissivity > 0 radiate
  bool wallConduction =
      true; ///< `wall_conduction: on|off`: contact conduction to fixed-temperature walls
  bool wallLensConduction =
      true; ///< `wall_lens_conduction: on|off`: gas-lens conduction to them (needs κ_g)
};

/// Heat the particles received since the system was built (or restarted from a state file
/// written by it), J. Conduction between particles moves heat between particles only and is
/// not listed; conduction from fixed-temperature walls is (`wall`).
struct HeatTotals {
  double convection = 0.0; ///< from the gas (Σ_c (H T_g − H_Tp) V_c Δt), the gas loses the same
  double radiation = 0.0;  ///< from the radiative environment (Eq. 27)
  double wall = 0.0;       ///< from fixed-temperature walls (kernels/wall_conduction.h)
};

/// One entry of the heat ledger as the DEM server reports it (StepDone ledger, energy, J).
struct HeatLedgerEntry {
  const char* name;          ///< ledger name, e.g. "dem.heat_from_gas_J"
  double HeatTotals::*value; ///< the total it reports
};

/// The heat ledger in report order: a new HeatTotals field is reported by adding its row here.
inline constexpr HeatLedgerEntry kHeatLedger[] = {
    {"dem.heat_from_gas_J", &HeatTotals::convection},
    {"dem.heat_radiation_J", &HeatTotals::radiation},
    {"dem.heat_wall_J", &HeatTotals::wall},
};

} // namespace coredem::dem
