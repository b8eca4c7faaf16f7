// coredem-dem: D of docs/session.md over the protocol library and the DEM core.
#include "coredem/server/dem_server.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <span>

#include <fcntl.h>
#include <google/protobuf/stubs/logging.h>
#include <malloc.h>
#include <sys/stat.h>
#include <unistd.h>

#include "admission.h"
#include "configure_map.h"
#include "coredem/common/check.h"
#include "coredem/common/files.h"
#include "coredem/common/log.h"
#include "coredem/dem/bed_height.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/time_handler.h"
#include "coredem/protocol/coupling_scheme.h"
#include "coredem/protocol/protocol.h"
#include "state_meta.h"
#include "timers.h"

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr const char* kSoftware = "coredem-dem 0.1.0";
/// Relative tolerance of dt comparisons (grant vs GasFields, dt_dem·n_sub vs dt_cfd).
constexpr double kDtTolerance = 1e-12;
/// Longest error text sent back to a peer (longer ones are cut, "...(N bytes)").
constexpr std::size_t kMaxReplyText = 4096;
/// Unknown Configure options named one by one in the log; the rest are counted.
constexpr std::size_t kLoggedIgnoredOptions = 5;

/// A peer-supplied string for a log line or a reply (escaped, length-capped).
std::string safe(std::string_view text, std::size_t maxBytes = 120) {
  return proto::printable(text, maxBytes);
}

std::string randomSessionId() {
  std::random_device rd;
  std::mt19937_64 gen((static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^
                      static_cast<std::uint64_t>(Clock::now().time_since_epoch().count()));
  return fmt::format("{:016x}", gen());
}

std::string hexPeer(const proto::PeerId& p) {
  std::string s;
  for (unsigned char ch : p) {
    s += fmt::format("{:02x}", ch);
  }
  return s;
}

const char* stateName(SessionState s) {
  switch (s) {
  case SessionState::Idle:
    return "idle";
  case SessionState::Connected:
    return "connected";
  case SessionState::Configured:
    return "configured";
  }
  return "?";
}

/// libprotobuf's own messages (e.g. one ERROR line per refused string field with invalid UTF-8,
/// which any peer can trigger per message): to the log at debug level, not to stderr.
void protobufLog(google::protobuf::LogLevel level, const char* file, int line,
                 const std::string& message) {
  static auto log = coredem::logger("protocol.protobuf");
  log->debug("libprotobuf {} {}:{}: {}", static_cast<int>(level), file, line,
             proto::printable(message, 200));
}

std::string readKey(const fs::path& p) {
  std::ifstream in(p);
  COREDEM_CHECK(in.good(),
                "cannot read the CURVE key file {}: create the pair with "
                "`coredem-dem --generate-curve-keys DIR`",
                p.string());
  std::string k;
  in >> k;
  COREDEM_CHECK(k.size() == 40, "{} does not hold a 40-character Z85 CURVE key", p.string());
  return k;
}

proto::TransportOptions transportOptions(const ServerOptions& o) {
  proto::TransportOptions t;
  t.sender = kSoftware;
  t.allowInsecure = o.insecure;
  t.maxMessageBytes = o.maxMessageBytes;
  if (!o.curveKeysDir.empty()) {
    t.curve.serverPublicKey = readKey(fs::path(o.curveKeysDir) / "server.public");
    t.curve.serverSecretKey = readKey(fs::path(o.curveKeysDir) / "server.secret");
  }
  if (!o.clientKeysFile.empty()) {
    COREDEM_CHECK(!o.curveKeysDir.empty(),
                  "--client-keys {} needs --curve-keys DIR (the allow-list authenticates CURVE "
                  "clients)",
                  o.clientKeysFile);
    t.curve.allowedClientKeys = proto::readAllowedClientKeys(o.clientKeysFile);
    COREDEM_CHECK(!t.curve.allowedClientKeys.empty(),
                  "--client-keys {} lists no key: nobody could connect", o.clientKeysFile);
  }
  return t;
}

/// Flushes a written file to disk before it is renamed into place.
struct Grant {
  proto::PeerId peer;
  std::uint64_t sequence = 0;
  std::int64_t step = 0;
  double time = 0.0;
  double dtCfd = 0.0;
  std::uint32_t nSub = 1;
  std::string checkpointDir;
};

struct Held {
  proto::Request request;
  Clock::time_point since;
};

} // namespace

struct DemServer::Impl {
  ServerOptions opt;
  Limits limits;
  proto::Server server;
  std::string endpoint;
  std::shared_ptr<spdlog::logger> log = coredem::logger("dem.server");
  std::atomic<bool> stopFlag{false};
  bool sessionEnded = false;

  // ---- the session ---------------------------------------------------------------------
  SessionState state = SessionState::Idle;
  std::string session;
  proto::PeerId oPeer;
  std::string oName;
  // The CFD participant: one connection per rank (docs/protocol.md "Decomposed CFD"); rankCount
  // is fixed by the first CFD Hello (0: none yet) and free again when no rank is connected.
  std::uint32_t rankCount = 0;
  std::vector<proto::PeerId> rankPeers;
  std::vector<std::string> rankNames;
  /// The protocol minor agreed with each CFD rank's Hello (Q_rad goes only to ranks of 1.3+).
  std::vector<std::uint32_t> rankMinors;
  Clock::time_point started, lastActivity;
  std::map<proto::PeerId, std::uint64_t> lastSequence;
  std::unique_ptr<dem::DemSystem> system;
  std::uint64_t cells = 0;
  std::uint32_t species = 0;
  std::vector<std::string> speciesNames;
  double cellVolume = 0.0;
  std::int64_t lastStep = 0;  ///< last completed step
  std::int64_t stepsDone = 0; ///< in this session
  std::optional<Grant> grant;
  std::optional<Held> held;
  std::map<std::uint32_t, Held> partials; ///< partial GasFields of the step, by rank
  ServerLedgers ledgers;
  /// Staggered coupling (Configure option coupling_scheme = staggered, docs/coupling-schemes.md):
  /// GasFields of step n are answered at once with the sources computed in step n-1.
  bool staggered = false;
  StaggeredState lag;    ///< pending sources and the lag ledgers (staggered only)
  v1::Ledger lastLedger; ///< the ledger of the last StepDone (sent with the lagged Sources)
  ExchangeTimes xt;      ///< --timers: exchange and advance seconds this session
  std::optional<Clock::time_point> stepEnd; ///< when the last StepDone left (wait_for_peer starts)
  Clock::time_point lastReceived{};         ///< when receive() returned the message being handled

  explicit Impl(ServerOptions o)
      : opt(std::move(o))
      , limits(limitsFor(opt.maxMemoryBytes > 0 ? opt.maxMemoryBytes : defaultMaxMemory(),
                         opt.maxSubSteps))
      , server(transportOptions(opt)) {}

  /// The session's orchestrator or CFD participant (the connections that said Hello).
  bool isMember(const proto::PeerId& p) const {
    return state != SessionState::Idle && !p.empty() && (p == oPeer || rankOf(p) >= 0);
  }

  /// The CFD rank of a connection, or -1.
  int rankOf(const proto::PeerId& p) const {
    for (std::size_t r = 0; r < rankPeers.size(); ++r) {
      if (!p.empty() && rankPeers[r] == p) {
        return static_cast<int>(r);
      }
    }
    return -1;
  }

  /// The CFD participant's name for logs ("-" when none).
  std::string cfdName() const {
    std::string n;
    for (std::size_t r = 0; r < rankNames.size(); ++r) {
      if (!rankPeers[r].empty()) {
        n = rankNames[r];
        break;
      }
    }
    if (n.empty()) {
      return "-";
    }
    return rankCount > 1 ? fmt::format("{} ({} ranks)", n, rankCount) : n;
  }

  bool anyRankConnected() const {
    return std::any_of(rankPeers.begin(), rankPeers.end(),
                       [](const proto::PeerId& p) { return !p.empty(); });
  }

  // ---- replies ---------------------------------------------------------------------------
  void send(const proto::PeerId& peer, proto::Message m, std::uint64_t sequence,
            std::int64_t step) {
    // The session id goes to the session's members only (docs/security.md): a stranger's reply
    // carries none, in the envelope or the text.
    m.setSessionId(isMember(peer) ? session : std::string());
    m.setSequence(sequence);
    m.setStep(step);
    server.reply(peer, std::move(m));
  }

  std::string peerName(const proto::PeerId& p) const {
    if (!oPeer.empty() && p == oPeer) {
      return fmt::format("orchestrator '{}'", oName);
    }
    if (const int r = rankOf(p); r >= 0) {
      return rankCount > 1 ? fmt::format("CFD rank {} of {} '{}'", r, rankCount, rankNames[r])
                           : fmt::format("CFD participant '{}'", rankNames[r]);
    }
    return fmt::format("peer {}", hexPeer(p));
  }

  void refuse(const proto::Request& r, v1::ErrorCode code, const std::string& message) {
    const auto& env = r.message.envelope();
    log->warn("session {}: refused {} from {}: {}: {}", session.empty() ? "-" : session,
              proto::messageTypeName(env.type()), peerName(r.peer), proto::errorCodeName(code),
              safe(message, 400));
    // Our own text with escaped, capped peer strings; capped as a whole too.
    send(r.peer,
         proto::makeError(code,
                          message.size() > kMaxReplyText ? safe(message, kMaxReplyText) : message,
                          env.sequence(), env.type()),
         env.sequence(), env.step());
  }

  void reject(const proto::Request& r, v1::ErrorCode code, const std::string& reason) {
    const auto& env = r.message.envelope();
    log->warn("rejected Hello from '{}' ({}): {}: {}", safe(env.sender()), hexPeer(r.peer),
              proto::errorCodeName(code), safe(reason, 400));
    auto m = proto::makeReject(code, reason);
    m.envelope().mutable_reject()->set_server_protocol_major(proto::kProtocolVersion.major);
    m.envelope().mutable_reject()->set_server_protocol_minor(proto::kProtocolVersion.minor);
    m.setSequence(env.sequence());
    server.reply(r.peer, std::move(m));
  }

  // ---- session ---------------------------------------------------------------------------
  void endSession(const std::string& reason,
                  v1::ErrorCode code = v1::ERROR_CODE_UNEXPECTED_MESSAGE) {
    if (state == SessionState::Idle) {
      return;
    }
    if (held) {
      refuse(held->request, code,
             "the session ended before this step was granted (" + reason + ")");
    }
    for (auto& [rank, h] : partials) {
      refuse(h.request, code, "the session ended before this step ran (" + reason + ")");
    }
    if (grant) {
      auto m = proto::makeError(code,
                                "the session ended during step " + std::to_string(grant->step) +
                                    " (" + reason + ")",
                                grant->sequence, v1::MESSAGE_TYPE_STEP_GRANT);
      send(grant->peer, std::move(m), grant->sequence, grant->step);
    }
    const double secs = std::chrono::duration<double>(Clock::now() - started).count();
    log->info("session {} ended: {} (orchestrator '{}', CFD participant '{}', {} steps, {:.1f} s)",
              session, reason, oName, cfdName(), stepsDone, secs);
    if (opt.timers && system) {
      const auto st = system->stageTimes();
      log->info("session {}: {}", session, timersReport(xt, st, secs, true));
      const std::string path = opt.timersFile.empty() ? "coredem-dem-timers.json" : opt.timersFile;
      try {
        writeTextFile(path, timersJson(xt, st, secs, session, system->backendName(), opt.threads));
        log->info("session {}: timers written to {}", session, path);
      } catch (const std::exception& e) {
        log->error("session {}: {}", session, e.what());
      }
    }
    xt = ExchangeTimes();
    stepEnd.reset();
    state = SessionState::Idle;
    session.clear();
    oPeer.clear();
    rankPeers.clear();
    rankNames.clear();
    rankMinors.clear();
    rankCount = 0;
    oName.clear();
    lastSequence.clear();
    system.reset();
    ::malloc_trim(0); // the session's particles and grids go back to the system
    grant.reset();
    held.reset();
    partials.clear();
    ledgers = ServerLedgers();
    staggered = false;
    lag = StaggeredState();
    lastLedger.Clear();
    stepsDone = 0;
    sessionEnded = true;
  }

  /// The peer's name for logs and replies (escaped, at most 64 bytes of the peer's text).
  static std::string nameOf(const proto::Request& r) {
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
  static std::string keyNote(const proto::Request& r) {
    return r.clientKey.empty() ? std::string() : ", client key " + r.clientKey;
  }

  /// A closed connection (the transport's socket monitor): the orchestrator's ends the
  /// session; the CFD participant's frees its role for a new connection.
  void onDisconnected(const proto::PeerId& p) {
    lastSequence.erase(p);
    if (state == SessionState::Idle) {
      return;
    }
    if (p == oPeer) {
      endSession(fmt::format("the connection of orchestrator '{}' closed", oName),
                 v1::ERROR_CODE_TRANSPORT);
    } else if (const int r = rankOf(p); r >= 0) {
      const std::string who = peerName(p);
      log->warn("session {}: the connection of {} closed; a new CFD participant may join with "
                "the session id",
                session, who);
      if (held && held->request.peer == p) {
        held.reset();
      }
      rankPeers[r].clear();
      rankNames[r].clear();
      rankMinors[r] = 0;
      if (!partials.empty()) {
        partials.erase(static_cast<std::uint32_t>(r));
        failPartialStep(v1::ERROR_CODE_TRANSPORT,
                        fmt::format("the connection of {} closed during step {}", who,
                                    grant ? grant->step : lastStep + 1));
      }
      if (!anyRankConnected()) {
        rankCount = 0;
      }
    }
  }

  void onHello(const proto::Request& r) {
    const auto& env = r.message.envelope();
    if (env.body_case() != v1::Envelope::kHello) {
      refuse(r, v1::ERROR_CODE_BODY_MISMATCH, "a HELLO envelope must carry a Hello body");
      return;
    }
    const auto& h = env.hello();
    const auto n =
        proto::negotiate(proto::kProtocolVersion, {h.protocol_major(), h.protocol_minor()});
    if (!n.accepted) {
      reject(r, v1::ERROR_CODE_VERSION, n.status.message);
      return;
    }
    if (h.role() == v1::ROLE_ORCHESTRATOR) {
      if (state != SessionState::Idle) {
        // Never the session id: the caller is not a member (or, on the orchestrator's own
        // connection, already knows it).
        const double secs = std::chrono::duration<double>(Clock::now() - started).count();
        reject(r, v1::ERROR_CODE_SESSION_BUSY,
               r.peer == oPeer
                   ? std::string("this connection is already the orchestrator of the active "
                                 "session; a second Hello is refused (send Shutdown to end it)")
                   : fmt::format("coredem-dem at {} already serves another session (for {:.0f} "
                                 "s); wait until it ends or start another coredem-dem",
                                 endpoint, secs));
        return;
      }
      session = randomSessionId();
      oPeer = r.peer;
      oName = nameOf(r);
      state = SessionState::Connected;
      started = lastActivity = Clock::now();
      sessionEnded = false;
      lastSequence[r.peer] = env.sequence();
      log->info("session {}: orchestrator '{}' connected (protocol {}.{}, peer {}{})", session,
                oName, n.agreed.major, n.agreed.minor, hexPeer(r.peer), keyNote(r));
    } else if (h.role() == v1::ROLE_CFD) {
      if (state == SessionState::Idle) {
        reject(r, v1::ERROR_CODE_NOT_CONFIGURED,
               "no active session: the orchestrator connects first and passes its session id to "
               "the CFD participant (COREDEM_SESSION)");
        return;
      }
      if (env.session_id() != session) {
        reject(r, v1::ERROR_CODE_UNKNOWN_SESSION,
               fmt::format("session id '{}' is not the active session of coredem-dem at {}; use "
                           "the id the orchestrator passes in COREDEM_SESSION",
                           safe(env.session_id(), 40), endpoint));
        return;
      }
      if (r.peer == oPeer) {
        reject(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
               "this connection is the session's orchestrator; the CFD participant says Hello "
               "on its own connection");
        return;
      }
      // Decomposed (v1.2): rank r of K; rank_count 0 (older peers) or 1 is one rank.
      const std::uint32_t k = std::max<std::uint32_t>(1, h.rank_count());
      const std::uint32_t rank = h.rank();
      if (rank >= k) {
        reject(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
               fmt::format("Hello of CFD rank {} of {}: the rank index must be below the rank "
                           "count",
                           rank, k));
        return;
      }
      if (anyRankConnected() && k != rankCount) {
        reject(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
               fmt::format("the session's CFD participant runs on {} rank(s) ('{}'); this Hello "
                           "says {}: every rank of one decomposed run gives the same rank count",
                           rankCount, cfdName(), k));
        return;
      }
      if (const int mine = rankOf(r.peer); mine >= 0 && static_cast<std::uint32_t>(mine) != rank) {
        reject(r, v1::ERROR_CODE_SESSION_BUSY,
               fmt::format("this connection is CFD rank {}; a rank says Hello on its own "
                           "connection",
                           mine));
        return;
      }
      if (!anyRankConnected()) {
        rankCount = k;
        rankPeers.assign(k, proto::PeerId());
        rankNames.assign(k, std::string());
        rankMinors.assign(k, 0);
      }
      if (!rankPeers[rank].empty() && rankPeers[rank] != r.peer) {
        // Each role is bound to the connection that said Hello first; the role is freed when
        // that connection closes (onDisconnected).
        reject(r, v1::ERROR_CODE_SESSION_BUSY,
               k == 1 ? fmt::format("the session already has a CFD participant ('{}') on another "
                                    "connection; a second one is refused",
                                    rankNames[rank])
                      : fmt::format("CFD rank {} of {} is already connected ('{}') on another "
                                    "connection; a duplicate rank index is refused",
                                    rank, k, rankNames[rank]));
        return;
      }
      rankPeers[rank] = r.peer;
      rankNames[rank] = nameOf(r);
      rankMinors[rank] = n.agreed.minor;
      lastSequence[r.peer] = env.sequence();
      if (k > 1) {
        log->info("session {}: CFD rank {} of {} '{}' connected (protocol {}.{}, peer {}{})",
                  session, rank, k, rankNames[rank], n.agreed.major, n.agreed.minor,
                  hexPeer(r.peer), keyNote(r));
      } else {
        log->info("session {}: CFD participant '{}' connected (protocol {}.{}, peer {}{})", session,
                  rankNames[rank], n.agreed.major, n.agreed.minor, hexPeer(r.peer), keyNote(r));
      }
    } else {
      reject(r, v1::ERROR_CODE_UNSUPPORTED,
             "coredem-dem takes sessions of an orchestrator (ROLE_ORCHESTRATOR) and its CFD "
             "participant (ROLE_CFD) only");
      return;
    }
    auto w = proto::makeWelcome(v1::ROLE_DEM, kSoftware, n.agreed.major, n.agreed.minor, session);
    send(r.peer, std::move(w), env.sequence(), env.step());
  }

  void onConfigure(const proto::Request& r) {
    const auto& c = r.message.envelope().configure();
    if (r.peer != oPeer) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE, "only the session's orchestrator configures");
      return;
    }
    if (stepsDone > 0 || grant) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             "the session has started stepping; start a new session to configure again");
      return;
    }
    if (const auto s = proto::validateConfigure(c); !s.ok()) {
      refuse(r, s.code, s.message);
      return;
    }
    // Admission control before anything is allocated: counts against the memory budget.
    if (const std::string why = admitConfigure(c, limits); !why.empty()) {
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION, why);
      return;
    }
    // The coupling scheme is the server's own option (not a DEM model): an unknown value is
    // refused, never taken for the default.
    bool nextStaggered = false;
    for (const auto& kv : c.options()) {
      if (kv.key() == proto::fields::kCouplingSchemeOption) {
        if (kv.value() == "staggered") {
          nextStaggered = true;
        } else if (kv.value() != "sequential") {
          refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
                 fmt::format("Configure option {} = '{}': this server runs 'sequential' or "
                             "'staggered'",
                             proto::fields::kCouplingSchemeOption, safe(kv.value(), 64)));
          return;
        }
      }
    }
    std::unique_ptr<dem::DemSystem> next;
    std::uint32_t nSub = 0;
    ServerLedgers restored;
    StaggeredState restoredLag;
    restoredLag.speciesComputed.assign(static_cast<std::size_t>(c.species_size()), 0.0);
    std::vector<std::string> ignored;
    try {
      COREDEM_CHECK(c.coupling_mesh().has_cartesian(), "Configure has no Cartesian coupling grid");
      auto cfg = toDemConfig(c, &ignored);
      cfg.interrupt = &stopFlag; // SIGINT/SIGTERM stop a long placement
      next = std::make_unique<dem::DemSystem>(cfg, dem::parseBackend(opt.backend), opt.threads);
      if (!c.initial_state_file().empty()) {
        COREDEM_CHECK(fs::exists(c.initial_state_file()), "initial state file '{}' does not exist",
                      c.initial_state_file());
        next->readState(c.initial_state_file());
        restored = readServerLedgers(c.initial_state_file(), c.species_size());
        if (nextStaggered) {
          restoredLag = readStaggeredState(c.initial_state_file(),
                                           proto::cellCount(c.coupling_mesh()), c.species_size());
        }
      }
      COREDEM_CHECK(std::isfinite(next->dtDemMax()) && next->dtDemMax() > 0.0,
                    "no stable DEM time step can be derived (dt_dem_max = {}): give the particle "
                    "sets (with an initial state file too, they define the sizes and materials)",
                    next->dtDemMax());
      if (c.sub_cycling().dt_cfd() > 0.0) {
        nSub = static_cast<std::uint32_t>(
            dem::TimeHandler::subStepsFor(c.sub_cycling().dt_cfd(), next->dtDemMax()));
      }
    } catch (const dem::Interrupted& e) {
      next.reset();
      log->warn("session {}: Configure stopped by a signal ({})", session, e.what());
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("the server is stopping: Configure was {}", e.what()));
      return;
    } catch (const coredem::UserError& e) {
      next.reset();
      ::malloc_trim(0); // give a large failed build's memory back to the system
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION, e.what());
      return;
    } catch (const std::bad_alloc&) {
      next.reset();
      ::malloc_trim(0);
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
             fmt::format("Configure: out of memory while building the particles although the "
                         "estimate fits the {} budget; lower coredem-dem --max-memory so that "
                         "such a Configure is refused up front",
                         formatBytes(limits.memoryBytes)));
      return;
    }
    for (std::size_t i = 0; i < ignored.size() && i < kLoggedIgnoredOptions; ++i) {
      log->warn("session {}: Configure option '{}' is not a DEM server option (ignored)", session,
                safe(ignored[i], 64));
    }
    if (ignored.size() > kLoggedIgnoredOptions) {
      log->warn("session {}: {} more Configure options are not DEM server options (ignored)",
                session, ignored.size() - kLoggedIgnoredOptions);
    }
    system = std::move(next);
    system->setInterruptFlag(&stopFlag); // SIGINT/SIGTERM stop a long step within a sub-step
    ledgers = restored;
    staggered = nextStaggered;
    lag = restoredLag;
    lastLedger.Clear();
    if (staggered) {
      log->info("session {}: staggered coupling: GasFields of step n are answered with the sources "
                "of step n-1{}",
                session,
                lag.hasPending ? " (pending sources of the restart step read from the state file)"
                : c.initial_state_file().empty()
                    ? "; step 1 gets the sources of the initial state"
                    : "; the state file holds no pending sources: the first step gets the sources "
                      "of the restart state");
    }
    if (ledgers.speciesToGas.size() != static_cast<std::size_t>(c.species_size())) {
      ledgers.speciesToGas.assign(static_cast<std::size_t>(c.species_size()), 0.0);
    }
    cells = proto::cellCount(c.coupling_mesh());
    species = static_cast<std::uint32_t>(c.species_size());
    speciesNames.clear();
    for (const auto& s : c.species()) {
      speciesNames.push_back(s.name());
    }
    const auto& g = c.coupling_mesh().cartesian();
    cellVolume = g.spacing().x() * g.spacing().y() * g.spacing().z();
    lastStep = c.start_step();
    state = SessionState::Configured;
    const double dtMax = system->dtDemMax();
    log->info("session {}: configured by '{}': {} particles{}, grid {} x {} x {}, {} gas species, "
              "backend {}, dt_dem_max {:.4g} s, start step {}",
              session, oName, system->particleCount(),
              c.initial_state_file().empty() ? "" : " from " + safe(c.initial_state_file(), 200),
              g.counts().x(), g.counts().y(), g.counts().z(), species, system->backendName(), dtMax,
              lastStep);
    auto m = proto::makeConfigured(cells, system->particleCount(), species, nSub, dtMax);
    send(r.peer, std::move(m), r.message.envelope().sequence(), lastStep);
  }

  void onGrant(const proto::Request& r) {
    const auto& env = r.message.envelope();
    const auto& g = env.step_grant();
    if (r.peer != oPeer) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE, "only the session's orchestrator grants steps");
      return;
    }
    if (state != SessionState::Configured) {
      refuse(r, v1::ERROR_CODE_NOT_CONFIGURED, "send Configure before the first StepGrant");
      return;
    }
    if (grant) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("step {} is still running (waiting for the CFD participant's GasFields)",
                         grant->step));
      return;
    }
    if (env.step() != lastStep + 1) {
      refuse(
          r, v1::ERROR_CODE_OUT_OF_ORDER,
          fmt::format("StepGrant for step {}, but the next step is {}", env.step(), lastStep + 1));
      return;
    }
    const double dtMax = system->dtDemMax();
    if (g.n_sub() > limits.subSteps) {
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
             fmt::format("StepGrant of step {}: n_sub = {} exceeds the limit {} (coredem-dem "
                         "--max-sub-steps); use a smaller CFD step",
                         env.step(), g.n_sub(), limits.subSteps));
      return;
    }
    if (!(g.dt_cfd() > 0.0) || !std::isfinite(g.dt_cfd()) || g.n_sub() < 1) {
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
             fmt::format("StepGrant of step {}: dt_cfd = {} s and n_sub = {} must be positive",
                         env.step(), g.dt_cfd(), g.n_sub()));
      return;
    }
    if (g.dt_cfd() / g.n_sub() > dtMax * (1.0 + kDtTolerance)) {
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
             fmt::format("StepGrant of step {}: dt_cfd/n_sub = {:.6g} s exceeds this DEM's "
                         "dt_dem_max = {:.6g} s; use n_sub >= {:.0f}",
                         env.step(), g.dt_cfd() / g.n_sub(), dtMax,
                         std::ceil(g.dt_cfd() / dtMax))); // a double: never throws or wraps
      return;
    }
    if (g.dt_dem() > 0.0 &&
        std::abs(g.dt_dem() * g.n_sub() - g.dt_cfd()) > kDtTolerance * g.dt_cfd()) {
      refuse(r, v1::ERROR_CODE_INVALID_CONFIGURATION,
             fmt::format("StepGrant of step {}: dt_dem * n_sub = {:.17g} s differs from dt_cfd = "
                         "{:.17g} s",
                         env.step(), g.dt_dem() * g.n_sub(), g.dt_cfd()));
      return;
    }
    Grant next;
    next.peer = r.peer;
    next.sequence = env.sequence();
    next.step = env.step();
    next.time = env.time();
    next.dtCfd = g.dt_cfd();
    next.nSub = g.n_sub();
    next.checkpointDir = g.has_checkpoint() ? g.checkpoint().directory() : std::string();
    grant = next;
    log->debug("session {}: step {} granted (dt {} s, n_sub {})", session, next.step, next.dtCfd,
               next.nSub);
    if (held) {
      auto h = std::move(*held);
      held.reset();
      runStep(h.request);
    } else if (rankCount > 0 && partials.size() == rankCount) {
      runPartialStep();
    }
  }

  proto::Expectation gasExpectation(const proto::PeerId& peer) const {
    proto::Expectation e;
    e.types = {v1::MESSAGE_TYPE_GAS_FIELDS};
    e.sessionId = session;
    e.sequenceAfter = lastSequence.count(peer) != 0 ? lastSequence.at(peer) : 0;
    e.step = grant ? grant->step : lastStep + 1;
    e.cells = cells;
    e.species = species;
    return e;
  }

  void onGasFields(proto::Request& r) {
    const int rank = rankOf(r.peer);
    if (rank < 0) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             "GasFields come from the session's CFD participant: send Hello{role=CFD} with the "
             "session id first");
      return;
    }
    if (r.message.envelope().gas_fields().partial()) {
      onPartialGasFields(r, static_cast<std::uint32_t>(rank));
      return;
    }
    if (rankCount > 1) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("whole-grid GasFields in a session whose CFD participant runs on {} "
                         "ranks: each rank sends a partial GasFields of the cells it touches "
                         "(docs/protocol.md \"Decomposed CFD\")",
                         rankCount));
      return;
    }
    if (!partials.empty()) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             "a partial GasFields of this step is already waiting; send partial ones only");
      return;
    }
    if (held) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("the GasFields of step {} are already waiting for their StepGrant",
                         held->request.message.envelope().step()));
      return;
    }
    if (!grant) { // the grant is on its way from O on another connection: wait for it
      held = Held{std::move(r), Clock::now()};
      return;
    }
    runStep(r);
  }

  /// One reply of a step: the request it answers and, for a partial GasFields, its cells.
  struct StepReply {
    const proto::Request* request = nullptr;
    std::span<const std::int64_t> cells; ///< partial: the rank's coupling cells
    bool partial = false;
  };

  void refuseAll(const std::vector<StepReply>& to, v1::ErrorCode code, const std::string& text) {
    for (const StepReply& t : to) {
      refuse(*t.request, code, text);
    }
  }

  void runStep(const proto::Request& r) { runStepOn(r.message, {StepReply{&r, {}, false}}); }

  // ---- decomposed CFD (docs/protocol.md "Decomposed CFD") ----------------------------------
  void onPartialGasFields(proto::Request& r, std::uint32_t rank) {
    if (held) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             "a whole-grid GasFields of this step is already waiting; send whole-grid ones only");
      return;
    }
    if (partials.count(rank) != 0) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("CFD rank {} already sent its GasFields of step {}", rank,
                         partials.at(rank).request.message.envelope().step()));
      return;
    }
    partials.emplace(rank, Held{std::move(r), Clock::now()});
    if (grant && partials.size() == rankCount) {
      runPartialStep();
    }
  }

  /// Answers every waiting rank and the orchestrator's grant with `code`/`text`; the step is
  /// not run (the orchestrator stops the run).
  void failPartialStep(v1::ErrorCode code, const std::string& text) {
    log->error("session {}: {}", session, text);
    for (auto& [rank, h] : partials) {
      refuse(h.request, code, text);
    }
    partials.clear();
    if (grant) {
      send(grant->peer, proto::makeError(code, text, grant->sequence, v1::MESSAGE_TYPE_STEP_GRANT),
           grant->sequence, grant->step);
      grant.reset();
    }
  }

  /// Combines the K partial GasFields in rank order (independent of their arrival order) into
  /// the whole-grid gas of the step and runs it: V_g = sum_r V_r,g, f_g = sum_r S_r,g / V_g,
  /// fluid fraction V_g / V_c (exactly 1 within 1e-12 of V_c, 0 for cells no rank touches, whose
  /// gas is the volume-weighted average of all cells).
  void runPartialStep() {
    namespace f = proto::fields;
    std::map<std::uint32_t, Held> parts;
    parts.swap(partials);
    std::vector<StepReply> to;
    for (auto& [rank, h] : parts) { // std::map: rank order
      to.push_back(StepReply{
          &h.request, h.request.message.findArray(f::kTouchedCells)->as<std::int64_t>(), true});
    }
    const auto& first = parts.begin()->second.request.message.envelope();
    const auto n = static_cast<std::size_t>(cells);
    std::vector<double> volume(n, 0.0);
    for (const StepReply& t : to) {
      const auto fv = t.request->message.values<double>(f::kFluidVolume);
      for (std::size_t i = 0; i < t.cells.size(); ++i) {
        volume[static_cast<std::size_t>(t.cells[i])] += fv[i];
      }
    }
    double totalVolume = 0.0;
    for (std::size_t g = 0; g < n; ++g) {
      totalVolume += volume[g];
    }
    if (!(totalVolume > 0.0)) {
      failPartialStep(v1::ERROR_CODE_INVALID_CONFIGURATION,
                      fmt::format("step {}: the {} CFD ranks' GasFields touch no coupling cell",
                                  first.step(), rankCount));
      refuseAll(to, v1::ERROR_CODE_INVALID_CONFIGURATION, "the ranks touch no coupling cell");
      return;
    }
    auto gas =
        proto::makeGasFields(first.step(), first.time(), first.gas_fields().dt(), cells, species);
    for (const auto& spec : f::gasFields()) {
      const std::size_t q = f::componentsOf(spec.extent, species);
      std::vector<double> sum(n * q, 0.0), all(q, 0.0);
      for (const StepReply& t : to) {
        const auto v = t.request->message.values<double>(spec.name);
        for (std::size_t i = 0; i < t.cells.size(); ++i) {
          const std::size_t g = static_cast<std::size_t>(t.cells[i]);
          for (std::size_t c = 0; c < q; ++c) {
            sum[g * q + c] += v[i * q + c];
          }
        }
      }
      for (std::size_t g = 0; g < n; ++g) {
        for (std::size_t c = 0; c < q; ++c) {
          all[c] += sum[g * q + c];
        }
      }
      for (std::size_t g = 0; g < n; ++g) {
        for (std::size_t c = 0; c < q; ++c) {
          sum[g * q + c] = volume[g] > 0.0 ? sum[g * q + c] / volume[g] : all[c] / totalVolume;
        }
      }
      gas.addArray<double>(spec.name, std::span<const double>(sum),
                           f::shapeOf(spec.extent, cells, species));
    }
    std::vector<double> fraction(n, 1.0);
    bool partFluid = false;
    for (std::size_t g = 0; g < n; ++g) {
      const double v = volume[g];
      if (v > cellVolume * (1.0 + 1e-6)) {
        failPartialStep(
            v1::ERROR_CODE_INVALID_CONFIGURATION,
            fmt::format("step {}: the CFD ranks' fluid volume in coupling cell {} is {} "
                        "m3, more than the cell's {} m3 (overlapping decomposition?)",
                        first.step(), g, v, cellVolume));
        refuseAll(to, v1::ERROR_CODE_INVALID_CONFIGURATION, "overlapping fluid volumes");
        return;
      }
      fraction[g] = std::abs(v - cellVolume) <= 1e-12 * cellVolume ? 1.0
                    : v <= 1e-12 * cellVolume                      ? 0.0
                                                                   : std::min(1.0, v / cellVolume);
      partFluid = partFluid || fraction[g] != 1.0;
    }
    if (partFluid) {
      gas.addArray<double>(f::kFluidFraction, std::span<const double>(fraction), {cells});
    }
    if (const auto st = proto::validateGasRanges(gas); !st.ok()) {
      const std::string text = "the combined GasFields of the CFD ranks: " + st.message;
      refuseAll(to, st.code, text);
      if (grant) {
        send(grant->peer,
             proto::makeError(st.code, text, grant->sequence, v1::MESSAGE_TYPE_STEP_GRANT),
             grant->sequence, grant->step);
        grant.reset();
      }
      return;
    }
    runStepOn(gas, to);
  }

  /// The Sources answering the GasFields `gasMessage` of the step with the cell sources `s`: the
  /// whole grid, or each rank's cells (decomposed CFD).
  void sendSources(const std::vector<StepReply>& to, const proto::Message& gasMessage,
                   const dem::CellSources& s, const v1::Ledger& ledger) {
    namespace f = proto::fields;
    const auto& env = gasMessage.envelope();
    const auto n = static_cast<std::size_t>(cells);
    const double dt = grant->dtCfd;
    for (const StepReply& t : to) {
      const auto& req = t.request->message.envelope();
      const std::uint64_t rows = t.partial ? t.cells.size() : cells;
      auto src = proto::makeSources(env.step(), env.time(), dt, cells, species, grant->nSub);
      if (t.partial) {
        src.envelope().mutable_sources()->set_partial(true);
        src.envelope().mutable_sources()->set_touched_count(rows);
        src.addArray<std::int64_t>(f::kTouchedCells, t.cells, {rows});
      }
      std::vector<double> picked;
      auto add = [&](std::string_view name, const std::vector<double>& v) {
        std::span<const double> values(v);
        if (t.partial) {
          const std::size_t q = v.size() / n;
          picked.resize(t.cells.size() * q);
          for (std::size_t i = 0; i < t.cells.size(); ++i) {
            for (std::size_t c = 0; c < q; ++c) {
              picked[i * q + c] = v[static_cast<std::size_t>(t.cells[i]) * q + c];
            }
          }
          values = picked;
        }
        src.addArray<double>(name, values, f::shapeOf(name, rows, species));
      };
      add(f::kVoidFraction, s.epsG);
      add(f::kDragCoefficient, s.kSl);
      add(f::kDragCoefficientTimesUs, s.kSlUs);
      add(f::kHeatCoefficient, s.heatH);
      add(f::kHeatCoefficientTimesTp, s.heatHTp);
      add(f::kSpeciesSources, s.rSpecies);
      add(f::kHomogeneousHeat, s.qHom);
      // v1.3: the radiation heat of the particles goes to the gas; an older peer never sees it
      // (the heat then stays with the particles' environment, as before 1.3).
      if (const int r = rankOf(t.request->peer);
          r >= 0 && rankMinors[static_cast<std::size_t>(r)] >= proto::kMinorRadiation &&
          s.qRad.size() == n) {
        add(f::kRadiationHeat, s.qRad);
      }
      *src.envelope().mutable_sources()->mutable_ledger() = ledger;
      send(t.request->peer, std::move(src), req.sequence(), env.step());
    }
  }

  /// Staggered: answers the GasFields of step n at once with the pending sources of step n-1 (for
  /// the first step of a session without pending sources: those of the current state, evaluated
  /// without advancing) and books them as applied with this step's T_g and Δt, the values the gas
  /// applies them with. False when the session ended.
  bool sendLaggedSources(const std::vector<StepReply>& to, const proto::Message& gasMessage,
                         const dem::GasFieldsView& gas) {
    if (!lag.hasPending) {
      try {
        lag.pending = system->evaluateSources(grant->dtCfd / grant->nSub);
        lag.pendingDt = 0.0; // S^0: rates of the initial state, applied as they are
        lag.hasPending = true;
      } catch (const std::exception& e) {
        log->error("session {}: step {}: the initial sources failed in the DEM core: {}", session,
                   grant->step, e.what());
        refuseAll(to, v1::ERROR_CODE_INTERNAL,
                  fmt::format("step {}: evaluating the initial sources failed in the DEM core: {}",
                              grant->step, e.what()));
        endSession(fmt::format("step {}: the initial sources failed: {}", grant->step, e.what()),
                   v1::ERROR_CODE_INTERNAL);
        return false;
      }
      log->info("session {}: step {} gets the sources of the particles at t = {} s (staggered "
                "coupling, no pending sources)",
                session, grant->step, grant->time);
    }
    if (lastLedger.ByteSizeLong() == 0) { // the first step of a session
      lastLedger = ledgerMessage(system->particles());
    }
    dem::CellSources& p = lag.pending;
    const double dt = grant->dtCfd;
    const auto n = static_cast<std::size_t>(cells);
    // The released mass and its heat (R_species, Q_hom) are amounts over the step that computed
    // them: with a different Δt now (adaptive Δt_CFD) the rates are rescaled so that the gas gets
    // exactly what the particles released. The coefficients (ε_g, K_sl, K_sl U_s, H, H T_p)
    // describe the particles and are sent as they are.
    if (lag.pendingDt > 0.0 && lag.pendingDt != dt) {
      const double scale = lag.pendingDt / dt;
      for (double& v : p.rSpecies) {
        v *= scale;
      }
      for (double& v : p.qHom) {
        v *= scale;
      }
      for (double& v : p.qRad) {
        v *= scale;
      }
    }
    double heat = 0.0;
    for (std::size_t c = 0; c < n; ++c) {
      heat += p.heatHTp[c] - p.heatH[c] * gas.Tg[c];
    }
    lag.heatApplied += heat * cellVolume * dt;
    for (std::size_t k = 0; k < species; ++k) {
      double sum = 0.0;
      for (std::size_t c = 0; c < n; ++c) {
        sum += p.rSpecies[c * species + k];
      }
      ledgers.speciesToGas[k] += sum * cellVolume * dt;
    }
    sendSources(to, gasMessage, p, lastLedger);
    lag.hasPending = false; // applied by the gas in this step; the step computes the next ones
    return true;
  }

  void runStepOn(const proto::Message& gasMessage, const std::vector<StepReply>& to) {
    const auto& env = gasMessage.envelope();
    const auto& body = env.gas_fields();
    if (std::abs(body.dt() - grant->dtCfd) > kDtTolerance * grant->dtCfd) {
      refuseAll(to, v1::ERROR_CODE_OUT_OF_ORDER,
                fmt::format("GasFields of step {} carry dt = {:.17g} s; the step was granted with "
                            "dt = {:.17g} s",
                            env.step(), body.dt(), grant->dtCfd));
      return;
    }
    const auto t0 = Clock::now();
    namespace f = proto::fields;
    dem::GasFieldsView view;
    view.ug = gasMessage.values<double>(f::kGasVelocity);
    view.gradP = gasMessage.values<double>(f::kPressureGradient);
    view.Tg = gasMessage.values<double>(f::kGasTemperature);
    view.rhoG = gasMessage.values<double>(f::kGasDensity);
    view.muG = gasMessage.values<double>(f::kGasViscosity);
    view.kappaG = gasMessage.values<double>(f::kGasConductivity);
    view.cpG = gasMessage.values<double>(f::kGasHeatCapacity);
    view.Yg = gasMessage.values<double>(f::kGasMassFractions);
    if (const auto ff = gasMessage.findArray(f::kFluidFraction)) {
      view.fluidFraction = ff->as<double>();
    }
    try {
      system->setGasFields(view);
    } catch (const coredem::UserError& e) {
      refuseAll(to, v1::ERROR_CODE_INVALID_CONFIGURATION,
                fmt::format("GasFields of step {}: {}", env.step(), e.what()));
      return;
    }
    auto tGas = Clock::now();
    xt.unpack += std::chrono::duration<double>(tGas - t0).count();
    if (staggered) { // the lagged Sources leave before the step is computed (timed as pack_send)
      if (!sendLaggedSources(to, gasMessage, view)) {
        return;
      }
      const auto tSent = Clock::now();
      xt.packSend += std::chrono::duration<double>(tSent - tGas).count();
      tGas = tSent;
    }
    const dem::CellSources* s = nullptr;
    try {
      s = &system->advance(grant->dtCfd, static_cast<int>(grant->nSub));
    } catch (const dem::Interrupted& e) {
      // A signal (or DemServer::stop) during a long step: answer both members and end the
      // session at once; run() then returns.
      log->warn("session {}: step {} stopped by a signal ({}): ending the session", session,
                grant->step, e.what());
      const std::string reason = fmt::format("the server is stopping: step {} was interrupted ({})",
                                             grant->step, e.what());
      if (!staggered) { // staggered: the GasFields were answered with the lagged Sources
        refuseAll(to, v1::ERROR_CODE_UNEXPECTED_MESSAGE, reason);
      }
      endSession(reason); // answers the StepGrant too
      return;
    } catch (const std::exception& e) {
      log->error("session {}: step {} failed in the DEM core: {}", session, grant->step, e.what());
      if (!staggered) {
        refuseAll(to, v1::ERROR_CODE_INTERNAL,
                  fmt::format("step {} failed in the DEM core: {}", grant->step, e.what()));
      }
      auto m = proto::makeError(v1::ERROR_CODE_INTERNAL, e.what(), grant->sequence,
                                v1::MESSAGE_TYPE_STEP_GRANT);
      send(grant->peer, std::move(m), grant->sequence, grant->step);
      const auto failed = grant->step;
      grant.reset();
      // The DEM state is unknown after a failed step: end the session rather than leave it
      // half-alive (every later step would fail too).
      endSession(fmt::format("step {} failed in the DEM core: {}", failed, e.what()),
                 v1::ERROR_CODE_INTERNAL);
      return;
    }
    const double dt = grant->dtCfd;
    const auto tAdvanced = Clock::now();
    xt.advance += std::chrono::duration<double>(tAdvanced - tGas).count();
    xt.particleSubSteps += static_cast<std::uint64_t>(system->particleCount()) * grant->nSub;

    // Ledgers: the species the particles gave to the gas during this step (the heat from the gas
    // is the DEM core's HeatTotals::convection, booked there once).
    // Staggered: booked here as computed; the gas gets them with the next GasFields, where they
    // are booked as applied (sendLaggedSources).
    const auto n = static_cast<std::size_t>(cells);
    std::vector<double>& booked = staggered ? lag.speciesComputed : ledgers.speciesToGas;
    for (std::size_t k = 0; k < species; ++k) {
      double sum = 0.0;
      for (std::size_t c = 0; c < n; ++c) {
        sum += s->rSpecies[c * species + k];
      }
      booked[k] += sum * cellVolume * dt;
    }
    if (staggered) {
      lag.pending = *s;
      lag.pendingDt = dt;
      lag.hasPending = true;
    }
    const auto particles = system->particles();
    v1::Ledger ledger = ledgerMessage(particles);
    const auto tLedgers = Clock::now();
    xt.ledgers += std::chrono::duration<double>(tLedgers - tAdvanced).count();

    // Sources to C (sequential; staggered sent them before advancing): the whole grid, or each
    // rank's cells.
    if (!staggered) {
      sendSources(to, gasMessage, *s, ledger);
    }
    lastLedger = ledger;
    xt.packSend += std::chrono::duration<double>(Clock::now() - tLedgers).count();
    {
      auto ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
      };
      log->debug("session {}: step {}: setGasFields {:.3f} ms, advance ({} sub-steps) {:.3f} ms, "
                 "ledgers + Sources {:.3f} ms",
                 session, env.step(), ms(t0, tGas), grant->nSub, ms(tGas, tAdvanced),
                 ms(tAdvanced, Clock::now()));
    }

    // Checkpoint requested with the grant, then StepDone to O.
    v1::StepDone done;
    *done.mutable_ledger() = ledger;
    bool checkpointOk = true;
    std::string checkpointError;
    if (!grant->checkpointDir.empty()) {
      try {
        const auto tc = Clock::now();
        const auto files = writeCheckpoint(grant->checkpointDir, grant->step);
        xt.checkpoint += std::chrono::duration<double>(Clock::now() - tc).count();
        done.mutable_checkpoint()->set_directory(grant->checkpointDir);
        for (const auto& file : files) {
          done.mutable_checkpoint()->add_files(file);
        }
      } catch (const std::exception& e) {
        checkpointOk = false;
        checkpointError = e.what();
      }
    }
    const auto tDone = Clock::now();
    addDiagnostics(done, particles);
    if (staggered) { // tells the orchestrator that this server runs the scheme it asked for
      proto::addNamedValue(done.mutable_diagnostics(), std::string(f::kCouplingLagDiagnostic), 1.0);
    }
    done.set_wall_seconds(std::chrono::duration<double>(Clock::now() - t0).count());
    if (checkpointOk) {
      send(grant->peer, proto::makeStepDone(grant->step, grant->time, done), grant->sequence,
           grant->step);
      xt.packSend += std::chrono::duration<double>(Clock::now() - tDone).count();
    } else {
      log->error("session {}: checkpoint of step {} into {} failed: {}", session, grant->step,
                 safe(grant->checkpointDir, 200), safe(checkpointError, 400));
      send(grant->peer,
           proto::makeError(
               v1::ERROR_CODE_CHECKPOINT_FAILED,
               fmt::format("step {} done, but writing its checkpoint into {} failed: {}",
                           grant->step, safe(grant->checkpointDir, 200), checkpointError),
               grant->sequence, v1::MESSAGE_TYPE_STEP_GRANT),
           grant->sequence, grant->step);
    }
    lastStep = grant->step;
    ++stepsDone;
    grant.reset();
    stepEnd = Clock::now();
    ++xt.steps;
    if (opt.timers && opt.timersEvery > 0 && xt.steps % opt.timersEvery == 0) {
      log->info("session {}: {}", session,
                timersReport(xt, system->stageTimes(),
                             std::chrono::duration<double>(Clock::now() - started).count(), false));
    }
  }

  v1::Ledger ledgerMessage(const dem::ParticleData& p) const {
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
    if (staggered) {
      // The lag (docs/coupling-schemes.md "Ledgers"): what the particles exchanged minus what the
      // gas has been handed, i.e. the pending step's transfer minus the first step's initial one.
      proto::addNamedValue(l.mutable_energy(), "dem.heat_in_flight_J",
                           heat.convection + lag.heatApplied);
      for (std::size_t k = 0; k < speciesNames.size(); ++k) {
        proto::addNamedValue(l.mutable_species(),
                             "dem.species_in_flight." + speciesNames[k] + "_kg",
                             lag.speciesComputed[k] - ledgers.speciesToGas[k]);
      }
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

  void addDiagnostics(v1::StepDone& done, const dem::ParticleData& p) const {
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
  }

  /// Writes DIR/dem.h5 (temp file + rename) and returns the file names relative to DIR.
  std::vector<std::string> writeCheckpoint(const std::string& dir, std::int64_t step) {
    fs::create_directories(dir);
    const fs::path final = fs::path(dir) / "dem.h5";
    const fs::path tmp = fs::path(dir) / ".dem.h5.tmp";
    fs::remove(tmp);
    system->writeState(tmp.string(), proto::kProtocolVersion.toString());
    ServerLedgers l = ledgers;
    writeServerLedgers(tmp.string(), l, step, session);
    if (staggered) {
      writeStaggeredState(tmp.string(), lag);
    }
    syncFile(tmp);
    fs::rename(tmp, final);
    log->info("session {}: checkpoint of step {} written to {}", session, step,
              safe(final.string(), 200));
    return {"dem.h5"};
  }

  void onCheckpoint(const proto::Request& r) {
    const auto& env = r.message.envelope();
    if (r.peer != oPeer) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             "only the session's orchestrator asks for checkpoints");
      return;
    }
    if (state != SessionState::Configured) {
      refuse(r, v1::ERROR_CODE_NOT_CONFIGURED, "nothing to checkpoint before Configure");
      return;
    }
    if (grant) {
      refuse(
          r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
          fmt::format("step {} is running; ask for a checkpoint between steps (or with the grant)",
                      grant->step));
      return;
    }
    const auto& dir = env.checkpoint_request().directory();
    if (dir.empty()) {
      refuse(r, v1::ERROR_CODE_CHECKPOINT_FAILED, "CheckpointRequest without a directory");
      return;
    }
    try {
      auto files = writeCheckpoint(dir, lastStep);
      send(r.peer, proto::makeCheckpointDone(lastStep, dir, files), env.sequence(), lastStep);
    } catch (const std::exception& e) {
      refuse(
          r, v1::ERROR_CODE_CHECKPOINT_FAILED,
          fmt::format("writing the state of step {} into {} failed: {}", lastStep, dir, e.what()));
    }
  }

  void onShutdown(const proto::Request& r) {
    const auto& env = r.message.envelope();
    if (r.peer != oPeer) {
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             "only the session's orchestrator ends the session");
      return;
    }
    send(r.peer, proto::makeAck("session " + session + " ended"), env.sequence(), env.step());
    endSession("Shutdown from the orchestrator" + (env.shutdown().reason().empty()
                                                       ? std::string()
                                                       : ": " + safe(env.shutdown().reason())));
  }

  // ---- dispatch --------------------------------------------------------------------------
  void handle(proto::Request& r) {
    const auto& env = r.message.envelope();
    if (!r.status.ok()) {
      refuse(r, r.status.code, r.status.message);
      return;
    }
    const auto type = env.type();
    if (type == v1::MESSAGE_TYPE_UNSPECIFIED || !v1::MessageType_IsValid(type)) {
      // Checked first, from anyone in any state (docs/protocol.md §5): an empty message (one
      // zero-byte frame parses as an Envelope with nothing set) or a type of a newer version.
      const auto s = proto::validate(r.message, proto::Expectation{});
      refuse(r, v1::ERROR_CODE_UNKNOWN_TYPE, s.message);
      return;
    }
    if (type == v1::MESSAGE_TYPE_HELLO) {
      onHello(r);
      return;
    }
    if (type == v1::MESSAGE_TYPE_HEARTBEAT) {
      if (state != SessionState::Idle && (r.peer == oPeer || rankOf(r.peer) >= 0)) {
        lastActivity = Clock::now();
      }
      send(r.peer, proto::makeHeartbeat(stateName(state)), env.sequence(), lastStep);
      return;
    }
    if (state == SessionState::Idle) {
      refuse(r, v1::ERROR_CODE_NOT_CONFIGURED,
             "no active session: an orchestrator starts one with Hello{role=ORCHESTRATOR}");
      return;
    }
    if (r.peer != oPeer && rankOf(r.peer) < 0) {
      refuse(r, v1::ERROR_CODE_UNKNOWN_SESSION,
             "this connection has not joined the active session: send Hello first");
      return;
    }
    switch (type) { // what D sends, or C sends to O: never D's to receive
    case v1::MESSAGE_TYPE_WELCOME:
    case v1::MESSAGE_TYPE_REJECT:
    case v1::MESSAGE_TYPE_CONFIGURED:
    case v1::MESSAGE_TYPE_SOURCES:
    case v1::MESSAGE_TYPE_STEP_DONE:
    case v1::MESSAGE_TYPE_CHECKPOINT_DONE:
    case v1::MESSAGE_TYPE_ERROR:
    case v1::MESSAGE_TYPE_ACK:
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("{} is a reply, never sent to the DEM server; it takes Hello, Configure, "
                         "StepGrant, GasFields, CheckpointRequest, Heartbeat and Shutdown",
                         proto::messageTypeName(type)));
      return;
    default:
      break;
    }
    proto::Expectation e;
    if (type == v1::MESSAGE_TYPE_GAS_FIELDS) {
      if (state != SessionState::Configured) {
        refuse(r, v1::ERROR_CODE_NOT_CONFIGURED, "GasFields before the orchestrator's Configure");
        return;
      }
      e = gasExpectation(r.peer);
    } else {
      e.sessionId = session;
      e.sequenceAfter = lastSequence[r.peer];
    }
    const auto tValidate = Clock::now();
    // The CFD's step and the transfer (decomposed: until the first rank's GasFields).
    if (type == v1::MESSAGE_TYPE_GAS_FIELDS && stepEnd && partials.empty()) {
      xt.waitPeer += std::chrono::duration<double>(lastReceived - *stepEnd).count();
    }
    auto s = proto::validate(r.message, e);
    if (s.ok() && type == v1::MESSAGE_TYPE_GAS_FIELDS && !env.gas_fields().partial()) {
      // Physical ranges (docs/protocol.md §3); a partial GasFields holds volume-weighted sums,
      // checked once combined (runPartialStep).
      s = proto::validateGasRanges(r.message);
    }
    if (type == v1::MESSAGE_TYPE_GAS_FIELDS) {
      xt.validate += std::chrono::duration<double>(Clock::now() - tValidate).count();
    }
    if (!s.ok()) {
      refuse(r, s.code, s.message);
      return;
    }
    lastSequence[r.peer] = env.sequence();
    lastActivity = Clock::now();
    switch (type) {
    case v1::MESSAGE_TYPE_CONFIGURE:
      onConfigure(r);
      break;
    case v1::MESSAGE_TYPE_STEP_GRANT:
      onGrant(r);
      break;
    case v1::MESSAGE_TYPE_GAS_FIELDS:
      onGasFields(r);
      break;
    case v1::MESSAGE_TYPE_CHECKPOINT_REQUEST:
      onCheckpoint(r);
      break;
    case v1::MESSAGE_TYPE_SHUTDOWN:
      onShutdown(r);
      break;
    default:
      refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
             fmt::format("coredem-dem does not take {} messages", proto::messageTypeName(type)));
    }
  }

  void housekeeping() {
    const auto now = Clock::now();
    if (held && std::chrono::duration<double>(now - held->since).count() > opt.grantWaitSeconds) {
      auto h = std::move(*held);
      held.reset();
      refuse(h.request, v1::ERROR_CODE_TIMEOUT,
             fmt::format("no StepGrant for step {} from orchestrator '{}' within {} s",
                         h.request.message.envelope().step(), oName, opt.grantWaitSeconds));
    }
    if (!partials.empty()) {
      auto oldest = partials.begin()->second.since;
      for (const auto& [rank, h] : partials) {
        oldest = std::min(oldest, h.since);
      }
      if (std::chrono::duration<double>(now - oldest).count() > opt.grantWaitSeconds) {
        const std::int64_t step = partials.begin()->second.request.message.envelope().step();
        if (partials.size() < rankCount) {
          std::string missing;
          for (std::uint32_t r = 0; r < rankCount; ++r) {
            if (partials.count(r) == 0) {
              missing += fmt::format("{}{}", missing.empty() ? "" : ", ", r);
            }
          }
          failPartialStep(v1::ERROR_CODE_TIMEOUT,
                          fmt::format("no GasFields of step {} from CFD rank(s) {} of {} within {} "
                                      "s of the first rank's (coredem-dem --grant-wait-s)",
                                      step, missing, rankCount, opt.grantWaitSeconds));
        } else {
          failPartialStep(v1::ERROR_CODE_TIMEOUT,
                          fmt::format("no StepGrant for step {} from orchestrator '{}' within {} s",
                                      step, oName, opt.grantWaitSeconds));
        }
      }
    }
    if (state != SessionState::Idle &&
        std::chrono::duration<double>(now - lastActivity).count() > opt.sessionTimeoutSeconds) {
      endSession(fmt::format("no message from orchestrator '{}' or CFD participant '{}' for {} s "
                             "(--timeout-s)",
                             oName, cfdName(), opt.sessionTimeoutSeconds),
                 v1::ERROR_CODE_TIMEOUT);
    }
  }
};

DemServer::DemServer(ServerOptions options)
    : _impl(std::make_unique<Impl>(std::move(options))) {
  auto& m = *_impl;
  google::protobuf::SetLogHandler(&protobufLog);
  dem::parseBackend(m.opt.backend); // fail early on a bad name
  if (!proto::isLoopbackEndpoint(m.opt.bind) && m.opt.curveKeysDir.empty()) {
    COREDEM_CHECK(
        m.opt.insecure,
        "--bind {} is not a loopback address: give --curve-keys DIR (CURVE encryption "
        "and authentication, docs/architecture.md) or, on a trusted network only, --insecure",
        m.opt.bind);
    m.log->warn("binding {} WITHOUT encryption (--insecure): anyone who reaches this port can "
                "drive this server",
                m.opt.bind);
  }
  m.endpoint = m.server.bind(m.opt.bind);
  m.log->info("coredem-dem listening on {} (backend {}, threads {}, session timeout {} s, memory "
              "budget {}: up to {} particles and {} cells; messages up to {}; n_sub up to {})",
              m.endpoint, m.opt.backend, m.opt.threads, m.opt.sessionTimeoutSeconds,
              formatBytes(m.limits.memoryBytes), m.limits.particles, m.limits.cells,
              m.opt.maxMessageBytes > 0
                  ? formatBytes(static_cast<std::uint64_t>(m.opt.maxMessageBytes))
                  : std::string("unlimited"),
              m.limits.subSteps);
}

DemServer::~DemServer() = default;

std::string DemServer::endpoint() const {
  return _impl->endpoint;
}
SessionState DemServer::sessionState() const {
  return _impl->state;
}

bool DemServer::poll(std::chrono::milliseconds wait) {
  auto& m = *_impl;
  if (m.stopFlag.load()) {
    return false;
  }
  auto req = m.server.receive(wait);
  m.lastReceived = Clock::now();
  for (const auto& p : m.server.takeDisconnected()) {
    m.onDisconnected(p);
  }
  if (req) {
    try {
      m.handle(*req);
    } catch (const std::exception& e) {
      // A bug or an unexpected failure while handling one message: answer; a session member's
      // message ends the session (its state is unknown), a stranger's changes nothing.
      const auto type = proto::messageTypeName(req->message.envelope().type());
      m.log->error("internal error while handling a {} message: {}", type, e.what());
      m.send(req->peer,
             proto::makeError(v1::ERROR_CODE_INTERNAL, std::string("internal error: ") + e.what(),
                              req->message.envelope().sequence(), req->message.envelope().type()),
             req->message.envelope().sequence(), req->message.envelope().step());
      if (m.isMember(req->peer)) {
        m.endSession(fmt::format("internal error while handling a {} message: {}", type, e.what()),
                     v1::ERROR_CODE_INTERNAL);
      }
    }
  }
  m.housekeeping();
  return !m.stopFlag.load() && !(m.opt.exitAfterSession && m.sessionEnded);
}

int DemServer::run() {
  while (poll(std::chrono::milliseconds(200))) {
  }
  if (_impl->state != SessionState::Idle) {
    _impl->endSession("the server is stopping");
  }
  _impl->log->info("coredem-dem at {} stopped", _impl->endpoint);
  return 0;
}

void DemServer::stop() {
  _impl->stopFlag.store(true);
}

namespace {
void writeKeyPair(const std::string& dir, const std::string& stem) {
  fs::create_directories(dir);
  const auto pair = proto::generateCurveKeyPair();
  const auto write = [](const fs::path& p, const std::string& key, bool secret) {
    const auto tmp = p.string() + ".tmp";
    ::unlink(tmp.c_str());
    // The secret key is created with mode 0600 (never readable by others, not even briefly).
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, secret ? 0600 : 0644);
    COREDEM_CHECK(fd >= 0, "cannot create {}", tmp);
    const std::string line = key + "\n";
    const bool ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) &&
                    ::fsync(fd) == 0;
    ::close(fd);
    COREDEM_CHECK(ok, "cannot write {}", tmp);
    fs::rename(tmp, p);
  };
  write(fs::path(dir) / (stem + ".public"), pair.first, false);
  write(fs::path(dir) / (stem + ".secret"), pair.second, true);
}
} // namespace

void generateCurveKeys(const std::string& dir) {
  writeKeyPair(dir, "server");
}

void generateClientKey(const std::string& dir) {
  writeKeyPair(dir, "client");
}

} // namespace coredem::server
