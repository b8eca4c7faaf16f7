#include "step_assembly.h"

#include <algorithm>
#include <cmath>

#include "partial_ranks.h"

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;

std::optional<Refusal> StepAssembly::checkGrant(const proto::Request& r, std::int64_t lastStep,
                                                double dtMax, std::uint64_t maxSubSteps) const {
  const auto& env = r.message.envelope();
  const auto& g = env.step_grant();
  if (_grant) {
    return Refusal{v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                   fmt::format("step {} is still running (waiting for the CFD participant's "
                               "GasFields)",
                               _grant->step)};
  }
  if (env.step() != lastStep + 1) {
    return Refusal{
        v1::ERROR_CODE_OUT_OF_ORDER,
        fmt::format("StepGrant for step {}, but the next step is {}", env.step(), lastStep + 1)};
  }
  if (g.n_sub() > maxSubSteps) {
    return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                   fmt::format("StepGrant of step {}: n_sub = {} exceeds the limit {} (coredem-dem "
                               "--max-sub-steps); use a smaller CFD step",
                               env.step(), g.n_sub(), maxSubSteps)};
  }
  if (!(g.dt_cfd() > 0.0) || !std::isfinite(g.dt_cfd()) || g.n_sub() < 1) {
    return Refusal{
        v1::ERROR_CODE_INVALID_CONFIGURATION,
        fmt::format("StepGrant of step {}: dt_cfd = {} s and n_sub = {} must be positive",
                    env.step(), g.dt_cfd(), g.n_sub())};
  }
  if (g.dt_cfd() / g.n_sub() > dtMax * (1.0 + kDtTolerance)) {
    return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                   fmt::format("StepGrant of step {}: dt_cfd/n_sub = {:.6g} s exceeds this DEM's "
                               "dt_dem_max = {:.6g} s; use n_sub >= {:.0f}",
                               env.step(), g.dt_cfd() / g.n_sub(), dtMax,
                               std::ceil(g.dt_cfd() / dtMax))}; // a double: never throws or wraps
  }
  if (g.dt_dem() > 0.0 &&
      std::abs(g.dt_dem() * g.n_sub() - g.dt_cfd()) > kDtTolerance * g.dt_cfd()) {
    return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                   fmt::format("StepGrant of step {}: dt_dem * n_sub = {:.17g} s differs from "
                               "dt_cfd = {:.17g} s",
                               env.step(), g.dt_dem() * g.n_sub(), g.dt_cfd())};
  }
  return std::nullopt;
}

void StepAssembly::grantStep(const proto::Request& r) {
  const auto& env = r.message.envelope();
  const auto& g = env.step_grant();
  Grant next;
  next.peer = r.peer;
  next.sequence = env.sequence();
  next.step = env.step();
  next.time = env.time();
  next.dtCfd = g.dt_cfd();
  next.nSub = g.n_sub();
  next.checkpointDir = g.has_checkpoint() ? g.checkpoint().directory() : std::string();
  _grant = next;
  _log->debug("session {}: step {} granted (dt {} s, n_sub {})", _members.session(), next.step,
              next.dtCfd, next.nSub);
}

std::optional<Held> StepAssembly::takeHeld() {
  std::optional<Held> h;
  if (_held) {
    h = std::move(*_held);
    _held.reset();
  }
  return h;
}

RankParts StepAssembly::takePartials() {
  RankParts parts;
  parts.swap(_partials);
  return parts;
}

StepAssembly::Next StepAssembly::onGasFields(proto::Request& r, std::uint32_t rank) {
  Next next = Next::Nothing;
  if (r.message.envelope().gas_fields().partial()) {
    onPartialGasFields(r, rank, next);
    return next;
  }
  if (_members.rankCount() > 1) {
    _replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                    fmt::format("whole-grid GasFields in a session whose CFD participant runs on "
                                "{} ranks: each rank sends a partial GasFields of the cells it "
                                "touches (docs/protocol.md \"Decomposed CFD\")",
                                _members.rankCount()));
    return next;
  }
  if (!_partials.empty()) {
    _replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                    "a partial GasFields of this step is already waiting; send partial ones only");
    return next;
  }
  if (_held) {
    _replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                    fmt::format("the GasFields of step {} are already waiting for their StepGrant",
                                _held->request.message.envelope().step()));
    return next;
  }
  if (!_grant) { // the grant is on its way from O on another connection: wait for it
    _held = Held{std::move(r), Clock::now()};
    return next;
  }
  return Next::RunWhole;
}

void StepAssembly::onPartialGasFields(proto::Request& r, std::uint32_t rank, Next& next) {
  if (_held) {
    _replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                    "a whole-grid GasFields of this step is already waiting; send whole-grid "
                    "ones only");
    return;
  }
  if (_partials.count(rank) != 0) {
    _replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                    fmt::format("CFD rank {} already sent its GasFields of step {}", rank,
                                _partials.at(rank).request.message.envelope().step()));
    return;
  }
  _partials.emplace(rank, Held{std::move(r), Clock::now()});
  if (_grant && _partials.size() == _members.rankCount()) {
    next = Next::RunPartial;
  }
}

std::optional<proto::Message> StepAssembly::combine(const std::vector<StepReply>& to,
                                                    const GridShape& grid, double cellVolume) {
  Combined c = combinePartialGasFields(to, grid, cellVolume, _members.rankCount());
  if (c.gas) {
    return std::move(c.gas);
  }
  const CombineFailure& why = c.failure;
  if (why.kind == CombineFailure::Kind::Volumes) {
    failPartialStep(why.code, why.stepText);
    _replies.refuseAll(to, why.code, why.rankText);
  } else {
    _replies.refuseAll(to, why.code, why.stepText);
    if (_grant) {
      failGrant(why.code, why.stepText);
    }
  }
  return std::nullopt;
}

proto::Expectation StepAssembly::gasExpectation(const proto::PeerId& peer, std::int64_t lastStep,
                                                const GridShape& grid) const {
  proto::Expectation e;
  e.types = {v1::MESSAGE_TYPE_GAS_FIELDS};
  e.sessionId = _members.session();
  e.sequenceAfter = _members.lastSequence(peer);
  e.step = _grant ? _grant->step : lastStep + 1;
  e.cells = grid.cells;
  e.species = grid.species;
  return e;
}

void StepAssembly::failGrant(v1::ErrorCode code, const std::string& text) {
  _replies.send(_grant->peer,
                proto::makeError(code, text, _grant->sequence, v1::MESSAGE_TYPE_STEP_GRANT),
                _grant->sequence, _grant->step);
  _grant.reset();
}

void StepAssembly::failPartialStep(v1::ErrorCode code, const std::string& text) {
  _log->error("session {}: {}", _members.session(), text);
  for (auto& [rank, h] : _partials) {
    _replies.refuse(h.request, code, text);
  }
  _partials.clear();
  if (_grant) {
    failGrant(code, text);
  }
}

void StepAssembly::dropHeldOf(const proto::PeerId& peer) {
  if (_held && _held->request.peer == peer) {
    _held.reset();
  }
}

void StepAssembly::rankLeft(std::uint32_t rank, const std::string& who, std::int64_t lastStep) {
  if (!_partials.empty()) {
    _partials.erase(rank);
    failPartialStep(v1::ERROR_CODE_TRANSPORT,
                    fmt::format("the connection of {} closed during step {}", who,
                                _grant ? _grant->step : lastStep + 1));
  }
}

void StepAssembly::expire(Clock::time_point now, double waitSeconds) {
  if (_held && std::chrono::duration<double>(now - _held->since).count() > waitSeconds) {
    auto h = std::move(*_held);
    _held.reset();
    _replies.refuse(h.request, v1::ERROR_CODE_TIMEOUT,
                    fmt::format("no StepGrant for step {} from orchestrator '{}' within {} s",
                                h.request.message.envelope().step(), _members.orchestratorName(),
                                waitSeconds));
  }
  if (_partials.empty()) {
    return;
  }
  auto oldest = _partials.begin()->second.since;
  for (const auto& [rank, h] : _partials) {
    oldest = std::min(oldest, h.since);
  }
  if (std::chrono::duration<double>(now - oldest).count() <= waitSeconds) {
    return;
  }
  const std::int64_t step = _partials.begin()->second.request.message.envelope().step();
  const std::uint32_t rankCount = _members.rankCount();
  if (_partials.size() < rankCount) {
    std::string missing;
    for (std::uint32_t r = 0; r < rankCount; ++r) {
      if (_partials.count(r) == 0) {
        missing += fmt::format("{}{}", missing.empty() ? "" : ", ", r);
      }
    }
    failPartialStep(v1::ERROR_CODE_TIMEOUT,
                    fmt::format("no GasFields of step {} from CFD rank(s) {} of {} within {} s of "
                                "the first rank's (coredem-dem --grant-wait-s)",
                                step, missing, rankCount, waitSeconds));
  } else {
    failPartialStep(v1::ERROR_CODE_TIMEOUT,
                    fmt::format("no StepGrant for step {} from orchestrator '{}' within {} s", step,
                                _members.orchestratorName(), waitSeconds));
  }
}

void StepAssembly::abandon(v1::ErrorCode code, const std::string& reason) {
  if (_held) {
    _replies.refuse(_held->request, code,
                    "the session ended before this step was granted (" + reason + ")");
  }
  for (auto& [rank, h] : _partials) {
    _replies.refuse(h.request, code, "the session ended before this step ran (" + reason + ")");
  }
  if (_grant) {
    auto m = proto::makeError(
        code, "the session ended during step " + std::to_string(_grant->step) + " (" + reason + ")",
        _grant->sequence, v1::MESSAGE_TYPE_STEP_GRANT);
    _replies.send(_grant->peer, std::move(m), _grant->sequence, _grant->step);
  }
  _grant.reset();
  _held.reset();
  _partials.clear();
}

} // namespace coredem::server
