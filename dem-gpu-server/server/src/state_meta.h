#pragma once
// The server's own part of a DEM state file: /server group with the step, the session and the
// cumulative ledgers, so that a restart continues the balances (the DEM core writes the rest).
#include <cstdint>
#include <string>
#include <vector>

#include "coredem/dem/dem_system.h"

namespace coredem::server {

/// The heat from the gas, ∫ Σ V_c (H T_g − H_Tp) dt, is the DEM core's HeatTotals::convection
/// (/meta heat_convection_J); files of earlier versions also hold /server heat_from_gas_J, which
/// is not read.
struct ServerLedgers {
  std::vector<double> speciesToGas; ///< kg per gas species, ∫ Σ V_c R_k dt
};

/// The staggered coupling scheme's state (docs/coupling-schemes.md): the sources computed in the
/// last step and not yet applied by the gas, and the two sides of its lag ledgers. Kept in
/// /server/staggered so that a resumed staggered run continues bitwise.
struct StaggeredState {
  bool hasPending = false;
  dem::CellSources pending; ///< computed in the last step, sent with the next GasFields
  /// Δt_CFD of the step that computed `pending` (0: evaluated without advancing, S^0): the
  /// amount rates R_species and Q_hom are rescaled to the Δt of the step that applies them.
  double pendingDt = 0.0;
  /// kg per gas species, ∫ Σ V_c R_k dt of the windows the DEM computed (at their own Δt); the
  /// applied side is ServerLedgers::speciesToGas.
  std::vector<double> speciesComputed;
  /// J, Σ (H_Tp − H T_g) V_c Δt of the sources sent to the gas, with the T_g and Δt of the step
  /// that applies them (the gas side of the heat transfer as the DEM handed it over).
  double heatApplied = 0.0;
};

/// Adds /server (attributes step, session; dataset species_to_gas_kg) to an existing HDF5 file.
/// Throws UserError on failure.
void writeServerLedgers(const std::string& path, const ServerLedgers& l, std::int64_t step,
                        const std::string& session);
/// Reads /server if present (else zero ledgers of `species` entries).
ServerLedgers readServerLedgers(const std::string& path, int species);

/// Adds /server/staggered (after writeServerLedgers) to an existing HDF5 file.
void writeStaggeredState(const std::string& path, const StaggeredState& s);
/// Reads /server/staggered if present (else hasPending false and zero ledgers); checks the sizes
/// against the configured cell and species counts.
StaggeredState readStaggeredState(const std::string& path, std::uint64_t cells, int species);

} // namespace coredem::server
