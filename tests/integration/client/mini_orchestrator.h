#pragma once
// Test driver playing O of docs/session.md with the real protocol library: it configures a
// real coredem-dem, serves a real CFD participant's control requests (Hello, Configure,
// Configured, StepDone) and forwards each grant to D. Not a mock of any part: both peers are
// the real programs; this is the smallest orchestrator that lets the participants be tested
// without the `coredem` CLI.
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "coredem/protocol/protocol.h"

namespace coredem::testing {

namespace v1 = coredem::v1;
namespace proto = coredem::protocol;
using namespace std::chrono_literals;

/// A small case: `count` particles of diameter d (RANDOM in the region [0, box]^3 minus a
/// margin, or LATTICE), box walls, gravity, a Cartesian grid of `cells`^3 cells over the box,
/// and the given gas species.
inline v1::Configure smallCase(int count, double d, double box, int cells,
                               std::vector<std::string> species = {"N2"}, bool random = true) {
  v1::Configure c;
  c.set_case_name("test");
  auto* g = c.mutable_coupling_mesh()->mutable_cartesian();
  g->mutable_origin()->set_x(0.0);
  g->mutable_origin()->set_y(0.0);
  g->mutable_origin()->set_z(0.0);
  g->mutable_spacing()->set_x(box / cells);
  g->mutable_spacing()->set_y(box / cells);
  g->mutable_spacing()->set_z(box / cells);
  g->mutable_counts()->set_x(cells);
  g->mutable_counts()->set_y(cells);
  g->mutable_counts()->set_z(cells);
  for (const auto& s : species) {
    auto* sp = c.add_species();
    sp->set_name(s);
    sp->set_molar_mass(0.028);
  }
  auto* m = c.add_materials();
  m->set_id(0);
  m->set_name("glass");
  m->set_density(2500.0);
  m->set_k_n(1000.0);
  m->set_e_n(0.9);
  m->set_friction(0.3);
  m->set_cp(840.0);
  m->set_conductivity(1.0);
  m->set_emissivity(0.9);
  auto* ps = c.add_particle_sets();
  ps->set_name("beads");
  ps->set_material_id(0);
  ps->set_count(static_cast<std::uint64_t>(count));
  ps->set_diameter(d);
  ps->set_density(2500.0);
  ps->set_temperature(300.0);
  ps->set_packing(random ? v1::PACKING_RANDOM : v1::PACKING_LATTICE);
  ps->mutable_region_min()->set_x(0.0);
  ps->mutable_region_min()->set_y(0.0);
  ps->mutable_region_min()->set_z(0.0);
  ps->mutable_region_max()->set_x(box);
  ps->mutable_region_max()->set_y(box);
  ps->mutable_region_max()->set_z(box);
  ps->set_seed(7);
  auto* w = c.mutable_walls()->mutable_box();
  w->mutable_min()->set_x(0.0);
  w->mutable_min()->set_y(0.0);
  w->mutable_min()->set_z(0.0);
  w->mutable_max()->set_x(box);
  w->mutable_max()->set_y(box);
  w->mutable_max()->set_z(box);
  c.mutable_gravity()->set_z(-9.81);
  // A placeholder plan (validateConfigure wants a consistent one); each grant sets the real one.
  c.mutable_sub_cycling()->set_dt_cfd(1e-4);
  c.mutable_sub_cycling()->set_n_sub(1);
  c.mutable_sub_cycling()->set_dt_dem(1e-4);
  return c;
}

/// O's side: a DEALER to D and a ROUTER for C's control requests.
class MiniOrchestrator {
public:
  struct Result {
    std::vector<v1::StepDone> cfd; ///< C's StepDone of each step
    std::vector<v1::StepDone> dem; ///< D's StepDone of each step
    std::vector<double> demCheckpointSteps;
  };

  MiniOrchestrator(const std::string& demEndpoint, v1::Configure configure,
                   std::chrono::milliseconds timeout = 20s)
      : _configure(std::move(configure))
      , _timeout(timeout) {
    _dem.connect(demEndpoint);
    auto w =
        _dem.request(proto::makeHello(v1::ROLE_ORCHESTRATOR, "mini-orchestrator (test)"), _timeout);
    proto::expectType(w, v1::MESSAGE_TYPE_WELCOME);
    _session = w.envelope().welcome().session_id();
    auto cfg = proto::makeConfigure(_configure);
    cfg.setSessionId(_session);
    auto r = _dem.request(std::move(cfg), _timeout);
    proto::expectType(r, v1::MESSAGE_TYPE_CONFIGURED);
    _dtDemMax = r.envelope().configured().dt_dem();
    _particles = r.envelope().configured().particle_count();
    _controlEndpoint = _control.bind("tcp://127.0.0.1:*");
  }

  const std::string& session() const { return _session; }
  const std::string& controlEndpoint() const { return _controlEndpoint; }
  double dtDemMax() const { return _dtDemMax; }
  std::uint64_t particles() const { return _particles; }
  proto::Client& dem() { return _dem; }

  /// Serves C for `steps` steps of dtCfd (n_sub = ceil(dtCfd/dtDemMax)); grants in
  /// `checkpoints` carry {step -> directory}. Ends with Shutdown to C and D.
  Result run(int steps, double dtCfd, const std::map<std::int64_t, std::string>& checkpoints = {},
             bool shutdownDem = true) {
    Result res;
    const std::int64_t first = _configure.start_step() + 1;
    const std::int64_t last = _configure.start_step() + steps;
    const auto nSub = static_cast<std::uint32_t>(std::ceil(dtCfd / _dtDemMax * (1.0 - 1e-12)));
    auto grant = [&](std::int64_t n) {
      auto g =
          proto::makeStepGrant(n, _configure.start_time() + static_cast<double>(n - first) * dtCfd,
                               dtCfd, nSub, dtCfd / nSub);
      g.setSessionId(_session);
      if (const auto it = checkpoints.find(n); it != checkpoints.end()) {
        g.envelope().mutable_step_grant()->mutable_checkpoint()->set_directory(it->second);
      }
      return g;
    };
    bool done = false;
    const auto deadline = std::chrono::steady_clock::now() + _timeout * (steps + 5);
    while (!done) {
      if (std::chrono::steady_clock::now() > deadline) {
        throw std::runtime_error("mini orchestrator: the run did not finish in time");
      }
      auto req = _control.receive(_timeout);
      if (!req) {
        throw std::runtime_error(
            "mini orchestrator: no request from the CFD participant within the deadline");
      }
      if (!req->status.ok()) {
        throw std::runtime_error("mini orchestrator: bad request: " + req->status.message);
      }
      const auto& env = req->message.envelope();
      const auto seq = env.sequence();
      auto reply = [&](proto::Message m) {
        m.setSessionId(_session);
        m.setSequence(seq);
        _control.reply(req->peer, std::move(m));
      };
      switch (env.type()) {
      case v1::MESSAGE_TYPE_HELLO:
        if (env.session_id() != _session) {
          reply(proto::makeReject(v1::ERROR_CODE_UNKNOWN_SESSION, "wrong session"));
        } else {
          reply(proto::makeWelcome(v1::ROLE_ORCHESTRATOR, "mini", 1, 0, _session));
        }
        break;
      case v1::MESSAGE_TYPE_CONFIGURE:
        reply(proto::makeConfigure(_configure));
        break;
      case v1::MESSAGE_TYPE_CONFIGURED:
        if (steps == 0) {
          reply(proto::makeShutdown("nothing to do"));
          done = true;
          break;
        }
        _dem.send(grant(first));
        reply(grant(first));
        break;
      case v1::MESSAGE_TYPE_STEP_DONE: {
        res.cfd.push_back(env.step_done());
        auto d = _dem.receive(_timeout);
        if (!d) {
          throw std::runtime_error("mini orchestrator: no StepDone from D for step " +
                                   std::to_string(env.step()));
        }
        proto::expectType(*d, v1::MESSAGE_TYPE_STEP_DONE);
        res.dem.push_back(d->envelope().step_done());
        if (env.step() >= last) {
          reply(proto::makeShutdown("end of the test run"));
          done = true;
        } else {
          _dem.send(grant(env.step() + 1));
          reply(grant(env.step() + 1));
        }
        break;
      }
      default:
        reply(proto::makeError(v1::ERROR_CODE_UNEXPECTED_MESSAGE, "mini orchestrator: unexpected"));
      }
    }
    if (shutdownDem) {
      shutdown();
    }
    return res;
  }

  void shutdown() {
    auto s = proto::makeShutdown("test done");
    s.setSessionId(_session);
    auto a = _dem.request(std::move(s), _timeout);
    proto::expectType(a, v1::MESSAGE_TYPE_ACK);
  }

private:
  v1::Configure _configure;
  std::chrono::milliseconds _timeout;
  proto::Client _dem;
  proto::Server _control;
  std::string _session, _controlEndpoint;
  double _dtDemMax = 0.0;
  std::uint64_t _particles = 0;
};

/// Value of a named entry in a NamedValue list (NaN if absent).
inline double named(const google::protobuf::RepeatedPtrField<v1::NamedValue>& l,
                    const std::string& name) {
  const auto v = proto::findNamedValue(l, name);
  return v ? *v : std::nan("");
}

} // namespace coredem::testing
