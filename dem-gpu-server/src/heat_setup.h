#pragma once
/// @file
/// What the engine's heat module needs besides the particles (plain data, filled by DemSystem).

#include <vector>

#include "coredem/dem/heat_options.h"
#include "coredem/dem/kernels/conduction_gas_lens.h"
#include "coredem/dem/kernels/convection.h"
#include "coredem/dem/kernels/wall_conduction.h"
#include "coredem/dem/kernels/wall_contact.h"

namespace coredem::dem {

/// Thermal properties of one material (index = material index).
struct HeatMaterial {
  double cp;         ///< J/(kg K), > 0
  double k;          ///< W/(m K), ≥ 0
  double emissivity; ///< −
};

/// The walls' thermal condition (kernels/wall_conduction.h): every wall of the run (analytic
/// and mesh, wall_lists.h) held at one temperature; adiabatic walls: not enabled.
struct ThermalWalls {
  bool enabled = false;
  double temperature = 0.0; ///< K, > 0
  double k = 0.0;           ///< wall material conductivity, W/(m K)
};

struct HeatSetup {
  /// The `models:` heat switches as configured: the one source of the terms' switches (the heat
  /// module derives what it evaluates from them and from the run: HeatTerms). An EngineSetup
  /// built in code has heat off until it sets them.
  HeatOptions options{.enabled = false};
  kernels::ConvectionParams convectionParams{};
  kernels::GasLensParams lensParams{};
  std::vector<HeatMaterial> materials;
  ThermalWalls walls;                         ///< fixed-temperature walls (or adiabatic)
  kernels::WallConductionParams wallParams{}; ///< contact / lens switches, FLPC, s_min
};

/// The terms a run evaluates: the switches of HeatSetup::options combined with what the run has
/// (a coupling grid, emissive materials). Derived, never stored beside the options.
struct HeatTerms {
  bool enabled = false;           ///< master switch; false: the heat module does nothing
  bool convection = false;        ///< Eqs. 19–21 (needs coupling and T_g, κ_g, c_p,g)
  bool contactConduction = false; ///< Eqs. 22–23
  bool lensConduction = false;    ///< Eqs. 24–26 (needs coupling and κ_g)
  bool radiation = false;         ///< Eqs. 27–28 (a) (needs coupling and T_g)

  static HeatTerms of(const HeatSetup& h, bool coupled) {
    bool anyEmissive = false;
    for (const HeatMaterial& m : h.materials)
      anyEmissive = anyEmissive || m.emissivity > 0;
    const HeatOptions& o = h.options;
    return HeatTerms{o.enabled, o.convection, o.contactConduction, o.lensConduction && coupled,
                     o.radiation && anyEmissive};
  }
};

} // namespace coredem::dem
