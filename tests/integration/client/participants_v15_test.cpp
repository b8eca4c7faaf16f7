// Protocol 1.5 in the coupling client, against stand-in DEM servers that agree 1.5 or 1.4 (the
// orchestrator side is a MiniOrchestrator on a real coredem-dem, as in participants_test.cpp):
// setHeatToParticles() sends Q_split with the next exchange only (what the server receives is
// bitwise the values given), releasedMomentum() views mom_p (or a caller buffer), and against a
// 1.4 server Q_split is refused naming both versions while mom_p is reported absent.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "coredem/client/participant.h"
#include "mini_orchestrator.h"
#include "process.h"

using namespace coredem::testing;
namespace fs = std::filesystem;

namespace {

/// A DEM server stand-in speaking protocol 1.`minor`: Welcome, and Sources of zeros (with mom_p
/// = 0.5 + cell + 0.25 axis when minor >= 5) for every GasFields; it keeps the Q_split of each
/// GasFields it receives (empty when absent).
class StandIn {
public:
  explicit StandIn(std::uint32_t minor)
      : _minor(minor) {
    _ep = _server.bind("tcp://127.0.0.1:*");
    _thread = std::thread([this] { serve(); });
  }
  ~StandIn() {
    _stop = true;
    _thread.join();
  }
  const std::string& endpoint() const { return _ep; }
  std::vector<std::vector<double>> splits() {
    std::lock_guard<std::mutex> lock(_mutex);
    return _splits;
  }

private:
  void serve() {
    namespace f = proto::fields;
    while (!_stop) {
      auto r = _server.receive(std::chrono::milliseconds(100));
      if (!r) {
        continue;
      }
      const auto& env = r->message.envelope();
      proto::Message w;
      if (r->message.type() == v1::MESSAGE_TYPE_HELLO) {
        w = proto::makeWelcome(v1::ROLE_DEM, "coredem-dem (stand-in)", 1, _minor, env.session_id());
      } else if (r->message.type() == v1::MESSAGE_TYPE_GAS_FIELDS) {
        const auto& g = env.gas_fields();
        {
          std::lock_guard<std::mutex> lock(_mutex);
          const auto q = r->message.findArray(f::kHeatToParticles);
          _splits.emplace_back();
          if (q) {
            const auto v = q->as<double>();
            _splits.back().assign(v.begin(), v.end());
          }
        }
        w = proto::makeSources(env.step(), env.time(), g.dt(), g.cell_count(), g.species_count(),
                               1);
        for (const auto& spec : f::sourceFields()) {
          const auto shape = f::shapeOf(spec.extent, g.cell_count(), g.species_count());
          w.addArray<double>(
              spec.name,
              std::vector<double>(shape[0] * f::componentsOf(spec.extent, g.species_count()), 0.0),
              shape);
        }
        if (_minor >= proto::kMinorReleasedMomentum) {
          std::vector<double> mom;
          for (std::uint64_t c = 0; c < g.cell_count(); ++c) {
            for (int a = 0; a < 3; ++a) {
              mom.push_back(0.5 + double(c) + 0.25 * a);
            }
          }
          w.addArray<double>(f::kReleasedMomentum, mom, {g.cell_count(), 3});
        }
        w.setSessionId(env.session_id());
        w.setStep(env.step());
      } else {
        w = proto::makeError(v1::ERROR_CODE_UNSUPPORTED, "stand-in");
      }
      w.setSequence(env.sequence());
      _server.reply(r->peer, std::move(w));
    }
  }

  std::uint32_t _minor;
  proto::Server _server;
  std::string _ep;
  std::atomic<bool> _stop{false};
  std::thread _thread;
  std::mutex _mutex;
  std::vector<std::vector<double>> _splits;
};

std::vector<coredem::client::NamedField> gas(std::size_t n,
                                             std::vector<std::vector<double>>& keep) {
  keep = {std::vector<double>(3 * n, 0.0), std::vector<double>(3 * n, 0.0),
          std::vector<double>(n, 300.0),   std::vector<double>(n, 1.2),
          std::vector<double>(n, 1.8e-5),  std::vector<double>(n, 0.03),
          std::vector<double>(n, 1000.0),  std::vector<double>(n, 1.0)};
  return {{"u_g", keep[0]},  {"grad_p", keep[1]},  {"T_g", keep[2]},  {"rho_g", keep[3]},
          {"mu_g", keep[4]}, {"kappa_g", keep[5]}, {"cp_g", keep[6]}, {"Y_g", keep[7]}};
}

/// Runs `body` as the CFD participant of a one-step MiniOrchestrator session on a real
/// coredem-dem whose DEM endpoint is the stand-in; returns what `body` reported ("" = fine).
template <class Body>
std::string asParticipant(const std::string& name, const std::string& demEp, Body body) {
  const auto dir = fs::temp_directory_path() /
                   ("coredem-participants-v15-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string failure = "not run";
  {
    DemProcess dem(dir);
    MiniOrchestrator o(dem.endpoint(), smallCase(27, 1e-3, 6e-3, 3, {"N2"}), 3s);
    std::thread cfd([&] {
      coredem::client::Options opt;
      opt.controlEndpoint = o.controlEndpoint();
      opt.demEndpoint = demEp;
      opt.sessionId = o.session();
      opt.timeoutSeconds = 20;
      coredem::client::Participant p(opt);
      try {
        p.initialize();
        failure = body(p);
      } catch (const std::exception& e) {
        failure = std::string("unexpected: ") + e.what();
      }
    });
    try {
      o.run(1, 2e-4, {}, false); // ends by timeout: the real DEM never gets the GasFields
    } catch (const std::exception&) {
    }
    cfd.join();
  }
  fs::remove_all(dir);
  return failure;
}

} // namespace

TEST(ParticipantsV15, HeatToParticlesIsSentAndReleasedMomentumIsReceived) {
  StandIn server(5);
  const std::string failure = asParticipant("v15", server.endpoint(), [&](auto& p) {
    std::string f;
    if (!p.takesHeatToParticles())
      f += "takesHeatToParticles() false; ";
    const auto n = static_cast<std::size_t>(p.grid().cellCount());
    std::vector<double> q(n);
    for (std::size_t c = 0; c < n; ++c)
      q[c] = (c % 2 == 0 ? 1.0 : -1.0) * (1.0 / 3.0 + double(c)); // either sign, not round
    // Not finite: refused, naming the index.
    std::vector<double> bad = q;
    bad[1] = std::nan("");
    try {
      p.setHeatToParticles(bad);
      f += "a NaN was accepted; ";
    } catch (const coredem::client::ClientError& e) {
      if (std::string(e.what()).find("Q_split[1]") == std::string::npos)
        f += std::string("NaN refused without naming the index: ") + e.what() + "; ";
    }
    p.setHeatToParticles(q);
    std::vector<std::vector<double>> keep;
    const auto& s = p.exchange(p.step(), p.dt(), gas(n, keep));
    const auto m = s.releasedMomentum();
    if (m.size != 3 * n)
      return f + "releasedMomentum() has " + std::to_string(m.size) + " values";
    for (std::size_t c = 0; c < n; ++c)
      for (int a = 0; a < 3; ++a)
        if (m[3 * c + a] != 0.5 + double(c) + 0.25 * a)
          return f + "mom_p differs at cell " + std::to_string(c);
    if (!s.has("mom_p") || s.field("mom_p").data != m.data)
      f += "field(mom_p) is not releasedMomentum(); ";
    const auto got = server.splits();
    if (got.size() != 1 || got[0] != q)
      f += "the server did not receive Q_split bitwise; ";
    return f;
  });
  EXPECT_EQ(failure, "");
}

TEST(ParticipantsV15, ReleasedMomentumIntoACallerBufferAndSplitOfTheWrongSizeIsRefused) {
  StandIn server(5);
  const std::string failure = asParticipant("v15buf", server.endpoint(), [&](auto& p) {
    std::string f;
    const auto n = static_cast<std::size_t>(p.grid().cellCount());
    std::vector<std::vector<double>> keep;
    p.setHeatToParticles(std::vector<double>(n + 1, 1.0)); // one too many
    try {
      p.exchange(p.step(), p.dt(), gas(n, keep));
      return f + "a Q_split of n + 1 values was sent";
    } catch (const coredem::client::ClientError& e) {
      if (std::string(e.what()).find("Q_split") == std::string::npos)
        f += std::string("refused without naming Q_split: ") + e.what() + "; ";
    }
    if (!server.splits().empty())
      f += "something was sent; ";
    p.setHeatToParticles(std::vector<double>(n, 2.0));
    std::vector<double> mom(3 * n, -1.0);
    const auto& s = p.exchange(p.step(), p.dt(), gas(n, keep), {{"mom_p", mom.data(), mom.size()}});
    if (s.releasedMomentum().data != mom.data() || mom[3 * 2 + 1] != 2.75)
      f += "mom_p was not received into the buffer; ";
    if (server.splits().size() != 1 || server.splits()[0] != std::vector<double>(n, 2.0))
      f += "the corrected Q_split was not sent; ";
    return f;
  });
  EXPECT_EQ(failure, "");
}

// Against a 1.4 server: Q_split is refused naming both versions (the heat would be dropped),
// given as a field too; mom_p is absent (releasedMomentum() empty, a buffer for it zeroed).
TEST(ParticipantsV15, AServerOfProtocol14TakesNoSplitAndSendsNoMomentum) {
  StandIn server(4);
  const std::string failure = asParticipant("v14", server.endpoint(), [&](auto& p) {
    std::string f;
    if (p.takesHeatToParticles())
      f += "takesHeatToParticles() true; ";
    const auto n = static_cast<std::size_t>(p.grid().cellCount());
    const std::vector<double> q(n, 1.0);
    try {
      p.setHeatToParticles(q);
      f += "setHeatToParticles accepted; ";
    } catch (const coredem::client::ClientError& e) {
      const std::string what = e.what();
      if (what.find("agreed protocol 1.4, this client speaks " +
                    proto::kProtocolVersion.toString()) == std::string::npos ||
          what.find("Q_split needs 1.5") == std::string::npos)
        f += "refusal: " + what + "; ";
    }
    std::vector<std::vector<double>> keep;
    auto fields = gas(n, keep);
    fields.push_back({"Q_split", q});
    try {
      p.exchange(p.step(), p.dt(), fields);
      f += "Q_split as a field was sent; ";
    } catch (const coredem::client::ClientError& e) {
      if (std::string(e.what()).find("agreed protocol 1.4") == std::string::npos)
        f += std::string("field refusal: ") + e.what() + "; ";
    }
    std::vector<double> mom(3 * n, -7.0);
    const auto& s = p.exchange(p.step(), p.dt(), gas(n, keep), {{"mom_p", mom.data(), mom.size()}});
    if (s.releasedMomentum().size != 0 || s.has("mom_p"))
      f += "mom_p reported; ";
    for (double v : mom)
      if (v != 0.0)
        return f + "the mom_p buffer was not zeroed";
    if (server.splits().size() != 1 || !server.splits()[0].empty())
      f += "a Q_split reached the 1.4 server; ";
    return f;
  });
  EXPECT_EQ(failure, "");
}
