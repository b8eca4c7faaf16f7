#pragma once
// One coupled step of the DEM server, once step assembly has its grant and gas: the gas into the
// DEM core (GasFieldsView from the field table, coupling_fields.h), the advance over n_sub
// sub-steps, the ledgers booked, the Sources to the CFD participant (sequential: after the
// advance; staggered: the lagged ones before it), the checkpoint asked for with the grant and
// the StepDone to the orchestrator; with the exchange timers of --timers.
#include <optional>
#include <string>
#include <vector>

#include "configured_session.h"
#include "coredem/common/log.h"
#include "coredem/server/dem_server.h"
#include "membership.h"
#include "replies.h"
#include "step_assembly.h"
#include "timers.h"

namespace coredem::server {

/// Why the session must end after a step (its members were answered).
struct SessionEnd {
  std::string reason;
  v1::ErrorCode code = v1::ERROR_CODE_UNEXPECTED_MESSAGE;
};

class StepRunner {
public:
  StepRunner(ConfiguredSession& session, StepAssembly& assembly, Replies& replies,
             const Membership& members, const ServerOptions& options,
             std::shared_ptr<spdlog::logger> log)
      : _s(session)
      , _assembly(assembly)
      , _replies(replies)
      , _members(members)
      , _opt(options)
      , _log(std::move(log)) {}

  /// Runs the granted step on the GasFields `gasMessage`, answering `to` (the whole-grid
  /// GasFields or each rank's partial one) and the grant. A reason when the session must end.
  std::optional<SessionEnd> run(const protocol::Message& gasMessage,
                                const std::vector<StepReply>& to);

  /// --timers: the exchange and advance seconds of this session.
  ExchangeTimes& times() { return _xt; }
  /// A GasFields arrived at `received`: the wait since the last StepDone left (the CFD's step
  /// and the transfer) is timed.
  void timeWaitForPeer(Clock::time_point received) {
    if (_stepEnd) {
      _xt.waitPeer += std::chrono::duration<double>(received - *_stepEnd).count();
    }
  }
  /// The session ended: the timers start again.
  void reset() {
    _xt = ExchangeTimes();
    _stepEnd.reset();
  }

private:
  /// The gas of the step into the DEM core; false when refused.
  bool setGas(const protocol::Message& gasMessage, const std::vector<StepReply>& to,
              dem::GasFieldsView& view);
  /// Staggered: the pending sources (S^0 for a first step) to `to` before the step is computed.
  std::optional<SessionEnd> sendLaggedSources(const std::vector<StepReply>& to,
                                              const protocol::Message& gasMessage,
                                              const dem::GasFieldsView& gas);
  /// The advance; nullptr and why the session ends when it failed.
  const dem::CellSources* advance(const std::vector<StepReply>& to, std::optional<SessionEnd>& end);
  /// The species the particles gave the gas during the step.
  void bookSpecies(const dem::CellSources& s, double dt);
  /// The checkpoint asked for with the grant, then StepDone (or the checkpoint's Error).
  void finish(const v1::Ledger& ledger, const dem::ParticleData& particles, Clock::time_point t0);

  ConfiguredSession& _s;
  StepAssembly& _assembly;
  Replies& _replies;
  const Membership& _members;
  const ServerOptions& _opt;
  std::shared_ptr<spdlog::logger> _log;
  ExchangeTimes _xt;                         ///< --timers: exchange and advance seconds
  std::optional<Clock::time_point> _stepEnd; ///< when the last StepDone left
};

} // namespace coredem::server
