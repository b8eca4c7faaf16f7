// Starting the participants of a run: the DEM server (started here or reached at dem.endpoint),
// its handshake and Configure; the CFD participant (by its row of the participant table) and
// its handshake; the receive loops with deadlines that watch both processes.
#include <fstream>
#include <thread>

#include <coredem/common/version.h>
#include <coredem/protocol/initial_state.h>

#include "configure.h"
#include "session_impl.h"

namespace fs = std::filesystem;
namespace v1 = coredem::v1;
using namespace std::chrono_literals;

namespace coredem::orchestrator {

using protocol::Message;

void Session::startDem() {
  protocol::TransportOptions transport;
  if (!_c.dem.serverKey.empty()) {
    std::ifstream in(_c.dem.serverKey);
    std::string key;
    in >> key;
    COREDEM_CHECK(key.size() == 40, "{}: not a Z85 CURVE public key (40 characters)",
                  _c.dem.serverKey.string());
    _serverKey = key;
    // A persistent client key (dem.client_key) for a server with an allow-list; otherwise a
    // throw-away pair (the server then admits any client that knows its public key).
    const auto pair = _c.dem.clientKey.empty()
                          ? protocol::generateCurveKeyPair()
                          : protocol::readClientKeyPair(_c.dem.clientKey.string());
    if (!_c.dem.clientKey.empty()) {
      _log->info("CURVE client key {} ({})", pair.first, _c.dem.clientKey.string());
    }
    transport.curve.serverPublicKey = key;
    transport.curve.clientPublicKey = pair.first;
    transport.curve.clientSecretKey = pair.second;
  }
  _dem = std::make_unique<protocol::Client>(transport);
  if (!_c.dem.endpoint.empty()) {
    _demEndpoint = _c.dem.endpoint;
    _log->info("using the DEM server at {}", _demEndpoint);
  } else {
    const fs::path exe = findProgram("coredem-dem");
    COREDEM_CHECK(!exe.empty(),
                  "coredem-dem not found next to coredem ({}) or on PATH; build it "
                  "(cmake --build build --target coredem-dem)",
                  executableDir().string());
    const fs::path epFile = _o.runDir / "logs" / "dem.endpoint";
    fs::remove(epFile);
    std::vector<std::string> argv = {
        exe.string(),
        "--bind",
        "tcp://127.0.0.1:*",
        "--backend",
        _c.dem.backend,
        "--exit-after-session",
        "--endpoint-file",
        epFile.string(),
        "--timeout-s",
        fmt::format("{}", std::max(_c.dem.timeoutSeconds, _c.cfd.timeoutSeconds) * 2)};
    if (_c.dem.threads > 0) {
      argv.insert(argv.end(), {"--threads", std::to_string(_c.dem.threads)});
    }
    if (_c.dem.timers || _o.timers) {
      argv.insert(argv.end(),
                  {"--timers", "--timers-file", (_o.runDir / "timers-dem.json").string()});
    }
    // OpenMP threads that spin at barriers stall every parallel region when the DEM shares
    // its cores with the CFD participant (docs/performance.md, "DEM core"); passive waiting
    // is the default here, and a policy set in the user's environment wins.
    std::map<std::string, std::string> demEnv;
    if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
      demEnv["OMP_WAIT_POLICY"] = "PASSIVE";
    }
    _demProc =
        std::make_unique<ChildProcess>(kDemName, argv, demEnv, _o.runDir / "logs" / "dem.log");
    const auto deadline =
        SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                 std::chrono::duration<double>(_c.dem.timeoutSeconds));
    while (!fs::exists(epFile)) {
      checkAlive();
      if (SteadyClock::now() > deadline) {
        throw ParticipantFault(kDemName, fmt::format("did not report its endpoint within {} s",
                                                     _c.dem.timeoutSeconds));
      }
      std::this_thread::sleep_for(10ms);
    }
    std::ifstream in(epFile);
    std::getline(in, _demEndpoint);
    fs::remove(epFile);
    _log->info("started the DEM server (pid {}) at {}", _demProc->pid(), _demEndpoint);
  }
  _dem->connect(_demEndpoint);
  Message hello = protocol::makeHello(v1::ROLE_ORCHESTRATOR, kVersion);
  _dem->send(std::move(hello));
  Message welcome;
  try {
    welcome =
        receiveFromDem(std::chrono::milliseconds(int(_c.dem.timeoutSeconds * 1000)), "Welcome");
  } catch (const ParticipantFault& e) {
    if (_demProc) {
      throw;
    }
    throw ParticipantFault(
        kDemName, fmt::format("no Welcome from {} within {} s: the server is not running there, "
                              "or it refused the connection (CURVE: dem.server_key must be the "
                              "server's public key{})",
                              _demEndpoint, _c.dem.timeoutSeconds,
                              _serverKey.empty() ? "; this case gives none" : ""));
  }
  try {
    protocol::expectType(welcome, v1::MESSAGE_TYPE_WELCOME);
  } catch (const protocol::ProtocolError& e) {
    throw ParticipantFault(kDemName, fmt::format("refused the session: {}", e.what()));
  }
  _session = welcome.envelope().welcome().session_id();
  _log->info("DEM session {} (server {}, protocol {}.{})", _session,
             welcome.envelope().welcome().software_version(),
             welcome.envelope().welcome().protocol_major(),
             welcome.envelope().welcome().protocol_minor());
  // Configure fields the agreed version does not have (chemistry: 1.1, wall shapes: 1.4) would
  // be ignored by the server: refuse before sending.
  if (const std::string why = demVersionRefusal(_c, welcome.envelope().welcome().protocol_major(),
                                                welcome.envelope().welcome().protocol_minor());
      !why.empty()) {
    throw ParticipantFault(kDemName, why);
  }
}

Message Session::receiveFromDem(std::chrono::milliseconds timeout, const std::string& awaited) {
  const auto deadline = SteadyClock::now() + timeout;
  while (true) {
    protocol::Status status;
    std::optional<Message> m = _dem->receive(50ms, {}, &status);
    if (m) {
      if (!status.ok()) {
        throw ParticipantFault(kDemName, "sent an undecodable reply: " + status.toString());
      }
      if (m->type() == v1::MESSAGE_TYPE_ERROR) {
        throw ParticipantFault(kDemName,
                               fmt::format("answered {} with Error {}: {}", awaited,
                                           protocol::errorCodeName(m->envelope().error().code()),
                                           m->envelope().error().message()));
      }
      if (m->type() == v1::MESSAGE_TYPE_HEARTBEAT) {
        continue;
      }
      return std::move(*m);
    }
    checkAlive();
    if (SteadyClock::now() > deadline) {
      _demUnresponsive = true;
      throw ParticipantFault(kDemName, fmt::format("stopped answering: no {} within {} s", awaited,
                                                   timeout.count() / 1000.0));
    }
  }
}

protocol::Request Session::receiveFromCfd(std::chrono::milliseconds timeout,
                                          const std::string& awaited) {
  const auto deadline = SteadyClock::now() + timeout;
  while (true) {
    std::optional<protocol::Request> r = _ctrl->receive(50ms);
    if (r) {
      if (!r->status.ok()) {
        _ctrl->reply(r->peer, protocol::makeError(r->status, r->message.envelope().sequence()));
        _log->warn("refused an undecodable message on the control socket: {}",
                   r->status.toString());
        continue;
      }
      if (r->message.type() == v1::MESSAGE_TYPE_HEARTBEAT) {
        Message hb = protocol::makeHeartbeat("running");
        hb.setSequence(r->message.envelope().sequence()).setSessionId(_session);
        _ctrl->reply(r->peer, std::move(hb));
        continue;
      }
      if (r->message.type() == v1::MESSAGE_TYPE_ERROR) {
        throw ParticipantFault(
            cfdName(), fmt::format("reported Error {}: {}",
                                   protocol::errorCodeName(r->message.envelope().error().code()),
                                   r->message.envelope().error().message()));
      }
      return std::move(*r);
    }
    checkAlive();
    if (SteadyClock::now() > deadline) {
      throw ParticipantFault(cfdName(), fmt::format("stopped answering: no {} within {} s", awaited,
                                                    timeout.count() / 1000.0));
    }
  }
}

void Session::configureDem(std::int64_t startStep, double startTime, const fs::path& initialState) {
  const double dt0 = _policy.lastDt();
  const SubcyclePlan provisional = planFor(_c, dt0, estimateDtDemMax(_c));
  _configure = buildConfigure(_c, _o.runDir, dt0, provisional);
  _configure.set_start_step(startStep);
  _configure.set_start_time(startTime);
  if (!initialState.empty()) {
    // A resume: this run's own checkpoint, read bit for bit (the server checks its hash), not
    // the new start from case.yaml's initial_state.
    _configure.set_initial_state_file(fs::absolute(initialState).string());
    auto& options = *_configure.mutable_options();
    for (auto it = options.begin(); it != options.end();) {
      it = it->key() == protocol::fields::kInitialStateOption ? options.erase(it) : it + 1;
    }
  }
  // A Configure with large mesh walls may exceed the server's message limit: the server started
  // here has the default limit; one at dem.endpoint may have been given a larger one.
  if (const std::string why = configureSizeRefusal(_configure, protocol::kDefaultMaxMessageBytes);
      !why.empty()) {
    if (_c.dem.endpoint.empty()) {
      throw CaseError(why);
    }
    _log->warn("{} (unless the server at {} was started with a larger limit)", why, _demEndpoint);
  }
  Message msg = protocol::makeConfigure(_configure);
  msg.setSessionId(_session).setStep(startStep).setTime(startTime);
  _dem->send(std::move(msg));
  Message reply =
      receiveFromDem(std::chrono::milliseconds(int(_c.dem.timeoutSeconds * 1000)), "Configured");
  if (reply.type() != v1::MESSAGE_TYPE_CONFIGURED) {
    throw ParticipantFault(kDemName, fmt::format("answered Configure with {}",
                                                 protocol::messageTypeName(reply.type())));
  }
  const auto& cd = reply.envelope().configured();
  COREDEM_CHECK(cd.n_sub() >= 1 && cd.dt_dem() > 0, "DEM server replied an invalid plan");
  // Configured.dt_dem is D's Δt_DEM,max = min(π √(m/k)/dt_factor, the integrator's stability
  // limit) over the material pairs (its n_sub is for the first
  // Δt_CFD); every later plan is n_sub = ceil(Δt_CFD/Δt_DEM,max).
  _dtDemMax = cd.dt_dem();
  if (_c.dtDem > _dtDemMax * (1.0 + 1e-12)) {
    throw CaseError(fmt::format(
        "time.dt_dem = {:.6g} s exceeds the DEM server's stable step dt_dem_max = {:.6g} s (the "
        "undamped contact duration pi*sqrt(m_eff/k_n) of the stiffest material pair over "
        "dem.dt_factor = {:g}, or the integrator's stability limit). Any one of: use "
        "time.dt_dem <= {:.6g} s (or remove it: the DEM then picks its own step); lower "
        "dem.dt_factor (Δt_DEM,max = t_col/dt_factor; docs/case-schema.md); soften the contact "
        "(a smaller materials[].k_n, or another contact law: models: {{contact: ...}}); "
        "or hold the particles with models: {{motion: frozen}}",
        _c.dtDem, _dtDemMax, dtFactorOf(_c), _dtDemMax));
  }
  _cells = cd.cell_count();
  _species = cd.species_count();
  _configure.mutable_sub_cycling()->set_n_sub(cd.n_sub());
  _configure.mutable_sub_cycling()->set_dt_dem(cd.dt_dem());
  // The plan that runs: a forced time.dt_dem sets n_sub = dt_CFD/dt_dem, not D's own n_sub.
  const SubcyclePlan runs = planFor(_c, dt0, _dtDemMax);
  _log->info("DEM configured: {} particles, {} coupling cells, dt_DEM = {:.4g} s (n_sub = {} for "
             "dt_CFD = {:.4g} s{}; the DEM's stable step dt_dem_max = {:.4g} s)",
             cd.particle_count(), cd.cell_count(), runs.dtDem, runs.nSub, dt0,
             _c.dtDem > 0.0 ? ", forced by time.dt_dem" : "", _dtDemMax);
}

void Session::startCfd(const fs::path& cfdRestart) {
  _ctrl = std::make_unique<protocol::Server>();
  _ctrlEndpoint = _ctrl->bind("tcp://127.0.0.1:*");
  LaunchInputs in;
  in.program = findProgram(_cfd.name);
  COREDEM_CHECK(!in.program.empty(), "{} not found next to coredem ({}) or on PATH", _cfd.name,
                executableDir().string());
  in.runDir = _o.runDir;
  in.controlEndpoint = _ctrlEndpoint;
  in.demEndpoint = _demEndpoint;
  in.session = _session;
  in.demServerKey = _serverKey;
  in.demClientKeyFile = _serverKey.empty() ? std::string() : _c.dem.clientKey.string();
  in.restartFile = cfdRestart;
  in.timers = _o.timers;
  prepareWorkDir(_cfd, _c, _o.runDir);
  LaunchCommand cmd = launchCommand(_cfd, _c, in);
  _cfdProc = std::make_unique<ChildProcess>(cfdName(), std::move(cmd.argv), cmd.env,
                                            _o.runDir / "logs" / "cfd.log");
  _log->info("started {} (pid {})", _cfd.name, _cfdProc->pid());
}

void Session::handshakeCfd() {
  const auto timeout = std::chrono::milliseconds(int(_c.cfd.timeoutSeconds * 1000));
  bool welcomed = false, configured = false;
  while (!configured) {
    protocol::Request r = receiveFromCfd(timeout, welcomed ? "Configure/Configured" : "Hello");
    const auto& env = r.message.envelope();
    const auto seq = env.sequence();
    if (r.message.type() == v1::MESSAGE_TYPE_HELLO) {
      const auto& h = env.hello();
      const auto nego =
          protocol::negotiate(protocol::kProtocolVersion, {h.protocol_major(), h.protocol_minor()});
      if (!nego.accepted) {
        Message rej = protocol::makeReject(v1::ERROR_CODE_VERSION, nego.status.message);
        rej.setSequence(seq);
        _ctrl->reply(r.peer, std::move(rej));
        throw ParticipantFault(cfdName(), nego.status.message);
      }
      if (env.session_id() != _session) {
        Message rej = protocol::makeReject(v1::ERROR_CODE_UNKNOWN_SESSION,
                                           "session id does not match this run's");
        rej.setSequence(seq);
        _ctrl->reply(r.peer, std::move(rej));
        continue;
      }
      Message w = protocol::makeWelcome(v1::ROLE_ORCHESTRATOR, kVersion, nego.agreed.major,
                                        nego.agreed.minor, _session);
      w.setSequence(seq).setSessionId(_session);
      _ctrl->reply(r.peer, std::move(w));
      _cfdPeer = r.peer;
      welcomed = true;
    } else if (r.message.type() == v1::MESSAGE_TYPE_CONFIGURE && welcomed) {
      Message cfg = protocol::makeConfigure(_configure);
      cfg.setSequence(seq)
          .setSessionId(_session)
          .setStep(_configure.start_step())
          .setTime(_configure.start_time());
      _ctrl->reply(r.peer, std::move(cfg));
    } else if (r.message.type() == v1::MESSAGE_TYPE_CONFIGURED && welcomed) {
      const auto& cd = env.configured();
      if (cd.cell_count() != _cells) {
        throw ParticipantFault(cfdName(), fmt::format("has {} coupling cells, the DEM server {}",
                                                      cd.cell_count(), _cells));
      }
      _pendingCfd = std::move(r); // answered with the first grant
      configured = true;
    } else {
      Message err = protocol::makeError(v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                                        fmt::format("{} is not expected during the handshake",
                                                    protocol::messageTypeName(r.message.type())),
                                        seq, r.message.type());
      _ctrl->reply(r.peer, std::move(err));
    }
  }
  _log->info("{} connected", _cfd.name);
}

} // namespace coredem::orchestrator
