#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>
#include <thread>

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/log.h>
#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/outputs.h>
#include <coredem/common/process.h>
#include <coredem/orchestrator/progress.h>
#include <coredem/orchestrator/session.h>
#include <coredem/orchestrator/sha256.h>
#include <coredem/orchestrator/time_handler.h>
#include <coredem/protocol/protocol.h>

#ifndef COREDEM_SOFTWARE_VERSION
#define COREDEM_SOFTWARE_VERSION "0.0.0"
#endif

namespace fs = std::filesystem;
namespace v1 = coredem::v1;
using namespace std::chrono_literals;

namespace coredem::orchestrator {
namespace {

using protocol::Message;
using Clock = std::chrono::steady_clock;

std::atomic<bool> gInterrupted{false};
extern "C" void onSignal(int) {
  gInterrupted = true;
}

class Interrupted : public UserError {
public:
  Interrupted()
      : UserError("interrupted (SIGINT/SIGTERM)") {}
};

const std::string kDemName = "DEM server coredem-dem";

std::string cfdName(const CaseConfig& c) {
  return "CFD participant " + c.cfd.participant;
}

v1::Vec3 vec(const Vec3& v) {
  v1::Vec3 out;
  out.set_x(v[0]);
  out.set_y(v[1]);
  out.set_z(v[2]);
  return out;
}

/// Smallest collision time over the particle sets (PHYSICS Eq. 12, m_eff = m/2 for equal
/// particles): t_col = sqrt(π² + ln² e_n) / sqrt(k_n / m_eff). Only used for the provisional
/// plan in Configure; the DEM server's reply is authoritative.
double estimateDtDemMax(const CaseConfig& c) {
  double tMin = std::numeric_limits<double>::infinity();
  for (const auto& p : c.particles) {
    const auto& m = c.materials[std::size_t(materialIndex(c, p.material))];
    const double rho = p.density > 0 ? p.density : m.density;
    const double mass = rho * std::numbers::pi * std::pow(p.diameter, 3) / 6.0;
    const double le = std::log(m.eN);
    const double t =
        std::sqrt(std::numbers::pi * std::numbers::pi + le * le) / std::sqrt(m.kN / (0.5 * mass));
    tMin = std::min(tMin, t);
  }
  return std::isfinite(tMin) ? tMin / 50.0 : c.dt.dt;
}

/// The sub-cycling plan of a step: from the forced DEM step time.dt_dem when given (n_sub =
/// dt/dt_dem; a step shortened to land on time.end gets n_sub = ceil), else from Δt_DEM,max.
SubcyclePlan planFor(const CaseConfig& c, double dt, double dtDemMax) {
  if (c.dtDem > 0.0) {
    const double ratio = dt / c.dtDem;
    double n = std::round(ratio);
    if (n < 1.0 || std::abs(ratio - n) > 1e-9 * n) {
      n = std::max(1.0, std::ceil(ratio));
    }
    return SubcyclePlan{std::int64_t(n), dt / n};
  }
  return planSubcycles(dt, dtDemMax);
}

v1::Configure buildConfigure(const CaseConfig& c, const fs::path& runDir, double dtCfd,
                             const SubcyclePlan& plan) {
  v1::Configure cfg;
  cfg.set_case_name(c.name);
  auto* grid = cfg.mutable_coupling_mesh()->mutable_cartesian();
  *grid->mutable_origin() = vec(c.grid.origin);
  *grid->mutable_spacing() = vec(c.grid.spacing);
  grid->mutable_counts()->set_x(c.grid.cells[0]);
  grid->mutable_counts()->set_y(c.grid.cells[1]);
  grid->mutable_counts()->set_z(c.grid.cells[2]);
  for (const auto& s : c.species) {
    auto* sp = cfg.add_species();
    sp->set_name(s.name);
    sp->set_molar_mass(s.molarMass);
  }
  auto* gas = cfg.mutable_gas()->mutable_constant();
  gas->set_density(c.gasProperties.density);
  gas->set_viscosity(c.gasProperties.viscosity);
  gas->set_conductivity(c.gasProperties.conductivity);
  gas->set_cp(c.gasProperties.cp);
  gas->set_temperature(c.gasProperties.temperature);
  gas->set_pressure(c.gasProperties.pressure);
  for (std::size_t i = 0; i < c.materials.size(); ++i) {
    const auto& m = c.materials[i];
    auto* mat = cfg.add_materials();
    mat->set_id(std::uint32_t(i));
    mat->set_name(m.name);
    mat->set_density(m.density);
    mat->set_k_n(m.kN);
    mat->set_e_n(m.eN);
    mat->set_friction(m.friction);
    if (m.ktFactor) {
      mat->set_kt_factor(*m.ktFactor);
    }
    if (m.etatFactor) {
      mat->set_etat_factor(*m.etatFactor);
    }
    mat->set_cp(m.cp);
    mat->set_conductivity(m.conductivity);
    mat->set_emissivity(m.emissivity);
  }
  for (const auto& p : c.particles) {
    auto* ps = cfg.add_particle_sets();
    ps->set_name(p.name);
    ps->set_material_id(std::uint32_t(materialIndex(c, p.material)));
    ps->set_count(p.count);
    ps->set_diameter(p.diameter);
    ps->set_density(p.density);
    ps->set_temperature(p.temperature);
    for (const auto& [name, f] : p.composition) {
      protocol::addNamedValue(ps->mutable_composition(), name, f);
    }
    ps->set_packing(p.packing == "random" ? v1::PACKING_RANDOM : v1::PACKING_LATTICE);
    if (!p.positions.empty()) { // explicit packing (time.dt_dem / positions: docs/case-schema.md)
      ps->set_packing(v1::PACKING_EXPLICIT);
      for (const auto& x : p.positions) {
        *ps->add_positions() = vec(x);
      }
    }
    *ps->mutable_region_min() = vec(p.regionMin);
    *ps->mutable_region_max() = vec(p.regionMax);
    ps->set_seed(p.seed);
    *ps->mutable_initial_velocity() = vec(p.velocity);
  }
  auto* walls = cfg.mutable_walls();
  if (c.walls.box) {
    *walls->mutable_box()->mutable_min() = vec(c.walls.box->first);
    *walls->mutable_box()->mutable_max() = vec(c.walls.box->second);
  }
  for (const auto& pl : c.walls.planes) {
    auto* p = walls->add_planes();
    *p->mutable_point() = vec(pl.point);
    *p->mutable_normal() = vec(pl.normal);
  }
  walls->set_material_id(std::uint32_t(std::max(0, materialIndex(c, c.walls.material))));
  walls->set_temperature(c.walls.temperature);
  *cfg.mutable_gravity() = vec(c.gravity);
  if (!c.initialState.empty()) {
    cfg.set_initial_state_file(c.initialState.string());
  }
  cfg.mutable_sub_cycling()->set_dt_cfd(dtCfd);
  cfg.mutable_sub_cycling()->set_n_sub(std::uint32_t(plan.nSub));
  cfg.mutable_sub_cycling()->set_dt_dem(plan.dtDem);
  for (const auto& [k, v] : c.models) {
    auto* kv = cfg.add_options();
    kv->set_key(k);
    kv->set_value(v);
  }
  cfg.set_output_directory(fs::absolute(runDir).string());
  addChemistryToConfigure(c, cfg);  // v1.1: solid species, reactions, chemistry
  return cfg;
}

/// Ledger entries and diagnostics of a StepDone as (name, value) pairs.
void collect(const v1::StepDone& done, std::vector<std::pair<std::string, double>>& row) {
  for (const auto& d : done.diagnostics()) {
    row.emplace_back(d.name(), d.value());
  }
  for (const auto* list :
       {&done.ledger().mass(), &done.ledger().energy(), &done.ledger().species()}) {
    for (const auto& v : *list) {
      row.emplace_back(v.name(), v.value());
    }
  }
}

struct SnapshotEntry {
  std::int64_t step;
  double time;
  std::string file; ///< relative to the run folder
};

std::vector<SnapshotEntry> readSnapshotIndex(const fs::path& runDir) {
  std::vector<SnapshotEntry> out;
  std::ifstream in(runDir / "snapshots" / "index.csv");
  std::string line;
  std::getline(in, line); // header
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string step, time, file;
    if (std::getline(s, step, ',') && std::getline(s, time, ',') && std::getline(s, file)) {
      out.push_back({std::stoll(step), doubleFromHex(time), file});
    }
  }
  return out;
}

void writeSnapshotIndex(const fs::path& runDir, const std::vector<SnapshotEntry>& snaps) {
  std::string text = "step,time_hex,file\n";
  std::vector<std::pair<double, std::string>> xdmf;
  for (const auto& s : snaps) {
    text += fmt::format("{},{},{}\n", s.step, doubleToHex(s.time), s.file);
    xdmf.emplace_back(s.time, s.file);
  }
  writeFileAtomic(runDir / "snapshots" / "index.csv", text);
  writeParticleXdmf(runDir / "particles.xdmf", xdmf);
}

// -----------------------------------------------------------------------------------------

class Session {
public:
  Session(const CaseConfig& config, const RunOptions& options)
      : _c(config)
      , _o(options)
      , _log(logger("orchestrator.session")) {}

  int run();

private:
  void checkAlive();
  void startDem();
  void configureDem(std::int64_t startStep, double startTime, const fs::path& initialState);
  void startCfd(const fs::path& gasRestart);
  protocol::Request receiveFromCfd(std::chrono::milliseconds timeout, const std::string& awaited);
  Message receiveFromDem(std::chrono::milliseconds timeout, const std::string& awaited);
  void handshakeCfd();
  void stepLoop(std::int64_t startStep);
  void takeSnapshot(std::int64_t step, double time);
  void shutdownAll(bool clean);

  const CaseConfig& _c;
  RunOptions _o;
  std::shared_ptr<spdlog::logger> _log;

  std::unique_ptr<ChildProcess> _demProc, _cfdProc;
  std::unique_ptr<protocol::Client> _dem;
  std::unique_ptr<protocol::Server> _ctrl;
  std::string _demEndpoint, _ctrlEndpoint, _session, _serverKey;
  v1::Configure _configure;
  double _dtDemMax = 0.0;
  std::uint64_t _cells = 0;
  std::uint32_t _species = 0;
  protocol::PeerId _cfdPeer;
  std::optional<protocol::Request> _pendingCfd; ///< C's request awaiting O's reply
  bool _demUnresponsive = false;                ///< D missed a deadline: do not wait on it

  TimeHandler _time;
  DtPolicy _policy{DtPolicyConfig{}};
  double _lastCourant = -1.0;
  std::int64_t _step = 0;
  std::vector<SnapshotEntry> _snapshots;
  std::unique_ptr<TimeseriesWriter> _timeseries;

  // overhead measurement
  double _overheadSum = 0.0, _stepWallSum = 0.0, _demWallSum = 0.0, _checkpointSum = 0.0,
         _snapshotSum = 0.0;
  std::int64_t _measured = 0;
};

void Session::checkAlive() {
  if (gInterrupted) {
    throw Interrupted();
  }
  if (_demProc) {
    if (auto why = _demProc->exitReason()) {
      throw ParticipantFault(kDemName,
                             fmt::format("process {} {} (log {}):\n{}", _demProc->pid(), *why,
                                         _demProc->logFile().string(), _demProc->logTail()));
    }
  }
  if (_cfdProc) {
    if (auto why = _cfdProc->exitReason()) {
      throw ParticipantFault(cfdName(_c),
                             fmt::format("process {} {} (log {}):\n{}", _cfdProc->pid(), *why,
                                         _cfdProc->logFile().string(), _cfdProc->logTail()));
    }
  }
}

void Session::startDem() {
  protocol::TransportOptions transport;
  if (!_c.dem.serverKey.empty()) {
    std::ifstream in(_c.dem.serverKey);
    std::string key;
    in >> key;
    COREDEM_CHECK(key.size() == 40, "{}: not a Z85 CURVE public key (40 characters)",
                  _c.dem.serverKey.string());
    _serverKey = key;
    const auto pair = protocol::generateCurveKeyPair();
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
      argv.insert(argv.end(), {"--timers", "--timers-file", (_o.runDir / "timers-dem.json").string()});
    }
    // OpenMP threads that spin at barriers stall every parallel region when the DEM shares
    // its cores with the CFD participant (docs/performance.md, "DEM core"); passive waiting
    // is the default here, and a policy set in the user's environment wins.
    std::map<std::string, std::string> demEnv;
    if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
      demEnv["OMP_WAIT_POLICY"] = "PASSIVE";
    }
    _demProc = std::make_unique<ChildProcess>(kDemName, argv, demEnv, _o.runDir / "logs" / "dem.log");
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(_c.dem.timeoutSeconds));
    while (!fs::exists(epFile)) {
      checkAlive();
      if (Clock::now() > deadline) {
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
  Message hello = protocol::makeHello(v1::ROLE_ORCHESTRATOR, COREDEM_SOFTWARE_VERSION);
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
  // Chemistry travels in Configure fields of protocol v1.1, which a v1.0 server would ignore.
  if (_c.usesChemistry() && welcome.envelope().welcome().protocol_minor() < 1) {
    throw ParticipantFault(
        kDemName, fmt::format("the DEM server speaks protocol {}.{}, but this case uses chemistry "
                              "(solid_species, reactions or chemistry), which needs protocol 1.1; "
                              "use a coredem-dem built from this release",
                              welcome.envelope().welcome().protocol_major(),
                              welcome.envelope().welcome().protocol_minor()));
  }
}

Message Session::receiveFromDem(std::chrono::milliseconds timeout, const std::string& awaited) {
  const auto deadline = Clock::now() + timeout;
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
    if (Clock::now() > deadline) {
      _demUnresponsive = true;
      throw ParticipantFault(kDemName, fmt::format("stopped answering: no {} within {} s", awaited,
                                                   timeout.count() / 1000.0));
    }
  }
}

protocol::Request Session::receiveFromCfd(std::chrono::milliseconds timeout,
                                          const std::string& awaited) {
  const auto deadline = Clock::now() + timeout;
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
            cfdName(_c), fmt::format("reported Error {}: {}",
                                     protocol::errorCodeName(r->message.envelope().error().code()),
                                     r->message.envelope().error().message()));
      }
      return std::move(*r);
    }
    checkAlive();
    if (Clock::now() > deadline) {
      throw ParticipantFault(cfdName(_c), fmt::format("stopped answering: no {} within {} s",
                                                      awaited, timeout.count() / 1000.0));
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
    _configure.set_initial_state_file(fs::absolute(initialState).string());
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
  // Configured.dt_dem is D's Δt_DEM,max = t_col,min/50 (its n_sub is for the first Δt_CFD);
  // every later plan is n_sub = ceil(Δt_CFD/Δt_DEM,max).
  _dtDemMax = cd.dt_dem();
  if (_c.dtDem > _dtDemMax * (1.0 + 1e-12)) {
    throw CaseError(fmt::format(
        "time.dt_dem = {:.6g} s exceeds the DEM server's stable step dt_dem_max = {:.6g} s "
        "(t_col/50); use time.dt_dem <= {:.6g} s, or hold the particles with models: "
        "{{motion: frozen}}",
        _c.dtDem, _dtDemMax, _dtDemMax));
  }
  _cells = cd.cell_count();
  _species = cd.species_count();
  _configure.mutable_sub_cycling()->set_n_sub(cd.n_sub());
  _configure.mutable_sub_cycling()->set_dt_dem(cd.dt_dem());
  _log->info("DEM configured: {} particles, {} coupling cells, dt_DEM = {:.4g} s (n_sub = {} for "
             "dt_CFD = {:.4g} s)",
             cd.particle_count(), cd.cell_count(), cd.dt_dem(), cd.n_sub(), dt0);
}

void Session::startCfd(const fs::path& gasRestart) {
  _ctrl = std::make_unique<protocol::Server>();
  _ctrlEndpoint = _ctrl->bind("tcp://127.0.0.1:*");
  const fs::path exe = findProgram(_c.cfd.participant);
  COREDEM_CHECK(!exe.empty(), "{} not found next to coredem ({}) or on PATH", _c.cfd.participant,
                executableDir().string());
  if (_c.cfd.participant == "coredemFoam") {
    // coredemFoam runs in a copy of the OpenFOAM case inside the run folder (made once; a
    // resumed run keeps it) and learns its peers from the environment (docs/client.md).
    const fs::path foamDir = _o.runDir / "openfoam";
    if (!fs::exists(foamDir / "system" / "controlDict")) {
      const fs::path src = _c.caseDir / _c.cfd.foamCase;
      COREDEM_CHECK(fs::is_regular_file(src / "system" / "controlDict"),
                    "cfd.case: {} is not an OpenFOAM case folder (no system/controlDict)",
                    src.string());
      fs::create_directories(foamDir);
      fs::copy(src, foamDir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    }
    std::vector<std::string> foamArgv = {exe.string(), "-case", foamDir.string()};
    if (!gasRestart.empty()) {
      foamArgv.insert(foamArgv.end(), {"-restart", gasRestart.string()});
    }
    if (_o.timers || _c.cfd.timers) {
      foamArgv.push_back("-timers");  // coredemFoam writes RUN/timers-cfd.json
    }
    std::map<std::string, std::string> env = {
        {"COREDEM_CONTROL_ENDPOINT", _ctrlEndpoint},
        {"COREDEM_DEM_ENDPOINT", _demEndpoint},
        {"COREDEM_SESSION", _session},
        {"COREDEM_TIMEOUT_S", fmt::format("{}", _c.cfd.timeoutSeconds)},
        // OpenFOAM reads its etc tree while its libraries load: Debian's unless set.
        {"WM_PROJECT_DIR",
         std::getenv("WM_PROJECT_DIR") ? std::getenv("WM_PROJECT_DIR") : "/usr/share/openfoam"}};
    if (!_serverKey.empty()) {
      env["COREDEM_DEM_SERVER_KEY"] = _serverKey; // remote DEM behind CURVE
    }
    _cfdProc =
        std::make_unique<ChildProcess>(cfdName(_c), foamArgv, env, _o.runDir / "logs" / "cfd.log");
    _log->info("started {} (pid {})", _c.cfd.participant, _cfdProc->pid());
    return;
  }
  std::vector<std::string> argv = {exe.string(),
                                   "--case",
                                   (_o.runDir / "case.yaml").string(),
                                   "--key",
                                   _c.cfd.gasKey,
                                   "--control",
                                   _ctrlEndpoint,
                                   "--dem",
                                   _demEndpoint,
                                   "--session",
                                   _session,
                                   "--timeout-s",
                                   fmt::format("{}", _c.cfd.timeoutSeconds)};
  if (!gasRestart.empty()) {
    argv.insert(argv.end(), {"--restart", gasRestart.string()});
  }
  std::map<std::string, std::string> env;
  if (!_serverKey.empty()) {
    env["COREDEM_DEM_SERVER_KEY"] = _serverKey;
  }
  _cfdProc = std::make_unique<ChildProcess>(cfdName(_c), argv, env, _o.runDir / "logs" / "cfd.log");
  _log->info("started {} (pid {})", _c.cfd.participant, _cfdProc->pid());
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
        throw ParticipantFault(cfdName(_c), nego.status.message);
      }
      if (env.session_id() != _session) {
        Message rej = protocol::makeReject(v1::ERROR_CODE_UNKNOWN_SESSION,
                                           "session id does not match this run's");
        rej.setSequence(seq);
        _ctrl->reply(r.peer, std::move(rej));
        continue;
      }
      Message w = protocol::makeWelcome(v1::ROLE_ORCHESTRATOR, COREDEM_SOFTWARE_VERSION,
                                        nego.agreed.major, nego.agreed.minor, _session);
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
        throw ParticipantFault(cfdName(_c), fmt::format("has {} coupling cells, the DEM server {}",
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
  _log->info("{} connected", _c.cfd.participant);
}

void Session::takeSnapshot(std::int64_t step, double time) {
  const fs::path tmp = _o.runDir / "snapshots" / ".incoming";
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  Message req = protocol::makeCheckpointRequest(step, fs::absolute(tmp).string(), "snapshot");
  req.setSessionId(_session).setTime(time);
  _dem->send(std::move(req));
  Message done = receiveFromDem(std::chrono::milliseconds(int(_c.dem.timeoutSeconds * 1000)),
                                "CheckpointDone of a snapshot");
  if (done.type() != v1::MESSAGE_TYPE_CHECKPOINT_DONE ||
      done.envelope().checkpoint_done().files().empty()) {
    throw ParticipantFault(kDemName, "answered a snapshot request without a file");
  }
  const std::string rel = fmt::format("snapshots/particles_{:08d}.h5", step);
  fs::rename(tmp / done.envelope().checkpoint_done().files(0), _o.runDir / rel);
  fs::remove_all(tmp);
  _snapshots.push_back({step, time, rel});
  writeSnapshotIndex(_o.runDir, _snapshots);
}

void Session::stepLoop(std::int64_t startStep) {
  _step = startStep;
  const auto demTimeout = std::chrono::milliseconds(int(_c.dem.timeoutSeconds * 1000));
  const auto cfdTimeout = std::chrono::milliseconds(int(_c.cfd.timeoutSeconds * 1000));
  Progress progress(_time.time(), _c.endTime, _step, _o.tty);
  auto lastCheckpointWall = Clock::now();
  auto afterPrevious = Clock::now();

  while (true) {
    const bool stopHere = _o.stopAfterStep && _step >= *_o.stopAfterStep;
    if (_time.reached(_c.endTime) || stopHere) {
      break;
    }
    const auto t0 = Clock::now();
    const std::int64_t step = _step + 1;
    const double tStart = _time.time();
    const double dt = _policy.next(_lastCourant, _time.remaining(_c.endTime));
    const SubcyclePlan plan = planFor(_c, dt, _dtDemMax);
    TimeHandler probe = _time;
    probe.advance(dt);
    const bool last = probe.reached(_c.endTime) || (_o.stopAfterStep && step >= *_o.stopAfterStep);
    const bool checkpoint =
        checkpointDue(step, last, _c.checkpoint.everySteps, _c.checkpoint.everySeconds,
                      std::chrono::duration<double>(Clock::now() - lastCheckpointWall).count());
    fs::path ckDir;
    if (checkpoint) {
      ckDir = fs::absolute(checkpointDir(_o.runDir, step));
      fs::remove_all(ckDir); // a stale, incomplete one from an earlier attempt
      fs::create_directories(ckDir);
    }
    auto makeGrant = [&] {
      Message g = protocol::makeStepGrant(step, tStart, dt, std::uint32_t(plan.nSub), plan.dtDem);
      g.setSessionId(_session);
      if (checkpoint) {
        g.envelope().mutable_step_grant()->mutable_checkpoint()->set_directory(ckDir.string());
      }
      return g;
    };
    _dem->send(makeGrant());
    {
      Message g = makeGrant();
      g.setSequence(_pendingCfd->message.envelope().sequence());
      _ctrl->reply(_pendingCfd->peer, std::move(g));
      _pendingCfd.reset();
    }
    _overheadSum += std::chrono::duration<double>(Clock::now() - afterPrevious).count();

    Message demDone = receiveFromDem(demTimeout, fmt::format("StepDone of step {}", step));
    if (demDone.type() != v1::MESSAGE_TYPE_STEP_DONE || demDone.envelope().step() != step) {
      throw ParticipantFault(kDemName,
                             fmt::format("answered the grant of step {} with {} of step {}", step,
                                         protocol::messageTypeName(demDone.type()),
                                         demDone.envelope().step()));
    }
    protocol::Request cfdDone;
    while (true) {
      cfdDone = receiveFromCfd(cfdTimeout, fmt::format("StepDone of step {}", step));
      if (cfdDone.message.type() == v1::MESSAGE_TYPE_STEP_DONE &&
          cfdDone.message.envelope().step() == step) {
        break;
      }
      Message err =
          protocol::makeError(v1::ERROR_CODE_OUT_OF_ORDER,
                              fmt::format("expected StepDone of step {}, got {} of step {}", step,
                                          protocol::messageTypeName(cfdDone.message.type()),
                                          cfdDone.message.envelope().step()),
                              cfdDone.message.envelope().sequence(), cfdDone.message.type());
      _ctrl->reply(cfdDone.peer, std::move(err));
    }
    const auto tDone = Clock::now();
    _time.advance(dt);
    _step = step;
    const auto& dd = demDone.envelope().step_done();
    const auto& cd = cfdDone.message.envelope().step_done();
    _lastCourant = cd.cfl();

    // The timeseries row of a step is written before its checkpoint manifest: a resume from
    // that checkpoint must find the row (a crash between the two would otherwise lose it).
    if (step % _c.output.timeseriesEvery == 0 || last) {
      std::vector<std::pair<std::string, double>> row = {
          {"step", double(step)},
          {"t", _time.time()},
          {"dt", dt},
          {"n_sub", double(plan.nSub)},
          {"dt_dem", plan.dtDem},
          {"courant", cd.cfl()},
          {"wall_step_s", std::chrono::duration<double>(tDone - t0).count()},
          {"wall_dem_s", dd.wall_seconds()}};
      collect(dd, row);
      collect(cd, row);
      // Heat balance: what the particles got from the gas (DEM) plus what the gas got from
      // the particles (CFD) is zero when both sides agree.
      const auto demHeat = protocol::findNamedValue(dd.ledger().energy(), "dem.heat_from_gas_J");
      const auto gasHeat =
          protocol::findNamedValue(cd.ledger().energy(), "gas.heat_from_particles_J");
      if (demHeat && gasHeat) {
        row.emplace_back("balance.heat_residual_J", *demHeat + *gasHeat);
      }
      _timeseries->write(row);
    }
    const auto tIo0 = Clock::now();
    if (checkpoint) {
      std::vector<std::pair<std::string, std::string>> files;
      for (const auto& f : dd.checkpoint().files()) {
        files.emplace_back(f, "dem");
      }
      for (const auto& f : cd.checkpoint().files()) {
        files.emplace_back(f, "cfd");
      }
      if (dd.checkpoint().files().empty()) {
        throw ParticipantFault(kDemName, fmt::format("wrote no checkpoint file for step {}", step));
      }
      Manifest m;
      m.step = step;
      m.time = _time.time();
      m.timeCompensation = _time.compensation();
      m.lastDt = _policy.lastDt();
      m.lastCourant = _lastCourant;
      m.softwareVersion = COREDEM_SOFTWARE_VERSION;
      m.protocolVersion = protocol::kProtocolVersion.toString();
      m.configHash = _c.configHash;
      writeManifest(ckDir, m, files);
      for (const auto& removed : pruneCheckpoints(_o.runDir, _c.checkpoint.keep)) {
        _log->debug("removed old checkpoint {}", removed.string());
      }
      lastCheckpointWall = Clock::now();
      _log->debug("checkpoint {} written", ckDir.string());
    }
    const auto tIo1 = Clock::now();
    if (_c.output.snapshotEvery > 0 && (step % _c.output.snapshotEvery == 0 || last)) {
      takeSnapshot(step, _time.time());
    }
    const auto tIo2 = Clock::now();
    _checkpointSum += std::chrono::duration<double>(tIo1 - tIo0).count();
    _snapshotSum += std::chrono::duration<double>(tIo2 - tIo1).count();
    _stepWallSum += std::chrono::duration<double>(tDone - t0).count();
    _demWallSum += dd.wall_seconds();
    ++_measured;
    progress.update(_step, _time.time());
    _pendingCfd = std::move(cfdDone);
    afterPrevious = Clock::now();
    _overheadSum += std::chrono::duration<double>(afterPrevious - tDone).count() -
                    std::chrono::duration<double>(tIo2 - tIo0).count();
  }
  progress.finish(_step, _time.time());
}

void Session::shutdownAll(bool clean) {
  // C: answer its pending request with Shutdown (or wait briefly for one), else stop it.
  if (_ctrl && _cfdProc && !_cfdProc->exitReason()) {
    if (!_pendingCfd) {
      try {
        auto r = _ctrl->receive(clean ? 2000ms : 300ms);
        if (r && r->status.ok()) {
          _pendingCfd = std::move(r);
        }
      } catch (const std::exception&) {
      }
    }
    if (_pendingCfd) {
      Message s = protocol::makeShutdown(clean ? "run finished" : "run aborted");
      s.setSequence(_pendingCfd->message.envelope().sequence()).setSessionId(_session);
      _ctrl->reply(_pendingCfd->peer, std::move(s));
      _pendingCfd.reset();
    }
    if (!_cfdProc->waitFor(clean ? 10000ms : 2000ms)) {
      _log->warn("stopping {} (pid {})", _c.cfd.participant, _cfdProc->pid());
      _cfdProc->stop();
    }
  }
  // D: Shutdown request when it is alive (ends the session; a server we started exits).
  if (_demUnresponsive && _demProc) {
    _log->warn("stopping the unresponsive DEM server (pid {})", _demProc->pid());
    _demProc->stop(1000ms);
  }
  if (_dem && !_demUnresponsive && (!_demProc || !_demProc->exitReason())) {
    try {
      Message s = protocol::makeShutdown(clean ? "run finished" : "run aborted");
      s.setSessionId(_session);
      _dem->send(std::move(s));
      _dem->receive(3000ms);
    } catch (const std::exception& e) {
      _log->debug("DEM shutdown: {}", e.what());
    }
    if (_demProc && !_demProc->waitFor(5000ms)) {
      _log->warn("stopping the DEM server (pid {})", _demProc->pid());
      _demProc->stop();
    }
  }
  if (_cfdProc) {
    _cfdProc->stop();
  }
  if (_demProc) {
    _demProc->stop();
  }
}

int Session::run() {
  fs::create_directories(_o.runDir / "logs");
  fs::create_directories(_o.runDir / "snapshots");
  fs::path initialState, gasRestart;
  std::int64_t startStep = 0;
  if (_o.resume) {
    const ResumeChoice choice = selectResumeCheckpoint(_o.runDir);
    for (const auto& s : choice.skipped) {
      _log->warn("skipping checkpoint {}: {}", s.dir.string(), s.reason);
    }
    COREDEM_CHECK(choice.dir.has_value(),
                  "{}: no complete checkpoint to resume from; start the run again with coredem run",
                  _o.runDir.string());
    const Manifest& m = *choice.manifest;
    COREDEM_CHECK(m.configHash == _c.configHash,
                  "{}: case.yaml of the run folder changed since checkpoint {} (config hash {} vs "
                  "{}); resume needs the case the run started with",
                  _o.runDir.string(), m.step, _c.configHash.substr(0, 12),
                  m.configHash.substr(0, 12));
    for (const auto& f : m.files) {
      if (f.participant == "dem" && initialState.empty()) {
        initialState = *choice.dir / f.path;
      }
      // The CFD participant's restart file: coredem-gas's gas.h5, coredemFoam's
      // coredemFoam.restart (the files of its time directory are listed as well).
      const bool restartFile = _c.cfd.participant == "coredemFoam"
                                   ? fs::path(f.path).filename() == "coredemFoam.restart"
                                   : fs::path(f.path).extension() == ".h5";
      if (f.participant == "cfd" && gasRestart.empty() && restartFile) {
        gasRestart = *choice.dir / f.path;
      }
    }
    COREDEM_CHECK(!initialState.empty(), "checkpoint {} has no DEM state file",
                  choice.dir->string());
    startStep = m.step;
    _time = TimeHandler(m.time, m.timeCompensation);
    _policy = DtPolicy(_c.dt, m.lastDt);
    _lastCourant = m.lastCourant;
    _snapshots.clear();
    for (const auto& s : readSnapshotIndex(_o.runDir)) {
      if (s.step <= m.step) {
        _snapshots.push_back(s);
      } else {
        fs::remove(_o.runDir / s.file);
      }
    }
    writeSnapshotIndex(_o.runDir, _snapshots);
    _timeseries = std::make_unique<TimeseriesWriter>(_o.runDir / "timeseries.csv", m.step);
    _log->info("resuming {} from checkpoint {} (step {}, t = {:.6g} s)", _o.runDir.string(),
               choice.dir->string(), m.step, m.time);
  } else {
    _time = TimeHandler();
    _policy = DtPolicy(_c.dt);
    _timeseries = std::make_unique<TimeseriesWriter>(_o.runDir / "timeseries.csv");
  }

  bool clean = false;
  try {
    startDem();
    configureDem(startStep, _time.time(), initialState);
    startCfd(gasRestart);
    handshakeCfd();
    if (!_o.resume && _c.output.snapshotEvery > 0) {
      takeSnapshot(0, 0.0);
    }
    stepLoop(startStep);
    clean = true;
  } catch (...) {
    shutdownAll(false);
    throw;
  }
  shutdownAll(clean);
  if (_measured > 0) {
    const double n = double(_measured);
    _log->info("{} steps: step wall {:.3f} ms, DEM compute {:.3f} ms, coupling overhead (wall - "
               "DEM) {:.3f} ms, orchestrator bookkeeping {:.1f} us per step; checkpoints {:.3f} s, "
               "snapshots {:.3f} s in total",
               _measured, 1e3 * _stepWallSum / n, 1e3 * _demWallSum / n,
               1e3 * (_stepWallSum - _demWallSum) / n, 1e6 * _overheadSum / n, _checkpointSum,
               _snapshotSum);
    writeFileAtomic(
        _o.runDir / "logs" / "overhead.json",
        fmt::format("{{\"steps\": {}, \"step_wall_s\": {:.9g}, \"dem_compute_s\": {:.9g}, "
                    "\"coupling_overhead_s\": {:.9g}, \"orchestrator_bookkeeping_s\": {:.9g}, "
                    "\"checkpoints_total_s\": {:.9g}, \"snapshots_total_s\": {:.9g}}}\n",
                    _measured, _stepWallSum / n, _demWallSum / n, (_stepWallSum - _demWallSum) / n,
                    _overheadSum / n, _checkpointSum, _snapshotSum));
  }
  return kExitOk;
}

} // namespace

void checkParticipantInput(const CaseConfig& config) {
  if (config.dem.endpoint.empty()) {
    COREDEM_CHECK(!findProgram("coredem-dem").empty(),
                  "coredem-dem not found next to coredem ({}) or on PATH; build it (cmake --build "
                  "build --target coredem-dem) or name a running server in dem.endpoint",
                  executableDir().string());
  }
  const fs::path exe = findProgram(config.cfd.participant);
  COREDEM_CHECK(!exe.empty(),
                "{} not found next to coredem ({}) or on PATH; build it (cmake --build "
                "build --target {})",
                config.cfd.participant, executableDir().string(), config.cfd.participant);
  if (config.cfd.participant == "coredemFoam") {
    const fs::path src = config.caseDir / config.cfd.foamCase;
    if (!fs::is_regular_file(src / "system" / "controlDict") &&
        !fs::is_regular_file(config.caseDir / "openfoam" / "system" / "controlDict")) {
      throw CaseError(fmt::format("{}: cfd.case: {} is not an OpenFOAM case folder (no "
                                  "system/controlDict); give the folder with system/, constant/ "
                                  "and 0/, relative to the case folder",
                                  config.caseFile.string(), src.string()));
    }
    return;
  }
  if (config.cfd.participant != "coredem-gas") {
    return;
  }
  char tmpl[] = "/tmp/coredem-check-XXXXXX";
  const int fd = ::mkstemp(tmpl);
  COREDEM_CHECK(fd >= 0, "cannot create a temporary file");
  ::close(fd);
  {
    ChildProcess check(
        "coredem-gas --check",
        {exe.string(), "--case", config.caseFile.string(), "--key", config.cfd.gasKey, "--check"},
        {}, tmpl);
    if (!check.waitFor(30000ms)) {
      check.stop();
    }
    const auto why = check.exitReason();
    if (check.exitCode() != 0) {
      std::ifstream in(tmpl);
      std::stringstream s;
      s << in.rdbuf();
      ::unlink(tmpl);
      // Keep the messages, drop the participant's log prefix "[time] [name] [level] ".
      std::string msg;
      std::string line;
      const std::regex prefix(R"(^\[[^\]]*\] \[[^\]]*\] \[[^\]]*\] )");
      while (std::getline(s, line)) {
        line = std::regex_replace(line, prefix, "");
        if (!line.empty()) {
          msg += (msg.empty() ? "" : "\n") + line;
        }
      }
      if (check.exitCode() == 2) {
        throw CaseError(msg.empty() ? config.caseFile.string() + ": gas section invalid" : msg);
      }
      COREDEM_CHECK(false, "coredem-gas --check {}: {}", why.value_or("failed"), msg);
    }
  }
  ::unlink(tmpl);
}

fs::path prepareRunDir(const CaseConfig& config, const std::optional<fs::path>& out) {
  fs::path dir;
  if (out) {
    dir = *out;
    if (fs::exists(dir / "case.yaml")) {
      throw CaseError(fmt::format("{} already holds a run; continue it with 'coredem resume {}' "
                                  "or choose another --out",
                                  dir.string(), dir.string()));
    }
  } else {
    dir = fs::path("runs") / config.name;
    if (fs::exists(dir)) {
      const std::time_t now = std::time(nullptr);
      std::tm tm{};
      ::localtime_r(&now, &tm);
      char buf[32];
      std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
      dir = fs::path("runs") / (config.name + "-" + buf);
      for (int i = 2; fs::exists(dir); ++i) {
        dir = fs::path("runs") / fmt::format("{}-{}-{}", config.name, buf, i);
      }
    }
  }
  fs::create_directories(dir / "logs");
  writeFileAtomic(dir / "case.yaml", config.text);
  writeFileAtomic(dir / "run.json",
                  fmt::format("{{\"case_dir\": \"{}\", \"case_file\": \"{}\", \"created\": \"{}\", "
                              "\"software_version\": \"{}\"}}\n",
                              config.caseDir.string(), config.caseFile.filename().string(),
                              utcNow(), COREDEM_SOFTWARE_VERSION));
  return fs::absolute(dir);
}

CaseConfig loadRunCase(const fs::path& runDir) {
  COREDEM_CHECK(fs::is_regular_file(runDir / "case.yaml") &&
                    fs::is_regular_file(runDir / "run.json"),
                "{} is not a run folder (no case.yaml/run.json); give the folder that "
                "'coredem run' created",
                runDir.string());
  std::ifstream in(runDir / "case.yaml", std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  fs::path caseDir = runDir;
  try {
    const YAML::Node run = YAML::LoadFile((runDir / "run.json").string());
    caseDir = run["case_dir"].as<std::string>();
  } catch (const std::exception& e) {
    COREDEM_CHECK(false, "{}: malformed run.json: {}", (runDir / "run.json").string(), e.what());
  }
  CaseConfig c = parseCase(text.str(), runDir / "case.yaml", caseDir);
  return c;
}

namespace {
/// Nothing half-written after a failure: checkpoint folders without a manifest and a
/// snapshot being received are removed.
void removeIncomplete(const fs::path& runDir) {
  for (const auto step : listCheckpointSteps(runDir)) {
    const fs::path d = checkpointDir(runDir, step);
    if (!fs::exists(d / "manifest.json")) {
      logger("orchestrator.session")->info("removing incomplete checkpoint {}", d.string());
      fs::remove_all(d);
    }
  }
  fs::remove_all(runDir / "snapshots" / ".incoming");
}
} // namespace

int runSession(const CaseConfig& config, const RunOptions& options) {
  auto log = logger("orchestrator.session");
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGPIPE, SIG_IGN);
  RunOptions opts = options;
  int restartsLeft = options.autoRestart;
  while (true) {
    try {
      Session session(config, opts);
      return session.run();
    } catch (const Interrupted& e) {
      removeIncomplete(opts.runDir);
      log->error("{}; participants stopped. Continue with: coredem resume {}", e.what(),
                 opts.runDir.string());
      return kExitInterrupted;
    } catch (const ParticipantFault& e) {
      log->error("{}", e.what());
      removeIncomplete(opts.runDir);
      const bool canResume = selectResumeCheckpoint(opts.runDir).dir.has_value();
      if (restartsLeft > 0 && canResume) {
        --restartsLeft;
        log->warn("auto-restart ({} left): relaunching the participants from the last complete "
                  "checkpoint",
                  restartsLeft);
        opts.resume = true;
        continue;
      }
      if (restartsLeft > 0) {
        log->error("no complete checkpoint to restart from");
      }
      log->error("the run stopped; the other participant was shut down. Continue with: coredem "
                 "resume {}",
                 opts.runDir.string());
      return kExitFault;
    }
  }
}

} // namespace coredem::orchestrator
