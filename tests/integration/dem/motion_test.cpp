// Single-particle motion: friction-driven rolling on a wall and Gidaspow terminal velocity.
#include <gtest/gtest.h>

#include "dem_test_util.h"

using namespace coredem::dem;
using namespace coredem::dem::testing;

TEST(Wall, SlidingSphereReachesRollingAtFiveSevenths) {
  // docs/physics.md §2.1 analytic check: a sphere launched sliding (ω = 0) on a frictional floor
  // ends rolling at v = 5/7 v0 (angular momentum about the contact point is conserved).
  DemConfig c;
  c.materials[0].mu = 0.3;
  c.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
  ParticleSet s;
  s.packing = Packing::Explicit;
  const double r = 0.5e-3, m = 2500 * 4.0 / 3.0 * kPi * r * r * r;
  const double v0 = 0.4;
  s.positions = {0, 0, r - m * 9.81 / 1000.0}; // resting overlap δ = m g / k_n
  s.velocities = {v0, 0, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  // Sliding lasts 2 v0/(7 μ g) = 0.039 s; run 0.1 s.
  const double dtCfd = 1e-3;
  const int nSub = coredem::dem::TimeHandler::subStepsFor(dtCfd, sys.dtDemMax());
  for (int k = 0; k < 100; ++k)
    sys.advance(dtCfd, nSub);
  const ParticleData p = sys.particles();
  EXPECT_NEAR(p.velocity[0], 5.0 / 7.0 * v0, 0.01 * 5.0 / 7.0 * v0);
  // rolling without slip: ω_y R_contact = v_x (lever arm R − δ)
  const double lever = r - (r - p.position[2]);
  EXPECT_NEAR(p.angularVelocity[1] * lever, p.velocity[0], 0.01 * p.velocity[0]);
  EXPECT_EQ(sys.contactCount(), 1u);
}

namespace {
/// Terminal velocity from Gidaspow/Wen–Yu (docs/physics.md §2.2) by bisection, independent of the
/// kernels: (ρ_p − ρ_g) g = ¾ C_D(Re) ε^−1.65 ρ_g v²/d with Re = ε ρ_g d v/μ_g
/// (weight − buoyancy = β V_p v/(1−ε)).
double terminalVelocity(double rhoP, double rhoG, double mu, double d, double eps, double g) {
  auto residual = [&](double v) {
    const double re = eps * rhoG * d * v / mu;
    const double cd = re < 1000 ? 24.0 / re * (1 + 0.15 * std::pow(re, 0.687)) : 0.44;
    return 0.75 * cd * std::pow(eps, -1.65) * rhoG * v * v / d - (rhoP - rhoG) * g;
  };
  double lo = 1e-9, hi = 100.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (residual(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}
} // namespace

TEST(Drag, SingleSphereSettlesAtGidaspowTerminalVelocity) {
  const double d = 0.2e-3, rhoP = 2500, rhoG = 1.2, mu = 1.8e-5, g = 9.81;
  DemConfig c;
  c.materials[0].kn = 1e-3; // no contacts here: a soft spring only lengthens Δt_DEM
  c.gravity = {0, 0, -g};
  c.grid.origin = {-0.05, -0.05, -10};
  c.grid.spacing = {0.1, 0.1, 11};
  c.grid.counts = {1, 1, 1};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.diameter = d;
  s.density = rhoP;
  s.positions = {0, 0, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  // Quiescent gas with hydrostatic pressure: ∇p = ρ_g g gives the buoyancy −V_p ∇p.
  const std::vector<double> ug{0, 0, 0}, gradP{0, 0, -rhoG * g}, rho{rhoG}, muv{mu};
  sys.setGasFields(GasFieldsView{ug, gradP, {}, rho, muv, {}, {}, {}, {}, {}});
  const double vp = kPi / 6 * d * d * d;
  const double eps = 1 - vp / (0.1 * 0.1 * 11);
  const double vt = terminalVelocity(rhoP, rhoG, mu, d, eps, g);
  const double dtCfd = 5e-3;
  const int nSub = coredem::dem::TimeHandler::subStepsFor(dtCfd, sys.dtDemMax());
  for (int k = 0; k < 200; ++k)
    sys.advance(dtCfd, nSub); // 1 s ≈ 10 relaxation times
  const ParticleData p = sys.particles();
  EXPECT_NEAR(-p.velocity[2], vt, 0.005 * vt) << "analytic v_t = " << vt;
  EXPECT_NEAR(p.velocity[0], 0.0, 1e-15);
  // the sub-step-averaged sources see the particle: ε_g and K_sl U_s = K_sl v_p
  const CellSources& src = sys.advance(dtCfd, nSub);
  EXPECT_NEAR(src.epsG[0], eps, 1e-15);
  EXPECT_GT(src.kSl[0], 0.0);
  EXPECT_NEAR(src.kSlUs[2] / src.kSl[0], -vt, 0.005 * vt);
}
