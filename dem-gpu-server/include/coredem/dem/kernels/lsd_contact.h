#pragma once
/// @file
/// Linear spring–dashpot (LSD) contact, normal + tangential with accumulated tangential
/// displacement and the Coulomb limit in the MFiX form — docs/physics.md §2.1, seed Eqs. 7–10
/// (MFiX calc_force_dem.f): the contact law `linear-spring-dashpot` of kernels/contact_law.h.
///
/// Conventions of contact_common.h (n from i to j, δ_n > 0 in contact, lever arm L_ij, v_ij);
///   v_n = (v_ij·n) n,  v_t = v_ij − v_n
///   (9)  f_n = −k_n δ_n n − η_n v_n                                       (N, on i)
///   (10) δ_t ← P_n(δ_t) + v_t Δt,  f_t = −k_t δ_t − η_t v_t;
///        if |k_t δ_t| > μ|f_n|:  f_t = −μ|f_n| t − η_t v_t,  δ_t ← (μ|f_n|/k_t) t,  t = δ_t/|δ_t|
///   (7)  torque on i: L_ij n × f_t                                        (N m)
/// P_n projects on the current tangent plane. The expressions are mirror-exact: evaluating
/// the pair from j's side (n → −n, v_ij → −v_ij, δ_t → −δ_t) gives exactly −f and the torque
/// L_ji n × f_t, so one evaluation per pair (contacts.h) gives both sides bitwise.

#include <math.h>

#include "coredem/dem/kernels/collision_time.h"
#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/contact_common.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/lanes.h"
#include "coredem/dem/kernels/model_list.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// Per-contact LSD parameters (SI). η_n from Eq. 13 with the pair's m_eff. S: the scalar type
/// (lanes.h), double but in the cpu backend's two-pair loop.
template <class S>
struct LsdParamsT {
  S kn;   ///< N/m
  S kt;   ///< N/m
  S etan; ///< kg/s
  S etat; ///< kg/s
  S mu;   ///< -
};
using LsdParams = LsdParamsT<double>;

/// The result of one LSD evaluation: the family's (contact_common.h).
template <class S>
using LsdResultT = ContactResultT<S>;
using LsdResult = ContactResult;

/// Eqs. 9–10 and 7. @pre deltaN > 0, |n| = 1, p.kt > 0. The Coulomb limit is a lane select:
/// a lane that does not slide keeps its values bitwise.
template <class S>
DEM_HD LsdResultT<S> lsdContact(const LsdParamsT<S>& p, Vec3T<S> n, S deltaN, Vec3T<S> vij, S lij,
                                Vec3T<S> deltaTOld, double dt) {
  const Vec3T<S> vn = dot(vij, n) * n;
  const Vec3T<S> vt = vij - vn;
  const Vec3T<S> fn = (-p.kn * deltaN) * n - p.etan * vn;
  Vec3T<S> dT = (deltaTOld - dot(deltaTOld, n) * n) + dt * vt;
  Vec3T<S> fs = -p.kt * dT;
  // |k_t δ_t| > μ|f_n| compared squared: no square root unless the contact slides.
  const auto slides = dot(fs, fs) > p.mu * p.mu * dot(fn, fn);
  if (laneAny(slides)) {
    const S fnMag = norm(fn);
    const S dMag = norm(dT);
    const Vec3T<S> t = laneSelect(dMag > 0.0, (1.0 / dMag) * dT, Vec3T<S>{S{}, S{}, S{}});
    fs = laneSelect(slides, (-p.mu * fnMag) * t, fs);
    dT = laneSelect(slides, (p.mu * fnMag / p.kt) * t, dT);
  }
  const Vec3T<S> ft = fs - p.etat * vt;
  LsdResultT<S> r;
  r.force = fn + ft;
  r.nxft = cross(n, ft);
  r.torque = lij * r.nxft;
  r.deltaT = dT;
  return r;
}

/// The properties of a material pair (a row of the pair table, EngineSetup::pairs): η_n's
/// factor without m_eff (Eq. 13), so that one row serves every particle mass. S: the scalar type.
template <class S>
struct LsdPairT {
  S kn;         ///< N/m
  S kt;         ///< N/m
  S dampFactor; ///< η_n = dampFactor·√(k_n m_eff) (-)
  S etatFactor; ///< η_t = etatFactor·η_n (-)
  S mu;         ///< -
};

/// The `models:` parameters of LSD (none: its parameters are the materials').
struct LsdModelParams {};

/// The LSD law as registered in kernels/contact_law.h (ContactLaws): the model declaration.
struct LinearSpringDashpot {
  static constexpr const char* name = "linear-spring-dashpot";
  static constexpr const char* doc = "linear spring–dashpot with tangential history and the "
                                     "Coulomb limit (MFiX; kernels/lsd_contact.h)";
  using Params = LsdModelParams;
  static constexpr auto params() { return noParams<Params>(); }

  template <class S>
  using PairT = LsdPairT<S>;
  using Pair = PairT<double>;
  template <class S>
  using ContactT = LsdParamsT<S>;

  /// The row of materials a and b (walls: a with itself; host): k_n the harmonic mean, e_n and
  /// μ the smaller, the k_t and η_t factors the mean [C] (docs/physics.md §2.1). Material:
  /// coredem::dem::Material (kn, en, mu, ktFactor, etatFactor).
  template <class Material>
  static Pair mix(const Params&, const Material& a, const Material& b) {
    const double kn = 2.0 * a.kn * b.kn / (a.kn + b.kn);
    const double en = b.en < a.en ? b.en : a.en; // std::min(a.en, b.en)
    const double mu = b.mu < a.mu ? b.mu : a.mu;
    const double ktFactor = 0.5 * (a.ktFactor + b.ktFactor);
    return Pair{kn, ktFactor * kn, dampingFactor(en), 0.5 * (a.etatFactor + b.etatFactor), mu};
  }

  /// Undamped duration of a contact of row p with effective mass meff, π √(m_eff/k_n): the time
  /// scale Δt_DEM,max resolves (collision_time.h; host).
  static double collisionTime(const Params&, const Pair& p, double meff, double /*reff*/) {
    return undampedCollisionTime(p.kn, meff);
  }

  /// Largest Δt for which the integrator keeps a contact of row p with effective mass meff
  /// stable (collision_time.h, Δt_s; host): the normal oscillator (k_n, m_eff, η_n) and the
  /// tangential one (k_t, η_t, and the mass m_eff/3.5 that the contact point's tangential
  /// motion has with the spheres' rotation, 1/m_eff + R²/I summed over both sides, I = 2/5 m R²).
  static double stableStep(const Params&, const Pair& p, double meff, double /*reff*/) {
    const double etan = p.dampFactor * ::sqrt(p.kn * meff);
    const double normal = dampedStepLimit(p.kn, meff, etan);
    if (!(p.kt > 0.0))
      return normal;
    const double tangential = dampedStepLimit(p.kt, meff / 3.5, p.etatFactor * etan);
    return tangential < normal ? tangential : normal;
  }

  /// The row's members in lanes: PairT<S>{load(&Pair::kn), …} (the cpu backend's pair lanes).
  template <class S, class Load>
  DEM_HD static PairT<S> gather(const Load& load) {
    return PairT<S>{load(&Pair::kn), load(&Pair::kt), load(&Pair::dampFactor),
                    load(&Pair::etatFactor), load(&Pair::mu)};
  }

  /// The parameters of one contact of row p with effective mass meff (walls: m_i): η_n, η_t
  /// (the radius does not enter).
  template <class S>
  DEM_HD static ContactT<S> contact(const PairT<S>& p, S meff, S /*reff*/) {
    const S etan = p.dampFactor * laneSqrt(p.kn * meff);
    return ContactT<S>{p.kn, p.kt, etan, p.etatFactor * etan, p.mu};
  }

  /// Force, torque and tangential history of contact c (lsdContact).
  template <class S>
  DEM_HD static ContactResultT<S> evaluate(const ContactT<S>& c, Vec3T<S> n, S deltaN, Vec3T<S> vij,
                                           S lij, Vec3T<S> deltaTOld, double dt) {
    return lsdContact(c, n, deltaN, vij, lij, deltaTOld, dt);
  }
};

} // namespace coredem::dem::kernels
