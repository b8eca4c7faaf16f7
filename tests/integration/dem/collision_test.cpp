// Binary collisions (docs/physics.md §2.1): restitution, contact duration, momentum.
#include <gtest/gtest.h>

#include "dem_test_util.h"

using namespace coredem::dem;
using namespace coredem::dem::testing;

namespace {
struct CollisionResult {
  double restitution;
  int contactSteps;
  double dt;
  double tcol;
  std::vector<double> p0, p1;
};

/// Head-on collision of two 1 mm glass spheres (docs/physics.md §7) approaching at ±v; `phase`
/// places the first overlap at that fraction of a step.
CollisionResult collide(double v, double phase, double d1 = 1e-3, double d2 = 1e-3) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  for (double d : {d1, d2}) {
    ParticleSet s;
    s.packing = Packing::Explicit;
    s.diameter = d;
    c.particleSets.push_back(s);
  }
  const double m1 = 2500 * kPi / 6 * d1 * d1 * d1, m2 = 2500 * kPi / 6 * d2 * d2 * d2;
  const double meff = m1 * m2 / (m1 + m2);
  const double ln = std::log(0.97);
  const double tcol =
      std::sqrt(meff / 1000.0) * std::sqrt(kPi * kPi + ln * ln); // Eq. 12 with Eq. 13
  const double mmin = std::min(m1, m2);
  const double dt = std::sqrt(mmin / 2 / 1000.0) * std::sqrt(kPi * kPi + ln * ln) / 50;
  const double gap = 2 * v * dt * (5 + phase);
  c.particleSets[0].positions = {0, 0, 0};
  c.particleSets[0].velocities = {v, 0, 0};
  c.particleSets[1].positions = {0.5 * (d1 + d2) + gap, 0, 0};
  c.particleSets[1].velocities = {-v, 0, 0};
  DemSystem sys(c, BackendKind::Cpu, 1);
  EXPECT_NEAR(sys.dtDemMax(), dt, 1e-15 * dt);
  CollisionResult r{};
  r.dt = sys.dtDemMax();
  r.tcol = tcol;
  r.p0 = momentum(sys.particles());
  bool started = false;
  for (int k = 0; k < 400; ++k) {
    sys.advance(r.dt, 1);
    if (sys.pairContactCount() > 0) {
      ++r.contactSteps;
      started = true;
    } else if (started) {
      break;
    }
  }
  const ParticleData p = sys.particles();
  const auto idx = indexByGid(p);
  r.restitution = (p.velocity[3 * idx[1]] - p.velocity[3 * idx[0]]) / (2 * v);
  r.p1 = momentum(p);
  return r;
}
} // namespace

TEST(BinaryCollision, RestitutionAndContactDuration) {
  // e_n within 1e-3 (docs/physics.md §2.1 analytic check) and t_col within 2 Δt_DEM, for contact
  // onsets at several phases within a step.
  for (double phase : {0.25, 0.5, 0.75}) {
    for (double v : {0.05, 0.5, 1.0}) {
      const CollisionResult r = collide(v, phase);
      EXPECT_NEAR(r.restitution, 0.97, 1e-3) << "v " << v << " phase " << phase;
      EXPECT_NEAR(r.contactSteps * r.dt, r.tcol, 2 * r.dt) << "v " << v << " phase " << phase;
    }
  }
}

TEST(BinaryCollision, UnequalSizesUseReducedMass) {
  const CollisionResult r = collide(0.3, 0.5, 1e-3, 1.5e-3);
  EXPECT_NEAR(r.contactSteps * r.dt, r.tcol, 2 * r.dt);
  // momentum is conserved to round-off (|p| ~ 1e-6 kg m/s)
  for (int d = 0; d < 3; ++d)
    EXPECT_NEAR(r.p1[d], r.p0[d], 1e-20);
}

TEST(ParticleCollisions, ConserveMomentumToRoundOff) {
  // 343 particles of the agitated deck without walls or gravity: only pair forces act.
  DemSystem sys(agitatedDeck(343, false), BackendKind::Cpu, 1);
  const ParticleData p0 = sys.particles();
  const auto m0 = momentum(p0);
  double scale = 0; // Σ m|v|
  for (std::size_t i = 0; i < p0.count; ++i)
    scale +=
        p0.mass[i] * std::hypot(p0.velocity[3 * i], p0.velocity[3 * i + 1], p0.velocity[3 * i + 2]);
  std::size_t contacts = 0;
  const double dt = sys.dtDemMax();
  for (int k = 0; k < 40; ++k) {
    sys.advance(50 * dt, 50);
    contacts += sys.pairContactCount();
  }
  EXPECT_GT(contacts, 50u); // the run really has collisions
  const auto m1 = momentum(sys.particles());
  for (int d = 0; d < 3; ++d)
    EXPECT_NEAR(m1[d], m0[d], 1e-13 * scale) << "component " << d;
}

TEST(BadInput, NonFinitePositionsAreRefusedAndRunawaysSurvive) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {0, 0, NAN};
  c.particleSets.push_back(s);
  EXPECT_THROW(DemSystem(c, BackendKind::Cpu, 1), coredem::UserError);
  // A particle flung at 1e300 m/s ends ~1e294 m away: the neighbour grid coarsens its cells
  // (bounded cell count) instead of allocating or overflowing; the run continues.
  c.particleSets[0].positions = {0, 0, 0, 0.01, 0, 0};
  c.particleSets[0].velocities = {0, 0, 0, 1e300, 0, 0};
  DemSystem sys(c, BackendKind::Cpu, 1);
  for (int k = 0; k < 3; ++k)
    sys.advance(sys.dtDemMax(), 1);
  EXPECT_GE(sys.stageTimes().rebuilds, 2u);
  const ParticleData p = sys.particles();
  const auto idx = indexByGid(p);
  EXPECT_GT(p.position[3 * idx[1]], 1e290);
  EXPECT_EQ(p.position[3 * idx[0]], 0.0);
}
