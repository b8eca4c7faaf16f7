#pragma once
/// @file
/// Translation and rotation of a particle over one DEM sub-step — docs/physics.md §2, Eqs. 6–7,
/// integrated by symplectic Euler: the velocities first, from the forces of the sub-step's
/// start, then the position with the new velocity:
///   v ← v + Δt (f + m g) / m,   ω ← ω + Δt τ / I  (I = 2/5 m R², a solid sphere),
///   x ← x + Δt v.
/// Also returns |x − x_ref|², the squared displacement since the last neighbour-list build
/// (the Verlet skin test).
///
/// A template on the scalar type S (lanes.h): S = double for one particle (every backend), or
/// Double4 for four particles at once, one per lane (the cpu backend's motion loop, motion.h in
/// the server's sources): the same operations in the same order, hence the same bits per lane.

#include "coredem/dem/kernels/body_force.h"
#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

template <class S>
struct MotionT {
  Vec3T<S> x; ///< new position (m)
  Vec3T<S> v; ///< new velocity (m/s)
  Vec3T<S> w; ///< new angular velocity (rad/s)
  S moved2;   ///< |x_new − x_ref|² (m²)
};

/// One sub-step dt of a sphere of mass m and radius r at x with velocity v and angular velocity
/// w, under force f (without gravity) and torque tq; xref: its position at the last
/// neighbour-list build.
template <class S>
DEM_HD MotionT<S> symplecticEuler(Vec3T<S> x, Vec3T<S> v, Vec3T<S> w, Vec3T<S> f, Vec3T<S> tq, S m,
                                  S r, Vec3 g, Vec3T<S> xref, double dt) {
  const S invM = 1.0 / m;
  const Vec3T<S> vn = v + (dt * invM) * (f + gravityForce(m, g)); // Eq. 6
  const S invI = 1.0 / (0.4 * m * r * r);                         // I = 2/5 m R² (Eq. 7)
  const Vec3T<S> wn = w + (dt * invI) * tq;
  const Vec3T<S> xn = x + dt * vn;
  const Vec3T<S> d = xn - xref;
  return {xn, vn, wn, dot(d, d)};
}

} // namespace coredem::dem::kernels
