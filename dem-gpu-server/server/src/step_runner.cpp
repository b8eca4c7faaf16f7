#include "step_runner.h"

#include <cmath>

#include "coredem/protocol/coupling_scheme.h"
#include "coupling_fields.h"
#include "reply_text.h"

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;

std::optional<SessionEnd> StepRunner::run(const proto::Message& gasMessage,
                                          const std::vector<StepReply>& to) {
  const auto& env = gasMessage.envelope();
  const auto& body = env.gas_fields();
  const Grant& grant = *_assembly.grant(); // until the step is done or failed
  if (std::abs(body.dt() - grant.dtCfd) > kDtTolerance * grant.dtCfd) {
    _replies.refuseAll(to, v1::ERROR_CODE_OUT_OF_ORDER,
                       fmt::format("GasFields of step {} carry dt = {:.17g} s; the step was "
                                   "granted with dt = {:.17g} s",
                                   env.step(), body.dt(), grant.dtCfd));
    return std::nullopt;
  }
  const auto t0 = Clock::now();
  dem::GasFieldsView view;
  if (!setGas(gasMessage, to, view)) {
    return std::nullopt;
  }
  auto tGas = Clock::now();
  _xt.unpack += std::chrono::duration<double>(tGas - t0).count();
  const bool staggered = _s.lag.enabled();
  if (staggered) { // the lagged Sources leave before the step is computed (timed as pack_send)
    if (auto end = sendLaggedSources(to, gasMessage, view)) {
      return end;
    }
    const auto tSent = Clock::now();
    _xt.packSend += std::chrono::duration<double>(tSent - tGas).count();
    tGas = tSent;
  }
  std::optional<SessionEnd> end;
  const dem::CellSources* s = advance(to, end);
  if (s == nullptr) {
    return end;
  }
  const double dt = grant.dtCfd;
  const auto tAdvanced = Clock::now();
  _xt.advance += std::chrono::duration<double>(tAdvanced - tGas).count();
  _xt.particleSubSteps += static_cast<std::uint64_t>(_s.system->particleCount()) * grant.nSub;
  bookSpecies(*s, dt);
  if (staggered) {
    _s.lag.keep(*s, dt);
  }
  const auto particles = _s.system->particles();
  v1::Ledger ledger = _s.ledger(particles);
  const auto tLedgers = Clock::now();
  _xt.ledgers += std::chrono::duration<double>(tLedgers - tAdvanced).count();

  // Sources to C (sequential; staggered sent them before advancing): the whole grid, or each
  // rank's cells.
  if (!staggered) {
    _replies.sendSources(to, gasMessage, *s, ledger, grant.dtCfd, grant.nSub, _s.grid);
  }
  _s.lastLedger = ledger;
  _xt.packSend += std::chrono::duration<double>(Clock::now() - tLedgers).count();
  {
    auto ms = [](Clock::time_point a, Clock::time_point b) {
      return std::chrono::duration<double, std::milli>(b - a).count();
    };
    _log->debug("session {}: step {}: setGasFields {:.3f} ms, advance ({} sub-steps) {:.3f} ms, "
                "ledgers + Sources {:.3f} ms",
                _members.session(), env.step(), ms(t0, tGas), grant.nSub, ms(tGas, tAdvanced),
                ms(tAdvanced, Clock::now()));
  }
  finish(ledger, particles, t0);
  return std::nullopt;
}

bool StepRunner::setGas(const proto::Message& gasMessage, const std::vector<StepReply>& to,
                        dem::GasFieldsView& view) {
  view = gasFieldsView(gasMessage);
  try {
    _s.system->setGasFields(view);
  } catch (const coredem::UserError& e) {
    _replies.refuseAll(
        to, v1::ERROR_CODE_INVALID_CONFIGURATION,
        fmt::format("GasFields of step {}: {}", gasMessage.envelope().step(), e.what()));
    return false;
  }
  return true;
}

std::optional<SessionEnd> StepRunner::sendLaggedSources(const std::vector<StepReply>& to,
                                                        const proto::Message& gasMessage,
                                                        const dem::GasFieldsView& gas) {
  const Grant& grant = *_assembly.grant();
  const std::string& session = _members.session();
  if (!_s.lag.hasPending()) {
    try {
      _s.lag.evaluateInitial(*_s.system, grant.dtCfd / grant.nSub);
    } catch (const std::exception& e) {
      _log->error("session {}: step {}: the initial sources failed in the DEM core: {}", session,
                  grant.step, e.what());
      _replies.refuseAll(
          to, v1::ERROR_CODE_INTERNAL,
          fmt::format("step {}: evaluating the initial sources failed in the DEM core: {}",
                      grant.step, e.what()));
      return SessionEnd{
          fmt::format("step {}: the initial sources failed: {}", grant.step, e.what()),
          v1::ERROR_CODE_INTERNAL};
    }
    _log->info("session {}: step {} gets the sources of the particles at t = {} s (staggered "
               "coupling, no pending sources)",
               session, grant.step, grant.time);
  }
  if (_s.lastLedger.ByteSizeLong() == 0) { // the first step of a session
    _s.lastLedger = _s.ledger(_s.system->particles());
  }
  const dem::CellSources& p =
      _s.lag.apply(grant.dtCfd, gas.Tg, static_cast<std::size_t>(_s.grid.cells), _s.grid.species,
                   _s.cellVolume, _s.ledgers.speciesToGas);
  _replies.sendSources(to, gasMessage, p, _s.lastLedger, grant.dtCfd, grant.nSub, _s.grid);
  _s.lag.markSent(); // applied by the gas in this step; the step computes the next ones
  return std::nullopt;
}

const dem::CellSources* StepRunner::advance(const std::vector<StepReply>& to,
                                            std::optional<SessionEnd>& end) {
  const Grant& grant = *_assembly.grant();
  const std::string& session = _members.session();
  const bool staggered = _s.lag.enabled();
  try {
    return &_s.system->advance(grant.dtCfd, static_cast<int>(grant.nSub));
  } catch (const dem::Interrupted& e) {
    // A signal (or DemServer::stop) during a long step: answer both members and end the
    // session at once; run() then returns.
    _log->warn("session {}: step {} stopped by a signal ({}): ending the session", session,
               grant.step, e.what());
    const std::string reason =
        fmt::format("the server is stopping: step {} was interrupted ({})", grant.step, e.what());
    if (!staggered) { // staggered: the GasFields were answered with the lagged Sources
      _replies.refuseAll(to, v1::ERROR_CODE_UNEXPECTED_MESSAGE, reason);
    }
    end = SessionEnd{reason, v1::ERROR_CODE_UNEXPECTED_MESSAGE}; // answers the StepGrant too
    return nullptr;
  } catch (const std::exception& e) {
    _log->error("session {}: step {} failed in the DEM core: {}", session, grant.step, e.what());
    if (!staggered) {
      _replies.refuseAll(to, v1::ERROR_CODE_INTERNAL,
                         fmt::format("step {} failed in the DEM core: {}", grant.step, e.what()));
    }
    const auto failed = grant.step;
    _assembly.failGrant(v1::ERROR_CODE_INTERNAL, e.what());
    // The DEM state is unknown after a failed step: end the session rather than leave it
    // half-alive (every later step would fail too).
    end = SessionEnd{fmt::format("step {} failed in the DEM core: {}", failed, e.what()),
                     v1::ERROR_CODE_INTERNAL};
    return nullptr;
  }
}

void StepRunner::bookSpecies(const dem::CellSources& s, double dt) {
  // Ledgers: the species the particles gave to the gas during this step (the heat from the gas
  // is the DEM core's HeatTotals::convection, booked there once).
  // Staggered: booked here as computed; the gas gets them with the next GasFields, where they
  // are booked as applied (sendLaggedSources).
  const auto n = static_cast<std::size_t>(_s.grid.cells);
  const std::uint32_t species = _s.grid.species;
  std::vector<double>& booked =
      _s.lag.enabled() ? _s.lag.speciesComputed() : _s.ledgers.speciesToGas;
  for (std::size_t k = 0; k < species; ++k) {
    double sum = 0.0;
    for (std::size_t c = 0; c < n; ++c) {
      sum += s.rSpecies[c * species + k];
    }
    booked[k] += sum * _s.cellVolume * dt;
  }
}

void StepRunner::finish(const v1::Ledger& ledger, const dem::ParticleData& particles,
                        Clock::time_point t0) {
  namespace f = proto::fields;
  const Grant& grant = *_assembly.grant();
  const std::string& session = _members.session();
  // Checkpoint requested with the grant, then StepDone to O.
  v1::StepDone done;
  *done.mutable_ledger() = ledger;
  bool checkpointOk = true;
  std::string checkpointError;
  if (!grant.checkpointDir.empty()) {
    try {
      const auto tc = Clock::now();
      const auto files = _s.writeCheckpoint(grant.checkpointDir, grant.step, session, *_log);
      _xt.checkpoint += std::chrono::duration<double>(Clock::now() - tc).count();
      done.mutable_checkpoint()->set_directory(grant.checkpointDir);
      for (const auto& file : files) {
        done.mutable_checkpoint()->add_files(file);
      }
    } catch (const std::exception& e) {
      checkpointOk = false;
      checkpointError = e.what();
    }
  }
  const auto tDone = Clock::now();
  _s.addDiagnostics(done, particles);
  if (_s.lag.enabled()) { // tells the orchestrator that this server runs the scheme it asked for
    proto::addNamedValue(done.mutable_diagnostics(), std::string(f::kCouplingLagDiagnostic), 1.0);
  }
  done.set_wall_seconds(std::chrono::duration<double>(Clock::now() - t0).count());
  if (checkpointOk) {
    _replies.send(grant.peer, proto::makeStepDone(grant.step, grant.time, done), grant.sequence,
                  grant.step);
    _xt.packSend += std::chrono::duration<double>(Clock::now() - tDone).count();
  } else {
    _log->error("session {}: checkpoint of step {} into {} failed: {}", session, grant.step,
                safe(grant.checkpointDir, 200), safe(checkpointError, 400));
    _replies.send(
        grant.peer,
        proto::makeError(v1::ERROR_CODE_CHECKPOINT_FAILED,
                         fmt::format("step {} done, but writing its checkpoint into {} failed: {}",
                                     grant.step, safe(grant.checkpointDir, 200), checkpointError),
                         grant.sequence, v1::MESSAGE_TYPE_STEP_GRANT),
        grant.sequence, grant.step);
  }
  _s.lastStep = grant.step;
  ++_s.stepsDone;
  _assembly.completeGrant();
  _stepEnd = Clock::now();
  ++_xt.steps;
  if (_opt.timers && _opt.timersEvery > 0 && _xt.steps % _opt.timersEvery == 0) {
    _log->info(
        "session {}: {}", session,
        timersReport(_xt, _s.system->stageTimes(),
                     std::chrono::duration<double>(Clock::now() - _members.started()).count(),
                     false));
  }
}

} // namespace coredem::server
