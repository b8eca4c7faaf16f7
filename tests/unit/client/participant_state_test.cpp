// The client's state checks, without any peer: every call out of order throws
// StateError naming the call and the state; missing peers in the environment are Argument
// errors naming the variable. This file is compiled as C++14 (CMake CXX_STANDARD 14) to prove
// that the public header works in OpenFOAM translation units.
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "coredem/client/coredem_client.h"
#include "coredem/client/participant.h"

#if __cplusplus >= 201703L
#error "participant_state_test.cpp must be compiled as C++14"
#endif

using coredem::client::ClientError;
using coredem::client::ErrorCode;
using coredem::client::Participant;
using coredem::client::State;
using coredem::client::StateError;

namespace {

template <class F>
std::string stateErrorOf(F f) {
  try {
    f();
  } catch (const StateError& e) {
    EXPECT_EQ(e.code(), ErrorCode::State);
    return e.what();
  } catch (const std::exception& e) {
    return std::string("wrong exception: ") + e.what();
  }
  return "no exception";
}

} // namespace

TEST(ParticipantState, CallsBeforeInitializeAreRefused) {
  Participant p;
  EXPECT_EQ(p.state(), State::Created);
  EXPECT_FALSE(p.isRunning());
  std::vector<double> v(3, 0.0);
  const auto e1 = stateErrorOf([&] { p.exchange(1, 0.1, {{"T_g", v}}); });
  EXPECT_NE(e1.find("exchange() called in state Created"), std::string::npos) << e1;
  const auto e2 = stateErrorOf([&] { p.advance(0.5); });
  EXPECT_NE(e2.find("advance() called in state Created"), std::string::npos) << e2;
  EXPECT_NE(stateErrorOf([&] { p.step(); }).find("step() called in state Created"),
            std::string::npos);
  EXPECT_NE(stateErrorOf([&] { p.dt(); }).find("dt()"), std::string::npos);
  EXPECT_NE(stateErrorOf([&] { p.grid(); }).find("grid()"), std::string::npos);
  EXPECT_NE(stateErrorOf([&] { p.sources(); }).find("sources()"), std::string::npos);
  EXPECT_NE(stateErrorOf([&] { p.requiresCheckpoint(); }).find("checkpointDir()"),
            std::string::npos);
  EXPECT_NE(stateErrorOf([&] { p.requiresOutput(); }).find("requiresOutput()"), std::string::npos);
}

TEST(ParticipantState, MissingEnvironmentNamesTheVariable) {
  ::unsetenv("COREDEM_CONTROL_ENDPOINT");
  ::unsetenv("COREDEM_DEM_ENDPOINT");
  ::unsetenv("COREDEM_SESSION");
  Participant p;
  try {
    p.initialize();
    FAIL() << "initialize() without endpoints must fail";
  } catch (const ClientError& e) {
    EXPECT_EQ(e.code(), ErrorCode::Argument);
    EXPECT_NE(std::string(e.what()).find("COREDEM_CONTROL_ENDPOINT"), std::string::npos)
        << e.what();
  }
  coredem::client::Options o;
  o.controlEndpoint = "tcp://127.0.0.1:1";
  Participant q(o);
  try {
    q.initialize();
    FAIL() << "initialize() without a DEM endpoint must fail";
  } catch (const ClientError& e) {
    EXPECT_NE(std::string(e.what()).find("COREDEM_DEM_ENDPOINT"), std::string::npos) << e.what();
  }
}

TEST(ParticipantState, FinalizeIsAlwaysAllowedAndFinal) {
  Participant p;
  p.finalize();
  EXPECT_EQ(p.state(), State::Finalized);
  p.finalize(); // no-op
  const auto e = stateErrorOf([&] { p.initialize(); });
  EXPECT_NE(e.find("initialize() called in state Finalized"), std::string::npos) << e;
}

TEST(ParticipantState, CApiReportsStateErrorsWithAMessage) {
  coredem_client* c = nullptr;
  ASSERT_EQ(coredem_client_create("tcp://127.0.0.1:1", "tcp://127.0.0.1:2", "s", &c), COREDEM_OK);
  coredem_grant g;
  EXPECT_EQ(coredem_client_grant(c, &g), COREDEM_ERROR_STATE);
  EXPECT_NE(std::string(coredem_client_last_error(c)).find("state Created"), std::string::npos);
  int output = -1;
  EXPECT_EQ(coredem_client_requires_output(c, &output), COREDEM_ERROR_STATE);
  EXPECT_EQ(coredem_client_requires_output(c, nullptr), COREDEM_ERROR_ARGUMENT);
  const double* v = nullptr;
  size_t n = 0;
  EXPECT_EQ(coredem_client_source(c, "eps_g", &v, &n), COREDEM_ERROR_STATE);
  EXPECT_EQ(coredem_client_set_timeout(c, -1.0), COREDEM_ERROR_ARGUMENT);
  EXPECT_EQ(coredem_client_is_running(c), 0);
  EXPECT_EQ(coredem_client_finalize(c), COREDEM_OK);
  EXPECT_EQ(coredem_client_state(c), COREDEM_STATE_FINALIZED);
  EXPECT_EQ(coredem_client_exchange(c, 1, 0.1, 0, nullptr, nullptr, nullptr), COREDEM_ERROR_STATE);
  coredem_client_destroy(c);
  EXPECT_EQ(coredem_client_initialize(nullptr), COREDEM_ERROR_ARGUMENT);
}

// The C API of decomposed runs: the rank is set before initialize/follow and checked; the
// partial exchange and the control state follow the participant's states; rank 0 of a decomposed
// run cannot follow and a rank > 0 cannot initialize.
TEST(ParticipantState, CApiRanksAreCheckedAndFollowTheStates) {
  coredem_client* c = nullptr;
  ASSERT_EQ(coredem_client_create("tcp://127.0.0.1:1", "tcp://127.0.0.1:2", "s", &c), COREDEM_OK);
  EXPECT_EQ(coredem_client_set_rank(c, 2, 2), COREDEM_ERROR_ARGUMENT);
  EXPECT_NE(std::string(coredem_client_last_error(c)).find("rank 2 of 2"), std::string::npos);
  EXPECT_EQ(coredem_client_set_rank(c, 1, 2), COREDEM_OK);
  EXPECT_EQ(coredem_client_initialize(c), COREDEM_ERROR_ARGUMENT); // rank 1 follows rank 0
  EXPECT_NE(std::string(coredem_client_last_error(c)).find("follows rank 0"), std::string::npos);
  const char* state = nullptr;
  std::size_t size = 0;
  EXPECT_EQ(coredem_client_control_state(c, &state, &size), COREDEM_ERROR_ARGUMENT);
  EXPECT_EQ(coredem_client_follow(c, "garbage\n", 8), COREDEM_ERROR_ARGUMENT);
  EXPECT_NE(std::string(coredem_client_last_error(c)).find("control state"), std::string::npos);
  const std::int64_t cells[] = {0};
  const double volume[] = {1.0};
  EXPECT_EQ(
      coredem_client_exchange_partial(c, 1, 0.1, 1, cells, volume, 0, nullptr, nullptr, nullptr),
      COREDEM_ERROR_STATE);
  EXPECT_EQ(
      coredem_client_exchange_partial(c, 1, 0.1, 1, nullptr, volume, 0, nullptr, nullptr, nullptr),
      COREDEM_ERROR_ARGUMENT);
  coredem_client_destroy(c);
}

TEST(ParticipantState, AnAbsentOrchestratorIsATimeoutNamingTheEndpoint) {
  coredem::client::Options o;
  o.controlEndpoint = "tcp://127.0.0.1:9"; // nothing listens there (discard port, no server)
  o.demEndpoint = "tcp://127.0.0.1:9";
  o.sessionId = "s";
  o.timeoutSeconds = 0.3;
  Participant p(o);
  try {
    p.initialize();
    FAIL() << "initialize() must time out";
  } catch (const ClientError& e) {
    EXPECT_EQ(e.code(), ErrorCode::Timeout) << e.what();
    EXPECT_NE(std::string(e.what()).find("tcp://127.0.0.1:9"), std::string::npos) << e.what();
  }
  EXPECT_EQ(p.state(), State::Created);
  p.finalize();
}
