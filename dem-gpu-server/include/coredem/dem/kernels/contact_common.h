#pragma once
/// @file
/// What every contact law shares (kernels/contact_law.h): the result of one contact evaluation
/// and the contact geometry of a pair (relative velocity at the contact point, lever arms).
///
/// Conventions: n = (x_j − x_i)/|x_j − x_i| points from i to j; δ_n = R_i + R_j − |x_j − x_i|
/// (> 0 in contact); L_ij = lever arm from the centre of i to the contact point;
///   v_ij = (v_i − v_j) + (L_ij ω_i + L_ji ω_j) × n.

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// One contact evaluated from i's side. S: the scalar type (lanes.h), double but in the cpu
/// backend's pair lanes.
template <class S>
struct ContactResultT {
  Vec3T<S> force;  ///< force on particle i (N); j receives −force
  Vec3T<S> torque; ///< torque on i (N m): L_ij n × f_t
  Vec3T<S> deltaT; ///< updated accumulated tangential displacement (m), to store
  Vec3T<S> nxft; ///< n × f_t (N): torque on i = L_ij n × f_t, on j = L_ji n × f_t (mirror-exact)
};
using ContactResult = ContactResultT<double>;

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

} // namespace coredem::dem::kernels
