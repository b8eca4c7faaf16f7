#pragma once
/// @file
/// Particle–wall contact with an infinite rigid plane (docs/physics.md §2, Eq. 8 with j → wall,
/// m_eff = m_i): the same LSD law as lsd_contact.h with the wall immobile. An axis-aligned
/// box is its six planes (normals pointing inwards).
///   overlap δ_n = R − (x − p)·n̂_w,  contact normal (i → wall) n = −n̂_w,
///   lever arm L = R − δ_n (centre to contact point), v_ij = v_i + L ω_i × n.

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// A plane through `point` with unit inward normal `normal` (particles on the normal's side).
struct PlaneWall {
  Vec3 point;
  Vec3 normal;
};

/// Overlap of a sphere (centre x, radius r) with the wall (m); > 0 means contact.
DEM_HD double wallOverlap(const PlaneWall& w, Vec3 x, double r) {
  return r - dot(x - w.point, w.normal);
}

/// Force/torque on the particle from the wall. @pre deltaN = wallOverlap(...) > 0.
DEM_HD LsdResult wallContact(const LsdParams& p, const PlaneWall& w, double deltaN, Vec3 vi,
                             Vec3 wi, double ri, Vec3 deltaTOld, double dt) {
  const Vec3 n = -w.normal;
  const double l = ri - deltaN;
  const Vec3 vij = relativeVelocity(vi, Vec3{0, 0, 0}, wi, Vec3{0, 0, 0}, l, 0.0, n);
  return lsdContact(p, n, deltaN, vij, l, deltaTOld, dt);
}

} // namespace coredem::dem::kernels
