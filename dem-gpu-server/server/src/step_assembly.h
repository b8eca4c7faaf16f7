#pragma once
// Step assembly of the DEM server: a step runs when the orchestrator's StepGrant and the CFD
// participant's GasFields are both in hand. The grant (checked against the session's progress
// and this DEM's Δt_DEM,max), a whole-grid GasFields held until its grant arrives, the partial
// GasFields of a decomposed CFD participant collected per rank, their combination into the
// step's gas (partial_ranks.h), and the timeouts of whatever waits.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coredem/common/log.h"
#include "coredem/protocol/protocol.h"
#include "membership.h"
#include "replies.h"

namespace coredem::server {

/// Relative tolerance of dt comparisons (grant vs GasFields, dt_dem·n_sub vs dt_cfd).
inline constexpr double kDtTolerance = 1e-12;

/// The orchestrator's StepGrant of the step in progress.
struct Grant {
  protocol::PeerId peer;
  std::uint64_t sequence = 0;
  std::int64_t step = 0;
  double time = 0.0;
  double dtCfd = 0.0;
  std::uint32_t nSub = 1;
  std::string checkpointDir;
};

/// A GasFields waiting for its StepGrant (or for the other ranks' partial ones).
struct Held {
  protocol::Request request;
  Clock::time_point since;
};

/// The partial GasFields of one step, by rank (std::map: rank order).
using RankParts = std::map<std::uint32_t, Held>;

class StepAssembly {
public:
  StepAssembly(Replies& replies, const Membership& members, std::shared_ptr<spdlog::logger> log)
      : _replies(replies)
      , _members(members)
      , _log(std::move(log)) {}

  /// The grant of the step in progress (none between steps).
  const std::optional<Grant>& grant() const { return _grant; }
  /// Whether partial GasFields of the next step are waiting.
  bool hasPartials() const { return !_partials.empty(); }

  /// Why a StepGrant cannot be taken (a step is running, out of order, n_sub over the limit, a
  /// dt that is not positive or exceeds Δt_DEM,max, dt_dem·n_sub ≠ dt_cfd), or nothing.
  std::optional<Refusal> checkGrant(const protocol::Request& r, std::int64_t lastStep, double dtMax,
                                    std::uint64_t maxSubSteps) const;
  /// Records a checked StepGrant.
  void grantStep(const protocol::Request& r);
  /// The whole-grid GasFields held for the new grant, if any (taken).
  std::optional<Held> takeHeld();
  /// Whether every rank's partial GasFields is in.
  bool partialsComplete() const {
    return _members.rankCount() > 0 && _partials.size() == _members.rankCount();
  }
  /// The partial GasFields of the step (taken).
  RankParts takePartials();

  /// What a GasFields from CFD rank `rank` leads to.
  enum class Next { Nothing, RunWhole, RunPartial };
  /// Files a GasFields (refused, held for its grant or kept until every rank's is in); RunWhole:
  /// run the step on `r` now; RunPartial: every rank's is in and granted.
  Next onGasFields(protocol::Request& r, std::uint32_t rank);

  /// The gas of a step combined from every rank's partial GasFields (`to`, in rank order), or
  /// nothing when they cannot be combined (then every rank and the grant were answered).
  std::optional<protocol::Message> combine(const std::vector<StepReply>& to, const GridShape& grid,
                                           double cellVolume);

  /// The Expectation a GasFields from `peer` is validated against.
  protocol::Expectation gasExpectation(const protocol::PeerId& peer, std::int64_t lastStep,
                                       const GridShape& grid) const;

  /// Answers the grant's orchestrator with an Error and drops the grant (the step is not run).
  /// @pre grant()
  void failGrant(v1::ErrorCode code, const std::string& text);
  /// The step ran: the grant is done.
  void completeGrant() { _grant.reset(); }
  /// Answers every waiting rank and the orchestrator's grant with `code`/`text`; the step is
  /// not run (the orchestrator stops the run).
  void failPartialStep(v1::ErrorCode code, const std::string& text);

  /// The connection `peer` of a CFD rank closed: its held GasFields is dropped (unanswered).
  void dropHeldOf(const protocol::PeerId& peer);
  /// CFD rank `rank` (named `who` in the texts) left while partial GasFields wait: its own is
  /// dropped and the step fails (the other ranks and the grant are answered).
  void rankLeft(std::uint32_t rank, const std::string& who, std::int64_t lastStep);
  /// Answers what waited longer than `waitSeconds` (no StepGrant, missing ranks).
  void expire(Clock::time_point now, double waitSeconds);
  /// The session ended: answers whatever waits or runs, then forgets it.
  void abandon(v1::ErrorCode code, const std::string& reason);

private:
  void onPartialGasFields(protocol::Request& r, std::uint32_t rank, Next& next);

  Replies& _replies;
  const Membership& _members;
  std::shared_ptr<spdlog::logger> _log;
  std::optional<Grant> _grant;
  std::optional<Held> _held;
  RankParts _partials;
};

} // namespace coredem::server
