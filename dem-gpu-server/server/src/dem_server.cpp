// coredem-dem: D of docs/session.md over the protocol library and the DEM core. The server's
// parts, each in its own file: membership.h (who is in the session), step_assembly.h (grants,
// held and partial GasFields; partial_ranks.h combines the ranks'), step_runner.h (one coupled
// step; staggered_lag.h, coupling_fields.h), configured_session.h (what a Configure set up;
// session_setup.h builds it) and replies.h (every message sent). DemServer::Impl below wires
// them to the transport.
#include "coredem/server/dem_server.h"

#include <atomic>
#include <filesystem>
#include <fstream>
#include <optional>
#include <variant>

#include <fcntl.h>
#include <google/protobuf/stubs/logging.h>
#include <sys/stat.h>
#include <unistd.h>

#include "admission.h"
#include "configured_session.h"
#include "coredem/common/check.h"
#include "coredem/common/log.h"
#include "coredem/dem/dem_system.h"
#include "coredem/protocol/protocol.h"
#include "membership.h"
#include "replies.h"
#include "reply_text.h"
#include "session_setup.h"
#include "step_assembly.h"
#include "step_runner.h"
#include "timers.h"

namespace coredem::server {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;
namespace fs = std::filesystem;

namespace {

constexpr const char* kSoftware = "coredem-dem 0.1.0";
/// Unknown Configure options named one by one in the log; the rest are counted.
constexpr std::size_t kLoggedIgnoredOptions = 5;

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

/// The replies of a step run on the partial GasFields `parts` (rank order).
std::vector<StepReply> repliesTo(RankParts& parts) {
  namespace f = proto::fields;
  std::vector<StepReply> to;
  for (auto& [rank, h] : parts) { // std::map: rank order
    to.push_back(StepReply{
        &h.request, h.request.message.findArray(f::kTouchedCells)->as<std::int64_t>(), true});
  }
  return to;
}

} // namespace

/// The wiring of the server's parts: the transport and the dispatch of each message to the part
/// that handles it (membership.h, step_assembly.h, step_runner.h, replies.h), the session's
/// start (session_setup.h) and end.
struct DemServer::Impl {
  ServerOptions opt;
  Limits limits;
  proto::Server server;
  std::string endpoint;
  std::shared_ptr<spdlog::logger> log = coredem::logger("dem.server");
  std::atomic<bool> stopFlag{false};
  bool sessionEnded = false;

  Membership members{log};
  Replies replies{server, members, log};
  StepAssembly assembly{replies, members, log};
  ConfiguredSession session;
  StepRunner runner{session, assembly, replies, members, opt, log};
  Clock::time_point lastReceived{}; ///< when receive() returned the message being handled

  explicit Impl(ServerOptions o)
      : opt(std::move(o))
      , limits(limitsFor(opt.maxMemoryBytes > 0 ? opt.maxMemoryBytes : defaultMaxMemory(),
                         opt.maxSubSteps))
      , server(transportOptions(opt)) {}

  const std::string& sessionId() const { return members.session(); }

  // ---- session ---------------------------------------------------------------------------
  void endSession(const std::string& reason,
                  v1::ErrorCode code = v1::ERROR_CODE_UNEXPECTED_MESSAGE) {
    if (members.state() == SessionState::Idle) {
      return;
    }
    assembly.abandon(code, reason);
    const double secs = std::chrono::duration<double>(Clock::now() - members.started()).count();
    log->info("session {} ended: {} (orchestrator '{}', CFD participant '{}', {} steps, {:.1f} s)",
              sessionId(), reason, members.orchestratorName(), members.cfdName(), session.stepsDone,
              secs);
    if (opt.timers && session.system) {
      const auto st = session.system->stageTimes();
      log->info("session {}: {}", sessionId(), timersReport(runner.times(), st, secs, true));
      const std::string path = opt.timersFile.empty() ? "coredem-dem-timers.json" : opt.timersFile;
      try {
        writeTextFile(path, timersJson(runner.times(), st, secs, sessionId(),
                                       session.system->backendName(), opt.threads));
        log->info("session {}: timers written to {}", sessionId(), path);
      } catch (const std::exception& e) {
        log->error("session {}: {}", sessionId(), e.what());
      }
    }
    runner.reset();
    members.end();
    session.end();
    sessionEnded = true;
  }

  void finishStep(std::optional<SessionEnd> end) {
    if (end) {
      endSession(end->reason, end->code);
    }
  }

  void runStep(const proto::Request& r) {
    finishStep(runner.run(r.message, {StepReply{&r, {}, false}}));
  }

  // ---- decomposed CFD (docs/protocol.md "Decomposed CFD") ----------------------------------
  void runPartialStep() {
    RankParts parts = assembly.takePartials();
    const std::vector<StepReply> to = repliesTo(parts);
    if (auto gas = assembly.combine(to, session.grid, session.cellVolume)) {
      finishStep(runner.run(*gas, to));
    }
  }

  /// A closed connection (the transport's socket monitor): the orchestrator's ends the
  /// session; the CFD participant's frees its role for a new connection.
  void onDisconnected(const proto::PeerId& p) {
    members.forgetSequence(p);
    if (members.state() == SessionState::Idle) {
      return;
    }
    if (p == members.orchestrator()) {
      endSession(
          fmt::format("the connection of orchestrator '{}' closed", members.orchestratorName()),
          v1::ERROR_CODE_TRANSPORT);
    } else if (const int r = members.rankOf(p); r >= 0) {
      const std::string who = members.peerName(p);
      log->warn("session {}: the connection of {} closed; a new CFD participant may join with "
                "the session id",
                sessionId(), who);
      assembly.dropHeldOf(p);
      members.releaseRank(r);
      assembly.rankLeft(static_cast<std::uint32_t>(r), who, session.lastStep);
      members.releaseRankCountIfNoneConnected();
    }
  }

  void onHello(const proto::Request& r) {
    const auto& env = r.message.envelope();
    if (env.body_case() != v1::Envelope::kHello) {
      replies.refuse(r, v1::ERROR_CODE_BODY_MISMATCH, "a HELLO envelope must carry a Hello body");
      return;
    }
    const auto& h = env.hello();
    const auto n =
        proto::negotiate(proto::kProtocolVersion, {h.protocol_major(), h.protocol_minor()});
    if (!n.accepted) {
      replies.reject(r, v1::ERROR_CODE_VERSION, n.status.message);
      return;
    }
    std::optional<Refusal> no;
    if (h.role() == v1::ROLE_ORCHESTRATOR) {
      no = members.admitOrchestrator(r, n.agreed, endpoint);
      if (!no) {
        sessionEnded = false;
      }
    } else if (h.role() == v1::ROLE_CFD) {
      no = members.admitCfd(r, n.agreed, endpoint);
    } else {
      no = Refusal{v1::ERROR_CODE_UNSUPPORTED,
                   "coredem-dem takes sessions of an orchestrator (ROLE_ORCHESTRATOR) and its CFD "
                   "participant (ROLE_CFD) only"};
    }
    if (no) {
      replies.reject(r, no->code, no->text);
      return;
    }
    auto w =
        proto::makeWelcome(v1::ROLE_DEM, kSoftware, n.agreed.major, n.agreed.minor, sessionId());
    replies.send(r.peer, std::move(w), env.sequence(), env.step());
  }

  void onConfigure(const proto::Request& r) {
    const auto& c = r.message.envelope().configure();
    if (r.peer != members.orchestrator()) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     "only the session's orchestrator configures");
      return;
    }
    if (session.stepsDone > 0 || assembly.grant()) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     "the session has started stepping; start a new session to configure again");
      return;
    }
    auto built = setUpSession(c, opt, limits, &stopFlag);
    if (const auto* no = std::get_if<SetupRefusal>(&built)) {
      if (!no->warning.empty()) {
        log->warn("session {}: {}", sessionId(), no->warning);
      }
      replies.refuse(r, no->refusal);
      return;
    }
    SessionSetup& s = std::get<SessionSetup>(built);
    const auto& ignored = s.ignoredOptions;
    for (std::size_t i = 0; i < ignored.size() && i < kLoggedIgnoredOptions; ++i) {
      log->warn("session {}: Configure option '{}' is not a DEM server option (ignored)",
                sessionId(), safe(ignored[i], 64));
    }
    if (ignored.size() > kLoggedIgnoredOptions) {
      log->warn("session {}: {} more Configure options are not DEM server options (ignored)",
                sessionId(), ignored.size() - kLoggedIgnoredOptions);
    }
    s.system->setInterruptFlag(&stopFlag); // SIGINT/SIGTERM stop a long step within a sub-step
    session.start(std::move(s.system), std::move(s.ledgers), s.staggered, std::move(s.lag), c);
    if (session.lag.enabled()) {
      log->info("session {}: staggered coupling: GasFields of step n are answered with the sources "
                "of step n-1{}",
                sessionId(),
                session.lag.hasPending()
                    ? " (pending sources of the restart step read from the state file)"
                : c.initial_state_file().empty()
                    ? "; step 1 gets the sources of the initial state"
                    : "; the state file holds no pending sources: the first step gets the sources "
                      "of the restart state");
    }
    members.setConfigured();
    const auto& system = *session.system;
    const auto& g = c.coupling_mesh().cartesian();
    const double dtMax = system.dtDemMax();
    log->info("session {}: configured by '{}': {} particles{}, grid {} x {} x {}, {} gas species, "
              "backend {}, dt_dem_max {:.4g} s, start step {}",
              sessionId(), members.orchestratorName(), system.particleCount(),
              c.initial_state_file().empty()
                  ? ""
                  : (s.newStart ? " (a new start) from " : " (a restart) from ") +
                        safe(c.initial_state_file(), 200),
              g.counts().x(), g.counts().y(), g.counts().z(), session.grid.species,
              system.backendName(), dtMax, session.lastStep);
    auto m = proto::makeConfigured(session.grid.cells, system.particleCount(), session.grid.species,
                                   s.nSub, dtMax);
    replies.send(r.peer, std::move(m), r.message.envelope().sequence(), session.lastStep);
  }

  void onGrant(const proto::Request& r) {
    if (r.peer != members.orchestrator()) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     "only the session's orchestrator grants steps");
      return;
    }
    if (members.state() != SessionState::Configured) {
      replies.refuse(r, v1::ERROR_CODE_NOT_CONFIGURED, "send Configure before the first StepGrant");
      return;
    }
    if (const auto no =
            assembly.checkGrant(r, session.lastStep, session.system->dtDemMax(), limits.subSteps)) {
      replies.refuse(r, *no);
      return;
    }
    assembly.grantStep(r);
    if (auto h = assembly.takeHeld()) {
      runStep(h->request);
    } else if (assembly.partialsComplete()) {
      runPartialStep();
    }
  }

  void onGasFields(proto::Request& r) {
    const int rank = members.rankOf(r.peer);
    if (rank < 0) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     "GasFields come from the session's CFD participant: send Hello{role=CFD} "
                     "with the session id first");
      return;
    }
    switch (assembly.onGasFields(r, static_cast<std::uint32_t>(rank))) {
    case StepAssembly::Next::RunWhole:
      runStep(r);
      break;
    case StepAssembly::Next::RunPartial:
      runPartialStep();
      break;
    case StepAssembly::Next::Nothing:
      break;
    }
  }

  void onCheckpoint(const proto::Request& r) {
    const auto& env = r.message.envelope();
    if (r.peer != members.orchestrator()) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     "only the session's orchestrator asks for checkpoints");
      return;
    }
    if (members.state() != SessionState::Configured) {
      replies.refuse(r, v1::ERROR_CODE_NOT_CONFIGURED, "nothing to checkpoint before Configure");
      return;
    }
    if (const auto& grant = assembly.grant()) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     fmt::format("step {} is running; ask for a checkpoint between steps (or "
                                 "with the grant)",
                                 grant->step));
      return;
    }
    const auto& dir = env.checkpoint_request().directory();
    if (dir.empty()) {
      replies.refuse(r, v1::ERROR_CODE_CHECKPOINT_FAILED, "CheckpointRequest without a directory");
      return;
    }
    const std::int64_t lastStep = session.lastStep;
    try {
      auto files = session.writeCheckpoint(dir, lastStep, sessionId(), *log);
      replies.send(r.peer, proto::makeCheckpointDone(lastStep, dir, files), env.sequence(),
                   lastStep);
    } catch (const std::exception& e) {
      replies.refuse(
          r, v1::ERROR_CODE_CHECKPOINT_FAILED,
          fmt::format("writing the state of step {} into {} failed: {}", lastStep, dir, e.what()));
    }
  }

  void onShutdown(const proto::Request& r) {
    const auto& env = r.message.envelope();
    if (r.peer != members.orchestrator()) {
      replies.refuse(r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                     "only the session's orchestrator ends the session");
      return;
    }
    replies.send(r.peer, proto::makeAck("session " + sessionId() + " ended"), env.sequence(),
                 env.step());
    endSession("Shutdown from the orchestrator" + (env.shutdown().reason().empty()
                                                       ? std::string()
                                                       : ": " + safe(env.shutdown().reason())));
  }

  // ---- dispatch --------------------------------------------------------------------------
  /// Refuses what no state takes (a bad decode, an unknown type, a reply sent to the server, a
  /// stranger's message) and answers Hello and Heartbeat; true when `r` goes on to validation.
  bool admit(proto::Request& r) {
    const auto& env = r.message.envelope();
    if (!r.status.ok()) {
      replies.refuse(r, r.status.code, r.status.message);
      return false;
    }
    const auto type = env.type();
    if (type == v1::MESSAGE_TYPE_UNSPECIFIED || !v1::MessageType_IsValid(type)) {
      // Checked first, from anyone in any state (docs/protocol.md §5): an empty message (one
      // zero-byte frame parses as an Envelope with nothing set) or a type of a newer version.
      const auto s = proto::validate(r.message, proto::Expectation{});
      replies.refuse(r, v1::ERROR_CODE_UNKNOWN_TYPE, s.message);
      return false;
    }
    if (type == v1::MESSAGE_TYPE_HELLO) {
      onHello(r);
      return false;
    }
    const SessionState state = members.state();
    if (type == v1::MESSAGE_TYPE_HEARTBEAT) {
      if (state != SessionState::Idle &&
          (r.peer == members.orchestrator() || members.rankOf(r.peer) >= 0)) {
        members.touch();
      }
      replies.send(r.peer, proto::makeHeartbeat(stateName(state)), env.sequence(),
                   session.lastStep);
      return false;
    }
    if (state == SessionState::Idle) {
      replies.refuse(r, v1::ERROR_CODE_NOT_CONFIGURED,
                     "no active session: an orchestrator starts one with Hello{role=ORCHESTRATOR}");
      return false;
    }
    if (r.peer != members.orchestrator() && members.rankOf(r.peer) < 0) {
      replies.refuse(r, v1::ERROR_CODE_UNKNOWN_SESSION,
                     "this connection has not joined the active session: send Hello first");
      return false;
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
      replies.refuse(
          r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
          fmt::format("{} is a reply, never sent to the DEM server; it takes Hello, Configure, "
                      "StepGrant, GasFields, CheckpointRequest, Heartbeat and Shutdown",
                      proto::messageTypeName(type)));
      return false;
    default:
      return true;
    }
  }

  /// The envelope checks of a member's message (docs/protocol.md §3, §5); refused when they fail.
  bool validated(proto::Request& r) {
    const auto& env = r.message.envelope();
    const auto type = env.type();
    const bool gas = type == v1::MESSAGE_TYPE_GAS_FIELDS;
    proto::Expectation e;
    if (gas) {
      if (members.state() != SessionState::Configured) {
        replies.refuse(r, v1::ERROR_CODE_NOT_CONFIGURED,
                       "GasFields before the orchestrator's Configure");
        return false;
      }
      e = assembly.gasExpectation(r.peer, session.lastStep, session.grid);
    } else {
      e.sessionId = sessionId();
      e.sequenceAfter = members.lastSequence(r.peer);
    }
    const auto tValidate = Clock::now();
    // The CFD's step and the transfer (decomposed: until the first rank's GasFields).
    if (gas && !assembly.hasPartials()) {
      runner.timeWaitForPeer(lastReceived);
    }
    auto s = proto::validate(r.message, e);
    if (s.ok() && gas && !env.gas_fields().partial()) {
      // Physical ranges (docs/protocol.md §3); a partial GasFields holds volume-weighted sums,
      // checked once combined (partial_ranks.h).
      s = proto::validateGasRanges(r.message);
    }
    if (gas) {
      runner.times().validate += std::chrono::duration<double>(Clock::now() - tValidate).count();
    }
    if (!s.ok()) {
      replies.refuse(r, s.code, s.message);
      return false;
    }
    return true;
  }

  void handle(proto::Request& r) {
    if (!admit(r) || !validated(r)) {
      return;
    }
    const auto& env = r.message.envelope();
    members.setLastSequence(r.peer, env.sequence());
    members.touch();
    switch (env.type()) {
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
      replies.refuse(
          r, v1::ERROR_CODE_UNEXPECTED_MESSAGE,
          fmt::format("coredem-dem does not take {} messages", proto::messageTypeName(env.type())));
    }
  }

  void housekeeping() {
    const auto now = Clock::now();
    assembly.expire(now, opt.grantWaitSeconds);
    if (members.state() != SessionState::Idle &&
        std::chrono::duration<double>(now - members.lastActivity()).count() >
            opt.sessionTimeoutSeconds) {
      endSession(fmt::format("no message from orchestrator '{}' or CFD participant '{}' for {} s "
                             "(--timeout-s)",
                             members.orchestratorName(), members.cfdName(),
                             opt.sessionTimeoutSeconds),
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
  return _impl->members.state();
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
      m.replies.send(
          req->peer,
          proto::makeError(v1::ERROR_CODE_INTERNAL, std::string("internal error: ") + e.what(),
                           req->message.envelope().sequence(), req->message.envelope().type()),
          req->message.envelope().sequence(), req->message.envelope().step());
      if (m.members.isMember(req->peer)) {
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
  if (_impl->members.state() != SessionState::Idle) {
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
