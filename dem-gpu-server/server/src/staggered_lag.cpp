#include "staggered_lag.h"

namespace coredem::server {

namespace proto = coredem::protocol;

void StaggeredLag::evaluateInitial(dem::DemSystem& system, double dtSub) {
  _state.pending = system.evaluateSources(dtSub);
  _state.pendingDt = 0.0; // S^0: rates of the initial state, applied as they are
  _state.hasPending = true;
}

const dem::CellSources& StaggeredLag::apply(double dt, std::span<const double> Tg,
                                            std::size_t cells, std::uint32_t species,
                                            double cellVolume, std::vector<double>& speciesToGas) {
  dem::CellSources& p = _state.pending;
  const std::size_t n = cells;
  // The released mass, its heat and its momentum (R_species, Q_hom, Q_rad, mom_p) are amounts
  // over the step that computed them: with a different Δt now (adaptive Δt_CFD) the rates are
  // rescaled so that the gas gets exactly what the particles released. The coefficients (ε_g, K_sl,
  // K_sl U_s, H, H T_p) describe the particles and are sent as they are.
  if (_state.pendingDt > 0.0 && _state.pendingDt != dt) {
    const double scale = _state.pendingDt / dt;
    for (double& v : p.rSpecies) {
      v *= scale;
    }
    for (double& v : p.qHom) {
      v *= scale;
    }
    for (double& v : p.qRad) {
      v *= scale;
    }
    for (double& v : p.momP) {
      v *= scale;
    }
  }
  double heat = 0.0;
  for (std::size_t c = 0; c < n; ++c) {
    heat += p.heatHTp[c] - p.heatH[c] * Tg[c];
  }
  _state.heatApplied += heat * cellVolume * dt;
  for (std::size_t k = 0; k < species; ++k) {
    double sum = 0.0;
    for (std::size_t c = 0; c < n; ++c) {
      sum += p.rSpecies[c * species + k];
    }
    speciesToGas[k] += sum * cellVolume * dt;
  }
  return p;
}

void StaggeredLag::keep(const dem::CellSources& s, double dt) {
  _state.pending = s;
  _state.pendingDt = dt;
  _state.hasPending = true;
}

void StaggeredLag::addInFlight(v1::Ledger& l, double heatConvection,
                               const std::vector<std::string>& species,
                               const std::vector<double>& speciesToGas) const {
  // The pending step's transfer minus the first step's initial one.
  proto::addNamedValue(l.mutable_energy(), "dem.heat_in_flight_J",
                       heatConvection + _state.heatApplied);
  for (std::size_t k = 0; k < species.size(); ++k) {
    proto::addNamedValue(l.mutable_species(), "dem.species_in_flight." + species[k] + "_kg",
                         _state.speciesComputed[k] - speciesToGas[k]);
  }
}

} // namespace coredem::server
