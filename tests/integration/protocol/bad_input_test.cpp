// Bad input over real tcp loopback sockets (docs/protocol.md): every malformed or inconsistent
// message gets an Error reply with its specific code, and the server then serves the next
// valid request correctly.
#include <limits>

#include "loopback_fixture.h"

using namespace coredem::protocol;
using namespace coredem::protocol::test;
namespace v1 = coredem::v1;

namespace {

class BadInput : public ::testing::Test {
protected:
  LoopbackThread server;
  Session session{server.endpoint()};

  /// Sends raw frames and returns the reply (an Error is expected).
  Message sendRaw(const Frames& frames) {
    session.client.sendFrames(frames);
    std::optional<Message> reply = session.client.receive(kTimeout);
    EXPECT_TRUE(reply.has_value()) << "no reply to a bad message";
    return reply ? std::move(*reply) : Message();
  }

  /// Frames of a valid GasFields for the expected step with a fresh sequence number
  /// (the client's counter is advanced past it).
  Frames validFrames() {
    Message m = gasFields(session.nextStep, session.id);
    std::uint64_t seq = session.client.nextSequence();
    m.setSequence(seq);
    Frames frames = m.encode();
    // Burn the number so that the client's next request uses a higher one.
    burned = seq;
    return frames;
  }

  void expectError(const Message& reply, v1::ErrorCode code, const std::string& needle = "") {
    ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_ERROR) << messageTypeName(reply.type());
    EXPECT_EQ(reply.envelope().error().code(), code)
        << errorCodeName(reply.envelope().error().code()) << ": "
        << reply.envelope().error().message();
    EXPECT_FALSE(reply.envelope().error().message().empty());
    if (!needle.empty()) {
      EXPECT_NE(reply.envelope().error().message().find(needle), std::string::npos)
          << reply.envelope().error().message();
    }
  }

  /// After a bad message: the next valid request is served correctly.
  void expectStillServing() {
    if (burned >= session.client.nextSequence()) {
      // Client::send keeps an explicit sequence and continues after it.
      Message ping = makeHeartbeat();
      ping.setSessionId(session.id).setSequence(burned + 1);
      Message pong = session.client.request(std::move(ping), kTimeout);
      ASSERT_EQ(pong.type(), v1::MESSAGE_TYPE_HEARTBEAT);
    }
    session.exchangeValidStep();
  }

  std::uint64_t burned = 0;
};

v1::Envelope envelopeOf(const Frames& frames) {
  v1::Envelope env;
  EXPECT_TRUE(env.ParseFromString(frames[0]));
  return env;
}

} // namespace

TEST_F(BadInput, ValidExchangeWorksRepeatedly) {
  for (int i = 0; i < 3; ++i) {
    session.exchangeValidStep();
  }
  EXPECT_EQ(server.service().errorsSent(), 0u);
}

TEST_F(BadInput, TruncatedArrayFrame) {
  Frames f = validFrames();
  f[3].resize(f[3].size() / 2);
  expectError(sendRaw(f), v1::ERROR_CODE_BYTE_LENGTH, "'T_g'");
  expectStillServing();
}

TEST_F(BadInput, TruncatedEnvelopeFrame) {
  Frames f = validFrames();
  f[0].resize(f[0].size() / 2);
  expectError(sendRaw(f), v1::ERROR_CODE_MALFORMED_ENVELOPE);
  expectStillServing();
}

TEST_F(BadInput, WrongFrameCount) {
  Frames f = validFrames();
  f.pop_back();
  expectError(sendRaw(f), v1::ERROR_CODE_FRAME_COUNT, "8 arrays but 7");
  expectStillServing();

  Frames g = validFrames();
  g.push_back(std::string(16, '\0'));
  expectError(sendRaw(g), v1::ERROR_CODE_FRAME_COUNT, "8 arrays but 9");
  expectStillServing();
}

TEST_F(BadInput, DtypeContradictingTheEnvelope) {
  // Descriptor says float32 but the frame holds float64 data: sizes disagree.
  Frames f = validFrames();
  v1::Envelope env = envelopeOf(f);
  env.mutable_arrays(2)->set_dtype(v1::DTYPE_FLOAT32);
  f[0] = env.SerializeAsString();
  expectError(sendRaw(f), v1::ERROR_CODE_BYTE_LENGTH, "'T_g'");
  expectStillServing();

  // Consistent float32 array where float64 is required.
  Message m = makeGasFields(session.nextStep, 0, 1e-3, kCells, kSpecies);
  m.setSessionId(session.id);
  Message full = gasFields(session.nextStep, session.id);
  for (std::size_t i = 0; i < full.arrayCount(); ++i) {
    ArrayView v = full.array(i);
    if (v.name() == "rho_g") {
      std::vector<float> rho(kCells, 1.2f);
      m.addArray<float>("rho_g", rho, {kCells});
    } else {
      m.addArrayBytes(v.name(), v.dtype(), v.shape(), v.bytes);
    }
  }
  expectError(session.client.request(std::move(m), kTimeout), v1::ERROR_CODE_DTYPE, "'rho_g'");
  expectStillServing();

  // A dtype this version does not know.
  Frames g = validFrames();
  env = envelopeOf(g);
  env.mutable_arrays(0)->set_dtype(static_cast<v1::DType>(77));
  g[0] = env.SerializeAsString();
  expectError(sendRaw(g), v1::ERROR_CODE_DTYPE, "'u_g'");
  expectStillServing();
}

TEST_F(BadInput, ShapeContradictingTheConfiguration) {
  // [N*3] instead of [N,3]: byte length is consistent, the shape is not.
  Frames f = validFrames();
  v1::Envelope env = envelopeOf(f);
  env.mutable_arrays(0)->clear_shape();
  env.mutable_arrays(0)->add_shape(kCells * 3);
  f[0] = env.SerializeAsString();
  expectError(sendRaw(f), v1::ERROR_CODE_SHAPE, "'u_g'");
  expectStillServing();

  // A grid of the wrong size (23 cells instead of 24) everywhere.
  Message m = makeGasFields(session.nextStep, 0, 1e-3, kCells - 1, kSpecies);
  m.setSessionId(session.id);
  expectError(session.client.request(std::move(m), kTimeout), v1::ERROR_CODE_SHAPE, "24 cells");
  expectStillServing();

  // Descriptor shape that promises more bytes than the frame holds.
  Frames g = validFrames();
  env = envelopeOf(g);
  env.mutable_arrays(3)->set_shape(0, kCells + 1);
  g[0] = env.SerializeAsString();
  expectError(sendRaw(g), v1::ERROR_CODE_BYTE_LENGTH, "'rho_g'");
  expectStillServing();
}

TEST_F(BadInput, NaNAndInfInAField) {
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()}) {
    Message full = gasFields(session.nextStep, session.id);
    Message m(full.envelope());
    for (std::size_t i = 0; i < full.arrayCount(); ++i) {
      ArrayView v = full.array(i);
      if (v.name() == "mu_g") {
        std::vector<double> mu(kCells, 1.8e-5);
        mu[17] = bad;
        m.addArray<double>("mu_g", mu, {kCells});
      } else {
        m.addArrayBytes(v.name(), v.dtype(), v.shape(), v.bytes);
      }
    }
    expectError(session.client.request(std::move(m), kTimeout), v1::ERROR_CODE_NON_FINITE,
                "'mu_g' contains");
    expectStillServing();
  }
  // The message names the first bad index.
  Message full = gasFields(session.nextStep, session.id);
  Message m(full.envelope());
  for (std::size_t i = 0; i < full.arrayCount(); ++i) {
    ArrayView v = full.array(i);
    if (v.name() == "Y_g") {
      std::vector<double> y(kCells * kSpecies, 0.5);
      y[2 * 7 + 1] = std::numeric_limits<double>::quiet_NaN();
      y[2 * 9] = std::numeric_limits<double>::quiet_NaN();
      m.addArray<double>("Y_g", y, {kCells, kSpecies});
    } else {
      m.addArrayBytes(v.name(), v.dtype(), v.shape(), v.bytes);
    }
  }
  expectError(session.client.request(std::move(m), kTimeout), v1::ERROR_CODE_NON_FINITE,
              "NaN at flat index 15 (row 7, column 1)");
  expectStillServing();
}

TEST_F(BadInput, UnknownMessageType) {
  Frames f = validFrames();
  v1::Envelope env = envelopeOf(f);
  env.set_type(static_cast<v1::MessageType>(99));
  f[0] = env.SerializeAsString();
  expectError(sendRaw(f), v1::ERROR_CODE_UNKNOWN_TYPE, "99");
  expectStillServing();

  // Type and body disagree.
  Frames g = validFrames();
  env = envelopeOf(g);
  env.set_type(v1::MESSAGE_TYPE_STEP_GRANT);
  g[0] = env.SerializeAsString();
  expectError(sendRaw(g), v1::ERROR_CODE_BODY_MISMATCH);
  expectStillServing();

  // A valid message the loopback server does not accept (Sources travel the other way).
  Message s = makeSources(session.nextStep, 0, 1e-3, kCells, kSpecies, 1);
  s.setSessionId(session.id);
  for (const auto& spec : fields::sourceFields()) {
    std::vector<double> v(kCells * fields::componentsOf(spec.extent, kSpecies), 0.0);
    s.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, kCells, kSpecies));
  }
  expectError(session.client.request(std::move(s), kTimeout), v1::ERROR_CODE_UNEXPECTED_MESSAGE);
  expectStillServing();
}

TEST_F(BadInput, OutOfOrderStepAndSequence) {
  session.exchangeValidStep(); // step 0 done, step 1 expected
  Message ahead = gasFields(session.nextStep + 5, session.id);
  expectError(session.client.request(std::move(ahead), kTimeout), v1::ERROR_CODE_OUT_OF_ORDER,
              "step 1 expected");
  expectStillServing();

  Message behind = gasFields(session.nextStep - 1, session.id);
  expectError(session.client.request(std::move(behind), kTimeout), v1::ERROR_CODE_OUT_OF_ORDER);
  expectStillServing();

  // A replayed (old) sequence number.
  Message replay = gasFields(session.nextStep, session.id);
  replay.setSequence(1);
  Frames f = replay.encode();
  expectError(sendRaw(f), v1::ERROR_CODE_OUT_OF_ORDER, "not greater");
  expectStillServing();
}

TEST_F(BadInput, WrongSessionId) {
  Message m = gasFields(session.nextStep, "someone-else");
  expectError(session.client.request(std::move(m), kTimeout), v1::ERROR_CODE_UNKNOWN_SESSION);
  expectStillServing();
}

TEST_F(BadInput, WrongMajorVersionFromTheSessionPeer) {
  Message hello = makeHello(v1::ROLE_CFD, "future 9", 2, 0);
  Message reply = session.client.request(std::move(hello), kTimeout);
  ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_REJECT);
  EXPECT_EQ(reply.envelope().reject().code(), v1::ERROR_CODE_VERSION);
  EXPECT_NE(reply.envelope().reject().reason().find(kProtocolVersion.toString()),
            std::string::npos);
  EXPECT_NE(reply.envelope().reject().reason().find("2.0"), std::string::npos);
  expectStillServing(); // the existing session is untouched
}

TEST_F(BadInput, GarbageBytes) {
  const std::string junk("\xff\xfe\xfd garbage \x00\x01\x02\x8f\xff", 18);
  burned = session.client.nextSequence();
  Message reply = sendRaw(Frames{junk});
  expectError(reply, v1::ERROR_CODE_MALFORMED_ENVELOPE, "not a valid coredem.v1.Envelope");
  EXPECT_EQ(reply.envelope().error().offending_sequence(), 0u);
  expectStillServing();

  reply = sendRaw(Frames{junk, junk, std::string(1000, '\xaa')});
  expectError(reply, v1::ERROR_CODE_MALFORMED_ENVELOPE);
  expectStillServing();

  // An empty envelope parses (all defaults) but has no type.
  reply = sendRaw(Frames{std::string()});
  expectError(reply, v1::ERROR_CODE_UNKNOWN_TYPE);
  expectStillServing();
  EXPECT_GE(server.service().errorsSent(), 3u);
}
