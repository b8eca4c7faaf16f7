#pragma once
/// @file
/// Model switches of the particle heat transfer integrated in the DEM step (docs/heat-coupling.md).
/// Plain data; set from `Configure.options` (case.yaml `models:`) through the model registry
/// (coredem/dem/models.h, applyModelOption).

#include <cstdio>
#include <string>

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
  /// Each Nusselt correlation's parameters, `convection.<model>.<key>` (hashed with the other
  /// models' parameters: models.h modelParamsHashText).
  kernels::ParamPack<kernels::NusseltModels> nusseltModels{};
};

/// Heat the particles received since the system was built (or restarted from a state file
/// written by it), J. Conduction between particles moves heat between particles only and is
/// not listed; conduction from fixed-temperature walls is (`wall`).
struct HeatTotals {
  /// From the gas: Σ_c (H T_g − H_Tp) V_c Δt (the gas loses the same) plus the heat split the gas
  /// sent (protocol 1.5 Q_split, GasFieldsView::heatToParticles) given to the particles
  double convection = 0.0;
  double radiation = 0.0; ///< from the radiative environment (Eq. 27)
  double wall = 0.0;      ///< from fixed-temperature walls (kernels/wall_conduction.h)
  /// Heat split the gas sent for coupling cells without particles: given to nobody (the gas
  /// removed it), booked here so that the ledgers close
  double splitUnassigned = 0.0;
};

/// One entry of the heat ledger: how the DEM server reports it (StepDone ledger, energy, J) and
/// how the state file keeps it (/meta attribute, 0 when a file predates it).
struct HeatLedgerEntry {
  const char* name;           ///< ledger name, e.g. "dem.heat_from_gas_J"
  double HeatTotals::*value;  ///< the total it reports
  const char* stateAttribute; ///< /meta attribute of the DEM state file
};

/// The heat ledger in report order: a new HeatTotals field is reported, checkpointed and restored
/// by adding its row here.
inline constexpr HeatLedgerEntry kHeatLedger[] = {
    {"dem.heat_from_gas_J", &HeatTotals::convection, "heat_convection_J"},
    {"dem.heat_radiation_J", &HeatTotals::radiation, "heat_radiation_J"},
    {"dem.heat_wall_J", &HeatTotals::wall, "heat_wall_J"},
    {"dem.heat_split_unassigned_J", &HeatTotals::splitUnassigned, "heat_split_unassigned_J"},
};

/// The heat options' part of the configuration hash (a restart with other options is refused),
/// appended to `text` as "%.17g;" values. A new option appends its value only when it differs
/// from its default, so that the hashes of earlier configurations stay the same.
inline void appendHeatHashText(const HeatOptions& h, double wallTemperature, int wallMaterial,
                               std::string& text) {
  auto num = [&](double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g;", v);
    text += b;
  };
  text += "|heat:";
  for (double v :
       {double(h.convection), double(static_cast<int>(h.nusselt)), double(h.reynoldsWithVoidage),
        h.voidageExponent, double(h.contactConduction), double(h.lensConduction), h.lensFraction,
        h.minSeparation, h.lensRelTol, double(h.radiation)})
    num(v);
  if (wallTemperature > 0.0) { // absent for adiabatic walls: earlier hashes unchanged
    text += "|wallT:";
    for (double v : {wallTemperature, double(wallMaterial), double(h.wallConduction),
                     double(h.wallLensConduction)})
      num(v);
  }
}

} // namespace coredem::dem
