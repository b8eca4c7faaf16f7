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

/// Per-contact LSD parameters (SI). η_n from Eq. 13 with the pair's m_eff.
struct LsdParams {
  double kn;   ///< N/m
  double kt;   ///< N/m
  double etan; ///< kg/s
  double etat; ///< kg/s
  double mu;   ///< -
};

struct LsdResult {
  Vec3 force;  ///< f_n + f_t on particle i (N)
  Vec3 torque; ///< torque on i (N m)
  Vec3 deltaT; ///< updated accumulated tangential displacement (m), to store
  Vec3 nxft;   ///< n × f_t (N): torque on i = L_ij n × f_t, on j = L_ji n × f_t (mirror-exact)
};

/// Contact point velocity difference v_ij (m/s).
DEM_HD Vec3 relativeVelocity(Vec3 vi, Vec3 vj, Vec3 wi, Vec3 wj, double lij, double lji, Vec3 n) {
  return (vi - vj) + cross(lij * wi + lji * wj, n);
}

/// Radical-plane lever arm L_ij = l/2 + (R_i² − R_j²)/(2l) (MFiX), l = centre distance (m).
DEM_HD double leverArm(double l, double ri, double rj) {
  return 0.5 * l + (ri * ri - rj * rj) / (2.0 * l);
}

/// leverArm with 1/l already known (no division); mirror-exact as leverArm is:
/// leverArmInv(l, 1/l, rj, ri) uses the negated difference of the same squares.
DEM_HD double leverArmInv(double l, double invL, double ri, double rj) {
  return 0.5 * l + (ri * ri - rj * rj) * (0.5 * invL);
}

/// Eqs. 9–10 and 7. @pre deltaN > 0, |n| = 1, p.kt > 0.
DEM_HD LsdResult lsdContact(const LsdParams& p, Vec3 n, double deltaN, Vec3 vij, double lij,
                            Vec3 deltaTOld, double dt) {
  const Vec3 vn = dot(vij, n) * n;
  const Vec3 vt = vij - vn;
  const Vec3 fn = (-p.kn * deltaN) * n - p.etan * vn;
  Vec3 dT = (deltaTOld - dot(deltaTOld, n) * n) + dt * vt;
  Vec3 fs = -p.kt * dT;
  // |k_t δ_t| > μ|f_n| compared squared: no square root unless the contact slides.
  if (dot(fs, fs) > p.mu * p.mu * dot(fn, fn)) {
    const double fnMag = norm(fn);
    const double dMag = norm(dT);
    const Vec3 t = dMag > 0.0 ? (1.0 / dMag) * dT : Vec3{0, 0, 0};
    fs = (-p.mu * fnMag) * t;
    dT = (p.mu * fnMag / p.kt) * t;
  }
  const Vec3 ft = fs - p.etat * vt;
  LsdResult r;
  r.force = fn + ft;
  r.nxft = cross(n, ft);
  r.torque = lij * r.nxft;
  r.deltaT = dT;
  return r;
}

} // namespace coredem::dem::kernels
