// The golden messages of protocol/golden/ (v1.0 and v1.1) replayed to the real DEM server
// over tcp loopback, in session order, each as it is on disk except for the session id (the
// server makes up its own; the goldens carry "golden-session"). What the server receives is
// accepted: Hello (CFD), Configure, StepGrant, GasFields (structure; its array values are test
// patterns, see below), CheckpointRequest, Heartbeat, Shutdown. What only the server or the
// orchestrator sends (Welcome, Configured, Sources, StepDone, ...) is refused
// UNEXPECTED_MESSAGE and changes nothing. Also the points where docs/protocol.md and
// docs/client.md had contradicted the server: a second orchestrator Hello, a CFD Hello
// before Configure and without a session, an empty message.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "coredem/protocol/fields.h"
#include "coredem/protocol/multipart_file.h"
#include "coredem/protocol/protocol.h"
#include "server_thread.h"

namespace proto = coredem::protocol;
namespace v1 = coredem::v1;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kGolden = COREDEM_GOLDEN_DIR;

/// The golden message `name` of `version` with the session id replaced.
proto::Message golden(const std::string& version, const std::string& name,
                      const std::string& session) {
  proto::Status s;
  auto m =
      proto::Message::decode(proto::readMultipartFile(kGolden / version / (name + ".cdmf")), &s);
  EXPECT_TRUE(s.ok()) << version << "/" << name << ": " << s.toString();
  m.setSessionId(session);
  return m;
}

std::string codeOf(const proto::Message& reply) {
  if (reply.type() == v1::MESSAGE_TYPE_ERROR) {
    return proto::errorCodeName(reply.envelope().error().code()) + ": " +
           reply.envelope().error().message();
  }
  if (reply.type() == v1::MESSAGE_TYPE_REJECT) {
    return "Reject " + proto::errorCodeName(reply.envelope().reject().code()) + ": " +
           reply.envelope().reject().reason();
  }
  return proto::messageTypeName(reply.type());
}

/// The golden GasFields with physical values in its arrays (same names, shapes, step, dt).
proto::Message physicalGasFields(const proto::Message& g) {
  proto::Message m(g.envelope());
  const auto cells = g.envelope().gas_fields().cell_count();
  const auto species = g.envelope().gas_fields().species_count();
  for (const auto& spec : proto::fields::gasFields()) {
    const auto shape = proto::fields::shapeOf(spec.extent, cells, species);
    std::size_t n = 1;
    for (auto d : shape) {
      n *= d;
    }
    double value = 0.0;
    if (spec.name == proto::fields::kGasTemperature) {
      value = 300.0;
    } else if (spec.name == proto::fields::kGasDensity) {
      value = 1.2;
    } else if (spec.name == proto::fields::kGasViscosity) {
      value = 1.8e-5;
    } else if (spec.name == proto::fields::kGasConductivity) {
      value = 0.026;
    } else if (spec.name == proto::fields::kGasHeatCapacity) {
      value = 1005.0;
    } else if (spec.name == proto::fields::kGasMassFractions) {
      value = 1.0 / static_cast<double>(species);
    }
    std::vector<double> v(n, value);
    m.addArray<double>(spec.name, v, shape);
  }
  return m;
}

/// Runs `body` in a fresh temporary working folder (the golden CheckpointRequest names the
/// relative folder checkpoints/3, written by the in-process server).
struct TempCwd {
  fs::path old = fs::current_path();
  fs::path dir;
  explicit TempCwd(const std::string& name) {
    dir = fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::current_path(dir);
  }
  ~TempCwd() {
    fs::current_path(old);
    fs::remove_all(dir);
  }
};

} // namespace

class GoldenReplay : public ::testing::TestWithParam<std::string> {};

TEST_P(GoldenReplay, EveryGoldenMessageIsAcceptedInSessionOrder) {
  const std::string version = GetParam();
  TempCwd cwd("coredem-golden-replay-" + version);
  ServerThread srv;
  for (const bool fromStepTwo : {false, true}) {
    SCOPED_TRACE(fromStepTwo ? "session configured at start_step 2" : "golden Configure as is");
    proto::Client o;
    o.connect(srv.endpoint());
    auto welcome = o.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "golden replay"), 10s);
    ASSERT_EQ(welcome.type(), v1::MESSAGE_TYPE_WELCOME) << codeOf(welcome);
    const std::string session = welcome.envelope().welcome().session_id();

    // Configure (sequence 2). The golden StepGrant and GasFields are of step 3, the first step
    // after a Configure with start_step 2: the second session moves the golden start_step
    // (3) to 2 so that they are the session's next step (docs/protocol.md §7).
    auto configure = golden(version, "configure", session);
    if (fromStepTwo) {
      configure.envelope().mutable_configure()->set_start_step(2);
    }
    auto configured = o.request(std::move(configure), 30s);
    if (version == "v1.1") {
      // The v1.1 golden Configure carries every v1.1 field, but its chemistry switches are not
      // a consistent model: CLG oxygen-carrier reduction and the water-gas shift need gas
      // species (CO, H2O, ...) that its species list (O2, N2) lacks. D refuses it naming
      // that, changing nothing; the same Configure with those two switches off is accepted.
      ASSERT_EQ(configured.type(), v1::MESSAGE_TYPE_ERROR) << codeOf(configured);
      EXPECT_EQ(configured.envelope().error().code(), v1::ERROR_CODE_INVALID_CONFIGURATION);
      EXPECT_NE(configured.envelope().error().message().find("needs gas species CO"),
                std::string::npos)
          << codeOf(configured);
      auto consistent = golden(version, "configure", session);
      auto* clg = consistent.envelope().mutable_configure()->mutable_chemistry()->mutable_clg();
      clg->set_oc_reduction(false);
      clg->set_wgs(false);
      if (fromStepTwo) {
        consistent.envelope().mutable_configure()->set_start_step(2);
      }
      consistent.setSequence(3);
      configured = o.request(std::move(consistent), 30s);
    }
    ASSERT_EQ(configured.type(), v1::MESSAGE_TYPE_CONFIGURED) << codeOf(configured);
    EXPECT_EQ(configured.envelope().configured().cell_count(), 2u);

    proto::Client c; // the CFD participant: the golden Hello (role CFD, sequence 1)
    c.connect(srv.endpoint());
    auto cw = c.request(golden(version, "hello", session), 10s);
    ASSERT_EQ(cw.type(), v1::MESSAGE_TYPE_WELCOME) << codeOf(cw);

    if (fromStepTwo) {
      o.send(golden(version, "step_grant", session)); // step 3, sequence 4
      // The golden GasFields (step 3, sequence 3): structure accepted; its values are test
      // patterns (0.25 (f + 1) + 0.125 i: T_g below 1 K) that the physical ranges refuse,
      // naming them.
      const auto g = golden(version, "gas_fields", session);
      auto refused = c.request(golden(version, "gas_fields", session), 10s);
      ASSERT_EQ(refused.type(), v1::MESSAGE_TYPE_ERROR) << codeOf(refused);
      EXPECT_EQ(refused.envelope().error().code(), v1::ERROR_CODE_INVALID_CONFIGURATION)
          << codeOf(refused);
      EXPECT_NE(refused.envelope().error().message().find("range"), std::string::npos)
          << codeOf(refused);
      // The same message with physical values: the step runs.
      auto gas = physicalGasFields(g);
      gas.setSequence(4);
      auto sources = c.request(std::move(gas), 60s);
      ASSERT_EQ(sources.type(), v1::MESSAGE_TYPE_SOURCES) << codeOf(sources);
      EXPECT_EQ(sources.envelope().step(), 3);
      auto done = o.receive(60s);
      ASSERT_TRUE(done.has_value());
      EXPECT_EQ(done->type(), v1::MESSAGE_TYPE_STEP_DONE) << codeOf(*done);
    }

    // Messages only D or O send (sequences renumbered after the CFD's): refused, nothing
    // changes.
    std::uint64_t seq = 10;
    for (const char* name : {"welcome", "configured", "sources", "step_done", "checkpoint_done",
                             "reject", "error", "ack"}) {
      auto m = golden(version, name, session);
      m.setSequence(seq++);
      auto reply = c.request(std::move(m), 10s);
      EXPECT_EQ(reply.type(), v1::MESSAGE_TYPE_ERROR) << name << ": " << codeOf(reply);
      EXPECT_EQ(reply.envelope().error().code(), v1::ERROR_CODE_UNEXPECTED_MESSAGE)
          << name << ": " << codeOf(reply);
    }

    auto cp = o.request(golden(version, "checkpoint_request", session), 30s); // sequence 5
    ASSERT_EQ(cp.type(), v1::MESSAGE_TYPE_CHECKPOINT_DONE) << codeOf(cp);
    EXPECT_EQ(cp.envelope().checkpoint_done().directory(), "checkpoints/3");
    EXPECT_TRUE(fs::exists(cwd.dir / "checkpoints" / "3"));
    fs::remove_all(cwd.dir / "checkpoints");
    auto hb = o.request(golden(version, "heartbeat", session), 10s); // sequence 6
    EXPECT_EQ(hb.type(), v1::MESSAGE_TYPE_HEARTBEAT) << codeOf(hb);
    auto ack = o.request(golden(version, "shutdown", session), 10s); // sequence 7
    EXPECT_EQ(ack.type(), v1::MESSAGE_TYPE_ACK) << codeOf(ack);
  }
}

INSTANTIATE_TEST_SUITE_P(Versions, GoldenReplay, ::testing::Values("v1.0", "v1.1"),
                         [](const auto& info) {
                           return info.param == "v1.0" ? std::string("v1_0") : "v1_1";
                         });

// docs/protocol.md §4–5 and docs/client.md against coredem-dem, point by point.
TEST(DocsAgree, HelloOrderAndEmptyMessages) {
  ServerThread srv;
  // A CFD Hello without any session: Reject NOT_CONFIGURED.
  proto::Client c;
  c.connect(srv.endpoint());
  auto h = proto::makeHello(v1::ROLE_CFD, "early cfd");
  h.setSessionId("0123456789abcdef");
  auto early = c.request(std::move(h), 10s);
  ASSERT_EQ(early.type(), v1::MESSAGE_TYPE_REJECT) << codeOf(early);
  EXPECT_EQ(early.envelope().reject().code(), v1::ERROR_CODE_NOT_CONFIGURED) << codeOf(early);

  proto::Client o;
  o.connect(srv.endpoint());
  auto w = o.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "orchestrator"), 10s);
  ASSERT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  const std::string session = w.envelope().welcome().session_id();

  // A second Hello from the orchestrator's own connection: Reject SESSION_BUSY, no new
  // session (the loopback test server starts a fresh one instead; docs/protocol.md §4).
  auto again = o.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "orchestrator"), 10s);
  ASSERT_EQ(again.type(), v1::MESSAGE_TYPE_REJECT) << codeOf(again);
  EXPECT_EQ(again.envelope().reject().code(), v1::ERROR_CODE_SESSION_BUSY);
  EXPECT_EQ(again.envelope().session_id(), "") << "a Reject never carries the session id";

  // A CFD Hello with the id after the orchestrator's Hello but before its Configure: Welcome
  // (the role is bound; data messages wait for Configure: NOT_CONFIGURED).
  h = proto::makeHello(v1::ROLE_CFD, "cfd");
  h.setSessionId(session);
  auto cw = c.request(std::move(h), 10s);
  ASSERT_EQ(cw.type(), v1::MESSAGE_TYPE_WELCOME) << codeOf(cw);
  EXPECT_EQ(cw.envelope().welcome().session_id(), session);
  auto gas = proto::makeGasFields(1, 0.0, 1e-4, 1, 1);
  gas.setSessionId(session);
  auto notConfigured = c.request(std::move(gas), 10s);
  ASSERT_EQ(notConfigured.type(), v1::MESSAGE_TYPE_ERROR) << codeOf(notConfigured);
  EXPECT_EQ(notConfigured.envelope().error().code(), v1::ERROR_CODE_NOT_CONFIGURED);

  // An empty message (one frame of zero bytes, all ZeroMQ can carry of "nothing"): it parses
  // as an Envelope with every field unset, so its type is missing: UNKNOWN_TYPE, sequence 0.
  proto::Client raw;
  raw.connect(srv.endpoint());
  raw.sendFrames(proto::Frames{std::string()});
  auto empty = raw.receive(10s);
  ASSERT_TRUE(empty.has_value());
  ASSERT_EQ(empty->type(), v1::MESSAGE_TYPE_ERROR) << codeOf(*empty);
  EXPECT_EQ(empty->envelope().error().code(), v1::ERROR_CODE_UNKNOWN_TYPE) << codeOf(*empty);
  EXPECT_EQ(empty->envelope().error().offending_sequence(), 0u);
  // Undecodable bytes: MALFORMED_ENVELOPE.
  raw.sendFrames(proto::Frames{std::string("\xff\xfe garbage", 10)});
  auto garbage = raw.receive(10s);
  ASSERT_TRUE(garbage.has_value());
  EXPECT_EQ(garbage->envelope().error().code(), v1::ERROR_CODE_MALFORMED_ENVELOPE)
      << codeOf(*garbage);
  // The session is untouched by all of that.
  auto hb = proto::makeHeartbeat("o");
  hb.setSessionId(session);
  EXPECT_EQ(o.request(std::move(hb), 10s).type(), v1::MESSAGE_TYPE_HEARTBEAT);
}
