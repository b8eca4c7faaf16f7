#pragma once
// The server's own part of a DEM state file: /server group with the step, the session and the
// cumulative ledgers, so that a restart continues the balances (the DEM core writes the rest).
#include <cstdint>
#include <string>
#include <vector>

namespace coredem::server {

/// The heat from the gas, ∫ Σ V_c (H T_g − H_Tp) dt, is the DEM core's HeatTotals::convection
/// (/meta heat_convection_J); files of earlier versions also hold /server heat_from_gas_J, which
/// is not read.
struct ServerLedgers {
  std::vector<double> speciesToGas; ///< kg per gas species, ∫ Σ V_c R_k dt
};

/// Adds /server (attributes step, session; dataset species_to_gas_kg) to an existing HDF5 file.
/// Throws UserError on failure.
void writeServerLedgers(const std::string& path, const ServerLedgers& l, std::int64_t step,
                        const std::string& session);
/// Reads /server if present (else zero ledgers of `species` entries).
ServerLedgers readServerLedgers(const std::string& path, int species);

} // namespace coredem::server
