// The coupling client (docs/client.md): C's side of docs/session.md over the protocol library.
#include "coredem/client/participant.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>

#include "coredem/common/check.h"
#include "coredem/common/log.h"
#include "coredem/common/version.h"
#include "coredem/protocol/protocol.h"
#include "participant_impl.h"

namespace coredem::client {

namespace detail {

const std::string kLibraryVersion = std::string("coredem-client ") + coredem::kVersion;

std::string fromEnv(const std::string& given, const char* var) {
  if (!given.empty()) {
    return given;
  }
  const char* v = std::getenv(var);
  return v != nullptr ? std::string(v) : std::string();
}

} // namespace detail

using detail::fromEnv;
using detail::kDefaultTimeoutS;
using detail::kLibraryVersion;

const char* stateName(State s) {
  switch (s) {
  case State::Created:
    return "Created";
  case State::Granted:
    return "Granted";
  case State::Exchanged:
    return "Exchanged";
  case State::Finished:
    return "Finished";
  case State::Finalized:
    return "Finalized";
  }
  return "?";
}

ConstView Sources::field(const std::string& name) const {
  if (const auto v = views.find(name); v != views.end()) {
    return v->second;
  }
  const auto it = arrays.find(name);
  if (it == arrays.end()) {
    std::string sent;
    for (const auto& n : names())
      sent += (sent.empty() ? "" : ", ") + n;
    throw ClientError(ErrorCode::Argument,
                      "Sources: no array '" + name + "' (D sent: " + sent + ")");
  }
  return ConstView(it->second.data(), it->second.size());
}

ConstView Sources::radiationHeat() const {
  const std::string name(proto::fields::kRadiationHeat);
  return has(name) ? field(name) : ConstView();
}

ConstView Sources::releasedMomentum() const {
  const std::string name(proto::fields::kReleasedMomentum);
  return has(name) ? field(name) : ConstView();
}

bool Sources::has(const std::string& name) const {
  return views.count(name) == 1 || arrays.count(name) == 1;
}

std::vector<std::string> Sources::names() const {
  std::set<std::string> n;
  for (const auto& kv : views)
    n.insert(kv.first);
  for (const auto& kv : arrays)
    n.insert(kv.first);
  return {n.begin(), n.end()};
}

proto::TransportOptions Participant::Impl::transport(bool forDem) const {
  proto::TransportOptions t;
  t.sender =
      opt.name + " (" + (opt.softwareVersion.empty() ? kLibraryVersion : opt.softwareVersion) + ")";
  if (forDem) {
    const auto key = fromEnv(opt.demServerPublicKey, "COREDEM_DEM_SERVER_KEY");
    const auto keyFile = fromEnv(opt.demClientKeyFile, "COREDEM_DEM_CLIENT_KEY_FILE");
    COREDEM_CHECK(!key.empty() || keyFile.empty(),
                  "{}: a client key ({}) is given but no DEM server public key "
                  "(COREDEM_DEM_SERVER_KEY): client keys are only used with CURVE",
                  opt.name, keyFile);
    if (!key.empty()) {
      const auto pair =
          keyFile.empty() ? proto::generateCurveKeyPair() : proto::readClientKeyPair(keyFile);
      t.curve.serverPublicKey = key;
      t.curve.clientPublicKey = pair.first;
      t.curve.clientSecretKey = pair.second;
    }
  }
  return t;
}

void Participant::Impl::takeGrantOrShutdown(const proto::Message& reply,
                                            std::int64_t expectedStep) {
  if (reply.type() == v1::MESSAGE_TYPE_SHUTDOWN) {
    shutdownReason = reply.envelope().shutdown().reason();
    state = State::Finished;
    log->info("{}: the orchestrator ended the run ({})", opt.name,
              shutdownReason.empty() ? "no reason given" : shutdownReason);
    return;
  }
  proto::expectType(reply, v1::MESSAGE_TYPE_STEP_GRANT);
  proto::Expectation e;
  e.types = {v1::MESSAGE_TYPE_STEP_GRANT};
  e.step = expectedStep;
  if (const auto s = proto::validate(reply, e); !s.ok()) {
    throw proto::ProtocolError(s.code,
                               "orchestrator " + controlEp + " sent a bad StepGrant: " + s.message);
  }
  const auto& g = reply.envelope().step_grant();
  COREDEM_CHECK(g.dt_cfd() > 0.0 && g.n_sub() >= 1,
                "orchestrator {} granted step {} with dt_cfd = {} s and n_sub = {}: both must "
                "be positive",
                controlEp, expectedStep, g.dt_cfd(), g.n_sub());
  step = reply.envelope().step();
  time = reply.envelope().time();
  dt = g.dt_cfd();
  nSub = static_cast<int>(g.n_sub());
  dtDem = g.dt_dem() > 0.0 ? g.dt_dem() : dt / nSub;
  checkpointDir = g.has_checkpoint() ? g.checkpoint().directory() : std::string();
  outputRequested = g.has_checkpoint() && g.checkpoint().tag() == proto::kOutputTag;
  state = State::Granted;
}

proto::Message Participant::Impl::handshake(proto::Client& client, const std::string& peer,
                                            bool rank) {
  auto hello = proto::makeHello(v1::ROLE_CFD, opt.softwareVersion.empty() ? kLibraryVersion
                                                                          : opt.softwareVersion);
  hello.setSessionId(session);
  if (rank && decomposed()) {
    hello.envelope().mutable_hello()->set_rank(static_cast<std::uint32_t>(opt.rank));
    hello.envelope().mutable_hello()->set_rank_count(static_cast<std::uint32_t>(opt.rankCount));
  }
  auto reply = client.request(std::move(hello), timeout);
  proto::expectType(reply, v1::MESSAGE_TYPE_WELCOME);
  const auto& w = reply.envelope().welcome();
  COREDEM_CHECK(w.protocol_major() == proto::kProtocolVersion.major,
                "{} at {} speaks protocol {}.{}, this client {}", peer, client.endpoint(),
                w.protocol_major(), w.protocol_minor(), proto::kProtocolVersion.toString());
  log->info("{}: connected to {} at {} (protocol {}.{}, session {})", opt.name, peer,
            client.endpoint(), w.protocol_major(), w.protocol_minor(), session);
  return reply;
}

void Participant::Impl::checkRank() const {
  COREDEM_CHECK(opt.rankCount >= 0 && opt.rank >= 0 &&
                    (opt.rankCount <= 1 ? opt.rank == 0 : opt.rank < opt.rankCount),
                "{}: rank {} of {} ranks: the rank index must lie in [0, rank count)", opt.name,
                opt.rank, opt.rankCount);
}

void Participant::Impl::connectDem() {
  dem = std::make_unique<proto::Client>(transport(true));
  dem->connect(demEp);
  const auto w = handshake(*dem, "DEM server", true);
  demMinor = static_cast<int>(w.envelope().welcome().protocol_minor());
  if (decomposed() && demMinor < static_cast<int>(proto::kMinorDecomposed)) {
    throw ClientError(ErrorCode::Peer,
                      fmt::format("{}: the DEM server at {} agreed protocol 1.{}, this client "
                                  "speaks {}; a decomposed CFD participant ({} ranks) needs "
                                  "1.{} or later on both sides: update coredem-dem",
                                  opt.name, demEp, demMinor, proto::kProtocolVersion.toString(),
                                  opt.rankCount, proto::kMinorDecomposed));
  }
}

void Participant::Impl::readEnvironment() {
  controlEp = fromEnv(opt.controlEndpoint, "COREDEM_CONTROL_ENDPOINT");
  demEp = fromEnv(opt.demEndpoint, "COREDEM_DEM_ENDPOINT");
  session = fromEnv(opt.sessionId, "COREDEM_SESSION");
  COREDEM_CHECK(!demEp.empty(), "no DEM server endpoint: set COREDEM_DEM_ENDPOINT (or "
                                "Options::demEndpoint / --dem), e.g. tcp://127.0.0.1:40125");
  COREDEM_CHECK(!session.empty(), "no session id: set COREDEM_SESSION (or Options::sessionId / "
                                  "--session) to the id the orchestrator passes");
  double t = opt.timeoutSeconds;
  if (t <= 0.0) {
    const auto env = fromEnv("", "COREDEM_TIMEOUT_S");
    t = kDefaultTimeoutS;
    if (!env.empty()) {
      char* end = nullptr;
      t = std::strtod(env.c_str(), &end);
      COREDEM_CHECK(end != env.c_str() && *end == '\0' && t > 0.0,
                    "COREDEM_TIMEOUT_S='{}' is not a positive number of seconds", env);
    }
  }
  timeout = std::chrono::milliseconds(static_cast<std::int64_t>(std::ceil(t * 1000.0)));
}

void Participant::Impl::initialize() {
  checkRank();
  COREDEM_CHECK(opt.rank == 0,
                "{}: rank {} of a decomposed run follows rank 0 (Participant::follow) instead of "
                "calling initialize()",
                opt.name, opt.rank);
  controlEp = fromEnv(opt.controlEndpoint, "COREDEM_CONTROL_ENDPOINT");
  COREDEM_CHECK(!controlEp.empty(),
                "no orchestrator control endpoint: set COREDEM_CONTROL_ENDPOINT "
                "(or Options::controlEndpoint / --control), e.g. tcp://127.0.0.1:40123");
  readEnvironment();

  // 1. Hello to O.
  control = std::make_unique<proto::Client>(transport(false));
  control->connect(controlEp);
  handshake(*control, "orchestrator");

  // 2. The case.
  proto::Message ask(v1::MESSAGE_TYPE_CONFIGURE);
  ask.setBody(v1::Configure{});
  ask.setSessionId(session);
  auto cfg = control->request(std::move(ask), timeout);
  proto::expectType(cfg, v1::MESSAGE_TYPE_CONFIGURE);
  const auto& c = cfg.envelope().configure();
  COREDEM_CHECK(c.coupling_mesh().has_cartesian(),
                "orchestrator {} sent a Configure without a Cartesian coupling grid; this "
                "client supports coupling_mesh.cartesian only",
                controlEp);
  const auto& g = c.coupling_mesh().cartesian();
  grid.origin[0] = g.origin().x();
  grid.origin[1] = g.origin().y();
  grid.origin[2] = g.origin().z();
  grid.spacing[0] = g.spacing().x();
  grid.spacing[1] = g.spacing().y();
  grid.spacing[2] = g.spacing().z();
  grid.counts[0] = static_cast<std::int64_t>(g.counts().x());
  grid.counts[1] = static_cast<std::int64_t>(g.counts().y());
  grid.counts[2] = static_cast<std::int64_t>(g.counts().z());
  COREDEM_CHECK(grid.cellCount() > 0, "orchestrator {} sent an empty coupling grid ({} x {} x {})",
                controlEp, grid.counts[0], grid.counts[1], grid.counts[2]);
  grid.species.clear();
  grid.molarMasses.clear();
  for (const auto& s : c.species()) {
    grid.species.push_back(s.name());
    grid.molarMasses.push_back(s.molar_mass());
  }
  startStep = c.start_step();
  startTime = c.start_time();

  // 3. Hello to D.
  connectDem();

  // 4. Ready: the reply is the first grant.
  auto ready = proto::makeConfigured(static_cast<std::uint64_t>(grid.cellCount()), 0,
                                     static_cast<std::uint32_t>(grid.species.size()), 0, 0.0);
  ready.setSessionId(session);
  ready.setStep(startStep);
  takeGrantOrShutdown(control->request(std::move(ready), timeout), startStep + 1);
  if (state == State::Granted) {
    log->info("{}: coupled on a {} x {} x {} grid with {} species; first grant: step {}, dt {} s",
              opt.name, grid.counts[0], grid.counts[1], grid.counts[2], grid.species.size(), step,
              dt);
  }
}

void Participant::Impl::advance(double courant, const Ledgers& ledgers,
                                const std::vector<std::string>& files) {
  COREDEM_CHECK(opt.rank == 0,
                "advance: rank {} of a decomposed run follows rank 0's control state "
                "(Participant::follow); only rank 0 reports the step to the orchestrator",
                opt.rank);
  COREDEM_CHECK(std::isfinite(courant) && courant >= 0.0,
                "advance: the Courant number must be finite and >= 0 (got {})", courant);
  COREDEM_CHECK(files.empty() || !checkpointDir.empty(),
                "advance: checkpoint files given for step {}, but its grant asked for no "
                "checkpoint",
                step);
  v1::StepDone body;
  body.set_cfl(courant);
  auto fill = [](auto* list, const std::vector<std::pair<std::string, double>>& values) {
    for (const auto& [name, value] : values) {
      proto::addNamedValue(list, name, value);
    }
  };
  fill(body.mutable_ledger()->mutable_mass(), ledgers.mass);
  fill(body.mutable_ledger()->mutable_energy(), ledgers.energy);
  fill(body.mutable_ledger()->mutable_species(), ledgers.species);
  fill(body.mutable_diagnostics(), ledgers.diagnostics);
  if (!checkpointDir.empty()) {
    body.mutable_checkpoint()->set_directory(checkpointDir);
    for (const auto& f : files) {
      body.mutable_checkpoint()->add_files(f);
    }
  }
  auto done = proto::makeStepDone(step, time, body);
  done.setSessionId(session);
  takeGrantOrShutdown(control->request(std::move(done), timeout), step + 1);
}

std::string Participant::Impl::controlState() const {
  COREDEM_CHECK(state == State::Granted || state == State::Finished,
                "controlState() after initialize() or advance() (state {})", stateName(state));
  std::string out = "coredem-control-state 1\n";
  const auto str = [&](const std::string& v) { out += fmt::format("{}:{}\n", v.size(), v); };
  const auto num = [&](double v) { out += fmt::format("{:a}\n", v); }; // exact (hex float)
  const auto integer = [&](std::int64_t v) { out += fmt::format("{}\n", v); };
  for (int a = 0; a < 3; ++a) {
    num(grid.origin[a]);
    num(grid.spacing[a]);
    integer(grid.counts[a]);
  }
  integer(static_cast<std::int64_t>(grid.species.size()));
  for (std::size_t k = 0; k < grid.species.size(); ++k) {
    str(grid.species[k]);
    num(grid.molarMasses[k]);
  }
  integer(startStep);
  num(startTime);
  integer(state == State::Finished ? 1 : 0);
  str(shutdownReason);
  integer(step);
  num(time);
  num(dt);
  integer(nSub);
  num(dtDem);
  str(checkpointDir);
  integer(outputRequested ? 1 : 0);
  return out;
}

void Participant::Impl::follow(const std::string& text) {
  COREDEM_CHECK(state == State::Created || state == State::Exchanged,
                "follow() is called first (instead of initialize()) and after each exchange; "
                "state {}",
                stateName(state));
  std::size_t pos = 0;
  const auto line = [&]() {
    const auto end = text.find('\n', pos);
    COREDEM_CHECK(end != std::string::npos, "follow(): truncated control state");
    std::string l = text.substr(pos, end - pos);
    pos = end + 1;
    return l;
  };
  const auto str = [&]() {
    const auto colon = text.find(':', pos);
    COREDEM_CHECK(colon != std::string::npos, "follow(): malformed control state");
    const std::size_t n = std::stoull(text.substr(pos, colon - pos));
    COREDEM_CHECK(colon + 1 + n < text.size() && text[colon + 1 + n] == '\n',
                  "follow(): malformed control state");
    std::string v = text.substr(colon + 1, n);
    pos = colon + 2 + n;
    return v;
  };
  const auto num = [&]() { return std::strtod(line().c_str(), nullptr); };
  const auto integer = [&]() { return static_cast<std::int64_t>(std::stoll(line())); };
  COREDEM_CHECK(line() == "coredem-control-state 1",
                "follow(): not a control state of this client library version");
  Grid g;
  for (int a = 0; a < 3; ++a) {
    g.origin[a] = num();
    g.spacing[a] = num();
    g.counts[a] = integer();
  }
  const std::int64_t nSpecies = integer();
  for (std::int64_t k = 0; k < nSpecies; ++k) {
    g.species.push_back(str());
    g.molarMasses.push_back(num());
  }
  const std::int64_t start = integer();
  const double startT = num();
  const bool finished = integer() != 0;
  std::string reason = str();
  const std::int64_t nextStep = integer();
  const double nextTime = num();
  const double nextDt = num();
  const int nextNSub = static_cast<int>(integer());
  const double nextDtDem = num();
  std::string dir = str();
  const bool output = integer() != 0;
  if (state == State::Created) {
    checkRank();
    COREDEM_CHECK(opt.rank > 0 && opt.rankCount > 1,
                  "{}: follow() is for ranks > 0 of a decomposed run (rank {} of {})", opt.name,
                  opt.rank, opt.rankCount);
    readEnvironment();
    grid = g;
    startStep = start;
    startTime = startT;
    connectDem();
  } else if (nextStep != step + 1 && !finished) {
    throw ClientError(ErrorCode::Protocol,
                      fmt::format("{}: rank {} is at step {} but rank 0's next grant is of step "
                                  "{}",
                                  opt.name, opt.rank, step, nextStep));
  }
  if (finished) {
    shutdownReason = std::move(reason);
    state = State::Finished;
    return;
  }
  step = nextStep;
  time = nextTime;
  dt = nextDt;
  nSub = nextNSub;
  dtDem = nextDtDem;
  checkpointDir = std::move(dir);
  outputRequested = output;
  state = State::Granted;
}

void Participant::Impl::finalize() {
  if (state == State::Finalized) {
    return;
  }
  if (state == State::Granted || state == State::Exchanged) {
    log->warn("{}: finalize() during step {} before the orchestrator ended the run", opt.name,
              step);
  }
  dem.reset();
  control.reset();
  sources = Sources();
  state = State::Finalized;
}

namespace {

/// Runs f, turning every exception into ClientError with the matching code.
template <class F>
decltype(auto) guarded(const char* call, F&& f) {
  try {
    return f();
  } catch (const ClientError&) {
    throw;
  } catch (const proto::TimeoutError& e) {
    throw ClientError(ErrorCode::Timeout, std::string(call) + ": " + e.what());
  } catch (const proto::PeerError& e) {
    throw ClientError(ErrorCode::Peer, std::string(call) + ": the peer refused: " + e.what());
  } catch (const proto::TransportError& e) {
    throw ClientError(ErrorCode::Protocol, std::string(call) + ": " + e.what());
  } catch (const proto::ProtocolError& e) {
    throw ClientError(ErrorCode::Protocol, std::string(call) + ": " + e.what());
  } catch (const coredem::UserError& e) {
    throw ClientError(ErrorCode::Argument, std::string(call) + ": " + e.what());
  } catch (const std::exception& e) {
    throw ClientError(ErrorCode::Internal, std::string(call) + ": internal error: " + e.what());
  }
}

} // namespace

Participant::Participant(Options options)
    : _impl(std::make_unique<Impl>()) {
  _impl->opt = std::move(options);
}
Participant::~Participant() {
  if (_impl) {
    try {
      _impl->finalize();
    } catch (...) { // never throw from a destructor
    }
  }
}
Participant::Participant(Participant&&) noexcept = default;
Participant& Participant::operator=(Participant&&) noexcept = default;

void Participant::initialize() {
  _impl->require({State::Created}, "initialize", "initialize() is called once, first");
  guarded("initialize", [&] { _impl->initialize(); });
}

State Participant::state() const {
  return _impl->state;
}
bool Participant::isRunning() const {
  return _impl->state == State::Granted || _impl->state == State::Exchanged;
}

#define COREDEM_GRANT_GETTER(type, name, member)                                                   \
  type Participant::name() const {                                                                 \
    _impl->require({State::Granted, State::Exchanged}, #name,                                      \
                   "the grant is known between initialize()/advance() and the end of the run");    \
    return _impl->member;                                                                          \
  }
COREDEM_GRANT_GETTER(std::int64_t, step, step)
COREDEM_GRANT_GETTER(double, time, time)
COREDEM_GRANT_GETTER(double, dt, dt)
COREDEM_GRANT_GETTER(int, nSub, nSub)
COREDEM_GRANT_GETTER(double, dtDem, dtDem)
COREDEM_GRANT_GETTER(std::string, checkpointDir, checkpointDir)
COREDEM_GRANT_GETTER(bool, requiresOutput, outputRequested)
#undef COREDEM_GRANT_GETTER

bool Participant::requiresCheckpoint() const {
  return !checkpointDir().empty();
}

std::string Participant::shutdownReason() const {
  _impl->require({State::Finished, State::Finalized}, "shutdownReason", "the run has not ended");
  return _impl->shutdownReason;
}

const Grid& Participant::grid() const {
  _impl->require({State::Granted, State::Exchanged, State::Finished}, "grid",
                 "the grid arrives with initialize()");
  return _impl->grid;
}
std::int64_t Participant::startStep() const {
  _impl->require({State::Granted, State::Exchanged, State::Finished}, "startStep",
                 "the start step arrives with initialize()");
  return _impl->startStep;
}
double Participant::startTime() const {
  _impl->require({State::Granted, State::Exchanged, State::Finished}, "startTime",
                 "the start time arrives with initialize()");
  return _impl->startTime;
}

const Sources& Participant::exchange(std::int64_t step, double dt,
                                     const std::vector<NamedField>& fields) {
  _impl->require({State::Granted}, "exchange",
                 "exchange() once per grant, after initialize() or advance() granted a step");
  return guarded("exchange",
                 [&]() -> const Sources& { return _impl->exchange(step, dt, fields, {}); });
}

const Sources& Participant::exchange(std::int64_t step, double dt,
                                     const std::vector<NamedField>& fields,
                                     const std::vector<NamedBuffer>& into) {
  _impl->require({State::Granted}, "exchange",
                 "exchange() once per grant, after initialize() or advance() granted a step");
  return guarded("exchange",
                 [&]() -> const Sources& { return _impl->exchange(step, dt, fields, into); });
}

const Sources& Participant::exchangePartial(std::int64_t step, double dt,
                                            const std::vector<std::int64_t>& cells,
                                            ConstView fluidVolume,
                                            const std::vector<NamedField>& sums) {
  _impl->require({State::Granted}, "exchangePartial",
                 "exchangePartial() once per grant, after initialize()/follow() or advance()");
  return guarded("exchangePartial", [&]() -> const Sources& {
    return _impl->exchange(step, dt, sums, {}, &cells, fluidVolume);
  });
}

std::string Participant::controlState() const {
  return guarded("controlState", [&] { return _impl->controlState(); });
}

void Participant::follow(const std::string& controlState) {
  _impl->require({State::Created, State::Exchanged}, "follow",
                 "follow() replaces initialize() on ranks > 0 and takes each next grant after "
                 "exchangePartial()");
  guarded("follow", [&] { _impl->follow(controlState); });
}

int Participant::demProtocolMinor() const {
  return _impl->demMinor;
}

void Participant::setHeatToParticles(ConstView values) {
  _impl->require({State::Granted}, "setHeatToParticles",
                 "set Q_split after a grant, before that step's exchange()");
  guarded("setHeatToParticles", [&] {
    Impl& m = *_impl;
    COREDEM_CHECK(m.demMinor >= static_cast<int>(proto::kMinorHeatToParticles),
                  "setHeatToParticles: {}; Q_split needs 1.{} or later (an older DEM server "
                  "would drop the heat): update coredem-dem, or keep the split in the gas",
                  m.versionsAgreed(), proto::kMinorHeatToParticles);
    COREDEM_CHECK(values.size == 0 || values.data != nullptr,
                  "setHeatToParticles: {} values at a null pointer", values.size);
    for (std::size_t i = 0; i < values.size; ++i) {
      COREDEM_CHECK(std::isfinite(values[i]),
                    "setHeatToParticles: Q_split[{}] = {} J/m3 is not finite; check the gas "
                    "solution of that cell",
                    i, values[i]);
    }
    m.heatToParticles.assign(values.begin(), values.end());
    m.hasHeatToParticles = true;
  });
}

bool Participant::takesHeatToParticles() const {
  return _impl->demMinor >= static_cast<int>(proto::kMinorHeatToParticles);
}

ExchangeTimes Participant::lastExchangeTimes() const {
  return _impl->times;
}

const Sources& Participant::sources() const {
  _impl->require({State::Exchanged}, "sources", "sources exist between exchange() and advance()");
  return _impl->sources;
}

void Participant::advance(double courant, const Ledgers& ledgers,
                          const std::vector<std::string>& checkpointFiles) {
  _impl->require({State::Exchanged}, "advance", "advance() follows exchange() of the granted step");
  guarded("advance", [&] { _impl->advance(courant, ledgers, checkpointFiles); });
}

void Participant::finalize() {
  _impl->finalize();
}

} // namespace coredem::client
