// coredem-dem against hostile or careless peers over tcp loopback, one test per class of
// docs/security.md: admission control (counts against the memory budget, sub-steps), message
// size, overflow, sessions bound to peers, log hygiene. In each, the server answers at once
// with a specific error and keeps serving, or ends the session cleanly.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../client/mini_orchestrator.h"
#include "admission.h"
#include "coredem/common/log.h"
#include "coredem/server/dem_server.h"
#include "server_thread.h"

using namespace coredem::testing;
namespace server = coredem::server;

namespace {

constexpr int kParticles = 60;
constexpr double kD = 1e-3;
constexpr double kBox = 6e-3;
constexpr int kCells = 3;
constexpr std::size_t kN = kCells * kCells * kCells;

server::ServerOptions options(std::uint64_t memory = std::uint64_t{1} << 30,
                              std::int64_t message = std::int64_t{1} << 20,
                              std::uint64_t subSteps = 1000) {
  server::ServerOptions o;
  o.maxMemoryBytes = memory;
  o.maxMessageBytes = message;
  o.maxSubSteps = subSteps;
  o.grantWaitSeconds = 5.0;
  return o;
}

/// An orchestrator connection with its session (Hello answered by Welcome).
struct Orchestrator {
  proto::Client client;
  std::string session;
  explicit Orchestrator(const std::string& ep, const std::string& name = "test orchestrator") {
    client.connect(ep);
    auto w = client.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, name), 10s);
    proto::expectType(w, v1::MESSAGE_TYPE_WELCOME);
    session = w.envelope().welcome().session_id();
  }
  proto::Message configure(const v1::Configure& c) {
    auto m = proto::makeConfigure(c);
    m.setSessionId(session);
    return client.request(std::move(m), 20s);
  }
};

/// The refusal of `reply` (Error message or Reject reason), after checking its code.
std::string refusal(const proto::Message& reply, v1::ErrorCode code) {
  if (reply.type() == v1::MESSAGE_TYPE_REJECT) {
    EXPECT_EQ(reply.envelope().reject().code(), code) << reply.envelope().reject().reason();
    return reply.envelope().reject().reason();
  }
  EXPECT_EQ(reply.type(), v1::MESSAGE_TYPE_ERROR) << proto::messageTypeName(reply.type());
  EXPECT_EQ(reply.envelope().error().code(), code) << reply.envelope().error().message();
  return reply.envelope().error().message();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Uniform gas fields; `poison` may change one array before the message is built.
struct GasValues {
  std::vector<double> u = std::vector<double>(3 * kN, 0.0),
                      gradP = std::vector<double>(3 * kN, 0.0), T = std::vector<double>(kN, 300.0),
                      rho = std::vector<double>(kN, 1.2), mu = std::vector<double>(kN, 1.8e-5),
                      kappa = std::vector<double>(kN, 0.026), cp = std::vector<double>(kN, 1005.0),
                      Y = std::vector<double>(kN, 1.0);
};

proto::Message gasFields(std::int64_t step, double time, double dt, const std::string& session,
                         const GasValues& g = {}) {
  namespace f = proto::fields;
  const auto& [u, gradP, T, rho, mu, kappa, cp, Y] = g;
  auto m = proto::makeGasFields(step, time, dt, kN, 1);
  m.setSessionId(session);
  m.addArray(f::kGasVelocity, u, {kN, 3});
  m.addArray(f::kPressureGradient, gradP, {kN, 3});
  m.addArray(f::kGasTemperature, T, {kN});
  m.addArray(f::kGasDensity, rho, {kN});
  m.addArray(f::kGasViscosity, mu, {kN});
  m.addArray(f::kGasConductivity, kappa, {kN});
  m.addArray(f::kGasHeatCapacity, cp, {kN});
  m.addArray(f::kGasMassFractions, Y, {kN, 1});
  return m;
}

proto::Message cfdHello(const std::string& session, const std::string& name = "test cfd") {
  auto h = proto::makeHello(v1::ROLE_CFD, name);
  h.setSessionId(session);
  return h;
}

/// Says Hello as `role` until it is not refused with SESSION_BUSY (a closed connection is
/// noticed asynchronously); returns the last reply. At most ~10 s.
proto::Message helloUntilFree(proto::Client& c, v1::Role role, const std::string& session) {
  proto::Message reply;
  for (int i = 0; i < 100; ++i) {
    auto h = proto::makeHello(role, "newcomer");
    h.setSessionId(session);
    reply = c.request(std::move(h), 10s);
    if (reply.type() != v1::MESSAGE_TYPE_REJECT ||
        reply.envelope().reject().code() != v1::ERROR_CODE_SESSION_BUSY) {
      return reply;
    }
    std::this_thread::sleep_for(100ms);
  }
  return reply;
}

} // namespace

// ---- admission control and overflow ----------------------------------------------------------

TEST(Admission, LimitsFollowTheMemoryBudgetAndArithmeticSaturates) {
  const auto l = server::limitsFor(std::uint64_t{1} << 30, 1000);
  EXPECT_EQ(l.particles, (std::uint64_t{1} << 30) / server::MemoryModel::kParticleBase);
  EXPECT_EQ(l.cells, (std::uint64_t{1} << 30) / server::MemoryModel::kCellBase);
  EXPECT_EQ(l.subSteps, 1000u);
  constexpr auto kMax = std::numeric_limits<std::uint64_t>::max();
  EXPECT_EQ(server::estimateBytes(kMax, 1, 1, 1, 1), kMax);
  EXPECT_EQ(server::estimateBytes(1, 1, 1, 1, std::uint64_t{1} << 40), kMax);
  EXPECT_EQ(server::estimateBytes(0, 0, 0, 0, 0), 0u);
  EXPECT_EQ(server::parseBytes("8G"), std::uint64_t{8} << 30);
  EXPECT_EQ(server::parseBytes("512M"), std::uint64_t{512} << 20);
  EXPECT_EQ(server::parseBytes("1.5GiB"), std::uint64_t{3} << 29);
  EXPECT_EQ(server::parseBytes("4096"), 4096u);
  EXPECT_THROW(server::parseBytes("lots"), coredem::UserError);
  EXPECT_THROW(server::parseBytes("-1G"), coredem::UserError);
  EXPECT_THROW(server::parseBytes("8Q"), coredem::UserError);
  EXPECT_GE(server::defaultMaxMemory(), std::uint64_t{1} << 30);
}

TEST(Admission, HugeCountsAreRefusedNamingFieldValueAndLimitAndTheSessionStaysUsable) {
  ServerThread srv(options()); // 1 GiB budget: 524288 particles, 2097152 cells
  Orchestrator o(srv.endpoint());
  const auto base = smallCase(kParticles, kD, kBox, kCells);

  auto huge = base; // 10^12 particles: refused before anything is allocated
  huge.mutable_particle_sets(0)->set_count(1000000000000ull);
  auto msg = refusal(o.configure(huge), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "particle_sets[].count")) << msg;
  EXPECT_TRUE(contains(msg, "1000000000000")) << msg;
  EXPECT_TRUE(contains(msg, "524288")) << msg;
  EXPECT_TRUE(contains(msg, "--max-memory")) << msg;

  auto wrap = base; // two sets whose counts sum past 2^64
  wrap.mutable_particle_sets(0)->set_count(std::uint64_t{1} << 63);
  *wrap.add_particle_sets() = wrap.particle_sets(0);
  msg = refusal(o.configure(wrap), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "overflow")) << msg;

  auto materials = base; // the pair table is n^2: 2000 materials refused
  for (std::uint32_t id = 1; id < 2000; ++id) {
    auto* m = materials.add_materials();
    *m = base.materials(0);
    m->set_id(id);
  }
  msg = refusal(o.configure(materials), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "materials")) << msg;
  EXPECT_TRUE(contains(msg, "2000")) << msg;
  EXPECT_TRUE(contains(msg, "1024")) << msg;

  auto species = base; // 300 gas species
  for (int k = 0; k < 299; ++k) {
    auto* s = species.add_species();
    s->set_name(std::string("S").append(std::to_string(k)));
    s->set_molar_mass(0.03);
  }
  msg = refusal(o.configure(species), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "species (count) = 300")) << msg;
  EXPECT_TRUE(contains(msg, "256")) << msg;

  auto opts = base; // 300 options
  for (int k = 0; k < 300; ++k) {
    auto* kv = opts.add_options();
    kv->set_key(std::string("k").append(std::to_string(k)));
    kv->set_value("v");
  }
  msg = refusal(o.configure(opts), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "options (count) = 300")) << msg;

  auto longKey = base; // a 1000-byte option key
  auto* kv = longKey.add_options();
  kv->set_key(std::string(1000, 'k'));
  kv->set_value("v");
  msg = refusal(o.configure(longKey), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "1000 bytes")) << msg;
  EXPECT_LT(msg.size(), 400u) << msg;

  auto overflowGrid = base; // (2^32-1)^2 * 4 cells: overflows 64 bits, refused (not 0 cells)
  auto* counts = overflowGrid.mutable_coupling_mesh()->mutable_cartesian()->mutable_counts();
  counts->set_x(4294967295u);
  counts->set_y(4294967295u);
  counts->set_z(4);
  msg = refusal(o.configure(overflowGrid), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "overflow")) << msg;

  auto bigGrid = base; // 4e9 cells: past the protocol's int cell index
  counts = bigGrid.mutable_coupling_mesh()->mutable_cartesian()->mutable_counts();
  counts->set_x(2000);
  counts->set_y(2000);
  counts->set_z(1000);
  msg = refusal(o.configure(bigGrid), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "4000000000")) << msg;
  EXPECT_TRUE(contains(msg, "2147483647")) << msg;

  auto budgetGrid = base; // 3 M cells: under the protocol limit, over this budget's 2097152
  counts = budgetGrid.mutable_coupling_mesh()->mutable_cartesian()->mutable_counts();
  counts->set_x(3000);
  counts->set_y(1000);
  counts->set_z(1);
  msg = refusal(o.configure(budgetGrid), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "3000000")) << msg;
  EXPECT_TRUE(contains(msg, "2097152")) << msg;

  auto both = base; // each count within its limit, together over the budget
  both.mutable_particle_sets(0)->set_count(400000);
  counts = both.mutable_coupling_mesh()->mutable_cartesian()->mutable_counts();
  counts->set_x(1500);
  counts->set_y(1000);
  counts->set_z(1);
  msg = refusal(o.configure(both), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "estimated memory")) << msg;

  auto subSteps = base; // a plan of 5000 sub-steps against --max-sub-steps 1000
  subSteps.mutable_sub_cycling()->set_n_sub(5000);
  subSteps.mutable_sub_cycling()->set_dt_dem(1e-4 / 5000);
  msg = refusal(o.configure(subSteps), v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_TRUE(contains(msg, "sub_cycling.n_sub = 5000")) << msg;

  // Nothing of that changed the session: the valid Configure is accepted.
  auto ok = o.configure(base);
  ASSERT_EQ(ok.type(), v1::MESSAGE_TYPE_CONFIGURED);
  EXPECT_EQ(ok.envelope().configured().particle_count(), static_cast<std::uint64_t>(kParticles));
}

TEST(Admission, AbsurdSubStepCountsAreRefusedAndTheNextStepRuns) {
  ServerThread srv(options());
  MiniOrchestrator o(srv.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  proto::Client cfd;
  cfd.connect(srv.endpoint());
  proto::expectType(cfd.request(cfdHello(o.session()), 10s), v1::MESSAGE_TYPE_WELCOME);
  const double dt = 2e-4;
  // 3e9 sub-steps: negative as an int, hours of work as a count; and one past the limit.
  for (const std::uint32_t nSub : {3000000000u, 1001u}) {
    auto g = proto::makeStepGrant(1, 0.0, dt, nSub, dt / nSub);
    g.setSessionId(o.session());
    const auto msg =
        refusal(o.dem().request(std::move(g), 10s), v1::ERROR_CODE_INVALID_CONFIGURATION);
    EXPECT_TRUE(contains(msg, "n_sub = " + std::to_string(nSub))) << msg;
    EXPECT_TRUE(contains(msg, "1000")) << msg;
  }
  { // a CFD step of 10^10 s: 6e15 sub-steps needed; refused, the session goes on
    auto huge = proto::makeStepGrant(1, 0.0, 1e10, 1, 1e10);
    huge.setSessionId(o.session());
    const auto msg =
        refusal(o.dem().request(std::move(huge), 10s), v1::ERROR_CODE_INVALID_CONFIGURATION);
    EXPECT_TRUE(contains(msg, "dt_dem_max")) << msg;
  }
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  ASSERT_LE(nSub, 1000u);
  auto g = proto::makeStepGrant(1, 0.0, dt, nSub, dt / nSub);
  g.setSessionId(o.session());
  o.dem().send(std::move(g));
  auto src = cfd.request(gasFields(1, 0.0, dt, o.session()), 20s);
  EXPECT_EQ(src.type(), v1::MESSAGE_TYPE_SOURCES);
  auto done = o.dem().receive(20s);
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->type(), v1::MESSAGE_TYPE_STEP_DONE);
  o.shutdown();
}

// ---- poisoning: physical ranges of the gas fields -----------------------------------------------

TEST(GasRanges, AbsurdButFiniteGasFieldsAreRefusedAndTheStepRunsWithValidOnes) {
  ServerThread srv(options());
  MiniOrchestrator o(srv.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  proto::Client cfd;
  cfd.connect(srv.endpoint());
  proto::expectType(cfd.request(cfdHello(o.session()), 10s), v1::MESSAGE_TYPE_WELCOME);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  auto g = proto::makeStepGrant(1, 0.0, dt, nSub, dt / nSub);
  g.setSessionId(o.session());
  o.dem().send(std::move(g));
  struct Poison {
    const char* array;
    std::function<void(GasValues&)> apply;
  };
  const Poison poisons[] = {
      {"mu_g", [](GasValues& v) { v.mu[4] = 1e-310; }}, // denormal viscosity
      {"kappa_g", [](GasValues& v) { v.kappa[0] = 1e30; }},
      {"T_g", [](GasValues& v) { v.T[2] = 1e9; }},
      {"T_g", [](GasValues& v) { v.T[2] = 20.0; }}, // degrees Celsius sent as K
      {"u_g", [](GasValues& v) { v.u[3 * 5 + 2] = 1e8; }},
      {"rho_g", [](GasValues& v) { v.rho[1] = 1e-300; }},
      {"cp_g", [](GasValues& v) { v.cp[1] = 1e20; }},
      {"grad_p", [](GasValues& v) { v.gradP[0] = 1e300; }},
      {"Y_g", [](GasValues& v) { v.Y[7] = 0.5; }}, // sum 0.5
  };
  for (const Poison& p : poisons) {
    GasValues v;
    p.apply(v);
    const auto msg = refusal(cfd.request(gasFields(1, 0.0, dt, o.session(), v), 10s),
                             v1::ERROR_CODE_INVALID_CONFIGURATION);
    EXPECT_TRUE(contains(msg, std::string("'") + p.array + "'")) << p.array << ": " << msg;
    EXPECT_TRUE(contains(msg, "range")) << msg;
  }
  // The refused fields changed nothing: the valid ones run the step, with finite Sources.
  auto src = cfd.request(gasFields(1, 0.0, dt, o.session()), 20s);
  ASSERT_EQ(src.type(), v1::MESSAGE_TYPE_SOURCES);
  for (const double k : src.values<double>(proto::fields::kDragCoefficient)) {
    EXPECT_TRUE(std::isfinite(k));
  }
  auto done = o.dem().receive(20s);
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->type(), v1::MESSAGE_TYPE_STEP_DONE);
  o.shutdown();
}

// ---- message size ------------------------------------------------------------------------------

TEST(MessageSize, OversizedMessagesAreRefusedAndTheServerKeepsServing) {
  ServerThread srv(options()); // 1 MiB per frame
  const auto envelope = proto::makeHeartbeat("probe").encode().at(0);
  {
    // A 2 MiB frame: ZeroMQ closes that connection before allocating it; no reply.
    proto::Client big;
    big.connect(srv.endpoint());
    big.sendFrames({envelope, std::string(std::size_t{2} << 20, 'x')});
    EXPECT_FALSE(big.receive(1000ms).has_value());
  }
  proto::Client c;
  c.connect(srv.endpoint());
  // Frames under the limit that together exceed it: BYTE_LENGTH naming the limit.
  const std::string part(600 << 10, 'y');
  ASSERT_EQ(c.request(proto::makeHeartbeat("before"), 10s).type(), v1::MESSAGE_TYPE_HEARTBEAT);
  c.sendFrames({envelope, part, part, part});
  auto first = c.receive(10s);
  ASSERT_TRUE(first.has_value());
  auto msg = refusal(*first, v1::ERROR_CODE_BYTE_LENGTH);
  EXPECT_TRUE(contains(msg, std::to_string(std::int64_t{1} << 20))) << msg;
  // Too many frames: refused naming the frame limit.
  proto::Frames many(proto::kMaxFramesPerMessage + 10, std::string("z"));
  many.front() = envelope;
  c.sendFrames(many);
  auto reply = c.receive(10s);
  ASSERT_TRUE(reply.has_value());
  msg = refusal(*reply, v1::ERROR_CODE_BYTE_LENGTH);
  EXPECT_TRUE(contains(msg, std::to_string(proto::kMaxFramesPerMessage))) << msg;
  // The server still serves.
  auto hb = c.request(proto::makeHeartbeat("after"), 10s);
  EXPECT_EQ(hb.type(), v1::MESSAGE_TYPE_HEARTBEAT);
}

// ---- sessions bound to peers -------------------------------------------------------------------

TEST(SessionBinding, StrangersNeverLearnTheSessionId) {
  ServerThread srv(options());
  MiniOrchestrator o(srv.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  proto::Client stranger;
  stranger.connect(srv.endpoint());
  auto hb = stranger.request(proto::makeHeartbeat("probe"), 10s);
  ASSERT_EQ(hb.type(), v1::MESSAGE_TYPE_HEARTBEAT);
  EXPECT_EQ(hb.envelope().session_id(), "");
  std::vector<proto::Message> replies;
  replies.push_back(stranger.request(proto::makeConfigure(smallCase(1, kD, kBox, kCells)), 10s));
  replies.push_back(stranger.request(proto::makeShutdown("take over"), 10s));
  replies.push_back(stranger.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "second"), 10s));
  replies.push_back(stranger.request(cfdHello("guess"), 10s));
  replies.push_back(stranger.request(proto::makeHello(v1::ROLE_CFD, "no id"), 10s));
  for (const auto& r : replies) {
    const auto& env = r.envelope();
    EXPECT_EQ(env.session_id(), "") << proto::messageTypeName(r.type());
    const std::string text =
        r.type() == v1::MESSAGE_TYPE_REJECT ? env.reject().reason() : env.error().message();
    EXPECT_FALSE(text.empty());
    EXPECT_FALSE(contains(text, o.session())) << text;
  }
  EXPECT_EQ(replies[0].envelope().error().code(), v1::ERROR_CODE_UNKNOWN_SESSION);
  EXPECT_EQ(replies[2].envelope().reject().code(), v1::ERROR_CODE_SESSION_BUSY);
  EXPECT_EQ(replies[3].envelope().reject().code(), v1::ERROR_CODE_UNKNOWN_SESSION);
  // The session's members still get it.
  auto member = o.dem().request(
      [&] {
        auto h = proto::makeHeartbeat("member");
        h.setSessionId(o.session());
        return h;
      }(),
      10s);
  EXPECT_EQ(member.envelope().session_id(), o.session());
  o.shutdown();
}

TEST(SessionBinding, ASecondCfdIsRefusedAndTheFirstKeepsItsRole) {
  ServerThread srv(options());
  MiniOrchestrator o(srv.endpoint(), smallCase(kParticles, kD, kBox, kCells));
  auto first = std::make_unique<proto::Client>();
  first->connect(srv.endpoint());
  proto::expectType(first->request(cfdHello(o.session()), 10s), v1::MESSAGE_TYPE_WELCOME);
  // Someone who knows the session id says Hello as CFD on another connection: refused.
  proto::Client intruder;
  intruder.connect(srv.endpoint());
  auto msg = refusal(intruder.request(cfdHello(o.session(), "intruder"), 10s),
                     v1::ERROR_CODE_SESSION_BUSY);
  EXPECT_TRUE(contains(msg, "CFD participant")) << msg;
  // Its GasFields are not taken.
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  auto g = proto::makeStepGrant(1, 0.0, dt, nSub, dt / nSub);
  g.setSessionId(o.session());
  o.dem().send(std::move(g));
  refusal(intruder.request(gasFields(1, 0.0, dt, o.session()), 10s),
          v1::ERROR_CODE_UNKNOWN_SESSION);
  // The orchestrator's own connection cannot take the CFD role either.
  refusal(o.dem().request(cfdHello(o.session(), "orchestrator as cfd"), 10s),
          v1::ERROR_CODE_UNEXPECTED_MESSAGE);
  // The real participant steps.
  auto src = first->request(gasFields(1, 0.0, dt, o.session()), 20s);
  EXPECT_EQ(src.type(), v1::MESSAGE_TYPE_SOURCES);
  auto done = o.dem().receive(20s);
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->type(), v1::MESSAGE_TYPE_STEP_DONE);
  // When its connection closes, the role is free for a new participant.
  first.reset();
  proto::Client next;
  next.connect(srv.endpoint());
  auto w = helloUntilFree(next, v1::ROLE_CFD, o.session());
  EXPECT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  o.shutdown();
}

TEST(SessionBinding, ALostOrchestratorEndsTheSession) {
  ServerThread srv(options()); // session timeout 600 s: only the closed connection ends it
  std::string session;
  {
    Orchestrator o(srv.endpoint());
    session = o.session;
    ASSERT_EQ(o.configure(smallCase(kParticles, kD, kBox, kCells)).type(),
              v1::MESSAGE_TYPE_CONFIGURED);
  } // the orchestrator's socket closes
  proto::Client next;
  next.connect(srv.endpoint());
  auto w = helloUntilFree(next, v1::ROLE_ORCHESTRATOR, "");
  ASSERT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  EXPECT_NE(w.envelope().welcome().session_id(), session);
  // The old session id is dead: a CFD Hello with it is refused.
  proto::Client late;
  late.connect(srv.endpoint());
  refusal(late.request(cfdHello(session), 10s), v1::ERROR_CODE_UNKNOWN_SESSION);
}

TEST(SessionBinding, ReusingTheOrchestratorsRoutingIdGainsNothing) {
  ServerThread srv(options());
  proto::TransportOptions same;
  same.routingId = "orchestrator-1";
  auto o = std::make_unique<proto::Client>(same);
  o->connect(srv.endpoint());
  auto w = o->request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "real"), 10s);
  ASSERT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  const auto session = w.envelope().welcome().session_id();
  // While the orchestrator is connected, ZeroMQ refuses a second connection with its routing
  // id: nothing of it reaches the server.
  {
    proto::Client twin(same);
    twin.connect(srv.endpoint());
    auto s = proto::makeShutdown("take over");
    s.setSessionId(session);
    EXPECT_THROW(twin.request(std::move(s), 1s), proto::TimeoutError);
  }
  auto hb = proto::makeHeartbeat("still here");
  hb.setSessionId(session);
  EXPECT_EQ(o->request(std::move(hb), 10s).envelope().session_id(), session);
  // Once its connection closed, the session is over: a peer reusing the routing id (and the
  // session id it somehow learnt) meets no session.
  o.reset();
  proto::Client probe;
  probe.connect(srv.endpoint());
  auto free = helloUntilFree(probe, v1::ROLE_ORCHESTRATOR, "");
  ASSERT_EQ(free.type(), v1::MESSAGE_TYPE_WELCOME); // the old session ended
  proto::Client reuse(same);
  reuse.connect(srv.endpoint());
  auto cfg = proto::makeConfigure(smallCase(kParticles, kD, kBox, kCells));
  cfg.setSessionId(session);
  refusal(reuse.request(std::move(cfg), 10s), v1::ERROR_CODE_UNKNOWN_SESSION);
}

// ---- logs and replies --------------------------------------------------------------------------

TEST(Logs, PeerStringsAreEscapedAndCappedAndRepeatedWarningsSummarised) {
  std::ostringstream captured;
  auto log = coredem::logger("dem.server");
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
  log->sinks().push_back(sink);
  {
    ServerThread srv(options());
    // A name that tries to forge a log line, 100 kB long.
    const std::string evil =
        "evil\n[2026-01-01 00:00:00.000] [dem.server] [info] FORGED" + std::string(100000, 'x');
    proto::Client o;
    o.connect(srv.endpoint());
    auto hello = proto::makeHello(v1::ROLE_ORCHESTRATOR, "x");
    hello.envelope().set_sender(evil);
    auto w = o.request(std::move(hello), 10s);
    ASSERT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
    const auto session = w.envelope().welcome().session_id();
    // 200 unknown options: 5 warnings and one summary line.
    auto c = smallCase(kParticles, kD, kBox, kCells);
    for (int k = 0; k < 200; ++k) {
      auto* kv = c.add_options();
      kv->set_key("no_such_option_" + std::to_string(k));
      kv->set_value("1");
    }
    auto cfg = proto::makeConfigure(c);
    cfg.setSessionId(session);
    ASSERT_EQ(o.request(std::move(cfg), 20s).type(), v1::MESSAGE_TYPE_CONFIGURED);
    // A reply that names a peer string: escaped and capped.
    proto::Client stranger;
    stranger.connect(srv.endpoint());
    const auto reason =
        refusal(stranger.request(cfdHello("bad\nid" + std::string(100000, 'y')), 10s),
                v1::ERROR_CODE_UNKNOWN_SESSION);
    EXPECT_FALSE(contains(reason, "\n")) << reason;
    EXPECT_TRUE(contains(reason, "bad\\nid")) << reason;
    EXPECT_LT(reason.size(), 1000u);
    auto s = proto::makeShutdown("done\nFORGED TOO");
    s.setSessionId(session);
    ASSERT_EQ(o.request(std::move(s), 10s).type(), v1::MESSAGE_TYPE_ACK);
  }
  log->flush();
  auto& sinks = log->sinks();
  sinks.erase(std::remove(sinks.begin(), sinks.end(), sink), sinks.end());
  const std::string text = captured.str();
  std::istringstream lines(text);
  std::string line;
  int optionWarnings = 0, summaries = 0;
  while (std::getline(lines, line)) {
    EXPECT_FALSE(line.starts_with("[2026-01-01")) << "forged line: " << line;
    EXPECT_FALSE(line.starts_with("FORGED")) << "forged line: " << line;
    EXPECT_LT(line.size(), 2000u) << line.substr(0, 200);
    optionWarnings += contains(line, "is not a DEM server option") ? 1 : 0;
    summaries += contains(line, "195 more Configure options") ? 1 : 0;
  }
  EXPECT_EQ(optionWarnings, 5);
  EXPECT_EQ(summaries, 1);
  EXPECT_TRUE(contains(text, "evil\\n[2026")) << "the name is logged, escaped";
}

// ---- client authentication (CURVE + ZAP allow-list) --------------------------------------------

TEST(ClientKeys, OnlyClientsOnTheAllowListAreAdmitted) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("coredem-dem-client-keys-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  server::generateCurveKeys(dir.string());
  server::generateClientKey((dir / "alice").string());
  std::string serverPub, alicePub, aliceSec;
  std::ifstream(dir / "server.public") >> serverPub;
  std::ifstream(dir / "alice" / "client.public") >> alicePub;
  std::ifstream(dir / "alice" / "client.secret") >> aliceSec;
  ASSERT_EQ(alicePub.size(), 40u);
  {
    std::ofstream allow(dir / "authorized_keys");
    allow << "# CFD nodes allowed to drive this DEM server\n\n" << alicePub << " alice@node1\n";
  }
  auto o = options();
  o.curveKeysDir = dir.string();
  o.clientKeysFile = (dir / "authorized_keys").string();
  ServerThread srv(o);
  proto::TransportOptions alice;
  alice.curve.serverPublicKey = serverPub;
  alice.curve.clientPublicKey = alicePub;
  alice.curve.clientSecretKey = aliceSec;
  proto::Client allowed(alice);
  allowed.connect(srv.endpoint());
  EXPECT_EQ(allowed.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "alice"), 10s).type(),
            v1::MESSAGE_TYPE_WELCOME);
  // A client that knows the server's public key but made up its own key pair: the CURVE
  // handshake is refused by the ZAP handler and no message reaches the server.
  proto::TransportOptions mallory = alice;
  const auto pair = proto::generateCurveKeyPair();
  mallory.curve.clientPublicKey = pair.first;
  mallory.curve.clientSecretKey = pair.second;
  proto::Client refused(mallory);
  refused.connect(srv.endpoint());
  // The server answers the handshake with an ERROR (ZAP 400): the client says so at once,
  // naming its key, instead of waiting out its deadline.
  try {
    (void)refused.request(proto::makeHeartbeat("mallory"), 10s);
    ADD_FAILURE() << "a client key that is not on the allow-list must be refused";
  } catch (const proto::TimeoutError& e) {
    ADD_FAILURE() << "the refusal must be reported, not waited out: " << e.what();
  } catch (const proto::ProtocolError& e) {
    EXPECT_EQ(e.code(), v1::ERROR_CODE_SECURITY);
    EXPECT_TRUE(contains(e.what(), pair.first)) << e.what();
    EXPECT_TRUE(contains(e.what(), "allow-list")) << e.what();
  }
  // The allowed client is still served.
  EXPECT_EQ(allowed.request(proto::makeHeartbeat("alice"), 10s).type(), v1::MESSAGE_TYPE_HEARTBEAT);
  // A malformed allow-list is refused at start naming the line.
  {
    std::ofstream bad(dir / "bad_keys");
    bad << alicePub << "\nnot-a-key\n";
  }
  auto b = options();
  b.curveKeysDir = dir.string();
  b.clientKeysFile = (dir / "bad_keys").string();
  try {
    server::DemServer s(b);
    ADD_FAILURE() << "a malformed allow-list must be refused";
  } catch (const coredem::UserError& e) {
    EXPECT_TRUE(contains(e.what(), "line 2")) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// The persistent client pair of a user (`coredem-dem --generate-client-key DIR`), read back
// by the clients (readClientKeyPair: DIR or DIR/client.secret): admitted by a server that
// lists it; a secret readable by others, a mixed-up pair and a missing file are refused naming
// the file; a server without an allow-list (and loopback without keys) admits anyone as before.
TEST(ClientKeys, PersistentClientPairsAreReadAndChecked) {
  namespace fs = std::filesystem;
  const auto dir =
      fs::temp_directory_path() / ("coredem-dem-client-pair-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  server::generateCurveKeys(dir.string());
  server::generateClientKey((dir / "bob").string());
  server::generateClientKey((dir / "eve").string());
  std::string serverPub, bobPub;
  std::ifstream(dir / "server.public") >> serverPub;
  std::ifstream(dir / "bob" / "client.public") >> bobPub;
  std::ofstream(dir / "authorized_keys") << bobPub << " bob\n";

  const auto fromDir = proto::readClientKeyPair((dir / "bob").string());
  const auto fromFile = proto::readClientKeyPair((dir / "bob" / "client.secret").string());
  EXPECT_EQ(fromDir.first, bobPub);
  EXPECT_EQ(fromDir, fromFile);

  auto o = options();
  o.curveKeysDir = dir.string();
  o.clientKeysFile = (dir / "authorized_keys").string();
  ServerThread srv(o);
  auto clientOptions = [&](const std::pair<std::string, std::string>& pair) {
    proto::TransportOptions t;
    t.curve.serverPublicKey = serverPub;
    t.curve.clientPublicKey = pair.first;
    t.curve.clientSecretKey = pair.second;
    return t;
  };
  proto::Client bob(clientOptions(fromFile));
  bob.connect(srv.endpoint());
  EXPECT_EQ(bob.request(proto::makeHeartbeat("bob"), 10s).type(), v1::MESSAGE_TYPE_HEARTBEAT);
  proto::Client eve(clientOptions(proto::readClientKeyPair((dir / "eve").string())));
  eve.connect(srv.endpoint());
  try {
    (void)eve.request(proto::makeHeartbeat("eve"), 10s);
    ADD_FAILURE() << "eve's key is not on the allow-list";
  } catch (const proto::TimeoutError& e) {
    ADD_FAILURE() << "the refusal must be reported, not waited out: " << e.what();
  } catch (const proto::ProtocolError& e) {
    EXPECT_EQ(e.code(), v1::ERROR_CODE_SECURITY) << e.what();
  }

  // Checks of the files.
  auto refusedWith = [&](const fs::path& path, const std::string& part) {
    try {
      (void)proto::readClientKeyPair(path.string());
      ADD_FAILURE() << path << " must be refused";
    } catch (const proto::ProtocolError& e) {
      EXPECT_EQ(e.code(), v1::ERROR_CODE_SECURITY);
      EXPECT_TRUE(contains(e.what(), part)) << e.what();
      EXPECT_TRUE(contains(e.what(), path.string())) << e.what();
    }
  };
  fs::permissions(dir / "eve" / "client.secret", fs::perms::group_read | fs::perms::others_read,
                  fs::perm_options::add);
  refusedWith(dir / "eve" / "client.secret", "chmod 600");
  fs::copy_file(dir / "bob" / "client.public", dir / "eve" / "client.public",
                fs::copy_options::overwrite_existing);
  fs::permissions(dir / "eve" / "client.secret", fs::perms::owner_read | fs::perms::owner_write,
                  fs::perm_options::replace);
  refusedWith(dir / "eve" / "client.secret", "mixed up");
  refusedWith(dir / "nobody", "cannot read");

  // Without an allow-list any CURVE client is admitted; on loopback without keys, anyone.
  auto open = options();
  open.curveKeysDir = dir.string();
  ServerThread openSrv(open);
  proto::Client any(clientOptions(proto::generateCurveKeyPair()));
  any.connect(openSrv.endpoint());
  EXPECT_EQ(any.request(proto::makeHeartbeat("any"), 10s).type(), v1::MESSAGE_TYPE_HEARTBEAT);
  ServerThread plain(options());
  proto::Client plainClient;
  plainClient.connect(plain.endpoint());
  EXPECT_EQ(plainClient.request(proto::makeHeartbeat("plain"), 10s).type(),
            v1::MESSAGE_TYPE_HEARTBEAT);
  fs::remove_all(dir);
}

// ---- stoppable: a signal during a long step ---------------------------------------------------

// coredem-dem (the program) granted a step of 10^8 sub-steps (legal under its
// --max-sub-steps): SIGTERM during the step interrupts it within a sub-step, both members get
// an answer naming the interruption, and the program exits 0 well before the step could end.
TEST(Stoppable, SigtermDuringALongStepEndsTheSessionWithinASubStep) {
  namespace fs = std::filesystem;
  const auto dir =
      fs::temp_directory_path() / ("coredem-dem-sigterm-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string epFile = (dir / "endpoint").string(), logFile = (dir / "dem.log").string();
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int fd = ::open(logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(COREDEM_DEM_EXE, COREDEM_DEM_EXE, "--bind", "tcp://127.0.0.1:*", "--threads", "1",
            "--max-sub-steps", "1000000000", "--endpoint-file", epFile.c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  auto readAll = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  for (int i = 0; i < 2000 && !fs::exists(epFile); ++i) {
    std::this_thread::sleep_for(10ms);
  }
  std::string ep = readAll(epFile);
  while (!ep.empty() && std::isspace(static_cast<unsigned char>(ep.back()))) {
    ep.pop_back();
  }
  ASSERT_FALSE(ep.empty()) << readAll(logFile);
  int status = 0;
  bool exited = false;
  {
    MiniOrchestrator o(ep, smallCase(kParticles, kD, kBox, kCells));
    proto::Client cfd;
    cfd.connect(ep);
    proto::expectType(cfd.request(cfdHello(o.session()), 10s), v1::MESSAGE_TYPE_WELCOME);
    const std::uint32_t nSub = 100000000;
    const double dtDem = 0.5 * o.dtDemMax(), dt = dtDem * nSub;
    auto g = proto::makeStepGrant(1, 0.0, dt, nSub, dtDem);
    g.setSessionId(o.session());
    o.dem().send(std::move(g));
    cfd.send(gasFields(1, 0.0, dt, o.session()));
    std::this_thread::sleep_for(500ms); // the step is running
    ASSERT_EQ(::kill(pid, SIGTERM), 0);
    // Liveness bound, not a timing measurement: the step itself would take minutes.
    for (int i = 0; i < 1000 && !exited; ++i) {
      exited = ::waitpid(pid, &status, WNOHANG) == pid;
      if (!exited) {
        std::this_thread::sleep_for(10ms);
      }
    }
    if (exited) {
      auto cfdReply = cfd.receive(5s);
      ASSERT_TRUE(cfdReply.has_value());
      EXPECT_TRUE(contains(refusal(*cfdReply, v1::ERROR_CODE_UNEXPECTED_MESSAGE), "interrupted"));
      auto oReply = o.dem().receive(5s);
      ASSERT_TRUE(oReply.has_value());
      EXPECT_TRUE(contains(refusal(*oReply, v1::ERROR_CODE_UNEXPECTED_MESSAGE), "interrupted"));
    }
  }
  if (!exited) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    FAIL() << "coredem-dem did not exit within 10 s of SIGTERM\n" << readAll(logFile);
  }
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  const std::string log = readAll(logFile);
  EXPECT_TRUE(contains(log, "stopped by a signal")) << log;
  EXPECT_TRUE(contains(log, "interrupted after")) << log;
  fs::remove_all(dir);
}

// ---- failures inside D: a failed step ends the session -----------------------------------------

// A particle set launched at 1e300 m/s (finite, so the Configure passes) flies off in the
// first sub-step: the DEM core fails the step. Both members get an Error naming the failure,
// the session ends (no "step failed" to every later request), and the server serves the next
// orchestrator.
TEST(InternalFailure, AFailedStepEndsTheSessionAndTheServerServesTheNext) {
  ServerThread srv(options());
  auto c = smallCase(kParticles, kD, kBox, kCells);
  c.mutable_particle_sets(0)->mutable_initial_velocity()->set_x(1e300);
  MiniOrchestrator o(srv.endpoint(), c);
  proto::Client cfd;
  cfd.connect(srv.endpoint());
  proto::expectType(cfd.request(cfdHello(o.session()), 10s), v1::MESSAGE_TYPE_WELCOME);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  ASSERT_LE(nSub, 1000u);
  for (std::int64_t step = 1; step <= 3; ++step) { // the failure may need a rebuild to show
    auto g = proto::makeStepGrant(step, dt * double(step - 1), dt, nSub, dt / nSub);
    g.setSessionId(o.session());
    o.dem().send(std::move(g));
    auto reply = cfd.request(gasFields(step, dt * double(step - 1), dt, o.session()), 20s);
    if (reply.type() == v1::MESSAGE_TYPE_SOURCES) {
      auto done = o.dem().receive(20s);
      ASSERT_TRUE(done.has_value());
      ASSERT_EQ(done->type(), v1::MESSAGE_TYPE_STEP_DONE);
      continue;
    }
    const auto msg = refusal(reply, v1::ERROR_CODE_INTERNAL);
    EXPECT_TRUE(contains(msg, "failed in the DEM core")) << msg;
    EXPECT_TRUE(contains(msg, "unstable")) << msg;
    auto oReply = o.dem().receive(20s);
    ASSERT_TRUE(oReply.has_value());
    EXPECT_EQ(oReply->type(), v1::MESSAGE_TYPE_ERROR);
    // The session is over: the next grant meets no session, a new orchestrator is welcomed.
    auto next = proto::makeStepGrant(step + 1, dt * double(step), dt, nSub, dt / nSub);
    next.setSessionId(o.session());
    refusal(o.dem().request(std::move(next), 10s), v1::ERROR_CODE_NOT_CONFIGURED);
    Orchestrator fresh(srv.endpoint());
    EXPECT_NE(fresh.session, o.session());
    return;
  }
  FAIL() << "a particle at 1e300 m/s did not fail the step";
}

// A Configure whose random packing cannot succeed (500000 particles of 1 mm in a 6 mm box:
// about 10^9 placement attempts before it gives up): stopping the server interrupts the
// placement; the orchestrator is answered and the server thread ends.
TEST(Stoppable, StoppingDuringAParticlePlacementInterruptsIt) {
  auto srv = std::make_unique<ServerThread>(options(std::uint64_t{4} << 30));
  Orchestrator o(srv->endpoint());
  auto c = smallCase(kParticles, kD, kBox, kCells);
  c.mutable_particle_sets(0)->set_count(500000);
  auto m = proto::makeConfigure(c);
  m.setSessionId(o.session);
  o.client.send(std::move(m));
  std::this_thread::sleep_for(500ms); // placing
  srv.reset(); // stop() and join: returns only once the placement has stopped
  auto reply = o.client.receive(10s);
  ASSERT_TRUE(reply.has_value());
  const auto msg = refusal(*reply, v1::ERROR_CODE_UNEXPECTED_MESSAGE);
  EXPECT_TRUE(contains(msg, "interrupted while placing particle set 'beads'")) << msg;
}

// A string field with invalid UTF-8 (any peer can send one per message): refused
// MALFORMED_ENVELOPE, and libprotobuf's complaint goes to the log at debug level, not as an
// unescaped line on stderr per message.
TEST(Logs, InvalidUtf8IsRefusedWithoutALineOnStderrPerMessage) {
  ServerThread srv(options());
  proto::Client raw;
  raw.connect(srv.endpoint());
  auto hb = proto::makeHeartbeat("x");
  hb.envelope().set_sender(std::string("bad \xff\xfe utf-8"));
  auto frames = hb.encode();
  ::testing::internal::CaptureStderr();
  for (int i = 0; i < 3; ++i) {
    raw.sendFrames(frames);
    auto reply = raw.receive(10s);
    ASSERT_TRUE(reply.has_value());
    refusal(*reply, v1::ERROR_CODE_MALFORMED_ENVELOPE);
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_FALSE(contains(err, "libprotobuf")) << err;
}
