// The participants against a real coredem-dem process over tcp loopback: the C API program,
// coredem-gas (checkpoint + restart with identical ledgers) and the C++ client's argument checks.
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fstream>
#include <mutex>
#include <numbers>

#include <gtest/gtest.h>

#include "coredem/client/participant.h"
#include "mini_orchestrator.h"
#include "process.h"

using namespace coredem::testing;
namespace fs = std::filesystem;

namespace {

fs::path tempDir(const std::string& name) {
  const auto d = fs::temp_directory_path() /
                 ("coredem-participants-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

constexpr int kParticles = 50;
constexpr double kD = 1e-3;
constexpr double kBox = 6e-3;
constexpr int kCells = 3;
const double kVp = kParticles * std::numbers::pi * kD * kD * kD / 6.0;

std::map<std::string, std::string> env(const MiniOrchestrator& o, const std::string& dem) {
  return {{"COREDEM_CONTROL_ENDPOINT", o.controlEndpoint()},
          {"COREDEM_DEM_ENDPOINT", dem},
          {"COREDEM_SESSION", o.session()},
          {"COREDEM_TIMEOUT_S", "20"}};
}

} // namespace

TEST(Participants, CApiProgramRunsStepsAgainstARealServer) {
  const auto dir = tempDir("capi");
  DemProcess dem(dir);
  MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2", "O2"}));
  Child program({COREDEM_C_API_TEST_BIN}, env(o, dem.endpoint()));
  const auto res = o.run(4, 2e-4);
  EXPECT_EQ(program.wait(std::chrono::seconds(20)), 0);
  ASSERT_EQ(res.cfd.size(), 4u);
  ASSERT_EQ(res.dem.size(), 4u);
  for (const auto& done : res.cfd) {
    // Σ (1 − ε_g) V_c computed by the C program equals the particle volume (round-off).
    EXPECT_NEAR(named(done.ledger().energy(), "c_api.solid_volume_m3"), kVp, 1e-12 * kVp);
  }
  EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0)
      << "coredem-dem --exit-after-session did not exit cleanly";
  fs::remove_all(dir);
}

TEST(Participants, CoredemGasRunsCheckpointsAndRestartsWithIdenticalLedgers) {
  const auto dir = tempDir("gas");
  const auto caseFile = dir / "case.yaml";
  {
    std::ofstream out(caseFile);
    out << "gas:\n"
           "  u_g: [0.0, 0.0, 0.4]\n"
           "  T_g: {table: [[0.0, 300.0], [0.01, 400.0]]}\n"
           "  Y_g: {N2: 1.0}\n"
           "  regions:\n"
           "    - name: top\n"
           "      box: {min: [0, 0, 0.004], max: [0.006, 0.006, 0.006]}\n"
           "      u_g: [0.0, 0.0, 0.1]\n";
  }
  const std::vector<std::string> gasArgs = {COREDEM_GAS_BIN, "--case", caseFile.string(), "--key",
                                            "gas"};
  const double dt = 2e-4;
  const auto ck = (dir / "ck6").string();
  std::vector<v1::StepDone> straight;
  {
    DemProcess dem(dir);
    MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2"}));
    Child gas(gasArgs, env(o, dem.endpoint()));
    straight = o.run(12, dt, {{6, ck}}).cfd;
    EXPECT_EQ(gas.wait(std::chrono::seconds(20)), 0);
    EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0);
  }
  ASSERT_EQ(straight.size(), 12u);
  for (const auto& d : straight) {
    EXPECT_NEAR(named(d.diagnostics(), "gas.solid_volume_m3"), kVp, 1e-12 * kVp);
  }
  // Gas flowing up through the beads loses momentum to them.
  EXPECT_LT(named(straight.back().diagnostics(), "gas.momentum_from_particles_z_Ns"), 0.0);
  // Courant number: dt · 0.4 m/s / 2 mm in the fastest cell.
  EXPECT_NEAR(straight.back().cfl(), dt * 0.4 / (kBox / kCells), 1e-15);
  ASSERT_TRUE(straight[5].has_checkpoint());
  EXPECT_EQ(straight[5].checkpoint().files(0), "gas.h5");
  ASSERT_TRUE(fs::exists(fs::path(ck) / "gas.h5"));
  ASSERT_TRUE(fs::exists(fs::path(ck) / "dem.h5"));

  // Restart from step 6: D reads dem.h5, coredem-gas reads gas.h5; steps 7..12 again.
  std::vector<v1::StepDone> resumed;
  {
    DemProcess dem(dir);
    auto cfg = smallCase(kParticles, kD, kBox, kCells, {"N2"});
    cfg.set_initial_state_file((fs::path(ck) / "dem.h5").string());
    cfg.set_start_step(6);
    cfg.set_start_time(6 * dt);
    MiniOrchestrator o(dem.endpoint(), cfg);
    auto args = gasArgs;
    args.push_back("--restart");
    args.push_back((fs::path(ck) / "gas.h5").string());
    Child gas(args, env(o, dem.endpoint()));
    resumed = o.run(6, dt).cfd;
    EXPECT_EQ(gas.wait(std::chrono::seconds(20)), 0);
    EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0);
  }
  ASSERT_EQ(resumed.size(), 6u);
  // Bitwise: the DEM state restarts exactly and the ledgers' Kahan sums restart with their
  // compensation terms.
  const auto& a = straight.back();
  const auto& b = resumed.back();
  for (const char* name : {"gas.momentum_from_particles_x_Ns", "gas.momentum_from_particles_z_Ns",
                           "gas.solid_volume_m3"}) {
    EXPECT_EQ(named(a.diagnostics(), name), named(b.diagnostics(), name)) << name;
  }
  EXPECT_EQ(named(a.ledger().energy(), "gas.heat_from_particles_J"),
            named(b.ledger().energy(), "gas.heat_from_particles_J"));
  fs::remove_all(dir);
}

// Protocol 1.3: coredem-gas books the radiation heat the particles gave the gas
// (gas.heat_radiation_J = Σ Q_rad V_c Δt). Hot beads (900 K, emissivity 0.9) in 300 K gas:
// it equals the particles' radiation loss −dem.heat_radiation_J to 1e-12 relative, and the
// coupled energy ledger closes: Δ dem.thermal_energy_J + gas.heat_from_particles_J +
// gas.heat_radiation_J = 0 to round-off (no walls with a temperature: no other heat).
TEST(Participants, CoredemGasBooksTheRadiationHeatAndTheLedgerCloses) {
  const auto dir = tempDir("gas-radiation");
  const auto caseFile = dir / "case.yaml";
  {
    std::ofstream out(caseFile);
    out << "gas:\n"
           "  u_g: [0.0, 0.0, 0.2]\n"
           "  T_g: 300.0\n"
           "  Y_g: {N2: 1.0}\n";
  }
  auto cfg = smallCase(kParticles, kD, kBox, kCells, {"N2"});
  cfg.mutable_particle_sets(0)->set_temperature(900.0);
  std::vector<v1::StepDone> cfd, dem;
  double e0 = 0.0;
  {
    DemProcess d(dir);
    MiniOrchestrator o(d.endpoint(), cfg);
    Child gas({COREDEM_GAS_BIN, "--case", caseFile.string(), "--key", "gas"}, env(o, d.endpoint()));
    const auto res = o.run(6, 2e-4);
    cfd = res.cfd;
    dem = res.dem;
    EXPECT_EQ(gas.wait(std::chrono::seconds(20)), 0);
    EXPECT_EQ(d.wait(std::chrono::seconds(20)), 0);
  }
  ASSERT_EQ(cfd.size(), 6u);
  ASSERT_EQ(dem.size(), 6u);
  // Initial thermal energy: N m c_p T0 (all beads alike).
  const double mass = 2500.0 * std::numbers::pi * kD * kD * kD / 6.0;
  e0 = kParticles * mass * 840.0 * 900.0;
  const auto& c = cfd.back().ledger().energy();
  const auto& p = dem.back().ledger().energy();
  const double radIn = named(c, "gas.heat_radiation_J");
  const double radOut = named(p, "dem.heat_radiation_J");
  ASSERT_LT(radOut, 0.0);
  EXPECT_NEAR(radIn, -radOut, 1e-12 * -radOut);
  const double dE = named(p, "dem.thermal_energy_J") - e0;
  const double residual = dE + named(c, "gas.heat_from_particles_J") + radIn;
  std::printf("radiation: gas got %.17g J, particles lost %.17g J; coupled residual %.3g J of "
              "%.3g J exchanged\n",
              radIn, -radOut, residual, std::abs(dE));
  EXPECT_NEAR(residual, 0.0, 1e-9 * std::abs(dE) + 1e-12 * e0);
  fs::remove_all(dir);
}

TEST(Participants, CppClientChecksArgumentsBeforeSending) {
  const auto dir = tempDir("cpp");
  DemProcess dem(dir);
  MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2"}));
  std::string failure;
  std::thread cfd([&] {
    try {
      coredem::client::Options opt;
      opt.controlEndpoint = o.controlEndpoint();
      opt.demEndpoint = dem.endpoint();
      opt.sessionId = o.session();
      opt.timeoutSeconds = 20;
      coredem::client::Participant p(opt);
      p.initialize();
      const auto n = static_cast<std::size_t>(p.grid().cellCount());
      std::vector<double> v3(3 * n, 0.0), t(n, 300.0), rho(n, 1.2), mu(n, 1.8e-5), k(n, 0.03),
          cp(n, 1000.0), y(n, 1.0);
      std::vector<coredem::client::NamedField> fields = {
          {"u_g", v3},  {"grad_p", v3}, {"T_g", t},   {"rho_g", rho},
          {"mu_g", mu}, {"kappa_g", k}, {"cp_g", cp}, {"Y_g", y}};
      auto expectArgument = [&](auto&& call, const char* what, const char* mentions) {
        try {
          call();
          failure += std::string(what) + ": no error; ";
        } catch (const coredem::client::ClientError& e) {
          if (e.code() != coredem::client::ErrorCode::Argument ||
              std::string(e.what()).find(mentions) == std::string::npos) {
            failure += std::string(what) + ": " + e.what() + "; ";
          }
        }
      };
      expectArgument([&] { p.exchange(p.step(), 2 * p.dt(), fields); }, "other dt", "granted dt");
      expectArgument([&] { p.exchange(p.step() + 1, p.dt(), fields); }, "other step",
                     "granted step");
      auto missing = fields;
      missing.pop_back();
      expectArgument([&] { p.exchange(p.step(), p.dt(), missing); }, "missing Y_g", "'Y_g'");
      auto unknown = fields;
      unknown.push_back({"T_gas", t});
      expectArgument([&] { p.exchange(p.step(), p.dt(), unknown); }, "unknown name", "T_gas");
      auto shortT = fields;
      shortT[2].values.size -= 1;
      expectArgument([&] { p.exchange(p.step(), p.dt(), shortT); }, "short T_g", "needs");
      while (p.isRunning()) {
        const auto& s = p.exchange(p.step(), p.dt(), fields);
        if (s.field("eps_g").size != n)
          failure += "eps_g size; ";
        p.advance(0.0);
      }
      p.finalize();
    } catch (const std::exception& e) {
      failure += std::string("unexpected: ") + e.what();
    }
  });
  const auto res = o.run(2, 2e-4);
  cfd.join();
  EXPECT_EQ(failure, "");
  EXPECT_EQ(res.cfd.size(), 2u);
  EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0);
  fs::remove_all(dir);
}

TEST(Participants, CommandLinesRefuseBadInputWithExitCode2) {
  const auto dir = tempDir("cli");
  // coredem-dem: a non-loopback bind without CURVE keys or --insecure.
  Child dem({COREDEM_DEM_BIN, "--bind", "tcp://0.0.0.0:*"});
  EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 2);
  // coredem-gas --check: valid -> 0, unknown key -> 2, missing file -> 2.
  const auto good = dir / "good.yaml", bad = dir / "bad.yaml";
  std::ofstream(good) << "gas:\n  T_g: 500\n";
  std::ofstream(bad) << "gas:\n  T_g: 500\n  temperature: 3\n";
  Child ok({COREDEM_GAS_BIN, "--case", good.string(), "--check"});
  EXPECT_EQ(ok.wait(std::chrono::seconds(20)), 0);
  Child unknown({COREDEM_GAS_BIN, "--case", bad.string(), "--check"});
  EXPECT_EQ(unknown.wait(std::chrono::seconds(20)), 2);
  Child missing({COREDEM_GAS_BIN, "--case", (dir / "nope.yaml").string(), "--check"});
  EXPECT_EQ(missing.wait(std::chrono::seconds(20)), 2);
  // coredem-gas without peers: exit 2 naming the variable (stderr), not a hang.
  Child noPeers(
      {COREDEM_GAS_BIN, "--case", good.string()},
      {{"COREDEM_CONTROL_ENDPOINT", ""}, {"COREDEM_DEM_ENDPOINT", ""}, {"COREDEM_SESSION", ""}});
  EXPECT_EQ(noPeers.wait(std::chrono::seconds(20)), 2);
  fs::remove_all(dir);
}

TEST(Participants, PythonCtypesParticipantRunsAgainstARealServer) {
  if (COREDEM_PYTHON_OPTED_OUT) {
    GTEST_SKIP() << "opted out (COREDEM_TEST_OPT_OUT=python)";
  }
  ASSERT_FALSE(std::string(COREDEM_PYTHON).empty())
      << "no python3 with numpy (COREDEM_PYTHON): run scripts/install-deps.sh, or opt out with "
         "-DCOREDEM_TEST_OPT_OUT=python";
  const auto dir = tempDir("python");
  DemProcess dem(dir);
  MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2", "O2"}));
  auto e = env(o, dem.endpoint());
  e["COREDEM_CLIENT_LIB"] = COREDEM_CLIENT_SHARED_LIB;
  Child program({COREDEM_PYTHON, COREDEM_CTYPES_SCRIPT}, e);
  const auto res = o.run(3, 2e-4);
  EXPECT_EQ(program.wait(std::chrono::seconds(30)), 0);
  ASSERT_EQ(res.cfd.size(), 3u);
  for (const auto& done : res.cfd) {
    EXPECT_NEAR(named(done.ledger().energy(), "py.solid_volume_m3"), kVp, 1e-12 * kVp);
  }
  EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0);
  fs::remove_all(dir);
}

namespace {

/// Runs the small case for `steps` steps with one C++ participant; `exchange` is called once
/// per granted step and returns the Sources arrays to record (name -> values).
using Recorded = std::vector<std::map<std::string, std::vector<double>>>;
template <class Exchange>
Recorded runRecording(const std::string& name, int steps, Exchange&& exchange,
                      std::string& failure) {
  const auto dir = tempDir(name);
  DemProcess dem(dir);
  MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2"}));
  Recorded rec;
  std::thread cfd([&] {
    try {
      coredem::client::Options opt;
      opt.controlEndpoint = o.controlEndpoint();
      opt.demEndpoint = dem.endpoint();
      opt.sessionId = o.session();
      opt.timeoutSeconds = 20;
      coredem::client::Participant p(opt);
      p.initialize();
      while (p.isRunning()) {
        rec.push_back(exchange(p));
        p.advance(0.0);
      }
      p.finalize();
    } catch (const std::exception& e) {
      failure += name + ": unexpected: " + e.what() + "; ";
    }
  });
  const auto res = o.run(steps, 2e-4);
  cfd.join();
  EXPECT_EQ(res.cfd.size(), static_cast<std::size_t>(steps)) << name;
  EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0) << name;
  fs::remove_all(dir);
  return rec;
}

std::vector<coredem::client::NamedField> gasFields(std::size_t n,
                                                   std::vector<std::vector<double>>& keep) {
  keep = {std::vector<double>(3 * n, 0.0), std::vector<double>(3 * n, 0.0),
          std::vector<double>(n, 300.0),   std::vector<double>(n, 1.2),
          std::vector<double>(n, 1.8e-5),  std::vector<double>(n, 0.03),
          std::vector<double>(n, 1000.0),  std::vector<double>(n, 1.0)};
  for (std::size_t c = 0; c < n; ++c)
    keep[0][3 * c + 1] = 0.3; // gas rising: non-zero drag sources
  return {{"u_g", keep[0]},  {"grad_p", keep[1]},  {"T_g", keep[2]},  {"rho_g", keep[3]},
          {"mu_g", keep[4]}, {"kappa_g", keep[5]}, {"cp_g", keep[6]}, {"Y_g", keep[7]}};
}

} // namespace

// exchange(..., into): arrays received straight into caller buffers are bitwise the arrays the
// default path (views into the received frames) returns for the same run; field() then points
// into the caller's buffer; a wrong buffer size is refused before any buffer is written.
TEST(Participants, CppClientReceivesIntoCallerBuffersBitwiseAsViews) {
  constexpr int kSteps = 3;
  std::string failure;
  const Recorded viewed = runRecording(
      "views", kSteps,
      [&](coredem::client::Participant& p) {
        std::vector<std::vector<double>> keep;
        const auto n = static_cast<std::size_t>(p.grid().cellCount());
        const auto& s = p.exchange(p.step(), p.dt(), gasFields(n, keep));
        std::map<std::string, std::vector<double>> out;
        for (const auto& name : s.names()) {
          const auto v = s.field(name);
          out[name].assign(v.begin(), v.end());
        }
        const auto t = p.lastExchangeTimes();
        for (double x : {t.serialise, t.send, t.wait, t.receive}) {
          if (!(std::isfinite(x) && x >= 0.0))
            failure += "exchange time not finite and >= 0; ";
        }
        return out;
      },
      failure);

  std::vector<double> eps, kus, h, qr;
  const Recorded buffered = runRecording(
      "buffers", kSteps,
      [&](coredem::client::Participant& p) {
        std::vector<std::vector<double>> keep;
        const auto n = static_cast<std::size_t>(p.grid().cellCount());
        const auto fields = gasFields(n, keep);
        eps.assign(n, -7.0);
        kus.assign(3 * n, -7.0);
        h.assign(n, -7.0);
        qr.assign(n, -7.0);
        // Refusals (nothing is sent or written; the step is then exchanged as usual).
        auto expectArgument = [&](std::vector<coredem::client::NamedBuffer> into, const char* what,
                                  const char* mentions) {
          try {
            p.exchange(p.step(), p.dt(), fields, into);
            failure += std::string(what) + ": no error; ";
          } catch (const coredem::client::ClientError& e) {
            if (e.code() != coredem::client::ErrorCode::Argument ||
                std::string(e.what()).find(mentions) == std::string::npos)
              failure += std::string(what) + ": " + e.what() + "; ";
          }
        };
        std::vector<double> tooShort(3 * n - 1, -7.0);
        expectArgument(
            {{"eps_g", eps.data(), eps.size()}, {"K_sl_Us", tooShort.data(), tooShort.size()}},
            "short buffer", "'K_sl_Us' holds");
        expectArgument({{"T_g", eps.data(), eps.size()}}, "gas name as a Sources buffer",
                       "not a Sources array");
        if (eps[0] != -7.0 || tooShort[0] != -7.0)
          failure += "a refused call wrote a buffer; ";
        const auto& s = p.exchange(p.step(), p.dt(), fields,
                                   {{"eps_g", eps.data(), eps.size()},
                                    {"K_sl_Us", kus.data(), kus.size()},
                                    {"H", h.data(), h.size()},
                                    {"Q_rad", qr.data(), qr.size()}});
        if (s.field("eps_g").data != eps.data() || s.field("K_sl_Us").data != kus.data() ||
            s.field("H").data != h.data() || s.radiationHeat().data != qr.data() ||
            s.radiationHeat().size != n) {
          failure += "field() does not view the caller's buffers; ";
        }
        std::map<std::string, std::vector<double>> out;
        for (const auto& name : s.names()) {
          const auto v = s.field(name);
          out[name].assign(v.begin(), v.end());
        }
        return out;
      },
      failure);
  EXPECT_EQ(failure, "");
  ASSERT_EQ(viewed.size(), static_cast<std::size_t>(kSteps));
  ASSERT_EQ(buffered.size(), viewed.size());
  bool nonZeroDrag = false;
  for (std::size_t k = 0; k < viewed.size(); ++k) {
    EXPECT_EQ(buffered[k].size(), viewed[k].size()) << "step " << k + 1 << ": other array names";
    for (const auto& [name, v] : viewed[k]) {
      const auto it = buffered[k].find(name);
      ASSERT_NE(it, buffered[k].end()) << name;
      ASSERT_EQ(it->second.size(), v.size()) << name;
      // Bitwise: the same DEM run, the same bytes (no tolerance).
      EXPECT_EQ(std::memcmp(it->second.data(), v.data(), v.size() * sizeof(double)), 0)
          << "step " << k + 1 << ", " << name;
      if (name == "K_sl")
        for (double x : v)
          nonZeroDrag = nonZeroDrag || x > 0.0;
    }
  }
  EXPECT_TRUE(nonZeroDrag) << "the case should give drag (K_sl > 0) somewhere";
}

// A decomposed CFD participant on 2 ranks (threads here, MPI ranks in coredemFoam): rank 0 talks
// to the orchestrator and hands its control state to rank 1 (follow()); each rank exchanges its
// own cells with D (exchangePartial()). Cell 13 of the 27 is shared. The ranks' eps_g together
// give the particle volume (Σ (1 − ε) V_c over the coupling cells, each counted once) to
// round-off, and each rank receives exactly its cells.
TEST(Participants, TwoRanksExchangeTheirOwnCellsAndFollowRankZero) {
  const auto dir = tempDir("ranks");
  DemProcess dem(dir);
  MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2"}));
  const double h = kBox / kCells, vc = h * h * h;
  std::mutex m;
  std::condition_variable cv;
  std::deque<std::string> states; // rank 0 -> rank 1
  std::vector<double> solid(2, 0.0);
  std::vector<int> steps(2, 0);
  std::string failure;
  auto body = [&](int rank) {
    try {
      coredem::client::Options opt;
      opt.controlEndpoint = o.controlEndpoint();
      opt.demEndpoint = dem.endpoint();
      opt.sessionId = o.session();
      opt.timeoutSeconds = 20;
      opt.rank = rank;
      opt.rankCount = 2;
      coredem::client::Participant p(opt);
      auto handOver = [&] {
        if (rank == 0) {
          std::lock_guard<std::mutex> lock(m);
          states.push_back(p.controlState());
          cv.notify_all();
        } else {
          std::unique_lock<std::mutex> lock(m);
          cv.wait(lock, [&] { return !states.empty(); });
          const std::string s = states.front();
          states.pop_front();
          lock.unlock();
          p.follow(s);
        }
      };
      if (rank == 0) {
        p.initialize();
      }
      handOver();
      std::vector<std::int64_t> cells;
      std::vector<double> volume;
      for (std::int64_t c = rank == 0 ? 0 : 13; c < (rank == 0 ? 14 : 27); ++c) {
        cells.push_back(c);
        volume.push_back(c == 13 ? 0.5 * vc : vc);
      }
      const std::size_t n = cells.size();
      std::vector<double> v3(3 * n), t(n), rho(n), mu(n), k(n), cp(n), y(n);
      for (std::size_t i = 0; i < n; ++i) { // volume-weighted sums
        v3[3 * i + 2] = 0.2 * volume[i];
        t[i] = 300.0 * volume[i];
        rho[i] = 1.2 * volume[i];
        mu[i] = 1.8e-5 * volume[i];
        k[i] = 0.03 * volume[i];
        cp[i] = 1000.0 * volume[i];
        y[i] = volume[i];
      }
      std::vector<double> zero(3 * n, 0.0);
      std::vector<coredem::client::NamedField> sums = {
          {"u_g", v3},  {"grad_p", zero}, {"T_g", t},   {"rho_g", rho},
          {"mu_g", mu}, {"kappa_g", k},   {"cp_g", cp}, {"Y_g", y}};
      while (p.isRunning()) {
        const auto& s = p.exchangePartial(p.step(), p.dt(), cells, volume, sums);
        const auto eps = s.field("eps_g");
        if (eps.size != n) {
          failure += "rank " + std::to_string(rank) + ": eps_g size; ";
        }
        solid[std::size_t(rank)] = 0.0;
        for (std::size_t i = 0; i < eps.size; ++i) {
          if (!(rank == 1 && cells[i] == 13)) { // the shared cell once
            solid[std::size_t(rank)] += (1.0 - eps[i]) * vc;
          }
        }
        ++steps[std::size_t(rank)];
        if (rank == 0) {
          p.advance(0.0);
        }
        handOver();
      }
      p.finalize();
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(m);
      failure += "rank " + std::to_string(rank) + ": " + e.what() + "; ";
      if (rank == 0) { // let rank 1 end too
        states.push_back("broken");
        cv.notify_all();
      }
    }
  };
  std::thread r0(body, 0), r1(body, 1);
  const auto res = o.run(3, 2e-4);
  r0.join();
  r1.join();
  EXPECT_EQ(failure, "");
  EXPECT_EQ(res.cfd.size(), 3u); // one participant for the orchestrator: rank 0's StepDone
  EXPECT_EQ(steps[0], 3);
  EXPECT_EQ(steps[1], 3);
  EXPECT_NEAR(solid[0] + solid[1], kVp, 1e-12 * kVp);
  EXPECT_EQ(dem.wait(std::chrono::seconds(20)), 0);
  fs::remove_all(dir);
}

// Rank identity is checked before anything is sent; ranks > 0 never call initialize() or
// advance().
TEST(Participants, RankOptionsAreCheckedBeforeConnecting) {
  auto expectError = [](coredem::client::Options opt, bool follow, const char* mentions) {
    opt.controlEndpoint = "tcp://127.0.0.1:1";
    opt.demEndpoint = "tcp://127.0.0.1:1";
    opt.sessionId = "s";
    coredem::client::Participant p(opt);
    try {
      if (follow) {
        p.follow("coredem-control-state 1\n");
      } else {
        p.initialize();
      }
      ADD_FAILURE() << "no error for " << mentions;
    } catch (const coredem::client::ClientError& e) {
      EXPECT_NE(std::string(e.what()).find(mentions), std::string::npos) << e.what();
    }
  };
  coredem::client::Options o;
  o.rank = 2;
  o.rankCount = 2;
  expectError(o, false, "rank 2 of 2 ranks");
  o.rank = 1;
  expectError(o, false, "follows rank 0");
  expectError(o, true, "truncated control state");
}

// Protocol 1.2 is needed for fluid_fraction and for decomposed runs: against a DEM server that
// agrees 1.1 (a stand-in that answers Hello with Welcome{minor 1}) the client refuses both before
// sending, naming both versions, instead of having the older server silently ignore them.
TEST(Participants, FluidFractionAndRanksNeedADemServerOfProtocol12) {
  const auto dir = tempDir("v11");
  proto::Server oldDem;
  const std::string oldEp = oldDem.bind("tcp://127.0.0.1:*");
  std::atomic<bool> stop{false};
  std::thread server([&] {
    while (!stop) {
      auto r = oldDem.receive(100ms);
      if (!r) {
        continue;
      }
      auto w = r->message.type() == v1::MESSAGE_TYPE_HELLO
                   ? proto::makeWelcome(v1::ROLE_DEM, "coredem-dem 1.1 (stand-in)", 1, 1,
                                        r->message.envelope().session_id())
                   : proto::makeError(v1::ERROR_CODE_UNSUPPORTED, "stand-in");
      w.setSequence(r->message.envelope().sequence());
      oldDem.reply(r->peer, std::move(w));
    }
  });
  for (int ranks : {0, 2}) {
    DemProcess dem(dir);
    MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2"}), 3s);
    std::string error;
    std::thread cfd([&] {
      coredem::client::Options opt;
      opt.controlEndpoint = o.controlEndpoint();
      opt.demEndpoint = oldEp;
      opt.sessionId = o.session();
      opt.timeoutSeconds = 20;
      opt.rankCount = ranks;
      coredem::client::Participant p(opt);
      try {
        p.initialize();
        EXPECT_EQ(p.demProtocolMinor(), 1);
        const auto n = static_cast<std::size_t>(p.grid().cellCount());
        std::vector<double> v3(3 * n, 0.0), t(n, 300.0), rho(n, 1.2), mu(n, 1.8e-5), k(n, 0.03),
            cp(n, 1000.0), y(n, 1.0), ff(n, 0.5);
        p.exchange(p.step(), p.dt(),
                   {{"u_g", v3},
                    {"grad_p", v3},
                    {"T_g", t},
                    {"rho_g", rho},
                    {"mu_g", mu},
                    {"kappa_g", k},
                    {"cp_g", cp},
                    {"Y_g", y},
                    {"fluid_fraction", ff}});
      } catch (const coredem::client::ClientError& e) {
        error = e.what();
      }
    });
    try {
      o.run(1, 2e-4, {}, false); // ends by timeout: the participant gave up
    } catch (const std::exception&) {
    }
    cfd.join();
    EXPECT_NE(
        error.find("agreed protocol 1.1, this client speaks " + proto::kProtocolVersion.toString()),
        std::string::npos)
        << ranks << " ranks: " << error;
    EXPECT_NE(error.find(ranks > 1 ? "decomposed CFD participant (2 ranks)" : "fluid_fraction"),
              std::string::npos)
        << error;
  }
  stop = true;
  server.join();
  fs::remove_all(dir);
}

// Protocol 1.3: against a DEM server that agrees 1.2 (a stand-in: Welcome{minor 2}, and Sources
// without Q_rad, as a 1.2 server sends them) the client reports Q_rad absent: radiationHeat()
// is empty, has("Q_rad") is false, and a caller buffer given for it is set to zeros.
TEST(Participants, RadiationHeatIsAbsentFromADemServerOfProtocol12) {
  const auto dir = tempDir("v12");
  proto::Server oldDem;
  const std::string oldEp = oldDem.bind("tcp://127.0.0.1:*");
  std::atomic<bool> stop{false};
  std::thread server([&] {
    while (!stop) {
      auto r = oldDem.receive(100ms);
      if (!r) {
        continue;
      }
      const auto& env = r->message.envelope();
      proto::Message w;
      if (r->message.type() == v1::MESSAGE_TYPE_HELLO) {
        w = proto::makeWelcome(v1::ROLE_DEM, "coredem-dem 1.2 (stand-in)", 1, 2, env.session_id());
      } else if (r->message.type() == v1::MESSAGE_TYPE_GAS_FIELDS) {
        const auto& g = env.gas_fields();
        w = proto::makeSources(env.step(), env.time(), g.dt(), g.cell_count(), g.species_count(),
                               1);
        for (const auto& spec : proto::fields::sourceFields()) {
          const auto shape = proto::fields::shapeOf(spec.extent, g.cell_count(), g.species_count());
          std::uint64_t count = 1;
          for (auto d : shape)
            count *= d;
          w.addArray<double>(spec.name, std::vector<double>(count, 0.0), shape);
        }
        w.setSessionId(env.session_id());
        w.setStep(env.step());
      } else {
        w = proto::makeError(v1::ERROR_CODE_UNSUPPORTED, "stand-in");
      }
      w.setSequence(env.sequence());
      oldDem.reply(r->peer, std::move(w));
    }
  });
  {
    DemProcess dem(dir);
    MiniOrchestrator o(dem.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2"}), 3s);
    std::string failure = "not run";
    std::thread cfd([&] {
      coredem::client::Options opt;
      opt.controlEndpoint = o.controlEndpoint();
      opt.demEndpoint = oldEp;
      opt.sessionId = o.session();
      opt.timeoutSeconds = 20;
      coredem::client::Participant p(opt);
      try {
        p.initialize();
        failure.clear();
        if (p.demProtocolMinor() != 2)
          failure += "agreed minor " + std::to_string(p.demProtocolMinor()) + "; ";
        const auto n = static_cast<std::size_t>(p.grid().cellCount());
        std::vector<std::vector<double>> keep;
        std::vector<double> qr(n, -7.0);
        const auto& s =
            p.exchange(p.step(), p.dt(), gasFields(n, keep), {{"Q_rad", qr.data(), qr.size()}});
        if (s.radiationHeat().size != 0 || s.radiationHeat().data != nullptr)
          failure += "radiationHeat() not empty; ";
        if (s.has("Q_rad"))
          failure += "has(Q_rad); ";
        for (double v : qr)
          if (v != 0.0) {
            failure += "the Q_rad buffer was not zeroed; ";
            break;
          }
      } catch (const std::exception& e) {
        failure += std::string("unexpected: ") + e.what();
      }
    });
    try {
      o.run(1, 2e-4, {}, false); // ends by timeout: the real DEM never gets the GasFields
    } catch (const std::exception&) {
    }
    cfd.join();
    EXPECT_EQ(failure, "");
  }
  stop = true;
  server.join();
  fs::remove_all(dir);
}
