// Transport: ephemeral tcp ports, ipc, timeouts naming endpoint and awaited reply, refusal of
// non-loopback binds without CURVE, CURVE on loopback, receiving into caller buffers.
#include <filesystem>
#include <map>

#include <unistd.h>

#include "loopback_fixture.h"

using namespace coredem::protocol;
using namespace coredem::protocol::test;
namespace v1 = coredem::v1;

TEST(Transport, LoopbackDetection) {
  EXPECT_TRUE(isLoopbackEndpoint("tcp://127.0.0.1:5555"));
  EXPECT_TRUE(isLoopbackEndpoint("tcp://127.0.0.1:*"));
  EXPECT_TRUE(isLoopbackEndpoint("tcp://127.1.2.3:80"));
  EXPECT_TRUE(isLoopbackEndpoint("tcp://localhost:5555"));
  EXPECT_TRUE(isLoopbackEndpoint("tcp://[::1]:5555"));
  EXPECT_TRUE(isLoopbackEndpoint("ipc:///tmp/x.sock"));
  EXPECT_TRUE(isLoopbackEndpoint("inproc://x"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://0.0.0.0:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://*:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://192.168.1.4:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://1270.0.0.1:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://eth0:5555"));
  EXPECT_FALSE(isLoopbackEndpoint("tcp://[::]:5555"));
}

TEST(Transport, NonLoopbackBindWithoutCurveIsRefused) {
  Server server;
  for (const char* ep : {"tcp://0.0.0.0:*", "tcp://*:*", "tcp://10.0.0.1:*"}) {
    try {
      server.bind(ep);
      FAIL() << ep << " must be refused";
    } catch (const ProtocolError& e) {
      EXPECT_EQ(e.code(), v1::ERROR_CODE_SECURITY);
      EXPECT_NE(std::string(e.what()).find("CURVE"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(ep), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(server.endpoint(), "");
}

TEST(Transport, BindErrorsBecomeTransportErrors) {
  Server a;
  std::string ep = a.bind("tcp://127.0.0.1:*");
  Server b;
  EXPECT_THROW(b.bind(ep), TransportError); // port in use
  EXPECT_THROW(b.bind("tcp://127.0.0.1:notaport"), TransportError);
  Client c;
  EXPECT_THROW(c.connect("nonsense://x"), TransportError);
}

TEST(Transport, EphemeralPortIsReportedAndUsable) {
  LoopbackThread server;
  EXPECT_EQ(server.endpoint().rfind("tcp://127.0.0.1:", 0), 0u);
  EXPECT_EQ(server.endpoint().find('*'), std::string::npos);
  Session s(server.endpoint());
  s.exchangeValidStep();
}

TEST(Transport, IpcEndpoint) {
  auto path = std::filesystem::temp_directory_path() /
              ("coredem-ipc-test-" + std::to_string(::getpid()) + ".sock");
  {
    LoopbackThread server(kProtocolVersion, "ipc://" + path.string());
    EXPECT_EQ(server.endpoint(), "ipc://" + path.string());
    Session s(server.endpoint());
    s.exchangeValidStep();
    s.exchangeValidStep();
  }
  std::filesystem::remove(path);
}

TEST(Transport, RequestTimeoutNamesEndpointAndAwaitedReply) {
  Server silent; // bound, never answers
  std::string ep = silent.bind("tcp://127.0.0.1:*");
  Client client;
  client.connect(ep);
  try {
    (void)client.request(makeGasFields(7, 0, 1e-3, 1, 0), std::chrono::milliseconds(200));
    FAIL() << "expected TimeoutError";
  } catch (const TimeoutError& e) {
    std::string what = e.what();
    EXPECT_EQ(e.code(), v1::ERROR_CODE_TIMEOUT);
    EXPECT_EQ(e.endpoint(), ep);
    EXPECT_NE(what.find(ep), std::string::npos) << what;
    EXPECT_NE(what.find("GAS_FIELDS"), std::string::npos) << what;
    EXPECT_NE(what.find("step 7"), std::string::npos) << what;
    EXPECT_NE(e.awaited().find("GAS_FIELDS"), std::string::npos);
  }
  // The request did reach the server (nothing is lost, only unanswered).
  auto req = silent.receive(std::chrono::milliseconds(2000));
  ASSERT_TRUE(req.has_value());
  EXPECT_EQ(req->message.type(), v1::MESSAGE_TYPE_GAS_FIELDS);
}

TEST(Transport, StaleRepliesAfterATimeoutAreDiscarded) {
  Server server;
  std::string ep = server.bind("tcp://127.0.0.1:*");
  Client client;
  client.connect(ep);
  EXPECT_THROW((void)client.request(makeHeartbeat("a"), std::chrono::milliseconds(100)),
               TimeoutError);
  auto first = server.receive(std::chrono::milliseconds(2000));
  ASSERT_TRUE(first.has_value());
  // Late reply to the first request, then the client asks again.
  server.reply(first->peer,
               std::move(makeHeartbeat("late").setSequence(first->message.envelope().sequence())));
  std::uint64_t second = client.send(makeHeartbeat("b"));
  auto req = server.receive(std::chrono::milliseconds(2000));
  ASSERT_TRUE(req.has_value());
  EXPECT_EQ(req->message.envelope().sequence(), second);
  server.reply(req->peer, std::move(makeHeartbeat("fresh").setSequence(second)));
  // request() semantics: only the matching sequence is returned.
  std::optional<Message> r1 = client.receive(std::chrono::milliseconds(2000));
  ASSERT_TRUE(r1.has_value());
  EXPECT_EQ(r1->envelope().heartbeat().state(), "late");
  std::optional<Message> r2 = client.receive(std::chrono::milliseconds(2000));
  ASSERT_TRUE(r2.has_value());
  EXPECT_EQ(r2->envelope().heartbeat().state(), "fresh");

  // And through request(): the late reply is skipped.
  std::thread responder([&] {
    auto r = server.receive(std::chrono::milliseconds(5000));
    ASSERT_TRUE(r.has_value());
    server.reply(r->peer, std::move(makeHeartbeat("stale").setSequence(1)));
    server.reply(r->peer,
                 std::move(makeHeartbeat("match").setSequence(r->message.envelope().sequence())));
  });
  Message m = client.request(makeHeartbeat("c"), kTimeout);
  responder.join();
  EXPECT_EQ(m.envelope().heartbeat().state(), "match");
}

TEST(Transport, ReceiveIntoCallerProvidedBuffers) {
  LoopbackThread server;
  Session s(server.endpoint());
  // One caller buffer per Sources field (stand-ins for pinned host buffers).
  std::map<std::string, std::vector<double>> buffers;
  ReceiveOptions options;
  options.buffers = [&](const v1::ArrayDescriptor& d) -> std::span<std::byte> {
    if (!fields::findField(d.name())) {
      return {}; // keep the ZeroMQ frame (zero copy)
    }
    auto& b = buffers[d.name()];
    b.assign(d.byte_length() / sizeof(double), -1.0);
    return std::as_writable_bytes(std::span<double>(b));
  };
  Message reply = s.client.request(gasFields(0, s.id), kTimeout, options);
  ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_SOURCES);
  ASSERT_EQ(buffers.size(), fields::sourceFields().size());
  EXPECT_EQ(reply.array("eps_g").bytes.data(),
            reinterpret_cast<const std::byte*>(buffers["eps_g"].data()));
  for (double v : buffers["eps_g"]) {
    ASSERT_EQ(v, 1.0);
  }
  for (double v : buffers["K_sl_Us"]) {
    ASSERT_EQ(v, 0.0);
  }
  EXPECT_EQ(buffers["R_species"].size(), kCells * kSpecies);
  EXPECT_EQ(reply.values<double>("checksum").size(), 8u);
}

TEST(Transport, BufferProviderSeesOnlyTheMatchingReply) {
  Server server;
  std::string ep = server.bind("tcp://127.0.0.1:*");
  Client client;
  client.connect(ep);
  std::thread responder([&] {
    auto r = server.receive(std::chrono::milliseconds(5000));
    ASSERT_TRUE(r.has_value());
    std::vector<double> stale{-1.0, -1.0};
    std::vector<double> fresh{4.0, 5.0};
    Message old = makeAck("stale");
    old.setSequence(r->message.envelope().sequence() + 100); // not the awaited sequence
    old.addArray<double>("x", stale, {2});
    server.reply(r->peer, std::move(old));
    Message match = makeAck("match");
    match.setSequence(r->message.envelope().sequence());
    match.addArray<double>("x", fresh, {2});
    server.reply(r->peer, std::move(match));
  });
  std::vector<double> buffer(2, 0.0);
  int calls = 0;
  ReceiveOptions options;
  options.buffers = [&](const v1::ArrayDescriptor&) -> std::span<std::byte> {
    ++calls;
    return std::as_writable_bytes(std::span<double>(buffer));
  };
  Message m = client.request(makeHeartbeat(), kTimeout, options);
  responder.join();
  EXPECT_EQ(m.envelope().ack().note(), "match");
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(buffer, (std::vector<double>{4.0, 5.0}));
  EXPECT_EQ(m.array("x").bytes.data(), reinterpret_cast<const std::byte*>(buffer.data()));
}

TEST(Transport, SmallFramesFromTheWireAreAligned) {
  // Tiny arrays travel inside ZeroMQ's receive buffer at arbitrary offsets; the Message
  // must still hand out 8-byte aligned views.
  Server server;
  std::string ep = server.bind("tcp://127.0.0.1:*");
  Client client;
  client.connect(ep);
  Message m(v1::MESSAGE_TYPE_ACK);
  m.envelope().mutable_ack();
  std::vector<std::uint8_t> one{7};
  std::vector<double> d{1.25, 2.5};
  m.addArray<std::uint8_t>("b", one, {1});
  m.addArray<double>("d", d, {2});
  m.addArray<std::uint8_t>("c", one, {1});
  m.addArray<double>("e", d, {2});
  client.send(std::move(m));
  auto req = server.receive(std::chrono::milliseconds(5000));
  ASSERT_TRUE(req.has_value());
  ASSERT_TRUE(req->status.ok()) << req->status.toString();
  for (std::size_t i = 0; i < req->message.arrayCount(); ++i) {
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(req->message.array(i).bytes.data()) % 8, 0u) << i;
  }
  EXPECT_EQ(req->message.values<double>("e")[1], 2.5);
}

TEST(Transport, CurveOnLoopback) {
  std::pair<std::string, std::string> serverKeys, clientKeys;
  try {
    serverKeys = generateCurveKeyPair();
    clientKeys = generateCurveKeyPair();
  } catch (const ProtocolError& e) {
    // Debian's libzmq5 is built with libsodium: CURVE is part of every supported build.
    FAIL() << "no CURVE in this libzmq: " << e.what();
  }
  TransportOptions so;
  so.curve.serverPublicKey = serverKeys.first;
  so.curve.serverSecretKey = serverKeys.second;
  LoopbackService service(so);
  std::string ep = service.bind("tcp://127.0.0.1:*");
  std::atomic<bool> stop{false};
  std::thread t([&] { service.serve(&stop); });

  TransportOptions co;
  co.curve.serverPublicKey = serverKeys.first;
  co.curve.clientPublicKey = clientKeys.first;
  co.curve.clientSecretKey = clientKeys.second;
  Client good(co);
  good.connect(ep);
  Message w = good.request(makeHello(v1::ROLE_CFD, "curve"), kTimeout);
  EXPECT_EQ(w.type(), v1::MESSAGE_TYPE_WELCOME);

  Client plain; // no keys: the handshake fails at the ZeroMQ level, the request times out
  plain.connect(ep);
  EXPECT_THROW(
      (void)plain.request(makeHello(v1::ROLE_CFD, "plain"), std::chrono::milliseconds(300)),
      TimeoutError);

  TransportOptions bad = co;
  bad.curve.clientSecretKey = "short";
  EXPECT_THROW(Client{bad}, ProtocolError);
  stop = true;
  t.join();
}
