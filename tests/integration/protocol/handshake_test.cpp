// Handshake over tcp loopback: version negotiation (higher minor accepted with the lower
// minor used; other major rejected naming both versions), one session per server.
#include "loopback_fixture.h"

using namespace coredem::protocol;
using namespace coredem::protocol::test;
namespace v1 = coredem::v1;

TEST(Handshake, ClientWithHigherMinorIsAcceptedWithTheServersMinor) {
  LoopbackThread server(Version{1, 0});
  Client client;
  client.connect(server.endpoint());
  Message reply = client.request(makeHello(v1::ROLE_CFD, "newer", 1, 4), kTimeout);
  ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_WELCOME);
  EXPECT_EQ(reply.envelope().welcome().protocol_major(), 1u);
  EXPECT_EQ(reply.envelope().welcome().protocol_minor(), 0u);
  EXPECT_FALSE(reply.envelope().welcome().session_id().empty());
  EXPECT_EQ(reply.envelope().session_id(), reply.envelope().welcome().session_id());
}

TEST(Handshake, ServerWithHigherMinorUsesTheClientsMinor) {
  LoopbackThread server(Version{1, 3});
  Client client;
  client.connect(server.endpoint());
  Message reply = client.request(makeHello(v1::ROLE_CFD, "older", 1, 1), kTimeout);
  ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_WELCOME);
  EXPECT_EQ(reply.envelope().welcome().protocol_minor(), 1u);
}

TEST(Handshake, OtherMajorIsRejectedNamingBothVersions) {
  LoopbackThread server(Version{1, 0});
  Client client;
  client.connect(server.endpoint());
  Message reply = client.request(makeHello(v1::ROLE_CFD, "next-gen", 2, 1), kTimeout);
  ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_REJECT);
  const auto& r = reply.envelope().reject();
  EXPECT_EQ(r.code(), v1::ERROR_CODE_VERSION);
  EXPECT_NE(r.reason().find("1.0"), std::string::npos) << r.reason();
  EXPECT_NE(r.reason().find("2.1"), std::string::npos) << r.reason();
  EXPECT_EQ(r.server_protocol_major(), 1u);
  EXPECT_EQ(r.server_protocol_minor(), 0u);
  try {
    expectType(reply, v1::MESSAGE_TYPE_WELCOME);
    FAIL() << "a Reject must throw PeerError";
  } catch (const PeerError& e) {
    EXPECT_EQ(e.code(), v1::ERROR_CODE_VERSION);
  }
  // The server is still free: a compatible client gets a session.
  Message ok = client.request(makeHello(v1::ROLE_CFD, "current"), kTimeout);
  EXPECT_EQ(ok.type(), v1::MESSAGE_TYPE_WELCOME);
}

TEST(Handshake, SecondSessionIsRejectedAsBusy) {
  LoopbackThread server;
  Session first(server.endpoint());
  Client second;
  second.connect(server.endpoint());
  Message reply = second.request(makeHello(v1::ROLE_CFD, "intruder"), kTimeout);
  ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_REJECT);
  EXPECT_EQ(reply.envelope().reject().code(), v1::ERROR_CODE_SESSION_BUSY);
  // The session id is sent to the session's peer only (docs/security.md).
  EXPECT_EQ(reply.envelope().reject().reason().find(first.id), std::string::npos);
  EXPECT_EQ(reply.envelope().session_id(), "");
  // The second client cannot send data either; the first one goes on.
  Message data = gasFields(0, first.id);
  Message err = second.request(std::move(data), kTimeout);
  ASSERT_EQ(err.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(err.envelope().error().code(), v1::ERROR_CODE_NOT_CONFIGURED);
  first.exchangeValidStep();
}

TEST(Handshake, DataBeforeConfigureIsRefused) {
  LoopbackThread server;
  Client client;
  client.connect(server.endpoint());
  Message w = client.request(makeHello(v1::ROLE_CFD, "eager"), kTimeout);
  ASSERT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);
  const std::string id = w.envelope().welcome().session_id();
  Message err = client.request(gasFields(0, id), kTimeout);
  ASSERT_EQ(err.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(err.envelope().error().code(), v1::ERROR_CODE_NOT_CONFIGURED);

  v1::Configure bad = smallConfigure();
  bad.mutable_sub_cycling()->set_n_sub(3); // 3 * 2.5e-4 != 1e-3
  Message cerr = client.request(std::move(makeConfigure(bad).setSessionId(id)), kTimeout);
  ASSERT_EQ(cerr.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(cerr.envelope().error().code(), v1::ERROR_CODE_INVALID_CONFIGURATION);

  Message ok =
      client.request(std::move(makeConfigure(smallConfigure()).setSessionId(id)), kTimeout);
  ASSERT_EQ(ok.type(), v1::MESSAGE_TYPE_CONFIGURED);
  EXPECT_EQ(ok.envelope().configured().cell_count(), kCells);
  EXPECT_EQ(ok.envelope().configured().species_count(), kSpecies);
  EXPECT_EQ(ok.envelope().configured().n_sub(), 4u);
}

TEST(Handshake, ControlMessagesAndShutdown) {
  LoopbackThread server;
  Session s(server.endpoint());
  Message done = s.client.request(
      std::move(makeStepGrant(0, 0, 1e-3, 4, 2.5e-4).setSessionId(s.id)), kTimeout);
  ASSERT_EQ(done.type(), v1::MESSAGE_TYPE_STEP_DONE);
  EXPECT_EQ(done.envelope().step(), 0);
  EXPECT_DOUBLE_EQ(done.envelope().time(), 1e-3);
  Message cp =
      s.client.request(std::move(makeCheckpointRequest(0, "cp/0").setSessionId(s.id)), kTimeout);
  ASSERT_EQ(cp.type(), v1::MESSAGE_TYPE_CHECKPOINT_DONE);
  EXPECT_EQ(cp.envelope().checkpoint_done().directory(), "cp/0");
  Message hb = s.client.request(std::move(makeHeartbeat().setSessionId(s.id)), kTimeout);
  ASSERT_EQ(hb.type(), v1::MESSAGE_TYPE_HEARTBEAT);
  Message ack = s.client.request(std::move(makeShutdown("done").setSessionId(s.id)), kTimeout);
  ASSERT_EQ(ack.type(), v1::MESSAGE_TYPE_ACK);
  // After Shutdown the server stops serving: a further request times out with a clear error.
  try {
    (void)s.client.request(std::move(makeHeartbeat().setSessionId(s.id)),
                           std::chrono::milliseconds(300));
    FAIL() << "expected a timeout";
  } catch (const TimeoutError& e) {
    EXPECT_EQ(e.endpoint(), server.endpoint());
  }
}
