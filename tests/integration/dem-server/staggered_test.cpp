// coredem-dem with the staggered coupling scheme (Configure option coupling_scheme = staggered,
// docs/coupling-schemes.md) over real ZeroMQ loopback with the real DEM core:
// - the GasFields of step n are answered with the sources of step n-1: with the same prescribed
//   gas the particles move exactly as in the sequential scheme, so the staggered Sources of step
//   n+1 equal the sequential Sources of step n bit for bit, and step 1 gets the sources of the
//   initial state (never zero sources);
// - the lag ledger dem.heat_in_flight_J is the last step's particle heat gain minus the heat of
//   the step-1 sources;
// - a checkpoint holds the pending sources: a restarted staggered server continues bitwise;
// - an unknown scheme is refused.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numeric>

#include <gtest/gtest.h>

#include "../client/mini_orchestrator.h"
#include "coredem/protocol/coupling_scheme.h"
#include "coredem/server/dem_server.h"
#include "server_thread.h"

using namespace coredem::testing;
namespace fs = std::filesystem;

namespace {

constexpr int kParticles = 40;
constexpr double kD = 1e-3;
constexpr double kBox = 6e-3;
constexpr int kCells = 3;
constexpr std::size_t kN = kCells * kCells * kCells;
constexpr double kDt = 1e-4;

/// Uniform gas at 400 K (particles at 300 K: heat flows), upward flow (drag), one species.
proto::Message gasMessage(std::int64_t step, double time, const std::string& session) {
  namespace f = proto::fields;
  static const std::vector<double> u = [] {
    std::vector<double> v(3 * kN, 0.0);
    for (std::size_t c = 0; c < kN; ++c)
      v[3 * c + 2] = 0.3;
    return v;
  }();
  static const std::vector<double> zero3(3 * kN, 0.0), T(kN, 400.0), rho(kN, 1.2), mu(kN, 1.8e-5),
      kappa(kN, 0.026), cp(kN, 1005.0), Y(kN, 1.0);
  auto m = proto::makeGasFields(step, time, kDt, kN, 1);
  m.setSessionId(session);
  m.addArray(f::kGasVelocity, u, {kN, 3});
  m.addArray(f::kPressureGradient, zero3, {kN, 3});
  m.addArray(f::kGasTemperature, T, {kN});
  m.addArray(f::kGasDensity, rho, {kN});
  m.addArray(f::kGasViscosity, mu, {kN});
  m.addArray(f::kGasConductivity, kappa, {kN});
  m.addArray(f::kGasHeatCapacity, cp, {kN});
  m.addArray(f::kGasMassFractions, Y, {kN, 1});
  return m;
}

v1::Configure caseWith(const std::string& scheme) {
  auto c = smallCase(kParticles, kD, kBox, kCells);
  if (!scheme.empty()) {
    auto* kv = c.add_options();
    kv->set_key(std::string(proto::fields::kCouplingSchemeOption));
    kv->set_value(scheme);
  }
  return c;
}

struct StepResult {
  std::map<std::string, std::vector<double>> sources; ///< by Sources array name
  v1::StepDone done;
};

/// Runs steps [from, to] as O and C; the Sources and D's StepDone of each step.
std::vector<StepResult> run(const std::string& endpoint, MiniOrchestrator& o, std::int64_t from,
                            std::int64_t to,
                            const std::map<std::int64_t, std::string>& checkpoints = {}) {
  proto::Client cfd;
  cfd.connect(endpoint);
  auto hello = proto::makeHello(v1::ROLE_CFD, "test cfd");
  hello.setSessionId(o.session());
  proto::expectType(cfd.request(std::move(hello), 10s), v1::MESSAGE_TYPE_WELCOME);
  const auto nSub = static_cast<std::uint32_t>(std::ceil(kDt / o.dtDemMax()));
  std::vector<StepResult> out;
  for (std::int64_t n = from; n <= to; ++n) {
    const double t = static_cast<double>(n - 1) * kDt;
    auto g = proto::makeStepGrant(n, t, kDt, nSub, kDt / nSub);
    g.setSessionId(o.session());
    if (const auto it = checkpoints.find(n); it != checkpoints.end()) {
      g.envelope().mutable_step_grant()->mutable_checkpoint()->set_directory(it->second);
    }
    o.dem().send(std::move(g));
    auto src = cfd.request(gasMessage(n, t, o.session()), 20s);
    proto::expectType(src, v1::MESSAGE_TYPE_SOURCES);
    EXPECT_EQ(src.envelope().step(), n);
    StepResult r;
    for (const auto& name :
         {proto::fields::kVoidFraction, proto::fields::kDragCoefficient,
          proto::fields::kDragCoefficientTimesUs, proto::fields::kHeatCoefficient,
          proto::fields::kHeatCoefficientTimesTp}) {
      const auto v = src.values<double>(name);
      r.sources[std::string(name)].assign(v.begin(), v.end());
    }
    auto d = o.dem().receive(20s);
    EXPECT_TRUE(d.has_value()) << "no StepDone from D";
    proto::expectType(*d, v1::MESSAGE_TYPE_STEP_DONE);
    r.done = d->envelope().step_done();
    out.push_back(std::move(r));
  }
  return out;
}

fs::path tempDir(const std::string& name) {
  const auto d = fs::temp_directory_path() /
                 ("coredem-staggered-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

double sum(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0);
}

} // namespace

TEST(Staggered, GasFieldsOfStepNAreAnsweredWithTheSourcesOfStepNMinusOne) {
  constexpr int kSteps = 30;
  std::vector<StepResult> seq, stag;
  {
    ServerThread server;
    MiniOrchestrator o(server.endpoint(), caseWith(""));
    seq = run(server.endpoint(), o, 1, kSteps);
    o.shutdown();
  }
  {
    ServerThread server;
    MiniOrchestrator o(server.endpoint(), caseWith("staggered"));
    stag = run(server.endpoint(), o, 1, kSteps);
    o.shutdown();
  }
  ASSERT_EQ(seq.size(), stag.size());
  // The DEM side does not depend on the scheme (the gas is prescribed): same particles.
  for (const char* d : {"mean_T_p", "contacts", "bed_height_m"}) {
    EXPECT_EQ(named(seq.back().done.diagnostics(), d), named(stag.back().done.diagnostics(), d))
        << d;
  }
  // Only the staggered server reports the lag.
  EXPECT_EQ(named(stag.front().done.diagnostics(), "coupling_lag_steps"), 1.0);
  for (const auto& nv : seq.front().done.diagnostics()) {
    EXPECT_NE(nv.name(), "coupling_lag_steps");
  }
  // Step n+1 (staggered) = step n (sequential), bit for bit.
  for (int n = 1; n < kSteps; ++n) {
    for (const auto& [name, values] : seq[std::size_t(n - 1)].sources) {
      EXPECT_EQ(stag[std::size_t(n)].sources.at(name), values)
          << name << ": staggered step " << n + 1 << " vs sequential step " << n;
    }
  }
  // Step 1: the sources of the initial state, not zeros. ε_g is frozen at the window start in
  // both schemes (the same initial positions); the drag and heat coefficients are those of the
  // initial velocities and temperatures, so they are positive where particles are.
  const auto& first = stag.front().sources;
  // (The window average of n_sub equal values differs from the one value by round-off.)
  for (std::size_t c = 0; c < kN; ++c) {
    EXPECT_NEAR(first.at("eps_g")[c], seq.front().sources.at("eps_g")[c], 1e-14) << "cell " << c;
  }
  ASSERT_LT(sum(first.at("eps_g")), double(kN) - 1e-3) << "the test needs particles in cells";
  for (std::size_t c = 0; c < kN; ++c) {
    if (first.at("eps_g")[c] < 1.0) {
      EXPECT_GT(first.at("K_sl")[c], 0.0) << "cell " << c;
      EXPECT_GT(first.at("H")[c], 0.0) << "cell " << c;
      EXPECT_NEAR(first.at("H_Tp")[c] / first.at("H")[c], 300.0, 1e-9) << "cell " << c;
    }
  }
}

TEST(Staggered, HeatInFlightIsTheLastStepsGainLessTheInitialSources) {
  // With a uniform gas at T_g = 400 K, what the gas was handed in step 1 is
  // Σ_c (H_Tp − H T_g) V_c Δt of the step-1 Sources; the particles' gain of step n is
  // Δ dem.heat_from_gas_J. In flight after step n: gain_n − (−handed_1) … as a formula:
  // in_flight(n) = [hfg(n) − hfg(n−1)] + Σ_c (H_Tp¹ − H¹ T_g) V_c Δt.
  constexpr int kSteps = 12;
  ServerThread server;
  MiniOrchestrator o(server.endpoint(), caseWith("staggered"));
  const auto r = run(server.endpoint(), o, 1, kSteps);
  o.shutdown();
  const double vc = std::pow(kBox / kCells, 3);
  double handed1 = 0.0;
  for (std::size_t c = 0; c < kN; ++c) {
    handed1 += r[0].sources.at("H_Tp")[c] - r[0].sources.at("H")[c] * 400.0;
  }
  handed1 *= vc * kDt;
  ASSERT_LT(handed1, 0.0) << "the gas must give heat to the colder particles";
  for (int n = 2; n <= kSteps; ++n) {
    const double hfg = named(r[std::size_t(n - 1)].done.ledger().energy(), "dem.heat_from_gas_J");
    const double hfgPrev =
        named(r[std::size_t(n - 2)].done.ledger().energy(), "dem.heat_from_gas_J");
    const double inFlight =
        named(r[std::size_t(n - 1)].done.ledger().energy(), "dem.heat_in_flight_J");
    // Round-off of sums of ~1e-4 J values: 1e-9 of the step's transfer.
    EXPECT_NEAR(inFlight, (hfg - hfgPrev) + handed1, 1e-9 * std::abs(hfg - hfgPrev))
        << "step " << n;
  }
}

TEST(Staggered, RestartFromCheckpointIsBitwiseIdentical) {
  // Straight: 60 steps with checkpoints after 30 and 60. Restarted: a fresh server reads the
  // step-30 state (with its pending sources) and runs 31..60. Sources of every step after the
  // restart and the step-60 states are bitwise identical.
  const auto dir = tempDir("restart");
  std::vector<StepResult> a, b;
  {
    ServerThread server;
    MiniOrchestrator o(server.endpoint(), caseWith("staggered"));
    a = run(server.endpoint(), o, 1, 60,
            {{30, (dir / "a30").string()}, {60, (dir / "a60").string()}});
    o.shutdown();
  }
  {
    ServerThread server;
    auto cfg = caseWith("staggered");
    cfg.set_initial_state_file((dir / "a30" / "dem.h5").string());
    cfg.set_start_step(30);
    cfg.set_start_time(30 * kDt);
    MiniOrchestrator o(server.endpoint(), cfg);
    b = run(server.endpoint(), o, 31, 60, {{60, (dir / "b60").string()}});
    o.shutdown();
  }
  ASSERT_EQ(b.size(), 30u);
  for (std::size_t i = 0; i < b.size(); ++i) {
    for (const auto& [name, values] : a[30 + i].sources) {
      EXPECT_EQ(b[i].sources.at(name), values) << name << " of step " << 31 + i;
    }
  }
  EXPECT_EQ(named(a.back().done.ledger().energy(), "dem.heat_in_flight_J"),
            named(b.back().done.ledger().energy(), "dem.heat_in_flight_J"));
  for (const char* group : {"/particles", "/contacts", "/server/staggered"}) {
    const std::string cmd = std::string(COREDEM_H5DIFF) + " -q " +
                            (dir / "a60" / "dem.h5").string() + " " +
                            (dir / "b60" / "dem.h5").string() + " " + group + " " + group;
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  fs::remove_all(dir);
}

TEST(Staggered, UnknownSchemeIsRefused) {
  ServerThread server;
  proto::Client dem;
  dem.connect(server.endpoint());
  auto w = dem.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "test"), 10s);
  proto::expectType(w, v1::MESSAGE_TYPE_WELCOME);
  auto cfg = proto::makeConfigure(caseWith("jacobi"));
  cfg.setSessionId(w.envelope().welcome().session_id());
  auto r = dem.request(std::move(cfg), 20s);
  ASSERT_EQ(r.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(r.envelope().error().code(), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(r.envelope().error().message().find("coupling_scheme"), std::string::npos)
      << r.envelope().error().message();
}
