#pragma once
/// @file
/// Hertz–Mindlin contact with tangential history and the Coulomb limit, damping from the
/// restitution coefficient as LIGGGHTS (`pair gran model hertz tangential history`) and EDEM do —
/// docs/physics.md §2.1 "Hertz–Mindlin": the contact law `hertz-mindlin` of
/// kernels/contact_law.h.
///
/// Conventions of contact_common.h (n from i to j, δ_n > 0 in contact, lever arm L_ij, v_ij);
/// per pair E*, G*, R*, m*, e, μ; a = √(R* δ_n):
///   S_n = 2 E* a,  k_n = 4/3 E* a,  γ_n = 2 √(5/6) |β| √(S_n m*)
///   S_t = 8 G* a,  k_t = S_t,       γ_t = 2 √(5/6) |β| √(S_t m*)
///   β = ln e / √(ln² e + π²)   (dampingFactor(e) = 2|β|)
///   f_n = −k_n δ_n n − γ_n v_n                          (no clip: as LIGGGHTS' default)
///   δ_t ← P_n(δ_t) + v_t Δt,  f_t = −k_t δ_t − γ_t v_t;
///   if |f_t| > μ|f_n|:  f_t ← μ|f_n| f_t/|f_t|,  δ_t ← −(f_t + γ_t v_t)/k_t   (LIGGGHTS)
///   torque on i: L_ij n × f_t
/// With γ_n ∝ δ_n^¼ the collision is self-similar: the restitution coefficient does not depend on
/// the impact velocity, and equals e (the normal force turns slightly attractive before the
/// spheres part; unclipped, as in LIGGGHTS without `limitForce`).
/// Mirror-exact as lsd_contact.h: every term is odd in (n, v_ij, δ_t), R* and m* symmetric.

#include <array>

#include <math.h>

#include "coredem/dem/kernels/collision_time.h"
#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/contact_common.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/lanes.h"
#include "coredem/dem/kernels/model_list.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// The properties of a material pair (a row of the pair table). S: the scalar type (lanes.h).
template <class S>
struct HertzPairT {
  S estar; ///< E* (Pa): 1/E* = (1 − ν_a²)/E_a + (1 − ν_b²)/E_b
  S gstar; ///< G* (Pa): 1/G* = 2(2 − ν_a)(1 + ν_a)/E_a + 2(2 − ν_b)(1 + ν_b)/E_b
  S damp;  ///< 2 √(5/6) |β| = √(5/6) dampingFactor(e) (-)
  S mu;    ///< Coulomb friction coefficient (-)
};

/// One contact's parameters (the row with the pair's R* and m*).
template <class S>
struct HertzContactT {
  S estar, gstar, damp, mu;
  S reff; ///< R* (m); walls: R_i
  S meff; ///< m* (kg); walls: m_i
};

/// The `models:` parameters of Hertz–Mindlin.
struct HertzModelParams {
  /// Largest impact velocity expected (m/s): the collision time that Δt_DEM,max resolves is the
  /// one at this velocity (Hertz contacts shorten as the impact velocity grows).
  double vMax = 1.0;
};

/// Johnson (1985) §11.1: the duration of an elastic Hertz impact, t_c = c (m*²/(R* E*² v))^⅕,
/// c = 2 (15/16)^⅖ ∫₀¹ dx/√(1 − x^{5/2}) = 2.86827 (-).
inline constexpr double kHertzDurationConstant = 2.8682656991953315;

/// Maximum overlap of an elastic Hertz impact at velocity v (m): (15 m* v²/(16 E* √R*))^⅖.
inline double hertzMaxOverlap(double estar, double reff, double meff, double v) {
  return ::pow(15.0 * meff * v * v / (16.0 * estar * ::sqrt(reff)), 0.4);
}

/// Force, torque and tangential history of a Hertz–Mindlin contact (the file comment).
/// @pre deltaN > 0, |n| = 1, c.gstar > 0.
template <class S>
DEM_HD ContactResultT<S> hertzMindlinContact(const HertzContactT<S>& c, Vec3T<S> n, S deltaN,
                                             Vec3T<S> vij, S lij, Vec3T<S> deltaTOld, double dt) {
  const S a = laneSqrt(c.reff * deltaN);
  const S sn = 2.0 * c.estar * a;
  const S st = 8.0 * c.gstar * a;
  const S kn = (2.0 / 3.0) * sn;
  const S gn = c.damp * laneSqrt(sn * c.meff);
  const S gt = c.damp * laneSqrt(st * c.meff);
  const Vec3T<S> vn = dot(vij, n) * n;
  const Vec3T<S> vt = vij - vn;
  const Vec3T<S> fn = (-kn * deltaN) * n - gn * vn;
  Vec3T<S> dT = (deltaTOld - dot(deltaTOld, n) * n) + dt * vt;
  const Vec3T<S> damping = gt * vt;
  Vec3T<S> ft = -st * dT - damping;
  const auto slides = dot(ft, ft) > c.mu * c.mu * dot(fn, fn);
  if (laneAny(slides)) {
    const S ftMag = norm(ft);
    const S scale = laneSelect(ftMag > 0.0, c.mu * norm(fn) / ftMag, S{});
    const Vec3T<S> limited = scale * ft;
    ft = laneSelect(slides, limited, ft);
    dT = laneSelect(slides, (-1.0 / st) * (limited + damping), dT);
  }
  ContactResultT<S> r;
  r.force = fn + ft;
  r.nxft = cross(n, ft);
  r.torque = lij * r.nxft;
  r.deltaT = dT;
  return r;
}

/// The Hertz–Mindlin law as registered in kernels/contact_law.h (ContactLaws).
struct HertzMindlin {
  static constexpr const char* name = "hertz-mindlin";
  static constexpr const char* doc =
      "Hertz–Mindlin with tangential history and the Coulomb limit, damping from e as LIGGGHTS "
      "`model hertz tangential history` (kernels/hertz_mindlin_contact.h)";
  using Params = HertzModelParams;
  static constexpr auto params() {
    return std::array{ModelParam<Params>{
        "v_max", &Params::vMax, 0.0, 1e4, true, "m/s",
        "largest impact velocity expected: Δt_DEM,max resolves the Hertz collision time at it"}};
  }

  template <class S>
  using PairT = HertzPairT<S>;
  using Pair = PairT<double>;
  template <class S>
  using ContactT = HertzContactT<S>;

  /// The row of materials a and b (walls: a and the wall's material; host): E* and G* from both
  /// materials' E and ν, e and μ the smaller. Material: coredem::dem::Material (youngsModulus,
  /// poissonRatio, en, mu).
  template <class Material>
  static Pair mix(const Params&, const Material& a, const Material& b) {
    const double ie = (1.0 - a.poissonRatio * a.poissonRatio) / a.youngsModulus +
                      (1.0 - b.poissonRatio * b.poissonRatio) / b.youngsModulus;
    const double ig = 2.0 * (2.0 - a.poissonRatio) * (1.0 + a.poissonRatio) / a.youngsModulus +
                      2.0 * (2.0 - b.poissonRatio) * (1.0 + b.poissonRatio) / b.youngsModulus;
    const double en = b.en < a.en ? b.en : a.en;
    const double mu = b.mu < a.mu ? b.mu : a.mu;
    return Pair{1.0 / ie, 1.0 / ig, ::sqrt(5.0 / 6.0) * dampingFactor(en), mu};
  }

  /// Elastic Hertz collision time at the impact velocity v_max (Johnson 1985; host).
  static double collisionTime(const Params& params, const Pair& p, double meff, double reff) {
    return kHertzDurationConstant *
           ::pow(meff * meff / (reff * p.estar * p.estar * params.vMax), 0.2);
  }

  /// Largest stable Δt (collision_time.h, Δt_s; host): the normal and tangential oscillators
  /// with the tangent stiffnesses S_n, S_t at the largest overlap of an impact at v_max (the
  /// tangential mass m*/3.5 as lsd_contact.h).
  static double stableStep(const Params& params, const Pair& p, double meff, double reff) {
    const double a = ::sqrt(reff * hertzMaxOverlap(p.estar, reff, meff, params.vMax));
    const double sn = 2.0 * p.estar * a;
    const double st = 8.0 * p.gstar * a;
    const double normal = dampedStepLimit(sn, meff, p.damp * ::sqrt(sn * meff));
    const double tangential = dampedStepLimit(st, meff / 3.5, p.damp * ::sqrt(st * meff));
    return tangential < normal ? tangential : normal;
  }

  template <class S, class Load>
  DEM_HD static PairT<S> gather(const Load& load) {
    return PairT<S>{load(&Pair::estar), load(&Pair::gstar), load(&Pair::damp), load(&Pair::mu)};
  }

  /// One contact of row p with effective mass meff and radius reff (walls: m_i, R_i).
  template <class S>
  DEM_HD static ContactT<S> contact(const PairT<S>& p, S meff, S reff) {
    return ContactT<S>{p.estar, p.gstar, p.damp, p.mu, reff, meff};
  }

  template <class S>
  DEM_HD static ContactResultT<S> evaluate(const ContactT<S>& c, Vec3T<S> n, S deltaN, Vec3T<S> vij,
                                           S lij, Vec3T<S> deltaTOld, double dt) {
    return hertzMindlinContact(c, n, deltaN, vij, lij, deltaTOld, dt);
  }
};

} // namespace coredem::dem::kernels
