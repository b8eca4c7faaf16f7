// Kernel unit tests on the CPU against docs/physics.md §1.1 and §2 (Eqs. 9–17).
#include <cmath>
#include <initializer_list>
#include <utility>

#include <gtest/gtest.h>

#include "coredem/dem/kernels/body_force.h"
#include "coredem/dem/kernels/cell_sources.h"
#include "coredem/dem/kernels/collision_time.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/drag_gidaspow.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/kernels/wall_contact.h"

using namespace coredem::dem::kernels;

namespace {
constexpr double kPi = 3.14159265358979323846;
// Patil glass (docs/physics.md §7): d = 1 mm, ρ = 2500, k_n = 1000, e_n = 0.97.
const double kMass = 2500.0 * kPi / 6.0 * 1e-9;

// Test-only references (the engine uses collisionTime with the pair's η_n, and
// gidaspowParticleCoefficient).

/// Eq. 12 with η_n from Eq. 13 (restitution e_n).
double collisionTimeFromRestitution(double kn, double meff, double en) {
  return collisionTime(kn, meff, normalDamping(kn, meff, en));
}

/// Gidaspow's interphase momentum exchange coefficient β (kg/m³/s), ε already clipped, written
/// as the paper does (Ergun below the switch ε of GidaspowParams, Wen–Yu above).
double gidaspowBeta(double eps, double rhoG, double muG, double dp, double slip) {
  const double s = 1.0 - eps;
  if (eps <= GidaspowParams{}.epsSwitch) {
    return 150.0 * s * s * muG / (eps * dp * dp) + 1.75 * s * rhoG * slip / dp;
  }
  const double re = reynoldsParticle(eps, rhoG, dp, slip, muG);
  if (re <= 0.0) {
    // Re → 0: C_D ρ_g |Δu| → 24 μ_g/(ε d_p), so β → 18 μ_g (1−ε) ε^−2.65 / d_p² (finite).
    return 18.0 * muG * s * std::pow(eps, -2.65) / (dp * dp);
  }
  return 0.75 * dragCoefficientWenYu(re) * eps * s * rhoG * slip * std::pow(eps, -2.65) / dp;
}
} // namespace

TEST(Damping, Eq13MatchesClosedFormAndLimits) {
  const double meff = kMass / 2, kn = 1000, en = 0.97;
  const double l = std::log(en);
  const double expected = 2 * std::sqrt(kn * meff) * std::fabs(l) / std::sqrt(kPi * kPi + l * l);
  EXPECT_NEAR(normalDamping(kn, meff, en), expected, 1e-15 * expected);
  EXPECT_DOUBLE_EQ(normalDamping(kn, meff, 1.0), 0.0);                      // elastic
  EXPECT_DOUBLE_EQ(normalDamping(kn, meff, 0.0), 2 * std::sqrt(kn * meff)); // critical
  EXPECT_DOUBLE_EQ(effectiveMass(2.0, 2.0), 1.0);
  EXPECT_DOUBLE_EQ(effectiveMass(2.0, 0.0), 2.0); // wall
}

TEST(Damping, Eq11RestitutionRecoveredFromEq12And13) {
  // e_n = exp(−η_n t_col/(2 m_eff)) must return the input e_n (Eqs. 11–13 consistent).
  for (double en : {0.1, 0.5, 0.9, 0.97, 0.999}) {
    const double meff = 3.3e-7, kn = 250.0;
    const double eta = normalDamping(kn, meff, en);
    const double t = collisionTime(kn, meff, eta);
    EXPECT_NEAR(std::exp(-eta * t / (2 * meff)), en, 1e-13) << "e_n = " << en;
  }
}

TEST(CollisionTime, Eq12PatilValue) {
  // docs/physics.md §7 [V]: t_col = 8.04e-5 s, Δt_DEM = 1.61e-6 s for the glass pair.
  const double t = collisionTimeFromRestitution(1000.0, kMass / 2, 0.97);
  EXPECT_NEAR(t, std::sqrt(kMass / 2 / 1000.0) * std::sqrt(kPi * kPi + std::pow(std::log(0.97), 2)),
              1e-18);
  EXPECT_NEAR(t, 8.04e-5, 0.005e-5);
  EXPECT_NEAR(t / 50, 1.61e-6, 0.005e-6);
  EXPECT_TRUE(std::isinf(collisionTime(1.0, 1.0, 2.0))); // critically damped
}

TEST(LsdContact, NormalSpringAndDashpotEq9) {
  const LsdParams p{1000, 2000.0 / 7, 0.01, 0.005, 0.1};
  const Vec3 n{1, 0, 0};
  // Approaching head-on at 0.3 m/s, overlap 1e-5 m.
  const LsdResult r = lsdContact(p, n, 1e-5, Vec3{0.3, 0, 0}, 5e-4, Vec3{0, 0, 0}, 1e-6);
  EXPECT_NEAR(r.force.x, -1000 * 1e-5 - 0.01 * 0.3, 1e-15);
  EXPECT_EQ(r.force.y, 0.0);
  EXPECT_EQ(r.force.z, 0.0);
  EXPECT_EQ(norm(r.torque), 0.0);
}

TEST(LsdContact, TangentialSpringBelowCoulombLimitEq10) {
  const LsdParams p{1000, 2000.0 / 7, 0.0, 0.002, 0.5};
  const Vec3 n{0, 0, 1};
  const Vec3 old{1e-7, 0, 3e-8}; // has a normal component: projected away
  const double dt = 1e-6;
  const LsdResult r = lsdContact(p, n, 1e-4, Vec3{0.01, 0, 0}, 5e-4, old, dt);
  const double dT = 1e-7 + 0.01 * dt;
  EXPECT_NEAR(r.deltaT.x, dT, 1e-20);
  EXPECT_EQ(r.deltaT.z, 0.0);
  EXPECT_NEAR(r.force.x, -p.kt * dT - p.etat * 0.01, 1e-15);
  // torque on i = L n × f_t = 5e-4 (0,0,1)×(f_x,0,0) = (0, 5e-4 f_x, 0)
  EXPECT_NEAR(r.torque.y, 5e-4 * r.force.x, 1e-18);
}

TEST(LsdContact, CoulombLimitCapsSpringPartMfixForm) {
  const LsdParams p{1000, 2000.0 / 7, 0.0, 0.003, 0.1};
  const Vec3 n{0, 0, 1};
  const LsdResult r = lsdContact(p, n, 1e-5, Vec3{0.2, 0, 0}, 5e-4, Vec3{1e-4, 0, 0}, 1e-6);
  const double fn = 1000 * 1e-5;
  // spring part capped at μ|f_n|, dashpot added afterwards; δ_t rescaled to μ|f_n|/k_t.
  EXPECT_NEAR(r.force.x, -0.1 * fn - 0.003 * 0.2, 1e-15);
  EXPECT_NEAR(r.deltaT.x, 0.1 * fn / p.kt, 1e-18);
}

TEST(LsdContact, MirrorExactForBothSides) {
  const LsdParams p{800, 250, 0.02, 0.01, 0.3};
  const Vec3 xi{0.1, 0.2, 0.3}, xj{0.1007, 0.2003, 0.3002};
  const Vec3 vi{0.3, -0.1, 0.2}, vj{-0.2, 0.05, 0.1};
  const Vec3 wi{10, -3, 7}, wj{-4, 8, 2};
  const double ri = 4e-4, rj = 5e-4;
  const Vec3 dij = xj - xi, dji = xi - xj;
  const double l = norm(dij);
  const Vec3 nij = (1.0 / l) * dij, nji = (1.0 / norm(dji)) * dji;
  const double lij = leverArm(l, ri, rj), lji = leverArm(l, rj, ri);
  const Vec3 hist{3e-7, -1e-7, 2e-7};
  const LsdResult a = lsdContact(p, nij, ri + rj - l,
                                 relativeVelocity(vi, vj, wi, wj, lij, lji, nij), lij, hist, 1e-6);
  const LsdResult b = lsdContact(p, nji, ri + rj - l,
                                 relativeVelocity(vj, vi, wj, wi, lji, lij, nji), lji, -hist, 1e-6);
  EXPECT_EQ(a.force.x, -b.force.x);
  EXPECT_EQ(a.force.y, -b.force.y);
  EXPECT_EQ(a.force.z, -b.force.z);
  EXPECT_EQ(a.deltaT.x, -b.deltaT.x);
  EXPECT_EQ(a.deltaT.y, -b.deltaT.y);
  EXPECT_EQ(a.deltaT.z, -b.deltaT.z);
}

TEST(LsdContact, LeverArmRadicalPlane) {
  EXPECT_DOUBLE_EQ(leverArm(1.0, 0.5, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(leverArm(2.0, 1.5, 1.0), 1.0 + (2.25 - 1.0) / 4.0);
}

TEST(WallContact, OverlapNormalAndLever) {
  const Wall wall = planeWall({0, 0, 0}, {0, 0, 1});
  WallTouch t[kMaxWallTouches];
  ASSERT_EQ(wallTouches(wall, Vec3{5, 5, 4e-4}, 5e-4, t), 1);
  EXPECT_DOUBLE_EQ(5e-4 - t[0].h, 1e-4);
  const Vec3 w = t[0].n;
  const LsdParams p{1000, 2000.0 / 7, 0.0, 0.0, 0.1};
  const LsdResult r =
      wallContact(p, w, 1e-4, Vec3{0, 0, 0}, Vec3{0, 0, 0}, 5e-4, Vec3{0, 0, 0}, 1e-6);
  EXPECT_NEAR(r.force.z, 1000 * 1e-4, 1e-15); // pushes the particle up
  // Spinning about y with ω: the contact point (0,0,-L) moves at ω×(−L e_z) = (−ωL, 0, 0).
  const LsdResult s = wallContact(LsdParams{1000, 100, 0, 0.5, 10}, w, 1e-4, Vec3{0, 0, 0},
                                  Vec3{0, 100, 0}, 5e-4, Vec3{0, 0, 0}, 1e-6);
  const double L = 5e-4 - 1e-4;
  EXPECT_NEAR(s.deltaT.x, -100 * L * 1e-6, 1e-18);
  EXPECT_GT(s.force.x, 0.0); // friction opposes the contact point's slip
}

namespace {
/// A wall revolved about the z axis through the origin from a profile of (t, r) points.
Wall revolved(std::initializer_list<std::pair<double, double>> profile, int side) {
  Wall w{};
  w.point = Vec3{0, 0, 0};
  w.normal = Vec3{0, 0, 1};
  w.kind = kWallRevolved;
  w.side = side;
  for (const auto& [t, r] : profile) {
    w.t[w.points] = t;
    w.r[w.points] = r;
    ++w.points;
  }
  return w;
}
} // namespace

// Surfaces of revolution (docs/physics.md §2.1 "Walls"): distances and normals against the
// geometry by hand, to round-off (1e-15 m), for a capped vessel (inside), a capped insert
// (outside, with its convex rims) and a cone.
TEST(WallContact, RevolvedFacesRimsCornersAndTheFarSide) {
  const double R = 0.01, H = 0.05, reach = 5e-4, tol = 1e-15;
  WallTouch t[kMaxWallTouches];
  // Vessel: bottom cap, side, top cap, particles inside.
  const Wall vessel = revolved({{0, 0}, {0, R}, {H, R}, {H, 0}}, 1);
  ASSERT_EQ(wallTouches(vessel, Vec3{R - 4e-4, 0, H / 2}, reach, t), 1);
  EXPECT_NEAR(t[0].h, 4e-4, tol);
  EXPECT_NEAR(t[0].n.x, -1.0, tol); // towards the axis
  EXPECT_EQ(t[0].feature, 1);
  // The corner of floor and side: one touch per face (a concave corner), in feature order.
  ASSERT_EQ(wallTouches(vessel, Vec3{0, R - 4e-4, 3e-4}, reach, t), 2);
  EXPECT_NEAR(t[0].h, 3e-4, tol);
  EXPECT_NEAR(t[0].n.z, 1.0, tol);
  EXPECT_NEAR(t[1].h, 4e-4, tol);
  EXPECT_NEAR(t[1].n.y, -1.0, tol);
  // Slightly through the side: pushed back (h < 0); far behind it: the wall's other side.
  ASSERT_EQ(wallTouches(vessel, Vec3{R + 1e-4, 0, H / 2}, reach, t), 1);
  EXPECT_NEAR(t[0].h, -1e-4, tol);
  EXPECT_EQ(wallTouches(vessel, Vec3{R + 2e-3, 0, H / 2}, reach, t), 0);
  // Insert (outside): beyond its top rim the rim itself, distance and normal from the rim
  // point; along the side up to the rim the side, continuous at the rim's boundary.
  const Wall insert = revolved({{0, 0}, {0, R}, {H, R}, {H, 0}}, -1);
  const double a = 2e-4, b = 3e-4;
  ASSERT_EQ(wallTouches(insert, Vec3{R + b, 0, H + a}, reach, t), 1);
  EXPECT_NEAR(t[0].h, std::hypot(a, b), tol);
  EXPECT_NEAR(t[0].n.x, b / std::hypot(a, b), 1e-12);
  EXPECT_NEAR(t[0].n.z, a / std::hypot(a, b), 1e-12);
  EXPECT_EQ(t[0].feature, 3 + 2 - 1); // segments 0..2, then the interior points 1, 2
  ASSERT_EQ(wallTouches(insert, Vec3{R + b, 0, H - 1e-9}, reach, t), 1);
  EXPECT_NEAR(t[0].h, b, tol);
  ASSERT_EQ(wallTouches(insert, Vec3{R + b, 0, H + 1e-9}, reach, t), 1);
  EXPECT_NEAR(t[0].h, b, 1e-12);
  // Cone (frustum) from r = 4 mm at t = 0 to R at t = H: the distance to its line.
  const double r0 = 0.004;
  const Wall cone = revolved({{0, r0}, {H, R}}, 1);
  const double s = 0.006, z = 0.02, L = std::hypot(H, R - r0);
  const double expect = ((r0 + (R - r0) * z / H) - s) * H / L; // (radius at z − s) cos(angle)
  ASSERT_EQ(wallTouches(cone, Vec3{0, s, z}, 1e-2, t), 1);
  EXPECT_NEAR(t[0].h, expect, tol);
  EXPECT_LE(wallClearance(cone, Vec3{0, s, z}), t[0].h + tol);
}

TEST(Drag, GidaspowErgunBranch) {
  const double eps = 0.6, rho = 1.2, mu = 1.8e-5, d = 1e-3, slip = 0.7;
  const double s = 1 - eps;
  const double beta = 150 * s * s * mu / (eps * d * d) + 1.75 * s * rho * slip / d;
  EXPECT_NEAR(gidaspowBeta(eps, rho, mu, d, slip), beta, 1e-12 * beta);
  const double vol = kPi / 6 * d * d * d;
  EXPECT_NEAR(gidaspowParticleCoefficient(GidaspowParams{}, eps, rho, mu, d, vol, slip),
              beta * vol / s, 1e-12 * beta * vol / s);
}

TEST(Drag, GidaspowWenYuBranchBothReRegimes) {
  const double rho = 1.2, mu = 1.8e-5, d = 1e-3;
  for (double slip : {0.05, 3.0, 30.0}) { // Re_p ≈ 3, 190, >1000
    const double eps = 0.9;
    const double re = eps * rho * d * slip / mu;
    const double cd = re < 1000 ? 24 / re * (1 + 0.15 * std::pow(re, 0.687)) : 0.44;
    const double beta = 0.75 * cd * eps * (1 - eps) * rho * slip * std::pow(eps, -2.65) / d;
    EXPECT_NEAR(gidaspowBeta(eps, rho, mu, d, slip), beta, 1e-12 * beta) << "slip " << slip;
  }
}

TEST(Drag, WenYuDragCoefficientNearlyContinuousAtRe1000) {
  // Schiller–Naumann gives 24/1000 (1 + 0.15·1000^0.687) = 0.4365 at Re = 1000 vs 0.44 above:
  // the law has a 0.8 % jump there (as in MFiX); check both sides and the size of the jump.
  const double below = dragCoefficientWenYu(1000.0 * (1 - 1e-12));
  const double above = dragCoefficientWenYu(1000.0);
  EXPECT_NEAR(below, 24.0 / 1000.0 * (1 + 0.15 * std::pow(1000.0, 0.687)), 1e-9);
  EXPECT_DOUBLE_EQ(above, 0.44);
  EXPECT_LT(std::fabs(above - below) / above, 0.009);
  EXPECT_DOUBLE_EQ(dragCoefficientWenYu(5000.0), 0.44);
}

TEST(Drag, EpsClipAndStokesLimit) {
  const double rho = 1.2, mu = 1.8e-5, d = 1e-3, vol = kPi / 6e9;
  const GidaspowParams p{};
  // ε below ε_min = 0.35 is clipped (docs/physics.md §1.1 [C]).
  EXPECT_DOUBLE_EQ(gidaspowParticleCoefficient(p, 0.2, rho, mu, d, vol, 0.5),
                   gidaspowParticleCoefficient(p, 0.35, rho, mu, d, vol, 0.5));
  // Zero slip in the dilute branch: finite, equal to the Re → 0 limit.
  const double k0 = gidaspowParticleCoefficient(p, 0.95, rho, mu, d, vol, 0.0);
  const double kSmall = gidaspowParticleCoefficient(p, 0.95, rho, mu, d, vol, 1e-12);
  EXPECT_TRUE(std::isfinite(k0));
  EXPECT_NEAR(k0, kSmall, 1e-6 * k0);
  // Single sphere (ε → 1): Stokes drag 3π μ d at Re → 0.
  const double kStokes = gidaspowParticleCoefficient(p, 1.0 - 1e-9, rho, mu, d, vol, 1e-12);
  EXPECT_NEAR(kStokes, 3 * kPi * mu * d, 1e-6 * kStokes);
  const Vec3 f = dragForce(2.0, Vec3{1, 0, 0}, Vec3{0.25, 0, 0});
  EXPECT_DOUBLE_EQ(f.x, 1.5);
}

TEST(PressureGradient, MinusVolumeTimesGradP) {
  const double r = 5e-4;
  const Vec3 f = pressureGradientForce(sphereVolume(r), Vec3{0, 0, -11.8});
  EXPECT_NEAR(f.z, 4.0 / 3.0 * kPi * r * r * r * 11.8, 1e-20);
}

TEST(Pcm, CellIndexLayoutAndOutside) {
  const GridParams g{{0, 0, 0}, {1.0 / 0.01, 1.0 / 0.02, 1.0 / 0.03}, 4, 3, 2};
  EXPECT_EQ(pcmCell(g, Vec3{0.005, 0.005, 0.005}), 0);
  EXPECT_EQ(pcmCell(g, Vec3{0.035, 0.005, 0.005}), 3);
  EXPECT_EQ(pcmCell(g, Vec3{0.005, 0.025, 0.005}), 4); // i + nx j
  EXPECT_EQ(pcmCell(g, Vec3{0.015, 0.045, 0.035}), 1 + 4 * (2 + 3 * 1));
  EXPECT_EQ(pcmCell(g, Vec3{-1e-9, 0.005, 0.005}), -1);
  EXPECT_EQ(pcmCell(g, Vec3{0.04, 0.005, 0.005}), -1);
  EXPECT_EQ(pcmCell(g, Vec3{NAN, 0.005, 0.005}), -1);
  EXPECT_DOUBLE_EQ(pcmGasFraction(0.25e-6, 1e-6), 0.75);
}

TEST(CellSources, AveragesOverSubSteps) {
  CellAccumulator acc{0, 0, {0, 0, 0}};
  accumulate(acc, cellContribution(1e-9, 2e-3, Vec3{1, 0, 0}));
  accumulate(acc, cellContribution(1e-9, 4e-3, Vec3{0, 1, 0}));
  const CellAverages a = averageSources(acc, 2, 1e-6);
  EXPECT_DOUBLE_EQ(a.epsG, 1 - 2e-9 / 2e-6);
  EXPECT_DOUBLE_EQ(a.kSl, 6e-3 / 2e-6);
  EXPECT_DOUBLE_EQ(a.kSlUs.x, 2e-3 / 2e-6);
  EXPECT_DOUBLE_EQ(a.kSlUs.y, 4e-3 / 2e-6);
}

TEST(BodyForce, GravityIsMassTimesG) {
  const Vec3 f = gravityForce(kMass, Vec3{0, 0, -9.81});
  EXPECT_DOUBLE_EQ(f.z, -9.81 * kMass);
  EXPECT_EQ(f.x, 0.0);
}
