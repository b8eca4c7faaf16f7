// The Hertz–Mindlin contact law (kernels/hertz_mindlin_contact.h, docs/physics.md §2.1):
// normal impacts against Hertz theory (Johnson 1985) and the input restitution, oblique impacts
// against the rigid-body sliding solution and Maw–Barber–Fawcett's reversal, its mixing, Δt_DEM
// and configuration; material pairs and wall materials in whole DemSystem runs.
#include <array>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "config_setup.h"
#include "contact_pairs.h"
#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "coredem/dem/models.h"

using namespace coredem::dem;
namespace k = coredem::dem::kernels;
using k::Vec3;

namespace {

using Hm = k::HertzMindlin;
constexpr double kPi = 3.14159265358979323846;

Material material(double e, double nu, double en, double mu) {
  Material m;
  m.youngsModulus = e;
  m.poissonRatio = nu;
  m.en = en;
  m.mu = mu;
  return m;
}

/// What one impact gave: rebound velocities, contact time, largest overlap and force.
struct Impact {
  Vec3 v;      ///< centre velocity after (m/s); two spheres: relative, v_j − v_i
  Vec3 w;      ///< angular velocity after (rad/s), wall impacts
  double tc;   ///< s
  double dmax; ///< m
  double fmax; ///< N
};

/// Head-on impact of two equal spheres (radius r, mass m) at relative speed v, integrated as the
/// DEM does (symplectic Euler, kernels/motion.h) with the pair kernel (ownedPair), with
/// `steps` steps over the elastic Hertz duration at v.
Impact spheres(const Hm::Pair& p, double r, double m, double v, int steps) {
  const double meff = 0.5 * m, reff = 0.5 * r;
  const double dt = k::kHertzDurationConstant *
                    std::pow(meff * meff / (reff * p.estar * p.estar * v), 0.2) / steps;
  Vec3 xi{0, 0, 0}, xj{2 * r + 0.5 * v * dt, 0, 0}, vi{0.5 * v, 0, 0}, vj{-0.5 * v, 0, 0};
  const Vec3 zero{0, 0, 0};
  Vec3 hist = zero;
  Impact out{};
  bool started = false;
  for (int s = 0; s < 100 * steps; ++s) {
    const Vec3 d = xj - xi;
    const double l2 = k::dot(d, d);
    Vec3 f = zero;
    if (l2 < 4 * r * r) {
      started = true;
      out.tc += dt;
      const OwnedPair<double> op =
          ownedPair<Hm, double>(d, l2, r, r, m, m, p, vi, vj, zero, zero, hist, dt);
      f = op.res.force;
      hist = op.res.deltaT;
      out.dmax = std::max(out.dmax, 2 * r - std::sqrt(l2));
      out.fmax = std::max(out.fmax, std::fabs(f.x));
    } else if (started) {
      break;
    }
    vi += (dt / m) * f;
    vj += (-dt / m) * f;
    xi += dt * vi;
    xj += dt * vj;
  }
  out.v = vj - vi;
  return out;
}

/// A sphere (radius r, mass m) hitting a plane z = 0 with velocity (vt, 0, −vn), spin ω_y = w0,
/// through the wall kernel (wallContact), `steps` steps over the elastic duration at vn.
Impact onWall(const Hm::Pair& p, double r, double m, double vn, double vt, double w0, int steps) {
  const double dt =
      k::kHertzDurationConstant * std::pow(m * m / (r * p.estar * p.estar * vn), 0.2) / steps;
  const auto c = Hm::contact(p, m, r);
  Vec3 x{0, 0, r + 0.5 * vn * dt}, v{vt, 0, -vn}, w{0, w0, 0}, hist{0, 0, 0};
  const double inertia = 0.4 * m * r * r;
  Impact out{};
  bool started = false;
  for (int s = 0; s < 100 * steps; ++s) {
    Vec3 f{0, 0, 0}, t{0, 0, 0};
    if (x.z < r) {
      started = true;
      out.tc += dt;
      const k::ContactResult res = k::wallContact<Hm>(c, Vec3{0, 0, 1}, r - x.z, v, w, r, hist, dt);
      f = res.force;
      t = res.torque;
      hist = res.deltaT;
      out.dmax = std::max(out.dmax, r - x.z);
      out.fmax = std::max(out.fmax, std::fabs(f.z));
    } else if (started) {
      break;
    }
    v += (dt / m) * f;
    w += (dt / inertia) * t;
    x += dt * v;
  }
  out.v = v;
  out.w = w;
  return out;
}

} // namespace

// Mixing: E* and G* as LIGGGHTS (1/E* = Σ (1 − ν²)/E, 1/G* = Σ 2(2 − ν)(1 + ν)/E), e and μ the
// smaller, the damping factor 2√(5/6)|β| with β = ln e/√(ln² e + π²).
TEST(HertzMindlin, MixesLikeLiggghts) {
  const Material a = material(7e10, 0.25, 0.9, 0.3), b = material(2e11, 0.3, 0.7, 0.5);
  const Hm::Pair p = Hm::mix({}, a, b);
  EXPECT_NEAR(p.estar, 1.0 / ((1 - 0.0625) / 7e10 + (1 - 0.09) / 2e11), 1e-6);
  EXPECT_NEAR(p.gstar, 1.0 / (2 * 1.75 * 1.25 / 7e10 + 2 * 1.7 * 1.3 / 2e11), 1e-6);
  const double l = std::log(0.7), beta = l / std::sqrt(l * l + kPi * kPi);
  EXPECT_NEAR(p.damp, -2 * std::sqrt(5.0 / 6.0) * beta, 1e-15);
  EXPECT_EQ(p.mu, 0.3);
  // Same material: E* = E/(2(1 − ν²)).
  EXPECT_NEAR(Hm::mix({}, a, a).estar, 7e10 / (2 * (1 - 0.0625)), 1e-3);
}

// Head-on impacts of two spheres: the restitution is the input e within 1e-3 (relative) at every
// impact speed from 0.01 to 10 m/s (the damping ∝ δ^¼ makes the impact self-similar); elastic
// (e = 1): duration, largest overlap and peak force as Hertz theory (Johnson 1985 §11.1):
// t_c = 2.868 (m*²/(R* E*² v))^⅕ within 1 %, δ_max = (15 m* v²/(16 E* √R*))^⅖ and
// F_max = 4/3 E* √R* δ_max^{3/2} within 0.5 % (2000 steps per contact).
TEST(HertzMindlin, NormalImpactOfTwoSpheres) {
  const double r = 1e-3, m = 2500 * 4.0 / 3.0 * kPi * r * r * r;
  for (double e : {0.3, 0.5, 0.9, 1.0}) {
    const Hm::Pair p = Hm::mix({}, material(1e8, 0.3, e, 0.3), material(1e8, 0.3, e, 0.3));
    for (double v : {0.01, 0.1, 1.0, 10.0}) {
      const Impact im = spheres(p, r, m, v, 2000);
      EXPECT_NEAR(im.v.x / v, e, 1e-3 * e) << "e = " << e << ", v = " << v;
      EXPECT_NEAR(im.v.y, 0.0, 1e-15);
      if (e < 1.0)
        continue;
      const double meff = 0.5 * m, reff = 0.5 * r;
      const double tc = 2.868265699 * std::pow(meff * meff / (reff * p.estar * p.estar * v), 0.2);
      const double dmax = std::pow(15 * meff * v * v / (16 * p.estar * std::sqrt(reff)), 0.4);
      const double fmax = 4.0 / 3.0 * p.estar * std::sqrt(reff) * std::pow(dmax, 1.5);
      EXPECT_NEAR(im.tc, tc, 1e-2 * tc) << "v = " << v;
      EXPECT_NEAR(im.dmax, dmax, 5e-3 * dmax) << "v = " << v;
      EXPECT_NEAR(im.fmax, fmax, 5e-3 * fmax) << "v = " << v;
    }
  }
}

// The same against a wall (R* = R, m* = m): restitution e within 1e-3, elastic duration within
// 1 %, overlap and peak force within 0.5 %.
TEST(HertzMindlin, NormalImpactOnAWall) {
  const double r = 2e-3, m = 7800 * 4.0 / 3.0 * kPi * r * r * r;
  for (double e : {0.5, 0.9, 1.0}) {
    const Hm::Pair p = Hm::mix({}, material(2e9, 0.25, e, 0.0), material(2e11, 0.3, 1.0, 0.0));
    for (double v : {0.01, 1.0, 10.0}) {
      const Impact im = onWall(p, r, m, v, 0.0, 0.0, 2000);
      EXPECT_NEAR(im.v.z / v, e, 1e-3 * e) << "e = " << e << ", v = " << v;
      if (e < 1.0)
        continue;
      const double tc = 2.868265699 * std::pow(m * m / (r * p.estar * p.estar * v), 0.2);
      const double dmax = std::pow(15 * m * v * v / (16 * p.estar * std::sqrt(r)), 0.4);
      const double fmax = 4.0 / 3.0 * p.estar * std::sqrt(r) * std::pow(dmax, 1.5);
      EXPECT_NEAR(im.tc, tc, 1e-2 * tc) << "v = " << v;
      EXPECT_NEAR(im.dmax, dmax, 5e-3 * dmax) << "v = " << v;
      EXPECT_NEAR(im.fmax, fmax, 5e-3 * fmax) << "v = " << v;
    }
  }
}

// Oblique impacts on a wall (Maw, Barber & Fawcett 1976/1981; Kharaz, Gorham & Salman 2001).
// Gross sliding (v_t/v_n well above 7/2 μ(1 + e)): the rigid-body result with the Coulomb
// impulse μ(1 + e) m v_n, v_t' = v_t − μ(1 + e) v_n, R ω' = 5/2 μ(1 + e) v_n, so that the contact
// point's slip is v_t − 7/2 μ(1 + e) v_n; within 1 % of the tangential impulse (e = 1: no
// attractive normal force, whose |f_n| would add to the friction). Small angles (v_t/v_n below
// the sticking limit): the contact sticks, elastically (below).
TEST(HertzMindlin, ObliqueImpactOnAWall) {
  const double r = 2e-3, m = 2500 * 4.0 / 3.0 * kPi * r * r * r, mu = 0.2, vn = 1.0;
  for (double e : {1.0, 0.9}) {
    const Hm::Pair p = Hm::mix({}, material(7e10, 0.25, e, mu), material(2e11, 0.3, 1.0, mu));
    for (double ratio : {3.0, 5.0}) { // v_t/v_n > 7/2 μ (1 + e) = 1.4 (e = 1)
      const double vt = ratio * vn;
      const Impact im = onWall(p, r, m, vn, vt, 0.0, 2000);
      const double en = im.v.z / vn;
      const double jt = mu * (1 + en) * vn; // Coulomb's tangential impulse per mass
      const double tol = (e == 1.0 ? 1e-2 : 3e-2) * jt;
      EXPECT_NEAR(im.v.x, vt - jt, tol) << "e = " << e << ", v_t/v_n = " << ratio;
      EXPECT_NEAR(im.w.y * r, 2.5 * jt, 2.5 * tol) << "e = " << e << ", v_t/v_n = " << ratio;
    }
  }
  const Hm::Pair p = Hm::mix({}, material(7e10, 0.25, 1.0, mu), material(2e11, 0.3, 1.0, mu));
  for (double ratio : {0.05, 0.1}) { // sticking: ψ = 2 (v_t/v_n)/(7 μ) well below 1
    const double vt = ratio * vn;
    const Impact im = onWall(p, r, m, vn, vt, 0.0, 2000);
    const double slipAfter = im.v.x - im.w.y * r; // contact point: v_x + (ω × (−r ẑ))_x
    const double q = slipAfter / vt;
    // Elastic (e = 1) and stuck but for the micro-slip where f_n → 0 at the ends: the tangential
    // spring gives back what it stored, the kinetic energy (translation and rotation) is kept to
    // 2e-4 (measured 1.7e-5 and 7.2e-5; at v_t/v_n = 0.2 the slip costs 5e-3); the contact point's
    // tangential velocity comes back with |q| ≤ 1 (this model: q ≈ 0.99 at v_t/v_n 0.05, the
    // tangential oscillation completing about one period within the contact; docs/physics.md).
    const double before = 0.5 * m * (vn * vn + vt * vt);
    const double after = 0.5 * m * k::dot(im.v, im.v) + 0.2 * m * r * r * k::dot(im.w, im.w);
    EXPECT_NEAR(after, before, 2e-4 * before) << "v_t/v_n = " << ratio;
    EXPECT_LE(std::fabs(q), 1.0 + 1e-9) << "v_t/v_n = " << ratio;
    EXPECT_GT(im.w.y, 0.0);
  }
}

// The pair kernel is mirror-exact (evaluated from j's side: exactly −f, the torque L_ji n × f_t)
// with a sliding and a sticking history.
TEST(HertzMindlin, MirrorExact) {
  const Hm::Pair p = Hm::mix({}, material(1e8, 0.3, 0.6, 0.3), material(3e8, 0.2, 0.8, 0.5));
  const double ri = 1e-3, rj = 1.4e-3, mi = 1e-5, mj = 3e-5;
  const Vec3 d{2.3e-3, 2e-5, -1e-5};
  for (const Vec3 hist : {Vec3{0, 1e-6, 0}, Vec3{0, 1e-9, 2e-9}}) {
    const Vec3 vi{0.3, 0.1, -0.2}, vj{-0.1, 0.05, 0.3}, wi{10, -5, 3}, wj{-2, 8, 1};
    const OwnedPair<double> a =
        ownedPair<Hm, double>(d, k::dot(d, d), ri, rj, mi, mj, p, vi, vj, wi, wj, hist, 1e-7);
    const Vec3 md = -d;
    const OwnedPair<double> b =
        ownedPair<Hm, double>(md, k::dot(md, md), rj, ri, mj, mi, p, vj, vi, wj, wi, -hist, 1e-7);
    EXPECT_EQ(b.res.force.x, -a.res.force.x);
    EXPECT_EQ(b.res.force.y, -a.res.force.y);
    EXPECT_EQ(b.res.force.z, -a.res.force.z);
    EXPECT_EQ(b.res.deltaT.y, -a.res.deltaT.y);
    const Vec3 share = a.lji * a.res.nxft;
    EXPECT_EQ(b.res.torque.x, share.x);
    EXPECT_EQ(b.res.torque.z, share.z);
  }
}

// Δt_DEM,max with Hertz–Mindlin: the elastic collision time at v_max (contact.hertz-mindlin.v_max,
// default 1 m/s) over dt_factor, from the lightest particle (m*, R*) of each pair and the walls.
TEST(HertzMindlin, DtDemFromTheCollisionTimeAtVmax) {
  DemConfig c;
  c.contact = k::ContactLaw::HertzMindlin;
  c.materials = {material(1e8, 0.3, 0.9, 0.3)};
  const double r = 5e-4, m = 2500 * 4.0 / 3.0 * kPi * r * r * r;
  const double masses[1] = {m}, radii[1] = {r};
  const Hm::Pair p = Hm::mix({}, c.materials[0], c.materials[0]);
  const double tc = k::kHertzDurationConstant *
                    std::pow((0.5 * m) * (0.5 * m) / (0.5 * r * p.estar * p.estar * 1.0), 0.2);
  EXPECT_NEAR(dtDemMax(c, masses, radii), tc / 50, 1e-12 * tc);
  ASSERT_TRUE(applyModelOption(c, "contact.hertz-mindlin.v_max", "32"));
  EXPECT_NEAR(dtDemMax(c, masses, radii), tc / 2 / 50, 1e-12 * tc); // 32^⅕ = 2
  // Walls: R* = R, m* = m (a longer time: the particle pairs still bind).
  c.addBox({0, 0, 0}, {1, 1, 1});
  EXPECT_NEAR(dtDemMax(c, masses, radii), tc / 2 / 50, 1e-12 * tc);
  EXPECT_THROW(applyModelOption(c, "contact.hertz-mindlin.v_max", "0"), coredem::UserError);
}

// Configuration: the law refuses materials without E (naming the law) or with ν outside
// (−1, 0.5); material pairs and wall materials are checked; E, ν, the pairs and the walls'
// materials enter the configuration hash (the defaults add nothing).
TEST(HertzMindlin, ConfigurationIsCheckedAndHashed) {
  DemConfig c;
  c.materials = {material(0.0, 0.3, 0.9, 0.3)};
  c.addBox({0, 0, 0}, {0.01, 0.01, 0.01});
  const std::string lsdHash = cfg::hashConfig(c);
  c.materials[0].youngsModulus = 1e8; // LSD: E is not used and not hashed
  EXPECT_EQ(cfg::hashConfig(c), lsdHash);
  c.materials[0].youngsModulus = 0.0;
  c.contact = k::ContactLaw::HertzMindlin;
  try {
    cfg::validate(c);
    ADD_FAILURE() << "no youngs_modulus accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("hertz-mindlin needs youngs_modulus"), std::string::npos)
        << e.what();
  }
  c.materials[0].youngsModulus = 1e8;
  EXPECT_NO_THROW(cfg::validate(c));
  const std::string h0 = cfg::hashConfig(c);
  EXPECT_NE(h0, lsdHash);
  for (double nu : {0.5, -1.0, 0.7}) {
    c.materials[0].poissonRatio = nu;
    EXPECT_THROW(cfg::validate(c), coredem::UserError) << "ν = " << nu;
  }
  c.materials[0].poissonRatio = 0.25;
  EXPECT_NE(cfg::hashConfig(c), h0);
  c.materials[0].poissonRatio = 0.3;
  c.materials.push_back(material(2e8, 0.3, 0.9, 0.3));
  const std::string h1 = cfg::hashConfig(c);
  c.materialPairs.push_back(MaterialPair{0, 1, 0.5, 0.1});
  EXPECT_NO_THROW(cfg::validate(c));
  EXPECT_NE(cfg::hashConfig(c), h1);
  c.materialPairs.push_back(MaterialPair{1, 0, 0.6, 0.1}); // the same pair twice
  EXPECT_THROW(cfg::validate(c), coredem::UserError);
  c.materialPairs.back() = MaterialPair{1, 2, 0.6, 0.1}; // no material 2
  EXPECT_THROW(cfg::validate(c), coredem::UserError);
  c.materialPairs.pop_back();
  const std::string h2 = cfg::hashConfig(c);
  c.walls[4].material = 1;
  EXPECT_NO_THROW(cfg::validate(c));
  EXPECT_NE(cfg::hashConfig(c), h2);
  c.walls[4].material = 2;
  EXPECT_THROW(cfg::validate(c), coredem::UserError);
}

// The pair table: a material pair's e_n and μ replace the mixed ones for exactly that pair
// (both laws), the other rows keep the mixing.
TEST(MaterialPairs, OverrideExactlyThatRow) {
  for (k::ContactLaw law : {k::ContactLaw::LinearSpringDashpot, k::ContactLaw::HertzMindlin}) {
    DemConfig c;
    c.contact = law;
    c.materials = {material(1e8, 0.3, 0.9, 0.3), material(2e8, 0.3, 0.8, 0.4),
                   material(3e8, 0.3, 0.7, 0.5)};
    c.materialPairs.push_back(MaterialPair{2, 0, 0.4, std::nan("")});
    EngineSetup es;
    cfg::setUpContacts(c, es);
    DemConfig plain = c;
    plain.materialPairs.clear();
    EngineSetup ps;
    cfg::setUpContacts(plain, ps);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const bool paired = (a == 0 && b == 2) || (a == 2 && b == 0);
        const auto& row = es.pairs[3 * a + b];
        const auto& ref = ps.pairs[3 * a + b];
        if (law == k::ContactLaw::HertzMindlin) {
          const double damp = std::sqrt(5.0 / 6.0) * k::dampingFactor(0.4);
          EXPECT_EQ(row.of<Hm>().damp, paired ? damp : ref.of<Hm>().damp) << a << b;
          EXPECT_EQ(row.of<Hm>().mu, ref.of<Hm>().mu);
          EXPECT_EQ(row.of<Hm>().estar, ref.of<Hm>().estar);
        } else {
          using Lsd = k::LinearSpringDashpot;
          EXPECT_EQ(row.of<Lsd>().dampFactor,
                    paired ? k::dampingFactor(0.4) : ref.of<Lsd>().dampFactor)
              << a << b;
          EXPECT_EQ(row.of<Lsd>().kn, ref.of<Lsd>().kn);
        }
      }
  }
}

namespace {

/// One sphere (1 mm, 2500 kg/m³, material 0) on a floor z = 0 of material `floor` (−1: the
/// particle's own), moving with `v`, spinning with `w`, run for `duration` (s) in sub-steps of
/// Δt_DEM,max under gravity g (m/s², downwards).
ParticleData onFloor(DemConfig c, int floor, std::array<double, 3> v, std::array<double, 3> w,
                     double z, double duration, double g) {
  c.gravity = {0, 0, -g};
  c.walls = {Wall::plane({0, 0, 0}, {0, 0, 1})};
  c.walls[0].material = floor;
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.diameter = 1e-3;
  s.positions = {0, 0, z};
  s.velocities = {v[0], v[1], v[2]};
  s.angularVelocities = {w[0], w[1], w[2]};
  c.particleSets = {s};
  DemSystem sys(c, BackendKind::Cpu, 1);
  const int steps = static_cast<int>(std::ceil(duration / sys.dtDemMax()));
  for (int k = 0; k < steps; ++k)
    sys.advance(sys.dtDemMax(), 1);
  return sys.particles();
}

} // namespace

// Wall materials: a sphere resting on a frictionless floor (μ = 0 wall material) keeps its
// sliding velocity and its spin while the same floor with friction stops the slip within
// 30 ms (v = ω R: rolling, at 5/7 v_0 + 2/7 ω_0 R); the default floor (no material: the
// particle's own, today's behaviour) is the friction one. Hertz–Mindlin: its Coulomb limit
// bounds the whole tangential force (LSD keeps its tangential dashpot outside the limit, MFiX's
// form: a frictionless LSD wall also needs etat_factor 0, docs/physics.md §2.1).
TEST(MaterialPairs, FrictionlessWallKeepsSlipAndSpin) {
  DemConfig c;
  c.contact = k::ContactLaw::HertzMindlin;
  Material glass = material(1e7, 0.3, 0.5, 0.4);
  Material slick = glass;
  slick.mu = 0.0;
  c.materials = {glass, slick};
  const double r = 5e-4;
  const ParticleData free = onFloor(c, 1, {0.2, 0, 0}, {0, 30, 0}, r - 1e-7, 0.03, 9.81);
  EXPECT_EQ(free.velocity[0], 0.2);
  EXPECT_EQ(free.angularVelocity[1], 30.0);
  for (int floor : {0, -1}) {
    const ParticleData held = onFloor(c, floor, {0.2, 0, 0}, {0, 30, 0}, r - 1e-7, 0.03, 9.81);
    const double slip = held.velocity[0] - held.angularVelocity[1] * r; // contact point
    EXPECT_LT(std::fabs(slip), 1e-3 * 0.2) << "floor " << floor;
    EXPECT_NEAR(held.velocity[0], (5 * 0.2 + 2 * 30 * r) / 7, 2e-3) << "floor " << floor;
  }
}

// A material pair's restitution changes the rebound of exactly that pair: a sphere dropped on a
// floor of its own material (0) and one dropped on a floor of material 1 with the pair (0, 1)
// at e_n = 0.3; without the pair both rebound alike.
TEST(MaterialPairs, PairRestitutionChangesThatRebound) {
  for (k::ContactLaw law : {k::ContactLaw::LinearSpringDashpot, k::ContactLaw::HertzMindlin}) {
    DemConfig c;
    c.contact = law;
    Material a = material(1e7, 0.3, 0.9, 0.0);
    a.kn = 100.0;
    c.materials = {a, a};
    c.materials[1].name = "b";
    auto rebound = [&](const DemConfig& cc, int floor) {
      const ParticleData p = onFloor(cc, floor, {0, 0, -0.5}, {0, 0, 0}, 5e-4 + 2e-5, 2e-3, 0.0);
      return p.velocity[2];
    };
    const double own = rebound(c, 0), other = rebound(c, 1);
    EXPECT_GT(own, 0.3);
    EXPECT_EQ(own, other);
    DemConfig paired = c;
    paired.materialPairs.push_back(MaterialPair{1, 0, 0.3, std::nan("")});
    EXPECT_EQ(rebound(paired, 0), own); // the pair (0, 0) is not the pair (0, 1)
    EXPECT_NEAR(rebound(paired, 1) / own, 0.3 / 0.9, 0.05) << static_cast<int>(law);
  }
}
