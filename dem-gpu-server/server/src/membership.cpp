#include "membership.h"

#include <algorithm>
#include <random>

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;

namespace {

std::string randomSessionId() {
  std::random_device rd;
  std::mt19937_64 gen((static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^
                      static_cast<std::uint64_t>(Clock::now().time_since_epoch().count()));
  return fmt::format("{:016x}", gen());
}

/// The peer's name for logs and replies (escaped, at most 64 bytes of the peer's text).
std::string nameOf(const proto::Request& r) {
  const auto& env = r.message.envelope();
  if (!env.sender().empty()) {
    return safe(env.sender(), 64);
  }
  if (!env.hello().software_version().empty()) {
    return safe(env.hello().software_version(), 64);
  }
  return hexPeer(r.peer);
}

/// ", client key K" when the client's CURVE key was authenticated by the allow-list.
std::string keyNote(const proto::Request& r) {
  return r.clientKey.empty() ? std::string() : ", client key " + r.clientKey;
}

} // namespace

int Membership::rankOf(const proto::PeerId& p) const {
  for (std::size_t r = 0; r < _rankPeers.size(); ++r) {
    if (!p.empty() && _rankPeers[r] == p) {
      return static_cast<int>(r);
    }
  }
  return -1;
}

bool Membership::anyRankConnected() const {
  return std::any_of(_rankPeers.begin(), _rankPeers.end(),
                     [](const proto::PeerId& p) { return !p.empty(); });
}

std::string Membership::cfdName() const {
  std::string n;
  for (std::size_t r = 0; r < _rankNames.size(); ++r) {
    if (!_rankPeers[r].empty()) {
      n = _rankNames[r];
      break;
    }
  }
  if (n.empty()) {
    return "-";
  }
  return _rankCount > 1 ? fmt::format("{} ({} ranks)", n, _rankCount) : n;
}

std::string Membership::peerName(const proto::PeerId& p) const {
  if (!_oPeer.empty() && p == _oPeer) {
    return fmt::format("orchestrator '{}'", _oName);
  }
  if (const int r = rankOf(p); r >= 0) {
    return _rankCount > 1 ? fmt::format("CFD rank {} of {} '{}'", r, _rankCount, _rankNames[r])
                          : fmt::format("CFD participant '{}'", _rankNames[r]);
  }
  return fmt::format("peer {}", hexPeer(p));
}

std::uint64_t Membership::lastSequence(const proto::PeerId& p) const {
  const auto it = _lastSequence.find(p);
  return it != _lastSequence.end() ? it->second : 0;
}

std::optional<Refusal> Membership::admitOrchestrator(const proto::Request& r,
                                                     const proto::Version& agreed,
                                                     const std::string& endpoint) {
  if (_state != SessionState::Idle) {
    // Never the session id: the caller is not a member (or, on the orchestrator's own
    // connection, already knows it).
    const double secs = std::chrono::duration<double>(Clock::now() - _started).count();
    return Refusal{v1::ERROR_CODE_SESSION_BUSY,
                   r.peer == _oPeer
                       ? std::string("this connection is already the orchestrator of the active "
                                     "session; a second Hello is refused (send Shutdown to end it)")
                       : fmt::format("coredem-dem at {} already serves another session (for "
                                     "{:.0f} s); wait until it ends or start another coredem-dem",
                                     endpoint, secs)};
  }
  _session = randomSessionId();
  _oPeer = r.peer;
  _oName = nameOf(r);
  _state = SessionState::Connected;
  _started = _lastActivity = Clock::now();
  _lastSequence[r.peer] = r.message.envelope().sequence();
  _log->info("session {}: orchestrator '{}' connected (protocol {}.{}, peer {}{})", _session,
             _oName, agreed.major, agreed.minor, hexPeer(r.peer), keyNote(r));
  return std::nullopt;
}

std::optional<Refusal> Membership::admitCfd(const proto::Request& r, const proto::Version& agreed,
                                            const std::string& endpoint) {
  const auto& env = r.message.envelope();
  const auto& h = env.hello();
  if (_state == SessionState::Idle) {
    return Refusal{v1::ERROR_CODE_NOT_CONFIGURED,
                   "no active session: the orchestrator connects first and passes its session id "
                   "to the CFD participant (COREDEM_SESSION)"};
  }
  if (env.session_id() != _session) {
    return Refusal{v1::ERROR_CODE_UNKNOWN_SESSION,
                   fmt::format("session id '{}' is not the active session of coredem-dem at {}; "
                               "use the id the orchestrator passes in COREDEM_SESSION",
                               safe(env.session_id(), 40), endpoint)};
  }
  if (r.peer == _oPeer) {
    return Refusal{v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                   "this connection is the session's orchestrator; the CFD participant says Hello "
                   "on its own connection"};
  }
  // Decomposed (v1.2): rank r of K; rank_count 0 (older peers) or 1 is one rank.
  const std::uint32_t k = std::max<std::uint32_t>(1, h.rank_count());
  const std::uint32_t rank = h.rank();
  if (rank >= k) {
    return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                   fmt::format("Hello of CFD rank {} of {}: the rank index must be below the rank "
                               "count",
                               rank, k)};
  }
  if (anyRankConnected() && k != _rankCount) {
    return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                   fmt::format("the session's CFD participant runs on {} rank(s) ('{}'); this "
                               "Hello says {}: every rank of one decomposed run gives the same "
                               "rank count",
                               _rankCount, cfdName(), k)};
  }
  if (const int mine = rankOf(r.peer); mine >= 0 && static_cast<std::uint32_t>(mine) != rank) {
    return Refusal{v1::ERROR_CODE_SESSION_BUSY,
                   fmt::format("this connection is CFD rank {}; a rank says Hello on its own "
                               "connection",
                               mine)};
  }
  if (!anyRankConnected()) {
    _rankCount = k;
    _rankPeers.assign(k, proto::PeerId());
    _rankNames.assign(k, std::string());
    _rankMinors.assign(k, 0);
  }
  if (!_rankPeers[rank].empty() && _rankPeers[rank] != r.peer) {
    // Each role is bound to the connection that said Hello first; the role is freed when that
    // connection closes (releaseRank).
    return Refusal{v1::ERROR_CODE_SESSION_BUSY,
                   k == 1 ? fmt::format("the session already has a CFD participant ('{}') on "
                                        "another connection; a second one is refused",
                                        _rankNames[rank])
                          : fmt::format("CFD rank {} of {} is already connected ('{}') on another "
                                        "connection; a duplicate rank index is refused",
                                        rank, k, _rankNames[rank])};
  }
  _rankPeers[rank] = r.peer;
  _rankNames[rank] = nameOf(r);
  _rankMinors[rank] = agreed.minor;
  _lastSequence[r.peer] = env.sequence();
  if (k > 1) {
    _log->info("session {}: CFD rank {} of {} '{}' connected (protocol {}.{}, peer {}{})", _session,
               rank, k, _rankNames[rank], agreed.major, agreed.minor, hexPeer(r.peer), keyNote(r));
  } else {
    _log->info("session {}: CFD participant '{}' connected (protocol {}.{}, peer {}{})", _session,
               _rankNames[rank], agreed.major, agreed.minor, hexPeer(r.peer), keyNote(r));
  }
  return std::nullopt;
}

void Membership::releaseRank(int rank) {
  const auto r = static_cast<std::size_t>(rank);
  _rankPeers[r].clear();
  _rankNames[r].clear();
  _rankMinors[r] = 0;
}

void Membership::releaseRankCountIfNoneConnected() {
  if (!anyRankConnected()) {
    _rankCount = 0;
  }
}

void Membership::end() {
  _state = SessionState::Idle;
  _session.clear();
  _oPeer.clear();
  _rankPeers.clear();
  _rankNames.clear();
  _rankMinors.clear();
  _rankCount = 0;
  _oName.clear();
  _lastSequence.clear();
}

} // namespace coredem::server
