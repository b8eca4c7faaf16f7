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
  const double dt = std::sqrt(mmin / 2 / 1000.0) * kPi / 50; // undamped π √(m_eff/k_n) / 50
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

namespace {
/// Σ ½ m v² + ½ I ω² (J), I = 2/5 m R².
double kineticEnergy(const ParticleData& p) {
  double e = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) {
    const double* v = &p.velocity[3 * i];
    const double* w = &p.angularVelocity[3 * i];
    const double r = p.radius[i];
    e += 0.5 * p.mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
         0.2 * p.mass[i] * r * r * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  return e;
}
} // namespace

// A tiny restitution (e_n = 1e-10, 1e-30: η_n → 2√(k_n m_eff), critical damping) keeps
// Δt_DEM,max at π √(m_eff/k_n)/50 (docs/physics.md §2.1), not at the damped t_col/50, which
// grows as |ln e_n| (0.46/ω_0 and 1.38/ω_0, the latter beyond the integrator's stability limit
// 0.83/ω_0 of one critically damped contact). Head-on at ±0.5 m/s for 20 t_0: every sub-step
// finite, the kinetic energy never above the initial (to round-off, 1e-12), and the spheres part at
// no more than e_n times the approach speed: the critically damped overlap relaxes to zero without
// crossing it, so the separation speed left is the round-off of the decay (< 1e-9 of 1 m/s).
TEST(BinaryCollision, TinyRestitutionStaysStableAndDoesNotRebound) {
  for (double en : {1e-10, 1e-30}) {
    DemConfig c;
    c.gravity = {0, 0, 0};
    c.materials[0].en = en;
    const double d = 1e-3, v = 0.5, m = 2500 * kPi / 6 * d * d * d, meff = m / 2;
    const double t0 = kPi * std::sqrt(meff / 1000.0);
    for (int k = 0; k < 2; ++k) {
      ParticleSet s;
      s.packing = Packing::Explicit;
      s.diameter = d;
      s.positions = {k * (d + 2 * v * t0 / 50 * 5.3), 0, 0};
      s.velocities = {k == 0 ? v : -v, 0, 0};
      c.particleSets.push_back(s);
    }
    DemSystem sys(c, BackendKind::Cpu, 1);
    const double dt = sys.dtDemMax();
    const double e0 = kineticEnergy(sys.particles());
    double worst = 0.0; // largest kinetic energy / initial
    bool finite = true;
    const int steps = static_cast<int>(std::ceil(20 * t0 / dt));
    for (int k = 0; k < steps && finite; ++k) {
      sys.advance(dt, 1);
      const ParticleData p = sys.particles();
      for (double x : p.position)
        finite = finite && std::isfinite(x);
      worst = std::max(worst, kineticEnergy(p) / e0);
    }
    ASSERT_TRUE(finite) << "e_n = " << en << ": Δt_DEM,max = " << dt << " s = " << dt / t0
                        << " t_0";
    EXPECT_LE(worst, 1.0 + 1e-12) << "e_n = " << en << ": Δt_DEM,max = " << dt / t0 << " t_0";
    const ParticleData p = sys.particles();
    const auto idx = indexByGid(p);
    const double apart = p.velocity[3 * idx[1]] - p.velocity[3 * idx[0]];
    EXPECT_LE(apart, en * 2 * v + 1e-9) << "e_n = " << en << ": Δt_DEM,max = " << dt / t0 << " t_0";
  }
}

// A small bed (64 spheres of 1 mm in a 5 mm box, k_n = 1000 N/m, under gravity) settling with
// e_n = 1e-10 and 1e-30: Δt_DEM,max stays at π √(m/k_n)/50 so that each sphere's several
// contacts (up to ~7 in the packing: a stiffer mode than one contact's) stay within the
// integrator's stability limit. The mechanical energy KE + Σ m g z can only fall in a
// dissipative system (the elastic energy it leaves out is ≥ 0): checked every 0.1 ms for
// 30 ms (the fall and the first impacts) to 1e-9 of the initial potential energy above the
// floor.
TEST(PackedBed, TinyRestitutionSettlesWithoutGainingEnergy) {
  for (double en : {1e-10, 1e-30}) {
    DemConfig c;
    c.materials[0].en = en;
    c.materials[0].mu = 0.3;
    const double d = 1e-3, g = 9.81;
    ParticleSet s;
    s.packing = Packing::Lattice;
    s.spacing = 1.05 * d;
    s.count = 64;
    s.diameter = d;
    s.regionMin = {0, 0, 0};
    s.regionMax = {4.2e-3, 4.2e-3, 4.2e-3};
    s.velocityJitter = 0.05;
    s.seed = 5;
    c.particleSets.push_back(s);
    c.addBox({-0.4e-3, -0.4e-3, 0}, {4.6e-3, 4.6e-3, 10e-3});
    DemSystem sys(c, BackendKind::Cpu, 1);
    auto energy = [&](const ParticleData& p) {
      double e = kineticEnergy(p);
      for (std::size_t i = 0; i < p.count; ++i)
        e += p.mass[i] * g * p.position[3 * i + 2];
      return e;
    };
    const ParticleData p0 = sys.particles();
    const double e0 = energy(p0);
    double pot = 0.0; // Σ m g (z − R): the potential energy above the floor
    for (std::size_t i = 0; i < p0.count; ++i)
      pot += p0.mass[i] * g * (p0.position[3 * i + 2] - 0.5 * d);
    const double dtCfd = 1e-4;
    const int nSub = TimeHandler::subStepsFor(dtCfd, sys.dtDemMax());
    double worst = -HUGE_VAL; // largest (E − E_0)/pot
    for (int k = 0; k < 300; ++k) {
      sys.advance(dtCfd, nSub);
      const ParticleData p = sys.particles();
      const double e = energy(p);
      worst = std::max(worst, std::isfinite(e) ? (e - e0) / pot : HUGE_VAL);
    }
    EXPECT_LE(worst, 1e-9) << "e_n = " << en << ", " << nSub << " sub-steps of 0.1 ms";
  }
}
