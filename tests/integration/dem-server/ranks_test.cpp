// coredem-dem with a decomposed CFD participant (protocol v1.2, docs/protocol.md "Decomposed
// CFD"): K ranks, each on its own connection, send partial GasFields (the coupling cells their
// cells touch, fluid volumes and volume-weighted sums); D combines them in rank order, steps once
// and answers each rank with its cells' sources. Checked: the same step from 1 whole-grid
// participant and from 2 ranks (both arrival orders) gives the same sources and particles
// (arrival order: bitwise; 1 vs 2 ranks: within round-off, see kRegrouped); rank count mismatch,
// duplicate rank index, rank index out of range, a silent rank and a rank that leaves are refused
// with errors naming the rank, never a hang.
#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include <gtest/gtest.h>

#include "../client/mini_orchestrator.h"
#include "server_thread.h"

using namespace coredem::testing;

namespace {

namespace f = proto::fields;

constexpr int kParticles = 60;
constexpr double kD = 1e-3;
constexpr double kBox = 6e-3;
constexpr int kCellsPerAxis = 3;
constexpr std::size_t kCells = 27;
constexpr double kH = kBox / kCellsPerAxis;
/// Relative difference allowed between the 1-rank and the 2-rank sources after 3 steps: the
/// 2-rank gas is (V_0 f + V_1 f)/(V_0 + V_1) instead of f (a few ulp, 1e-16 relative) and the
/// DEM's response to it stays within a few hundred ulp over 3 steps of 60 particles.
constexpr double kRegrouped = 1e-11;

/// The gas of coupling cell c (varies per cell so that a wrong cell order shows).
struct Gas {
  std::vector<double> u, gradP, T, rho, mu, kappa, cp, Y;
  std::vector<double> split; ///< Q_split per cell (J/m3 of V_c), v1.5; empty: not sent
  Gas() {
    for (std::size_t c = 0; c < kCells; ++c) {
      u.insert(u.end(), {0.01 * double(c % 3), 0.0, 0.3 + 0.01 * double(c)});
      gradP.insert(gradP.end(), {0.0, 0.0, -11.0 - 0.1 * double(c)});
      T.push_back(300.0 + double(c));
      rho.push_back(1.2);
      mu.push_back(1.8e-5);
      kappa.push_back(0.026);
      cp.push_back(1005.0);
      Y.push_back(1.0);
    }
  }
  std::vector<std::pair<std::string_view, const std::vector<double>*>> arrays() const {
    return {{f::kGasVelocity, &u},      {f::kPressureGradient, &gradP},
            {f::kGasTemperature, &T},   {f::kGasDensity, &rho},
            {f::kGasViscosity, &mu},    {f::kGasConductivity, &kappa},
            {f::kGasHeatCapacity, &cp}, {f::kGasMassFractions, &Y}};
  }
  proto::Message whole(std::int64_t step, double time, double dt,
                       const std::string& session) const {
    auto m = proto::makeGasFields(step, time, dt, kCells, 1);
    m.setSessionId(session);
    for (const auto& [name, v] : arrays()) {
      m.addArray<double>(name, *v, f::shapeOf(name, kCells, 1));
    }
    if (!split.empty()) {
      m.addArray<double>(f::kHeatToParticles, split, {kCells});
    }
    return m;
  }
  /// Rank `rank` of 2: rank 0 holds cells 0..13 and half of cell 13's volume, rank 1 the other
  /// half of cell 13 and cells 14..26 (cell 13 is shared).
  proto::Message partial(int rank, std::int64_t step, double time, double dt,
                         const std::string& session) const {
    std::vector<std::int64_t> cells;
    std::vector<double> volume;
    const double v = kH * kH * kH;
    for (std::int64_t c = rank == 0 ? 0 : 13; c < (rank == 0 ? 14 : 27); ++c) {
      cells.push_back(c);
      volume.push_back(c == 13 ? (rank == 0 ? 0.375 * v : 0.625 * v) : v);
    }
    auto m = proto::makeGasFields(step, time, dt, kCells, 1);
    m.setSessionId(session);
    m.envelope().mutable_gas_fields()->set_partial(true);
    m.envelope().mutable_gas_fields()->set_touched_count(cells.size());
    m.addArray<std::int64_t>(f::kTouchedCells, cells, {cells.size()});
    m.addArray<double>(f::kFluidVolume, volume, {volume.size()});
    for (const auto& [name, values] : arrays()) {
      const std::size_t q = values->size() / kCells;
      std::vector<double> sums;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        for (std::size_t k = 0; k < q; ++k) {
          sums.push_back(volume[i] * (*values)[std::size_t(cells[i]) * q + k]);
        }
      }
      m.addArray<double>(name, sums, f::shapeOf(name, cells.size(), 1));
    }
    if (!split.empty()) {
      // Extensive: each rank its own part of a cell's heat (of the shared cell 13, in proportion
      // to its fluid volume), per coupling-cell volume; the server sums them.
      std::vector<double> q;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        q.push_back(split[std::size_t(cells[i])] * volume[i] / v);
      }
      m.addArray<double>(f::kHeatToParticles, q, {cells.size()});
    }
    return m;
  }
};

proto::Client cfdRank(const std::string& ep, const std::string& session, std::uint32_t rank,
                      std::uint32_t count, v1::MessageType expect = v1::MESSAGE_TYPE_WELCOME,
                      std::string* reason = nullptr,
                      std::uint32_t minor = proto::kProtocolVersion.minor) {
  proto::Client c;
  c.connect(ep);
  auto hello = proto::makeHello(v1::ROLE_CFD, "test cfd rank " + std::to_string(rank));
  hello.envelope().mutable_hello()->set_protocol_minor(minor);
  hello.envelope().mutable_hello()->set_rank(rank);
  hello.envelope().mutable_hello()->set_rank_count(count);
  hello.setSessionId(session);
  auto w = c.request(std::move(hello), 10s);
  EXPECT_EQ(w.type(), expect) << w.envelope().DebugString();
  if (reason != nullptr && w.type() == v1::MESSAGE_TYPE_REJECT) {
    *reason = w.envelope().reject().reason();
  }
  return c;
}

void grant(MiniOrchestrator& o, std::int64_t n, double dt, std::uint32_t nSub) {
  auto g = proto::makeStepGrant(n, double(n - 1) * dt, dt, nSub, dt / nSub);
  g.setSessionId(o.session());
  o.dem().send(std::move(g));
}

/// Whole-grid sources of one step: per array name, kCells rows (assembled from the ranks).
using GridSources = std::map<std::string, std::vector<double>>;

void take(const proto::Message& src, GridSources& out) {
  ASSERT_EQ(src.type(), v1::MESSAGE_TYPE_SOURCES) << src.envelope().DebugString();
  const bool partial = src.envelope().sources().partial();
  std::vector<std::int64_t> cells;
  if (partial) {
    const auto c = src.findArray(f::kTouchedCells)->as<std::int64_t>();
    cells.assign(c.begin(), c.end());
  } else {
    for (std::size_t c = 0; c < kCells; ++c) {
      cells.push_back(std::int64_t(c));
    }
  }
  std::vector<f::FieldSpec> specs(f::sourceFields().begin(), f::sourceFields().end());
  for (const auto& spec : f::optionalSourceFields()) { // v1.3 Q_rad, when sent
    if (src.findArray(spec.name)) {
      specs.push_back(spec);
    }
  }
  for (const auto& spec : specs) {
    const auto v = src.values<double>(spec.name);
    const std::size_t q = v.size() / cells.size();
    auto& dst = out[std::string(spec.name)];
    dst.resize(kCells * q, 0.0);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      for (std::size_t k = 0; k < q; ++k) {
        dst[std::size_t(cells[i]) * q + k] = v[i * q + k];
      }
    }
  }
}

struct RunResult {
  GridSources sources;  ///< of the last step
  v1::StepDone demDone; ///< of the last step
  /// Σ over the steps and cells of Q_rad V_c Δt (J): the radiation heat the gas received.
  double radiationToGas = 0.0;
  int stepsWithQrad = 0; ///< steps whose Sources carried Q_rad
  /// Σ over the steps and cells of mom_p V_c Δt (N s): the momentum the released mass brought.
  std::array<double, 3> momentumToGas{0.0, 0.0, 0.0};
  int stepsWithMomP = 0; ///< steps whose Sources carried mom_p
};

/// What a run adds to the base case (protocol 1.5).
struct Extras {
  bool reacting = false; ///< the beads hold B, which burns to the gas N2 (mom_p)
  bool split = false;    ///< the CFD sends Q_split every step
};

/// The base case; reacting: half of every bead is B (M = 0.028), B -> N2 at a constant rate.
v1::Configure rankCase(double hotT, const Extras& x) {
  v1::Configure cfg = smallCase(kParticles, kD, kBox, kCellsPerAxis);
  if (hotT > 0.0) {
    cfg.mutable_particle_sets(0)->set_temperature(hotT);
  }
  if (x.reacting) {
    for (auto [name, molar] : {std::pair{"B", 0.028}, {"I", 0.020}}) {
      auto* s = cfg.add_solid_species();
      s->set_name(name);
      s->set_molar_mass(molar);
    }
    for (auto [name, frac] : {std::pair{"B", 0.5}, {"I", 0.5}}) {
      auto* nv = cfg.mutable_particle_sets(0)->add_composition();
      nv->set_name(name);
      nv->set_value(frac);
    }
    auto* r = cfg.add_reactions();
    r->set_name("burn");
    for (auto [sp, nu] : {std::pair{"B", -1.0}, {"N2", 1.0}}) {
      auto* t = r->add_terms();
      t->set_species(sp);
      t->set_nu(nu);
    }
    r->mutable_rate()->set_law(v1::RATE_LAW_CONSTANT);
    r->mutable_rate()->set_a(1e-6); // mol/s per bead: 2.8e-8 kg/s of its 6.5e-7 kg of B
    r->set_heat_of_reaction(0.0);
  }
  return cfg;
}

/// Three steps with 1 whole-grid participant (ranks 0) or 2 ranks sending in `order`; `hotT` > 0:
/// the particles start at that temperature (radiation to the 300 K gas); `minor`: the protocol
/// minor the CFD ranks say in Hello.
RunResult run(int ranks, std::vector<int> order = {0, 1}, double hotT = 0.0,
              std::uint32_t minor = proto::kProtocolVersion.minor, Extras extras = {}) {
  ServerThread server;
  MiniOrchestrator o(server.endpoint(), rankCase(hotT, extras));
  Gas gas;
  if (extras.split) {
    for (std::size_t c = 0; c < kCells; ++c) {
      gas.split.push_back(2e5 * (1.0 + 0.1 * double(c)) * (c % 2 == 0 ? 1.0 : -0.5));
    }
  }
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  std::vector<proto::Client> c;
  for (int r = 0; r < std::max(ranks, 1); ++r) {
    c.push_back(cfdRank(server.endpoint(), o.session(), std::uint32_t(r),
                        std::uint32_t(std::max(ranks, 1)), v1::MESSAGE_TYPE_WELCOME, nullptr,
                        minor));
  }
  RunResult result;
  for (std::int64_t n = 1; n <= 3; ++n) {
    const double t = double(n - 1) * dt;
    grant(o, n, dt, nSub);
    result.sources.clear();
    if (ranks == 0) {
      take(c[0].request(gas.whole(n, t, dt, o.session()), 20s), result.sources);
    } else {
      for (int r : order) {
        c[std::size_t(r)].send(gas.partial(r, n, t, dt, o.session()));
      }
      for (int r = 0; r < ranks; ++r) {
        auto src = c[std::size_t(r)].receive(20s);
        EXPECT_TRUE(src.has_value()) << "no Sources for rank " << r;
        if (!src) {
          return result;
        }
        // Each rank gets its own cells only.
        EXPECT_EQ(src->envelope().sources().touched_count(), r == 0 ? 14u : 14u);
        take(*src, result.sources);
      }
    }
    auto d = o.dem().receive(20s);
    EXPECT_TRUE(d.has_value());
    proto::expectType(*d, v1::MESSAGE_TYPE_STEP_DONE);
    result.demDone = d->envelope().step_done();
    if (const auto q = result.sources.find(std::string(f::kRadiationHeat));
        q != result.sources.end()) {
      ++result.stepsWithQrad;
      double sum = 0.0;
      for (double v : q->second) {
        sum += v * kH * kH * kH * dt;
      }
      result.radiationToGas += sum;
    }
    if (const auto m = result.sources.find(std::string(f::kReleasedMomentum));
        m != result.sources.end()) {
      ++result.stepsWithMomP;
      for (std::size_t k = 0; k < m->second.size(); ++k) {
        result.momentumToGas[k % 3] += m->second[k] * kH * kH * kH * dt;
      }
    }
  }
  return result;
}

double relDiff(double a, double b) {
  const double s = std::max(std::abs(a), std::abs(b));
  return s > 0 ? std::abs(a - b) / s : 0.0;
}

} // namespace

TEST(DemServerRanks, ArrivalOrderDoesNotChangeAnyBit) {
  const RunResult a = run(2, {0, 1});
  const RunResult b = run(2, {1, 0});
  ASSERT_FALSE(a.sources.empty());
  EXPECT_EQ(a.sources, b.sources); // bitwise: combined in rank order whatever the arrival
  EXPECT_EQ(named(a.demDone.diagnostics(), "mean_T_p"), named(b.demDone.diagnostics(), "mean_T_p"));
  EXPECT_EQ(named(a.demDone.diagnostics(), "bed_height_m"),
            named(b.demDone.diagnostics(), "bed_height_m"));
}

TEST(DemServerRanks, TwoRanksAgreeWithOneWholeGridParticipantToRoundOff) {
  const RunResult one = run(0);
  const RunResult two = run(2);
  ASSERT_EQ(one.sources.size(), two.sources.size());
  double worst = 0.0, solid = 0.0;
  for (const auto& [name, v] : one.sources) {
    const auto& w = two.sources.at(name);
    ASSERT_EQ(v.size(), w.size()) << name;
    for (std::size_t i = 0; i < v.size(); ++i) {
      // Relative to the array's largest value (a source that is 0 in one and 1e-30 in the other
      // is round-off too).
      double scale = 0.0;
      for (double x : v) {
        scale = std::max(scale, std::abs(x));
      }
      if (scale > 0) {
        worst = std::max(worst, std::abs(v[i] - w[i]) / scale);
      }
    }
  }
  for (double x : one.sources.at("eps_g")) {
    solid += 1.0 - x;
  }
  EXPECT_GT(solid, 0.0); // the step had particles and drag
  std::printf("largest relative difference 1 vs 2 ranks: %.3g\n", worst);
  EXPECT_LE(worst, kRegrouped);
  EXPECT_LE(relDiff(named(one.demDone.diagnostics(), "bed_height_m"),
                    named(two.demDone.diagnostics(), "bed_height_m")),
            kRegrouped);
}

TEST(DemServerRanks, MismatchedCountsDuplicateAndOutOfRangeRanksAreRefused) {
  ServerThread server;
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCellsPerAxis));
  std::string why;
  cfdRank(server.endpoint(), o.session(), 2, 2, v1::MESSAGE_TYPE_REJECT, &why);
  EXPECT_NE(why.find("rank 2 of 2"), std::string::npos) << why;
  auto r0 = cfdRank(server.endpoint(), o.session(), 0, 2);
  cfdRank(server.endpoint(), o.session(), 1, 3, v1::MESSAGE_TYPE_REJECT, &why);
  EXPECT_NE(why.find("runs on 2 rank(s)"), std::string::npos) << why;
  EXPECT_NE(why.find("says 3"), std::string::npos) << why;
  cfdRank(server.endpoint(), o.session(), 0, 2, v1::MESSAGE_TYPE_REJECT, &why);
  EXPECT_NE(why.find("CFD rank 0 of 2 is already connected"), std::string::npos) << why;
  // A whole-grid GasFields in a 2-rank session is refused.
  auto r1 = cfdRank(server.endpoint(), o.session(), 1, 2);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  grant(o, 1, dt, nSub);
  auto e = r0.request(Gas().whole(1, 0.0, dt, o.session()), 20s);
  ASSERT_EQ(e.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_NE(e.envelope().error().message().find("runs on 2 ranks"), std::string::npos)
      << e.envelope().error().message();
  // The step still runs with the partial ones.
  r0.send(Gas().partial(0, 1, 0.0, dt, o.session()));
  r1.send(Gas().partial(1, 1, 0.0, dt, o.session()));
  for (auto* c : {&r0, &r1}) {
    auto s = c->receive(20s);
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->type(), v1::MESSAGE_TYPE_SOURCES) << s->envelope().DebugString();
  }
  auto d = o.dem().receive(20s);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->type(), v1::MESSAGE_TYPE_STEP_DONE);
}

TEST(DemServerRanks, ASilentRankFailsTheStepNamingIt) {
  ServerThread server(600.0, 1.0); // wait 1 s for the other ranks
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCellsPerAxis));
  auto r0 = cfdRank(server.endpoint(), o.session(), 0, 2);
  auto r1 = cfdRank(server.endpoint(), o.session(), 1, 2);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  grant(o, 1, dt, nSub);
  auto e = r0.request(Gas().partial(0, 1, 0.0, dt, o.session()), 20s);
  ASSERT_EQ(e.type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(e.envelope().error().code(), v1::ERROR_CODE_TIMEOUT);
  EXPECT_NE(e.envelope().error().message().find("from CFD rank(s) 1 of 2"), std::string::npos)
      << e.envelope().error().message();
  auto g = o.dem().receive(20s); // the orchestrator hears it too
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_NE(g->envelope().error().message().find("rank(s) 1"), std::string::npos);
}

TEST(DemServerRanks, ARankThatLeavesFailsTheStepNamingIt) {
  ServerThread server;
  MiniOrchestrator o(server.endpoint(), smallCase(kParticles, kD, kBox, kCellsPerAxis));
  auto r0 = cfdRank(server.endpoint(), o.session(), 0, 2);
  const double dt = 2e-4;
  const auto nSub = static_cast<std::uint32_t>(std::ceil(dt / o.dtDemMax()));
  {
    auto r1 = cfdRank(server.endpoint(), o.session(), 1, 2);
    grant(o, 1, dt, nSub);
    r0.send(Gas().partial(0, 1, 0.0, dt, o.session()));
    std::this_thread::sleep_for(200ms);
  } // rank 1's connection closes (a crashed rank)
  auto e = r0.receive(20s);
  ASSERT_TRUE(e.has_value()) << "rank 0 left waiting";
  ASSERT_EQ(e->type(), v1::MESSAGE_TYPE_ERROR);
  EXPECT_EQ(e->envelope().error().code(), v1::ERROR_CODE_TRANSPORT);
  EXPECT_NE(e->envelope().error().message().find("CFD rank 1 of 2"), std::string::npos)
      << e->envelope().error().message();
}

// Protocol 1.3: Q_rad, the radiation heat the particles gave the gas. Hot particles (900 K,
// emissivity 0.9) in 300 K gas, 3 steps: Σ Q_rad V_c Δt over cells and steps equals the
// particles' radiation loss (−dem.heat_radiation_J) to 1e-12 relative, whether one whole-grid
// participant or 2 ranks (partial Sources, each its own cells) receive it; a 1.2 peer receives
// no Q_rad (the heat then leaves the system as before) and the particles do the same.
TEST(DemServerRanks, RadiationHeatReachesTheGasWholeGridAndPartial) {
  const RunResult one = run(0, {0, 1}, 900.0);
  const RunResult two = run(2, {0, 1}, 900.0);
  const double lost = -named(one.demDone.ledger().energy(), "dem.heat_radiation_J");
  ASSERT_GT(lost, 0.0);
  EXPECT_EQ(one.stepsWithQrad, 3);
  EXPECT_EQ(two.stepsWithQrad, 3);
  EXPECT_NEAR(one.radiationToGas, lost, 1e-12 * lost);
  const double lostTwo = -named(two.demDone.ledger().energy(), "dem.heat_radiation_J");
  EXPECT_NEAR(two.radiationToGas, lostTwo, 1e-12 * lostTwo);
  EXPECT_NEAR(two.radiationToGas, one.radiationToGas, kRegrouped * lost);
  std::printf("radiation to the gas %.17g J, particles lost %.17g J (2 ranks: %.17g, %.17g)\n",
              one.radiationToGas, lost, two.radiationToGas, lostTwo);
}

TEST(DemServerRanks, APeerOfProtocol12ReceivesNoRadiationHeat) {
  const RunResult old = run(0, {0, 1}, 900.0, 2);
  const RunResult now = run(0, {0, 1}, 900.0);
  EXPECT_EQ(old.stepsWithQrad, 0);
  EXPECT_EQ(old.sources.count(std::string(f::kRadiationHeat)), 0u);
  EXPECT_EQ(now.stepsWithQrad, 3);
  // The DEM books the same radiation either way (the particles do not know who receives it).
  EXPECT_EQ(named(old.demDone.ledger().energy(), "dem.heat_radiation_J"),
            named(now.demDone.ledger().energy(), "dem.heat_radiation_J"));
  EXPECT_LT(named(old.demDone.ledger().energy(), "dem.heat_radiation_J"), 0.0);
  // A decomposed 1.2 run gets no Q_rad either.
  const RunResult oldTwo = run(2, {0, 1}, 900.0, 2);
  EXPECT_EQ(oldTwo.stepsWithQrad, 0);
}

// Protocol 1.5: mom_p, the momentum of the mass the particles release (burning beads moving in
// the gas). Σ mom_p V_c Δt over cells and steps equals the DEM's dem.momentum_released_*_Ns to
// 1e-12, whole grid or 2 ranks (partial Sources); a 1.4 peer, whole or decomposed, receives none.
TEST(DemServerRanks, ReleasedMomentumReachesPeersOfProtocol15Only) {
  const Extras burning{.reacting = true};
  const RunResult one = run(0, {0, 1}, 0.0, proto::kProtocolVersion.minor, burning);
  const RunResult two = run(2, {0, 1}, 0.0, proto::kProtocolVersion.minor, burning);
  EXPECT_EQ(one.stepsWithMomP, 3);
  EXPECT_EQ(two.stepsWithMomP, 3);
  const char* names[3] = {"dem.momentum_released_x_Ns", "dem.momentum_released_y_Ns",
                          "dem.momentum_released_z_Ns"};
  double size = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double dem = named(one.demDone.diagnostics(), names[a]);
    size = std::max(size, std::abs(dem));
    EXPECT_NEAR(one.momentumToGas[a], dem, 1e-12 * std::abs(dem)) << names[a];
    const double demTwo = named(two.demDone.diagnostics(), names[a]);
    EXPECT_NEAR(two.momentumToGas[a], demTwo, 1e-12 * std::abs(demTwo)) << names[a];
  }
  EXPECT_GT(size, 0.0); // the beads move (settling) while they burn
  std::printf("released momentum to the gas %.6g %.6g %.6g N s\n", one.momentumToGas[0],
              one.momentumToGas[1], one.momentumToGas[2]);
  for (std::uint32_t ranks : {0u, 2u}) {
    const RunResult old = run(int(ranks), {0, 1}, 0.0, proto::kMinorReleasedMomentum - 1, burning);
    EXPECT_EQ(old.stepsWithMomP, 0) << ranks << " ranks";
    EXPECT_EQ(old.sources.count(std::string(f::kReleasedMomentum)), 0u);
    EXPECT_EQ(old.stepsWithQrad, 3); // a 1.4 peer still gets Q_rad
  }
}

// Protocol 1.5: Q_split of a decomposed CFD is extensive: 2 ranks each send their own part of a
// cell's heat (the shared cell 13 split 0.375/0.625) and the server sums them, so the particles
// get what one whole-grid participant sending the whole heat gives them (to round-off). Given
// plus unassigned is, per step, Σ_c Q_split V_c (up to the window's convective response).
TEST(DemServerRanks, HeatSplitFromTwoRanksIsSummedPerCell) {
  const Extras split{.split = true};
  const RunResult one = run(0, {0, 1}, 0.0, proto::kProtocolVersion.minor, split);
  const RunResult two = run(2, {1, 0}, 0.0, proto::kProtocolVersion.minor, split);
  const RunResult none = run(0);
  const auto energy = [](const RunResult& r, const char* name) {
    return named(r.demDone.ledger().energy(), name);
  };
  const double booked =
      energy(one, "dem.heat_from_gas_J") + energy(one, "dem.heat_split_unassigned_J");
  const double bookedTwo =
      energy(two, "dem.heat_from_gas_J") + energy(two, "dem.heat_split_unassigned_J");
  EXPECT_LE(relDiff(booked, bookedTwo), kRegrouped) << booked << " vs " << bookedTwo;
  EXPECT_LE(relDiff(named(one.demDone.diagnostics(), "mean_T_p"),
                    named(two.demDone.diagnostics(), "mean_T_p")),
            kRegrouped);
  double sent = 0.0;
  for (std::size_t c = 0; c < kCells; ++c) {
    sent += 3 * 2e5 * (1.0 + 0.1 * double(c)) * (c % 2 == 0 ? 1.0 : -0.5) * kH * kH * kH;
  }
  const double delta = booked - energy(none, "dem.heat_from_gas_J");
  std::printf("split sent %.9g J, booked %.9g J (unassigned %.6g J)\n", sent, delta,
              energy(one, "dem.heat_split_unassigned_J"));
  EXPECT_NEAR(delta, sent, 1e-3 * std::abs(sent));
  EXPECT_NE(named(one.demDone.diagnostics(), "mean_T_p"),
            named(none.demDone.diagnostics(), "mean_T_p"));
  // The particles' energy balance closes with the split booked as heat from the gas.
  const double thermal0 = energy(none, "dem.thermal_energy_J") -
                          energy(none, "dem.heat_from_gas_J") -
                          energy(none, "dem.heat_radiation_J") - energy(none, "dem.heat_wall_J");
  const double thermal = energy(one, "dem.thermal_energy_J") - energy(one, "dem.heat_from_gas_J") -
                         energy(one, "dem.heat_radiation_J") - energy(one, "dem.heat_wall_J");
  EXPECT_NEAR(thermal, thermal0, 1e-9 * std::abs(thermal0));
}
