// coredem-soak: many coupled steps against a real coredem-dem process with injected peer
// faults, printing the server's memory (RSS) as it goes (bench/soak/run.sh; docs/security.md
// "Soak"). Not a timing benchmark: it checks that the server keeps serving and that its
// memory stays bounded, and exits 1 if either fails.
//
// The program plays both peers of a session (an orchestrator and a CFD participant, each its
// own connection) on a small case (60 particles, 27 coupling cells) and injects, on fixed
// step intervals:
//   * the CFD participant killed and restarted (its connection dropped, a new one says Hello
//     with the session id once the server has freed the role);
//   * the session ended by Shutdown, and the orchestrator's connection dropped without one
//     (the server ends the session), each followed by a new session (Configure at the step
//     reached, so the step count goes on);
//   * malformed messages interleaved: garbage bytes and an empty message from a stranger,
//     a truncated envelope and a GasFields with NaN from the CFD participant, a StepGrant for
//     the wrong step from the orchestrator; each must get its Error and change nothing;
//   * delayed replies: the CFD participant waits before sending its GasFields, the
//     orchestrator before granting.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "coredem/protocol/fields.h"
#include "coredem/protocol/protocol.h"

namespace proto = coredem::protocol;
namespace v1 = coredem::v1;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

constexpr int kCells = 3;
constexpr std::size_t kN = kCells * kCells * kCells;
constexpr double kBox = 6e-3;

v1::Configure smallCase(std::int64_t startStep, double startTime) {
  v1::Configure c;
  c.set_case_name("soak");
  auto* g = c.mutable_coupling_mesh()->mutable_cartesian();
  for (auto* v : {g->mutable_spacing()}) {
    v->set_x(kBox / kCells);
    v->set_y(kBox / kCells);
    v->set_z(kBox / kCells);
  }
  g->mutable_origin()->set_x(0.0);
  g->mutable_counts()->set_x(kCells);
  g->mutable_counts()->set_y(kCells);
  g->mutable_counts()->set_z(kCells);
  auto* sp = c.add_species();
  sp->set_name("N2");
  sp->set_molar_mass(0.028);
  auto* m = c.add_materials();
  m->set_id(0);
  m->set_name("glass");
  m->set_density(2500.0);
  m->set_k_n(1000.0);
  m->set_e_n(0.9);
  m->set_friction(0.3);
  m->set_cp(840.0);
  m->set_conductivity(1.0);
  m->set_emissivity(0.9);
  auto* ps = c.add_particle_sets();
  ps->set_name("beads");
  ps->set_material_id(0);
  ps->set_count(60);
  ps->set_diameter(1e-3);
  ps->set_density(2500.0);
  ps->set_temperature(300.0);
  ps->set_packing(v1::PACKING_RANDOM);
  ps->mutable_region_max()->set_x(kBox);
  ps->mutable_region_max()->set_y(kBox);
  ps->mutable_region_max()->set_z(kBox);
  ps->set_seed(7);
  auto* w = c.mutable_walls()->mutable_box();
  w->mutable_max()->set_x(kBox);
  w->mutable_max()->set_y(kBox);
  w->mutable_max()->set_z(kBox);
  c.mutable_gravity()->set_z(-9.81);
  c.mutable_sub_cycling()->set_dt_cfd(1e-4);
  c.mutable_sub_cycling()->set_n_sub(1);
  c.mutable_sub_cycling()->set_dt_dem(1e-4);
  c.set_start_step(startStep);
  c.set_start_time(startTime);
  return c;
}

proto::Message gasFields(std::int64_t step, double time, double dt, const std::string& session,
                         bool poison = false) {
  namespace f = proto::fields;
  auto m = proto::makeGasFields(step, time, dt, kN, 1);
  m.setSessionId(session);
  std::vector<double> zero3(3 * kN, 0.0), T(kN, 300.0);
  if (poison) {
    T[kN / 2] = std::nan("");
  }
  m.addArray(f::kGasVelocity, zero3, {kN, 3});
  m.addArray(f::kPressureGradient, zero3, {kN, 3});
  m.addArray(f::kGasTemperature, T, {kN});
  m.addArray(f::kGasDensity, std::vector<double>(kN, 1.2), {kN});
  m.addArray(f::kGasViscosity, std::vector<double>(kN, 1.8e-5), {kN});
  m.addArray(f::kGasConductivity, std::vector<double>(kN, 0.026), {kN});
  m.addArray(f::kGasHeatCapacity, std::vector<double>(kN, 1005.0), {kN});
  m.addArray(f::kGasMassFractions, std::vector<double>(kN, 1.0), {kN, 1});
  return m;
}

long rssKiB(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      return std::stol(line.substr(6));
    }
  }
  return -1;
}

struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void expect(bool ok, const std::string& what) {
  if (!ok) {
    throw Failure(what);
  }
}

std::string describe(const proto::Message& m) {
  if (m.type() == v1::MESSAGE_TYPE_ERROR) {
    return "Error " + proto::errorCodeName(m.envelope().error().code()) + ": " +
           m.envelope().error().message();
  }
  if (m.type() == v1::MESSAGE_TYPE_REJECT) {
    return "Reject " + proto::errorCodeName(m.envelope().reject().code()) + ": " +
           m.envelope().reject().reason();
  }
  return proto::messageTypeName(m.type());
}

struct Counts {
  std::uint64_t steps = 0, sessions = 0, cfdRestarts = 0, shutdowns = 0, orchestratorDrops = 0,
                malformed = 0, delayed = 0;
};

class Soak {
public:
  Soak(std::string endpoint, double dt)
      : _ep(std::move(endpoint))
      , _dt(dt) {}

  /// A new session whose first step is `step`: O's Hello (until the server is free),
  /// Configure, C's Hello.
  void open(std::int64_t step) {
    _o = std::make_unique<proto::Client>();
    _o->connect(_ep);
    proto::Message w;
    for (int i = 0; i < 200; ++i) { // a dropped orchestrator is noticed asynchronously
      w = _o->request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "coredem-soak"), 10s);
      if (w.type() == v1::MESSAGE_TYPE_WELCOME) {
        break;
      }
      std::this_thread::sleep_for(50ms);
    }
    expect(w.type() == v1::MESSAGE_TYPE_WELCOME, "orchestrator Hello: " + describe(w));
    _session = w.envelope().welcome().session_id();
    auto cfg = proto::makeConfigure(smallCase(step - 1, double(step - 1) * _dt));
    cfg.setSessionId(_session);
    auto r = _o->request(std::move(cfg), 30s);
    expect(r.type() == v1::MESSAGE_TYPE_CONFIGURED, "Configure: " + describe(r));
    const double dtMax = r.envelope().configured().dt_dem();
    _nSub = static_cast<std::uint32_t>(std::ceil(_dt / dtMax * (1.0 + 1e-9)));
    connectCfd();
    ++counts.sessions;
  }

  void connectCfd() {
    _c = std::make_unique<proto::Client>();
    _c->connect(_ep);
    proto::Message w;
    for (int i = 0; i < 200; ++i) { // the old connection's role is freed asynchronously
      auto h = proto::makeHello(v1::ROLE_CFD, "coredem-soak cfd");
      h.setSessionId(_session);
      w = _c->request(std::move(h), 10s);
      if (w.type() == v1::MESSAGE_TYPE_WELCOME) {
        return;
      }
      std::this_thread::sleep_for(50ms);
    }
    throw Failure("CFD Hello: " + describe(w));
  }

  void step(std::int64_t n, bool delayCfd, bool delayGrant) {
    const double t = double(n - 1) * _dt;
    if (delayGrant) {
      std::this_thread::sleep_for(20ms);
    }
    auto g = proto::makeStepGrant(n, t, _dt, _nSub, _dt / _nSub);
    g.setSessionId(_session);
    _o->send(std::move(g));
    if (delayCfd) {
      std::this_thread::sleep_for(20ms);
    }
    auto s = _c->request(gasFields(n, t, _dt, _session), 30s);
    expect(s.type() == v1::MESSAGE_TYPE_SOURCES, "step " + std::to_string(n) + ": " + describe(s));
    auto d = _o->receive(30s);
    expect(d.has_value() && d->type() == v1::MESSAGE_TYPE_STEP_DONE,
           "step " + std::to_string(n) + ": no StepDone" + (d ? ": " + describe(*d) : ""));
    ++counts.steps;
  }

  /// Malformed messages of every peer; each must be refused and change nothing.
  void malformed(std::int64_t next) {
    proto::Client stranger;
    stranger.connect(_ep);
    stranger.sendFrames({std::string("\xff\xfe\x01 garbage \x8f", 13)});
    auto r = stranger.receive(10s);
    expect(r && r->type() == v1::MESSAGE_TYPE_ERROR, "garbage was not refused");
    stranger.sendFrames({std::string()});
    r = stranger.receive(10s);
    expect(r && r->type() == v1::MESSAGE_TYPE_ERROR &&
               r->envelope().error().code() == v1::ERROR_CODE_UNKNOWN_TYPE,
           "an empty message was not refused UNKNOWN_TYPE");
    auto frames = gasFields(next, 0.0, _dt, _session).encode();
    frames[0].resize(frames[0].size() / 2); // truncated envelope
    _c->sendFrames(frames);
    r = _c->receive(10s);
    expect(r && r->type() == v1::MESSAGE_TYPE_ERROR, "a truncated envelope was not refused");
    auto bad = _o->request(
        [&] {
          auto g = proto::makeStepGrant(next + 5, 0.0, _dt, _nSub, _dt / _nSub);
          g.setSessionId(_session);
          return g;
        }(),
        10s);
    expect(bad.type() == v1::MESSAGE_TYPE_ERROR &&
               bad.envelope().error().code() == v1::ERROR_CODE_OUT_OF_ORDER,
           "a StepGrant for the wrong step: " + describe(bad));
    counts.malformed += 4;
  }

  /// A NaN GasFields before the good one of step n (granted first).
  void poisonedStep(std::int64_t n) {
    const double t = double(n - 1) * _dt;
    auto g = proto::makeStepGrant(n, t, _dt, _nSub, _dt / _nSub);
    g.setSessionId(_session);
    _o->send(std::move(g));
    auto e = _c->request(gasFields(n, t, _dt, _session, true), 30s);
    expect(e.type() == v1::MESSAGE_TYPE_ERROR &&
               e.envelope().error().code() == v1::ERROR_CODE_NON_FINITE,
           "a GasFields with NaN: " + describe(e));
    ++counts.malformed;
    auto s = _c->request(gasFields(n, t, _dt, _session), 30s);
    expect(s.type() == v1::MESSAGE_TYPE_SOURCES, "step " + std::to_string(n) + ": " + describe(s));
    auto d = _o->receive(30s);
    expect(d.has_value() && d->type() == v1::MESSAGE_TYPE_STEP_DONE, "no StepDone after NaN");
    ++counts.steps;
  }

  void restartCfd() {
    _c.reset(); // killed: the connection closes without a word
    connectCfd();
    ++counts.cfdRestarts;
  }

  void shutdown() {
    auto s = proto::makeShutdown("soak: session restart");
    s.setSessionId(_session);
    auto a = _o->request(std::move(s), 10s);
    expect(a.type() == v1::MESSAGE_TYPE_ACK, "Shutdown: " + describe(a));
    _c.reset();
    _o.reset();
    ++counts.shutdowns;
  }

  void dropOrchestrator() {
    _c.reset();
    _o.reset(); // the server ends the session when it sees the connection close
    ++counts.orchestratorDrops;
  }

  Counts counts;

private:
  std::string _ep;
  double _dt;
  std::unique_ptr<proto::Client> _o, _c;
  std::string _session;
  std::uint32_t _nSub = 1;
};

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"coredem-soak: coupled steps with injected peer faults against coredem-dem, "
               "printing its memory (not a timing benchmark)"};
  std::string dem = "coredem-dem", workDir;
  std::int64_t steps = 100000, every = 5000, cfdEvery = 1000, shutdownEvery = 5000,
               dropEvery = 10000;
  double dt = 1e-4, maxGrowthMiB = 64.0;
  app.add_option("--dem", dem, "the coredem-dem program")->capture_default_str();
  app.add_option("--steps", steps, "coupled steps")
      ->capture_default_str()
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{100000000}));
  app.add_option("--report-every", every, "steps between memory lines")->capture_default_str();
  app.add_option("--dt", dt, "CFD step (s)")->capture_default_str();
  app.add_option("--cfd-restart-every", cfdEvery, "steps between CFD participant restarts")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--shutdown-every", shutdownEvery, "steps between sessions ended by Shutdown")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--drop-every", dropEvery,
                 "steps between sessions ended by the orchestrator's connection dropping")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--max-growth-mib", maxGrowthMiB,
                 "largest growth of the server's RSS after the first tenth of the run")
      ->capture_default_str();
  app.add_option("--work-dir", workDir, "folder for the server's endpoint file and log");
  CLI11_PARSE(app, argc, argv);

  if (workDir.empty()) {
    workDir = (fs::temp_directory_path() / ("coredem-soak-" + std::to_string(::getpid()))).string();
  }
  fs::create_directories(workDir);
  const std::string epFile = workDir + "/endpoint", log = workDir + "/dem.log";
  fs::remove(epFile);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::setenv("COREDEM_LOG_LEVEL", "warn", 0); // refusals and session ends, not every session
    ::execlp(dem.c_str(), dem.c_str(), "--bind", "tcp://127.0.0.1:*", "--threads", "1",
             "--endpoint-file", epFile.c_str(), "--timeout-s", "120", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  for (int i = 0; i < 3000 && !fs::exists(epFile); ++i) {
    std::this_thread::sleep_for(10ms);
  }
  std::string ep;
  std::ifstream(epFile) >> ep;
  if (ep.empty()) {
    std::cerr << "coredem-soak: " << dem << " did not start; see " << log << "\n";
    ::kill(pid, SIGKILL);
    return 2;
  }
  std::printf("coredem-soak: %lld steps against %s (pid %d), log %s\n",
              static_cast<long long>(steps), ep.c_str(), pid, log.c_str());
  std::printf("%10s %10s %8s %9s %9s %9s %9s %9s\n", "step", "RSS_KiB", "wall_s", "sessions",
              "cfd_kill", "o_drop", "malformed", "delayed");
  const auto t0 = std::chrono::steady_clock::now();
  Soak soak(ep, dt);
  long baseline = -1, peak = 0;
  int rc = 0;
  try {
    soak.open(1);
    for (std::int64_t n = 1; n <= steps; ++n) {
      if (n > 1 && (n - 1) % dropEvery == 0) { // the orchestrator drops its connection
        soak.dropOrchestrator();
        soak.open(n);
      } else if (n > 1 && (n - 1) % shutdownEvery == 0) { // the session ends by Shutdown
        soak.shutdown();
        soak.open(n);
      } else if (n > 1 && (n - 1) % cfdEvery == 0) { // the CFD participant is killed and restarted
        soak.restartCfd();
      }
      if (n % 97 == 0) {
        soak.malformed(n);
      }
      if (n % 101 == 0) {
        soak.poisonedStep(n);
      } else {
        const bool delayCfd = n % 211 == 0, delayGrant = n % 307 == 0;
        soak.counts.delayed += (delayCfd ? 1 : 0) + (delayGrant ? 1 : 0);
        soak.step(n, delayCfd, delayGrant);
      }
      if (n % every == 0 || n == steps) {
        const long rss = rssKiB(pid);
        peak = std::max(peak, rss);
        if (baseline < 0 && n >= std::max<std::int64_t>(every, steps / 10)) {
          baseline = rss;
        }
        const auto& c = soak.counts;
        std::printf("%10lld %10ld %8.1f %9llu %9llu %9llu %9llu %9llu\n", static_cast<long long>(n),
                    rss,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                    static_cast<unsigned long long>(c.sessions),
                    static_cast<unsigned long long>(c.cfdRestarts),
                    static_cast<unsigned long long>(c.orchestratorDrops),
                    static_cast<unsigned long long>(c.malformed),
                    static_cast<unsigned long long>(c.delayed));
        std::fflush(stdout);
      }
    }
    soak.shutdown();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coredem-soak: FAILED after %llu steps: %s (server log: %s)\n",
                 static_cast<unsigned long long>(soak.counts.steps), e.what(), log.c_str());
    rc = 1;
  }
  ::kill(pid, SIGTERM);
  int status = 0;
  for (int i = 0; i < 1000 && ::waitpid(pid, &status, WNOHANG) == 0; ++i) {
    std::this_thread::sleep_for(10ms);
  }
  if (::waitpid(pid, &status, WNOHANG) == 0 && !WIFEXITED(status)) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    std::fprintf(stderr, "coredem-soak: the server did not exit within 10 s of SIGTERM\n");
    rc = 1;
  }
  if (rc == 0 && baseline > 0 && double(peak - baseline) / 1024.0 > maxGrowthMiB) {
    std::fprintf(stderr,
                 "coredem-soak: FAILED: the server's RSS grew from %ld KiB to %ld KiB after the "
                 "first tenth of the run (limit %.0f MiB)\n",
                 baseline, peak, maxGrowthMiB);
    rc = 1;
  }
  std::printf("coredem-soak: %s: %llu steps, %llu sessions, %llu CFD restarts, %llu Shutdowns, "
              "%llu orchestrator drops, %llu malformed messages refused, %llu delays; server RSS "
              "%ld KiB after the first tenth, peak %ld KiB\n",
              rc == 0 ? "OK" : "FAILED", static_cast<unsigned long long>(soak.counts.steps),
              static_cast<unsigned long long>(soak.counts.sessions),
              static_cast<unsigned long long>(soak.counts.cfdRestarts),
              static_cast<unsigned long long>(soak.counts.shutdowns),
              static_cast<unsigned long long>(soak.counts.orchestratorDrops),
              static_cast<unsigned long long>(soak.counts.malformed),
              static_cast<unsigned long long>(soak.counts.delayed), baseline, peak);
  return rc;
}
