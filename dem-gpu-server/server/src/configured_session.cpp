#include "configured_session.h"

#include <algorithm>
#include <filesystem>

#include <malloc.h>

#include "coredem/common/files.h"
#include "coredem/dem/bed_height.h"
#include "reply_text.h"

namespace coredem::server {

namespace proto = coredem::protocol;
namespace fs = std::filesystem;

void ConfiguredSession::start(std::unique_ptr<dem::DemSystem> built, ServerLedgers restored,
                              bool staggered, StaggeredState restoredLag, const v1::Configure& c) {
  system = std::move(built);
  ledgers = std::move(restored);
  lag.start(staggered, std::move(restoredLag));
  lastLedger.Clear();
  if (ledgers.speciesToGas.size() != static_cast<std::size_t>(c.species_size())) {
    ledgers.speciesToGas.assign(static_cast<std::size_t>(c.species_size()), 0.0);
  }
  grid.cells = proto::cellCount(c.coupling_mesh());
  grid.species = static_cast<std::uint32_t>(c.species_size());
  speciesNames.clear();
  for (const auto& s : c.species()) {
    speciesNames.push_back(s.name());
  }
  const auto& g = c.coupling_mesh().cartesian();
  cellVolume = g.spacing().x() * g.spacing().y() * g.spacing().z();
  lastStep = c.start_step();
}

void ConfiguredSession::end() {
  system.reset();
  ::malloc_trim(0); // the session's particles and grids go back to the system
  ledgers = ServerLedgers();
  lag.reset();
  lastLedger.Clear();
  stepsDone = 0;
}

v1::Ledger ConfiguredSession::ledger(const dem::ParticleData& p) const {
  v1::Ledger l;
  double mass = 0.0, kinetic = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) {
    const double m = p.mass[i];
    mass += m;
    const double inertia = 0.4 * m * p.radius[i] * p.radius[i];
    for (int a = 0; a < 3; ++a) {
      kinetic += 0.5 * m * p.velocity[3 * i + a] * p.velocity[3 * i + a] +
                 0.5 * inertia * p.angularVelocity[3 * i + a] * p.angularVelocity[3 * i + a];
    }
  }
  proto::addNamedValue(l.mutable_mass(), "dem.particle_mass_kg", mass);
  proto::addNamedValue(l.mutable_energy(), "dem.kinetic_energy_J", kinetic);
  // Particle heat balance (docs/heat-coupling.md): Δ thermal energy = heat from gas + radiation
  // + walls, all from the DEM core's heat ledger (kept across restarts in the state file).
  const dem::HeatTotals heat = system->heatTotals();
  for (const dem::HeatLedgerEntry& e : dem::kHeatLedger) {
    proto::addNamedValue(l.mutable_energy(), e.name, heat.*e.value);
  }
  proto::addNamedValue(l.mutable_energy(), "dem.thermal_energy_J", system->thermalEnergy());
  for (std::size_t k = 0; k < speciesNames.size(); ++k) {
    proto::addNamedValue(l.mutable_species(), "dem.species_to_gas." + speciesNames[k] + "_kg",
                         ledgers.speciesToGas[k]);
  }
  if (lag.enabled()) {
    lag.addInFlight(l, heat.convection, speciesNames, ledgers.speciesToGas);
  }
  // Chemistry ledgers (docs/thermochemistry.md): solid converted to gas by the particles'
  // reactions per gas species, reaction heat into the particles, WGS heat into the gas, removed
  // particles.
  if (system->config().chemistry.active()) {
    const dem::ChemistryTotals c = system->chemistryTotals();
    for (std::size_t k = 0; k < speciesNames.size() && k < c.gasProduced.size(); ++k) {
      proto::addNamedValue(l.mutable_species(), "dem.solid_to_gas." + speciesNames[k] + "_kg",
                           c.gasProduced[k]);
    }
    proto::addNamedValue(l.mutable_mass(), "dem.removed_mass_kg", c.removedMass());
    proto::addNamedValue(l.mutable_energy(), "dem.reaction_heat_J", c.reactionHeat);
    proto::addNamedValue(l.mutable_energy(), "dem.homogeneous_heat_J", c.homogeneousHeat);
    // Sensible enthalpy of the transferred mass (docs/physics.md §3.5): into the gas inside
    // Q_hom, and the particles' Σ m c_p T change by mass leaving at T_p (closes the particle
    // energy ledger).
    proto::addNamedValue(l.mutable_energy(), "dem.gas_sensible_heat_J", c.gasSensibleHeat);
    proto::addNamedValue(l.mutable_energy(), "dem.sensible_mass_enthalpy_J",
                         c.sensibleMassEnthalpy);
  }
  return l;
}

void ConfiguredSession::addDiagnostics(v1::StepDone& done, const dem::ParticleData& p) const {
  double sum = 0.0, lo = p.count > 0 ? p.temperature[0] : 0.0, hi = lo;
  for (std::size_t i = 0; i < p.count; ++i) {
    sum += p.temperature[i];
    lo = std::min(lo, p.temperature[i]);
    hi = std::max(hi, p.temperature[i]);
  }
  auto* d = done.mutable_diagnostics();
  proto::addNamedValue(d, "particles", static_cast<double>(p.count));
  proto::addNamedValue(d, "contacts", static_cast<double>(system->contactCount()));
  proto::addNamedValue(d, "mean_T_p", p.count > 0 ? sum / static_cast<double>(p.count) : 0.0);
  proto::addNamedValue(d, "min_T_p", lo);
  proto::addNamedValue(d, "max_T_p", hi);
  proto::addNamedValue(d, "dem_time_s", system->time());
  proto::addNamedValue(d, "bed_height_m",
                       dem::bedHeight(p.position, p.radius, p.count, system->config().gravity));
  // The momentum the particles' released gas carried away (cumulative, N s; protocol 1.5 sends
  // it to the gas as mom_p): the gas's gas.momentum_released_*_Ns receives the same.
  if (system->config().chemistry.active()) {
    const dem::ChemistryTotals c = system->chemistryTotals();
    const char* names[3] = {"dem.momentum_released_x_Ns", "dem.momentum_released_y_Ns",
                            "dem.momentum_released_z_Ns"};
    for (int a = 0; a < 3; ++a) {
      proto::addNamedValue(d, names[a], c.releasedMomentum[a]);
    }
  }
}

std::vector<std::string> ConfiguredSession::writeCheckpoint(const std::string& dir,
                                                            std::int64_t step,
                                                            const std::string& session,
                                                            spdlog::logger& log) const {
  fs::create_directories(dir);
  const fs::path final = fs::path(dir) / "dem.h5";
  const fs::path tmp = fs::path(dir) / ".dem.h5.tmp";
  fs::remove(tmp);
  system->writeState(tmp.string(), proto::kProtocolVersion.toString());
  ServerLedgers l = ledgers;
  writeServerLedgers(tmp.string(), l, step, session);
  if (lag.enabled()) {
    writeStaggeredState(tmp.string(), lag.state());
  }
  syncFile(tmp);
  fs::rename(tmp, final);
  log.info("session {}: checkpoint of step {} written to {}", session, step,
           safe(final.string(), 200));
  return {"dem.h5"};
}

} // namespace coredem::server
