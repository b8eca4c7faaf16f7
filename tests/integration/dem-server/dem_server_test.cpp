// coredem-dem's session over real ZeroMQ tcp loopback (ephemeral ports) with the real DEM core:
// Configure + GasFields -> Sources, one session at a time, invalid messages refused without
// changing anything, checkpoint -> fresh server -> bitwise identical continuation.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <thread>

#include <gtest/gtest.h>

#include "../client/mini_orchestrator.h"
#include "coredem/server/dem_server.h"
#include "server_thread.h"

using namespace coredem::testing;
namespace fs = std::filesystem;

namespace {

/// Uniform gas fields: upward flow so that drag acts, one species.
struct Gas {
  std::vector<double> u, gradP, T, rho, mu, kappa, cp, Y;
  Gas(std::size_t n, std::size_t ns) {
    u.assign(3 * n, 0.0);
    for (std::size_t c = 0; c < n; ++c)
      u[3 * c + 2] = 0.3;
    gradP.assign(3 * n, 0.0);
    T.assign(n, 300.0);
    rho.assign(n, 1.2);
    mu.assign(n, 1.8e-5);
    kappa.assign(n, 0.026);
    cp.assign(n, 1005.0);
    Y.assign(n * ns, 0.0);
    for (std::size_t c = 0; c < n && ns > 0; ++c)
      Y[c * ns] = 1.0;
  }
  proto::Message message(std::int64_t step, double time, double dt, std::size_t n, std::size_t ns,
                         const std::string& session) const {
    namespace f = proto::fields;
    auto m = proto::makeGasFields(step, time, dt, n, static_cast<std::uint32_t>(ns));
    m.setSessionId(session);
    m.addArray(f::kGasVelocity, u, {n, 3});
    m.addArray(f::kPressureGradient, gradP, {n, 3});
    m.addArray(f::kGasTemperature, T, {n});
    m.addArray(f::kGasDensity, rho, {n});
    m.addArray(f::kGasViscosity, mu, {n});
    m.addArray(f::kGasConductivity, kappa, {n});
    m.addArray(f::kGasHeatCapacity, cp, {n});
    m.addArray(f::kGasMassFractions, Y, {n, ns});
    return m;
  }
};

/// C's data connection to D.
struct Cfd {
  proto::Client client;
  std::string session;
  Cfd(const std::string& ep, const std::string& s)
      : session(s) {
    client.connect(ep);
    auto hello = proto::makeHello(v1::ROLE_CFD, "test cfd");
    hello.setSessionId(session);
    auto w = client.request(std::move(hello), 10s);
    proto::expectType(w, v1::MESSAGE_TYPE_WELCOME);
  }
};

struct Step {
  std::int64_t n;
  double time, dt;
  std::uint32_t nSub;
};

/// O grants step `s` to D (reply collected later).
void grant(MiniOrchestrator& o, const Step& s, const std::string& checkpointDir = {}) {
  auto g = proto::makeStepGrant(s.n, s.time, s.dt, s.nSub, s.dt / s.nSub);
  g.setSessionId(o.session());
  if (!checkpointDir.empty()) {
    g.envelope().mutable_step_grant()->mutable_checkpoint()->set_directory(checkpointDir);
  }
  o.dem().send(std::move(g));
}

v1::StepDone stepDone(MiniOrchestrator& o) {
  auto d = o.dem().receive(20s);
  EXPECT_TRUE(d.has_value()) << "no StepDone from D";
  proto::expectType(*d, v1::MESSAGE_TYPE_STEP_DONE);
  return d->envelope().step_done();
}

/// Runs steps [from, to] through O and C; returns the Sources of the last step.
proto::Message runSteps(MiniOrchestrator& o, Cfd& c, const Gas& gas, std::int64_t from,
                        std::int64_t to, double dt, std::uint32_t nSub, std::size_t cells,
                        std::size_t ns, const std::map<std::int64_t, std::string>& checkpoints = {},
                        std::vector<double>* contacts = nullptr) {
  proto::Message last;
  for (std::int64_t n = from; n <= to; ++n) {
    const Step s{n, static_cast<double>(n - 1) * dt, dt, nSub};
    const auto it = checkpoints.find(n);
    grant(o, s, it != checkpoints.end() ? it->second : std::string());
    last = c.client.request(gas.message(n, s.time, dt, cells, ns, c.session), 20s);
    proto::expectType(last, v1::MESSAGE_TYPE_SOURCES);
    const auto done = stepDone(o);
    if (contacts != nullptr) {
      contacts->push_back(named(done.diagnostics(), "contacts"));
    }
  }
  return last;
}

fs::path tempDir(const std::string& name) {
  const auto d =
      fs::temp_directory_path() / ("coredem-dem-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

constexpr int kParticles = 60;
constexpr double kD = 1e-3;
constexpr double kBox = 6e-3;
constexpr int kCells = 3; // 2 mm cells = 2 d_p

} // namespace

TEST(DemServer, ServesConfigureAndGasFieldsWithSourcesOfTheRightShape) {
  ServerThread server;
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCells, {"N2", "CO2"}));
  ASSERT_EQ(o.particles(), static_cast<std::uint64_t>(kParticles));
  ASSERT_GT(o.dtDemMax(), 0.0);
  Cfd c(server.endpoint(), o.session());
  const std::size_t n = kCells * kCells * kCells, ns = 2;
  Gas gas(n, ns);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  grant(o, {1, 0.0, dt, nSub});
  auto src = c.client.request(gas.message(1, 0.0, dt, n, ns, o.session()), 20s);
  proto::expectType(src, v1::MESSAGE_TYPE_SOURCES);
  EXPECT_EQ(src.envelope().step(), 1);
  EXPECT_EQ(src.envelope().sources().substeps(), nSub);
  namespace f = proto::fields;
  for (const auto& spec : f::sourceFields()) {
    const auto a = src.array(spec.name);
    EXPECT_EQ(a.shape(), f::shapeOf(spec.extent, n, ns)) << spec.name;
  }
  // PCM: Σ_c (1 − ε_g,c) V_c = Σ_p π d³/6 at every sub-step, hence for the average; every
  // particle stays inside the grid (the box walls are the grid's bounds). Round-off only.
  const auto eps = src.values<double>(f::kVoidFraction);
  const double vc = std::pow(kBox / kCells, 3);
  double solid = 0.0;
  for (double e : eps) {
    EXPECT_GE(e, 0.0);
    EXPECT_LE(e, 1.0);
    solid += (1.0 - e) * vc;
  }
  const double vp = kParticles * std::numbers::pi * kD * kD * kD / 6.0;
  EXPECT_NEAR(solid, vp, 1e-12 * vp);
  // Upward gas through particles: drag coefficient positive where there are particles.
  const auto k = src.values<double>(f::kDragCoefficient);
  double kSum = 0.0;
  for (double v : k)
    kSum += v;
  EXPECT_GT(kSum, 0.0);
  // D's StepDone: the particle mass ledger is N ρ π d³/6.
  const auto done = stepDone(o);
  EXPECT_NEAR(named(done.ledger().mass(), "dem.particle_mass_kg"), 2500.0 * vp,
              1e-12 * 2500.0 * vp);
  EXPECT_EQ(named(done.diagnostics(), "particles"), kParticles);
  o.shutdown();
}

TEST(DemServer, OneSessionAtATime) {
  ServerThread server;
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  // A second orchestrator gets Reject SESSION_BUSY; the session id is never sent to a
  // non-member (docs/security.md), neither in the text nor in the envelope.
  proto::Client second;
  second.connect(server.endpoint());
  auto r = second.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "second orchestrator"), 10s);
  ASSERT_EQ(r.type(), v1::MESSAGE_TYPE_REJECT);
  EXPECT_EQ(r.envelope().reject().code(), v1::ERROR_CODE_SESSION_BUSY);
  EXPECT_EQ(r.envelope().reject().reason().find(o.session()), std::string::npos)
      << r.envelope().reject().reason();
  EXPECT_EQ(r.envelope().session_id(), "");
  // A CFD participant with a wrong session id is rejected.
  proto::Client cfd;
  cfd.connect(server.endpoint());
  auto hello = proto::makeHello(v1::ROLE_CFD, "stray cfd");
  hello.setSessionId("not-the-session");
  auto rc = cfd.request(std::move(hello), 10s);
  ASSERT_EQ(rc.type(), v1::MESSAGE_TYPE_REJECT);
  EXPECT_EQ(rc.envelope().reject().code(), v1::ERROR_CODE_UNKNOWN_SESSION);
  // Another major version is rejected naming both versions.
  proto::Client future;
  future.connect(server.endpoint());
  auto rv = future.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "future", 2, 0), 10s);
  ASSERT_EQ(rv.type(), v1::MESSAGE_TYPE_REJECT);
  EXPECT_EQ(rv.envelope().reject().code(), v1::ERROR_CODE_VERSION);
  EXPECT_NE(rv.envelope().reject().reason().find("2.0"), std::string::npos);
  EXPECT_NE(rv.envelope().reject().reason().find(proto::kProtocolVersion.toString()),
            std::string::npos);
  // Heartbeats are answered to anyone, with the server's state.
  auto hb = future.request(proto::makeHeartbeat("probe"), 10s);
  ASSERT_EQ(hb.type(), v1::MESSAGE_TYPE_HEARTBEAT);
  EXPECT_EQ(hb.envelope().heartbeat().state(), "configured");
  // After the session ends, the next orchestrator is welcome.
  o.shutdown();
  auto w = second.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "second orchestrator"), 10s);
  EXPECT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
}

TEST(DemServer, GasFieldsBeforeTheGrantWaitForIt) {
  // C's GasFields may overtake O's grant (two connections): D holds them until the grant
  // arrives; without a grant they are refused with TIMEOUT after the grant wait.
  ServerThread server(600.0, 1.0);
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  Cfd c(server.endpoint(), o.session());
  const std::size_t n = kCells * kCells * kCells;
  Gas gas(n, 1);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  c.client.send(gas.message(1, 0.0, dt, n, 1, o.session()));
  EXPECT_FALSE(c.client.receive(200ms).has_value()) << "Sources before the grant";
  grant(o, {1, 0.0, dt, nSub});
  auto src = c.client.receive(20s);
  ASSERT_TRUE(src.has_value());
  EXPECT_EQ(src->type(), v1::MESSAGE_TYPE_SOURCES);
  EXPECT_EQ(src->envelope().step(), 1);
  stepDone(o);
  // Step 2's fields without a grant: refused after the 1 s grant wait, nothing done.
  auto e = c.client.request(gas.message(2, dt, dt, n, 1, o.session()), 10s);
  ASSERT_EQ(e.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(e.envelope().error().code(), v1::ERROR_CODE_TIMEOUT) << e.envelope().error().message();
  // The step can still be run normally.
  grant(o, {2, dt, dt, nSub});
  auto again = c.client.request(gas.message(2, dt, dt, n, 1, o.session()), 20s);
  EXPECT_EQ(again.type(), v1::MESSAGE_TYPE_SOURCES);
  stepDone(o);
  o.shutdown();
}

TEST(DemServer, SilentSessionEndsAndFreesTheServer) {
  ServerThread server(0.5);
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  // The orchestrator falls silent; after the session timeout another one is welcome.
  std::this_thread::sleep_for(1200ms);
  proto::Client next;
  next.connect(server.endpoint());
  auto w = next.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "next orchestrator"), 10s);
  EXPECT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  EXPECT_NE(w.envelope().welcome().session_id(), o.session());
}

TEST(DemServer, InvalidGasFieldsGetAnErrorAndChangeNothing) {
  // Two servers run the same 3 steps; one also receives invalid GasFields before each valid
  // one. Every invalid message gets an Error with its code, and the Sources of both servers
  // are bitwise identical (the refused messages changed nothing).
  const std::size_t n = kCells * kCells * kCells, ns = 1;
  Gas gas(n, ns);
  const double dt = 2e-4;
  std::vector<std::vector<double>> eps[2];
  for (int variant = 0; variant < 2; ++variant) {
    ServerThread server;
    MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCells));
    Cfd c(server.endpoint(), o.session());
    const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
    for (std::int64_t step = 1; step <= 3; ++step) {
      const double t = static_cast<double>(step - 1) * dt;
      grant(o, {step, t, dt, nSub});
      if (variant == 1) {
        auto expectError = [&](proto::Message m, v1::ErrorCode code, const char* what) {
          auto e = c.client.request(std::move(m), 10s);
          ASSERT_EQ(e.type(), v1::MESSAGE_TYPE_ERROR) << what;
          EXPECT_EQ(e.envelope().error().code(), code)
              << what << ": " << e.envelope().error().message();
        };
        Gas nan = gas;
        nan.T[n / 2] = std::nan("");
        expectError(nan.message(step, t, dt, n, ns, o.session()), v1::ERROR_CODE_NON_FINITE,
                    "NaN in T_g");
        Gas inf = gas;
        inf.u[4] = HUGE_VAL;
        expectError(inf.message(step, t, dt, n, ns, o.session()), v1::ERROR_CODE_NON_FINITE,
                    "Inf in u_g");
        // Wrong shape: a grid of n-1 cells.
        Gas small(n - 1, ns);
        expectError(small.message(step, t, dt, n - 1, ns, o.session()), v1::ERROR_CODE_SHAPE,
                    "n-1 cells");
        expectError(gas.message(step + 1, t, dt, n, ns, o.session()), v1::ERROR_CODE_OUT_OF_ORDER,
                    "next step");
        expectError(gas.message(step, t, 2 * dt, n, ns, o.session()), v1::ERROR_CODE_OUT_OF_ORDER,
                    "other dt");
        Gas neg = gas;
        neg.rho[0] = -1.0;
        expectError(neg.message(step, t, dt, n, ns, o.session()),
                    v1::ERROR_CODE_INVALID_CONFIGURATION, "negative density");
        // Garbage frames.
        c.client.sendFrames({std::string("\x01\x02garbage", 9)});
        auto g = c.client.receive(10s);
        ASSERT_TRUE(g.has_value());
        EXPECT_EQ(g->type(), v1::MESSAGE_TYPE_ERROR);
      }
      auto src = c.client.request(gas.message(step, t, dt, n, ns, o.session()), 20s);
      proto::expectType(src, v1::MESSAGE_TYPE_SOURCES);
      const auto e = src.values<double>(proto::fields::kVoidFraction);
      const auto k = src.values<double>(proto::fields::kDragCoefficientTimesUs);
      std::vector<double> both(e.begin(), e.end());
      both.insert(both.end(), k.begin(), k.end());
      eps[variant].push_back(both);
      stepDone(o);
    }
    o.shutdown();
  }
  ASSERT_EQ(eps[0].size(), eps[1].size());
  for (std::size_t s = 0; s < eps[0].size(); ++s) {
    EXPECT_EQ(eps[0][s], eps[1][s]) << "step " << s + 1; // bitwise
  }
}

/// Two sets moving towards each other (lower half up, upper half down) in a closed box with
/// gravity: collisions, wall contacts and tangential history from the first milliseconds.
v1::Configure collidingCase() {
  auto cfg = smallCase(40, kD, kBox, kCells);
  auto* lower = cfg.mutable_particle_sets(0);
  lower->mutable_region_max()->set_z(kBox / 2);
  lower->mutable_initial_velocity()->set_x(0.05);
  lower->mutable_initial_velocity()->set_z(0.6);
  auto* upper = cfg.add_particle_sets();
  *upper = *lower;
  upper->set_name("upper");
  upper->set_seed(8);
  upper->mutable_region_min()->set_z(kBox / 2);
  upper->mutable_region_max()->set_z(kBox);
  upper->mutable_initial_velocity()->set_x(-0.05);
  upper->mutable_initial_velocity()->set_z(-0.6);
  return cfg;
}

TEST(DemServer, RestartFromCheckpointIsBitwiseIdentical) {
  // Straight: 200 steps, checkpoints after steps 100 and 200. Restarted: a fresh server reads
  // the step-100 state and runs 101..200. Both step-200 states and the step-200 sources are
  // bitwise identical (h5diff without tolerance on /particles and /contacts).
  const auto dir = tempDir("restart");
  const std::size_t n = kCells * kCells * kCells, ns = 1;
  Gas gas(n, ns);
  const double dt = 1e-4;
  std::vector<double> lastEps[2];
  {
    ServerThread server;
    MiniOrchestrator o(server.endpoint(), collidingCase());
    Cfd c(server.endpoint(), o.session());
    const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
    std::vector<double> contacts;
    auto src =
        runSteps(o, c, gas, 1, 200, dt, nSub, n, ns,
                 {{100, (dir / "a100").string()}, {200, (dir / "a200").string()}}, &contacts);
    // The restart must carry contact history: contacts exist at the checkpoint step.
    EXPECT_GT(contacts[99], 0.0) << "no contacts at step 100: the test would not exercise history";
    const auto e = src.values<double>(proto::fields::kDragCoefficientTimesUs);
    lastEps[0].assign(e.begin(), e.end());
    o.shutdown();
  }
  ASSERT_TRUE(fs::exists(dir / "a100" / "dem.h5"));
  {
    ServerThread server;
    auto cfg = collidingCase();
    cfg.set_initial_state_file((dir / "a100" / "dem.h5").string());
    cfg.set_start_step(100);
    cfg.set_start_time(100 * dt);
    MiniOrchestrator o(server.endpoint(), cfg);
    EXPECT_EQ(o.particles(), 80u);
    Cfd c(server.endpoint(), o.session());
    const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
    auto src = runSteps(o, c, gas, 101, 200, dt, nSub, n, ns, {{200, (dir / "b200").string()}});
    const auto e = src.values<double>(proto::fields::kDragCoefficientTimesUs);
    lastEps[1].assign(e.begin(), e.end());
    o.shutdown();
  }
  EXPECT_EQ(lastEps[0], lastEps[1]);
  for (const char* group : {"/particles", "/contacts"}) {
    const std::string cmd = std::string(COREDEM_H5DIFF) + " -q " +
                            (dir / "a200" / "dem.h5").string() + " " +
                            (dir / "b200" / "dem.h5").string() + " " + group + " " + group;
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  fs::remove_all(dir);
}

TEST(DemServer, NonLoopbackBindNeedsCurveKeysOrInsecure) {
  coredem::server::ServerOptions o;
  o.bind = "tcp://0.0.0.0:*";
  try {
    coredem::server::DemServer s(o);
    FAIL() << "a non-loopback bind without CURVE keys must be refused";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("--curve-keys"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--insecure"), std::string::npos) << e.what();
  }
}

TEST(DemServer, CurveKeysAdmitOnlyClientsWithTheServerKey) {
  const auto dir = tempDir("curve");
  coredem::server::generateCurveKeys(dir.string());
  std::string pub;
  std::ifstream(dir / "server.public") >> pub;
  ASSERT_EQ(pub.size(), 40u);
  coredem::server::ServerOptions o;
  o.bind = "tcp://127.0.0.1:*";
  o.curveKeysDir = dir.string();
  coredem::server::DemServer server(o);
  std::thread t([&] { server.run(); });
  // With the server's public key: welcome.
  proto::TransportOptions good;
  const auto pair = proto::generateCurveKeyPair();
  good.curve.serverPublicKey = pub;
  good.curve.clientPublicKey = pair.first;
  good.curve.clientSecretKey = pair.second;
  proto::Client withKey(good);
  withKey.connect(server.endpoint());
  auto w = withKey.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "keyed"), 10s);
  EXPECT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  // Without keys (plain text) or with a wrong server key: the CURVE handshake fails and no
  // message reaches the server, so the request times out.
  proto::Client plain;
  plain.connect(server.endpoint());
  EXPECT_THROW(plain.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "plain"), 1s),
               proto::TimeoutError);
  proto::TransportOptions wrong = good;
  wrong.curve.serverPublicKey = proto::generateCurveKeyPair().first;
  proto::Client wrongKey(wrong);
  wrongKey.connect(server.endpoint());
  EXPECT_THROW(wrongKey.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "wrong"), 1s),
               proto::TimeoutError);
  server.stop();
  t.join();
  fs::remove_all(dir);
}

TEST(DemServer, InvalidConfigureIsRefusedAndTheSessionStaysUsable) {
  ServerThread server;
  proto::Client o;
  o.connect(server.endpoint());
  auto w = o.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "test orchestrator"), 10s);
  ASSERT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  const auto session = w.envelope().welcome().session_id();
  auto configure = [&](const v1::Configure& c) {
    auto m = proto::makeConfigure(c);
    m.setSessionId(session);
    return o.request(std::move(m), 20s);
  };
  // A particle set with a material id that does not exist.
  auto bad = smallCase(kParticles, kD, kBox, kCells);
  bad.mutable_particle_sets(0)->set_material_id(7);
  auto e = configure(bad);
  ASSERT_EQ(e.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(e.envelope().error().code(), v1::ERROR_CODE_INVALID_CONFIGURATION)
      << e.envelope().error().message();
  // More particles than fit in the region (random packing cannot place them).
  auto crowded = smallCase(500, kD, kBox, kCells); // 500 beads need 1.2 times the region
  auto e2 = configure(crowded);
  ASSERT_EQ(e2.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(e2.envelope().error().code(), v1::ERROR_CODE_INVALID_CONFIGURATION)
      << e2.envelope().error().message();
  // An initial state file that does not exist.
  auto missing = smallCase(kParticles, kD, kBox, kCells);
  missing.set_initial_state_file("/nonexistent/dem.h5");
  auto e3 = configure(missing);
  ASSERT_EQ(e3.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_NE(e3.envelope().error().message().find("/nonexistent/dem.h5"), std::string::npos);
  // A grant before a successful Configure is refused; the valid Configure then works.
  auto g = proto::makeStepGrant(1, 0.0, 1e-4, 100, 1e-6);
  g.setSessionId(session);
  auto e4 = o.request(std::move(g), 10s);
  ASSERT_EQ(e4.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(e4.envelope().error().code(), v1::ERROR_CODE_NOT_CONFIGURED);
  auto ok = configure(smallCase(kParticles, kD, kBox, kCells));
  ASSERT_EQ(ok.type(), v1::MESSAGE_TYPE_CONFIGURED);
  EXPECT_EQ(ok.envelope().configured().particle_count(), static_cast<std::uint64_t>(kParticles));
}
