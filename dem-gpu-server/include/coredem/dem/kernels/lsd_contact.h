#pragma once
/// @file
/// Linear spring–dashpot (LSD) contact, normal + tangential with accumulated tangential
/// displacement and the Coulomb limit in the MFiX form — docs/physics.md §2.1, seed Eqs. 7–10
/// (MFiX calc_force_dem.f).
///
/// Conventions: n = (x_j − x_i)/|x_j − x_i| points from i to j; δ_n = R_i + R_j − |x_j − x_i|
/// (> 0 in contact); L_ij = lever arm from the centre of i to the contact point;
///   v_ij = (v_i − v_j) + (L_ij ω_i + L_ji ω_j) × n,  v_n = (v_ij·n) n,  v_t = v_ij − v_n
///   (9)  f_n = −k_n δ_n n − η_n v_n                                       (N, on i)
///   (10) δ_t ← P_n(δ_t) + v_t Δt,  f_t = −k_t δ_t − η_t v_t;
///        if |k_t δ_t| > μ|f_n|:  f_t = −μ|f_n| t − η_t v_t,  δ_t ← (μ|f_n|/k_t) t,  t = δ_t/|δ_t|
///   (7)  torque on i: L_ij n × f_t                                        (N m)
/// P_n projects on the current tangent plane. The expressions are mirror-exact: evaluating
/// the pair from j's side (n → −n, v_ij → −v_ij, δ_t → −δ_t) gives exactly −f and the torque
/// L_ji n × f_t, so one evaluation per pair (contacts.h) gives both sides bitwise.

#include "coredem/dem/kernels/common.h"
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

template <class S>
struct LsdResultT {
  Vec3T<S> force;  ///< f_n + f_t on particle i (N)
  Vec3T<S> torque; ///< torque on i (N m)
  Vec3T<S> deltaT; ///< updated accumulated tangential displacement (m), to store
  Vec3T<S> nxft; ///< n × f_t (N): torque on i = L_ij n × f_t, on j = L_ji n × f_t (mirror-exact)
};
using LsdResult = LsdResultT<double>;

/// Contact point velocity difference v_ij (m/s).
template <class S>
DEM_HD Vec3T<S> relativeVelocity(Vec3T<S> vi, Vec3T<S> vj, Vec3T<S> wi, Vec3T<S> wj, S lij, S lji,
                                 Vec3T<S> n) {
  return (vi - vj) + cross(lij * wi + lji * wj, n);
}

/// Radical-plane lever arm L_ij = l/2 + (R_i² − R_j²)/(2l) (MFiX), l = centre distance (m).
DEM_HD double leverArm(double l, double ri, double rj) {
  return 0.5 * l + (ri * ri - rj * rj) / (2.0 * l);
}

/// leverArm with 1/l already known (no division); mirror-exact as leverArm is:
/// leverArmInv(l, 1/l, rj, ri) uses the negated difference of the same squares.
template <class S>
DEM_HD S leverArmInv(S l, S invL, S ri, S rj) {
  return 0.5 * l + (ri * ri - rj * rj) * (0.5 * invL);
}

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

} // namespace coredem::dem::kernels
