#pragma once
// The members of the DEM server's session (docs/session.md, docs/protocol.md "Decomposed CFD"):
// the orchestrator that opened it and the CFD participant's ranks, each bound to the connection
// that said Hello first; the session id, the sequence numbers seen per connection and the times
// of the session's start and last activity.
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coredem/common/log.h"
#include "coredem/protocol/protocol.h"
#include "coredem/server/dem_server.h"
#include "reply_text.h"

namespace coredem::server {

using Clock = std::chrono::steady_clock;

class Membership {
public:
  explicit Membership(std::shared_ptr<spdlog::logger> log)
      : _log(std::move(log)) {}

  SessionState state() const { return _state; }
  /// Connected → Configured (after a Configure was taken).
  void setConfigured() { _state = SessionState::Configured; }
  /// The session id ("" when idle).
  const std::string& session() const { return _session; }
  const protocol::PeerId& orchestrator() const { return _oPeer; }
  const std::string& orchestratorName() const { return _oName; }

  /// The session's orchestrator or CFD participant (the connections that said Hello).
  bool isMember(const protocol::PeerId& p) const {
    return _state != SessionState::Idle && !p.empty() && (p == _oPeer || rankOf(p) >= 0);
  }
  /// The CFD rank of a connection, or -1.
  int rankOf(const protocol::PeerId& p) const;
  /// The rank count of the CFD participant (0: none connected yet).
  std::uint32_t rankCount() const { return _rankCount; }
  /// The protocol minor agreed with a CFD rank's Hello (Q_rad goes only to ranks of 1.3+).
  std::uint32_t rankMinor(std::size_t rank) const { return _rankMinors[rank]; }
  bool anyRankConnected() const;
  /// The CFD participant's name for logs ("-" when none).
  std::string cfdName() const;
  /// A connection's name for logs: the orchestrator, a CFD rank, or its hex id.
  std::string peerName(const protocol::PeerId& p) const;

  /// The last sequence number taken from a connection (0: none).
  std::uint64_t lastSequence(const protocol::PeerId& p) const;
  void setLastSequence(const protocol::PeerId& p, std::uint64_t sequence) {
    _lastSequence[p] = sequence;
  }
  void forgetSequence(const protocol::PeerId& p) { _lastSequence.erase(p); }

  Clock::time_point started() const { return _started; }
  Clock::time_point lastActivity() const { return _lastActivity; }
  void touch() { _lastActivity = Clock::now(); }

  /// Hello{role=ORCHESTRATOR} with the agreed version: opens a session (new id, Connected) or
  /// says why not. `endpoint` is this server's, for the refusal's text.
  std::optional<Refusal> admitOrchestrator(const protocol::Request& r,
                                           const protocol::Version& agreed,
                                           const std::string& endpoint);
  /// Hello{role=CFD} with the agreed version: binds CFD rank r of K to the connection or says
  /// why not.
  std::optional<Refusal> admitCfd(const protocol::Request& r, const protocol::Version& agreed,
                                  const std::string& endpoint);
  /// A CFD rank's connection closed: its role is free for a new connection.
  void releaseRank(int rank);
  /// The rank count is free again once no rank is connected.
  void releaseRankCountIfNoneConnected();
  /// The session ended: Idle, no members.
  void end();

private:
  std::shared_ptr<spdlog::logger> _log;
  SessionState _state = SessionState::Idle;
  std::string _session;
  protocol::PeerId _oPeer;
  std::string _oName;
  // The CFD participant: one connection per rank; _rankCount is fixed by the first CFD Hello
  // (0: none yet) and free again when no rank is connected.
  std::uint32_t _rankCount = 0;
  std::vector<protocol::PeerId> _rankPeers;
  std::vector<std::string> _rankNames;
  std::vector<std::uint32_t> _rankMinors;
  std::map<protocol::PeerId, std::uint64_t> _lastSequence;
  Clock::time_point _started, _lastActivity;
};

} // namespace coredem::server
