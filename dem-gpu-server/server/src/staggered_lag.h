#pragma once
// The staggered coupling scheme's lag (Configure option coupling_scheme = staggered,
// docs/coupling-schemes.md): the GasFields of step n are answered at once with the sources
// computed in step n-1, booked as applied with step n's T_g and Δt; the sources step n computes
// wait for step n+1. The two sides of the lag's ledgers (computed and applied) make the
// in-flight entries of the ledger; the state goes into checkpoints (/server/staggered).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "coredem/dem/dem_system.h"
#include "coredem/protocol/protocol.h"
#include "state_meta.h"

namespace coredem::server {

class StaggeredLag {
public:
  /// Whether the session runs the staggered scheme.
  bool enabled() const { return _enabled; }
  /// The state written to and read from checkpoints.
  const StaggeredState& state() const { return _state; }
  /// Sources of an earlier step are waiting to be sent.
  bool hasPending() const { return _state.hasPending; }

  /// A new session: staggered or not, with the state read from its restart file.
  void start(bool enabled, StaggeredState restored) {
    _enabled = enabled;
    _state = std::move(restored);
  }
  /// The session ended.
  void reset() {
    _enabled = false;
    _state = StaggeredState();
  }

  /// S^0, the first step's sources when none are pending: the rates of the current state,
  /// evaluated without advancing (sub-step `dtSub`) and applied as they are. Throws what the DEM
  /// core throws.
  void evaluateInitial(dem::DemSystem& system, double dtSub);
  /// The pending sources as the gas applies them in a step of `dt` with temperatures `Tg`: the
  /// amounts R_species, Q_hom, Q_rad and mom_p rescaled from the Δt that computed them, booked as
  /// applied (heat, and the species into `speciesToGas`). Sent, then markSent().
  const dem::CellSources& apply(double dt, std::span<const double> Tg, std::size_t cells,
                                std::uint32_t species, double cellVolume,
                                std::vector<double>& speciesToGas);
  /// The pending sources went to the gas (this step computes the next ones).
  void markSent() { _state.hasPending = false; }
  /// The sources a step of `dt` computed, pending until the next GasFields.
  void keep(const dem::CellSources& s, double dt);
  /// kg per gas species the DEM computed (booked when computed; the applied side is the
  /// ServerLedgers).
  std::vector<double>& speciesComputed() { return _state.speciesComputed; }

  /// The lag in the ledger (docs/coupling-schemes.md "Ledgers"): what the particles exchanged
  /// minus what the gas has been handed (`heatConvection`: the DEM core's HeatTotals::convection).
  void addInFlight(v1::Ledger& l, double heatConvection, const std::vector<std::string>& species,
                   const std::vector<double>& speciesToGas) const;

private:
  bool _enabled = false;
  StaggeredState _state;
};

} // namespace coredem::server
