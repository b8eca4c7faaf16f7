#pragma once
// A loopback server on tcp://127.0.0.1:<ephemeral> served by a background thread, and a
// client that has done Hello + Configure (4 x 3 x 2 = 24 cells, 2 species).
#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include <coredem/protocol/fields.h>
#include <coredem/protocol/loopback.h>
#include <coredem/protocol/validate.h>

namespace coredem::protocol::test {

using namespace std::chrono_literals;

inline constexpr std::uint64_t kCells = 24;
inline constexpr std::uint32_t kSpecies = 2;
inline constexpr auto kTimeout = std::chrono::milliseconds(10000);

/// A running loopback server; stops and joins on destruction.
class LoopbackThread {
public:
  explicit LoopbackThread(Version version = kProtocolVersion,
                          const std::string& endpoint = "tcp://127.0.0.1:*")
      : _service(TransportOptions{}, version) {
    _endpoint = _service.bind(endpoint);
    _thread = std::thread([this] { _service.serve(&_stop); });
  }
  ~LoopbackThread() {
    _stop = true;
    _thread.join();
  }
  [[nodiscard]] const std::string& endpoint() const { return _endpoint; }
  LoopbackService& service() { return _service; }

private:
  LoopbackService _service;
  std::string _endpoint;
  std::atomic<bool> _stop{false};
  std::thread _thread;
};

inline v1::Configure smallConfigure() {
  v1::Configure c;
  auto* g = c.mutable_coupling_mesh()->mutable_cartesian();
  g->mutable_spacing()->set_x(0.01);
  g->mutable_spacing()->set_y(0.01);
  g->mutable_spacing()->set_z(0.01);
  g->mutable_counts()->set_x(4);
  g->mutable_counts()->set_y(3);
  g->mutable_counts()->set_z(2);
  auto* a = c.add_species();
  a->set_name("O2");
  a->set_molar_mass(0.032);
  auto* b = c.add_species();
  b->set_name("N2");
  b->set_molar_mass(0.028);
  c.mutable_sub_cycling()->set_dt_cfd(1e-3);
  c.mutable_sub_cycling()->set_n_sub(4);
  c.mutable_sub_cycling()->set_dt_dem(2.5e-4);
  return c;
}

/// Value of GasFields field f at flat index i.
inline double gasValue(std::size_t f, std::size_t i) {
  return 2.0 + static_cast<double>(f) + 0.01 * static_cast<double>(i);
}

/// A valid GasFields message for `step` on the small grid.
inline Message gasFields(std::int64_t step, const std::string& session) {
  Message m = makeGasFields(step, 1e-3 * static_cast<double>(step), 1e-3, kCells, kSpecies);
  m.setSessionId(session);
  std::size_t f = 0;
  for (const auto& spec : fields::gasFields()) {
    std::vector<double> v(kCells * fields::componentsOf(spec.extent, kSpecies));
    for (std::size_t i = 0; i < v.size(); ++i) {
      v[i] = gasValue(f, i);
    }
    m.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, kCells, kSpecies));
    ++f;
  }
  return m;
}

/// Client with an open, configured session on `server`.
class Session {
public:
  explicit Session(const std::string& endpoint) {
    client.connect(endpoint);
    Message w = client.request(makeHello(v1::ROLE_CFD, "test 1.0"), kTimeout);
    expectType(w, v1::MESSAGE_TYPE_WELCOME);
    id = w.envelope().welcome().session_id();
    Message c =
        client.request(std::move(makeConfigure(smallConfigure()).setSessionId(id)), kTimeout);
    expectType(c, v1::MESSAGE_TYPE_CONFIGURED);
  }
  Client client;
  std::string id;
  std::int64_t nextStep = 0;

  /// Sends a valid GasFields for the next step and checks the Sources reply completely.
  void exchangeValidStep() {
    Message reply = client.request(gasFields(nextStep, id), kTimeout);
    ASSERT_EQ(reply.type(), v1::MESSAGE_TYPE_SOURCES)
        << (reply.type() == v1::MESSAGE_TYPE_ERROR ? reply.envelope().error().message() : "");
    Expectation e;
    e.cells = kCells;
    e.species = kSpecies;
    e.step = nextStep;
    Status s = validate(reply, e);
    ASSERT_TRUE(s.ok()) << s.toString();
    for (double v : reply.values<double>(fields::kVoidFraction)) {
      ASSERT_EQ(v, 1.0);
    }
    for (const auto& spec : fields::sourceFields()) {
      if (spec.name != fields::kVoidFraction) {
        for (double v : reply.values<double>(spec.name)) {
          ASSERT_EQ(v, 0.0) << spec.name;
        }
      }
    }
    // The server's sums of what it received equal the sums of what was sent (same order).
    auto checksum = reply.values<double>("checksum");
    ASSERT_EQ(checksum.size(), fields::gasFields().size());
    for (std::size_t f = 0; f < checksum.size(); ++f) {
      double sum = 0;
      std::size_t n = kCells * fields::componentsOf(fields::gasFields()[f].extent, kSpecies);
      for (std::size_t i = 0; i < n; ++i) {
        sum += gasValue(f, i);
      }
      ASSERT_EQ(checksum[f], sum) << fields::gasFields()[f].name;
    }
    ++nextStep;
  }
};

} // namespace coredem::protocol::test
