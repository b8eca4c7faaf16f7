#pragma once
/// @file
/// Particle–wall contact with a rigid analytic wall (docs/physics.md §2, Eq. 8 with j → wall,
/// m_eff = m_i): the run's contact law (contact_law.h) with the wall immobile.
///
/// Two kinds of analytic wall:
/// * a plane (infinite, one-sided): particles live on the side its unit normal n̂_w points to;
///   an axis-aligned box is its six planes.
/// * a surface of revolution (cylinder, cone/frustum, disc cap, annulus): a profile polyline of
///   2–4 points (t_k, r_k) in the meridian half-plane (t along the unit axis â from `point`,
///   r ≥ 0 the distance from the axis), revolved about the axis. A cylinder is the segment
///   (t0, R)–(t1, R), a cone (t0, r0)–(t1, r1), a cap the segment to or from r = 0 at one end.
///   With the profile ordered so that (Δr, −Δt) of a segment points into the vessel (e.g. a
///   vessel's bottom cap (t0, 0)→(t0, R), its side (t0, R)→(t1, R), its top cap (t1, R)→(t1, 0)),
///   `side` = +1 keeps particles on that side (inside a vessel), −1 on the other (around a
///   solid insert), 0 on both (a thin shell such as a draft tube).
///
/// Contact regions (one contact per feature a sphere touches, none doubled or missing):
/// a segment is touched where the sphere centre projects onto it (0 ≤ λ ≤ 1); the profile's
/// interior points (rims between two segments of the same wall) where the centre projects past
/// both adjacent segments (a convex rim, seen from the particle). A concave junction (a vessel's
/// corner) gives two contacts, one per segment, as two planes would. The profile's free ends
/// have no rim contact: join them to another wall or close them with a cap. An infinite
/// cylinder (`infinite`) is one segment r = r_0 over every t.
///
/// For each touch: distance h from the centre to the surface (signed on a one-sided wall's
/// face, negative behind it: a particle pushed slightly through is pushed back; one behind a
/// revolved wall's face by more than the reach is on its far side and does not touch it) and the
/// unit normal n̂ from the wall towards the centre; then
///   overlap δ_n = R − h,  contact normal (i → wall) n = −n̂,  lever arm L = R − δ_n,
///   v_ij = v_i + L ω_i × n.

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/contact_common.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// The kind of an analytic wall.
enum WallKind : int {
  kWallPlane = 0,   ///< infinite one-sided plane
  kWallRevolved = 1 ///< profile polyline revolved about an axis
};

/// Most points of a revolved wall's profile (cap, side, cap).
inline constexpr int kMaxProfilePoints = 4;
/// Features of one analytic wall (segments, then interior points): the wall's history keys are
/// −(2 + k + nWalls·f) for wall k and feature f < kMaxWallFeatures.
inline constexpr int kMaxWallFeatures = 2 * kMaxProfilePoints - 3;
/// Most touches of one sphere with one analytic wall.
inline constexpr int kMaxWallTouches = 3;

/// An analytic wall (plain data, copied to the device as is).
struct Wall {
  Vec3 point;                  ///< plane: a point on it; revolved: the axis origin (t = 0)
  Vec3 normal;                 ///< plane: unit normal towards the particles; revolved: unit axis â
  double t[kMaxProfilePoints]; ///< revolved: profile, axial coordinates (m)
  double r[kMaxProfilePoints]; ///< revolved: profile, radii (m), ≥ 0
  int kind;                    ///< WallKind
  int points;                  ///< revolved: profile points, 2..kMaxProfilePoints
  int side;                    ///< revolved: +1, −1 or 0 (both sides), see the file comment
  int infinite;                ///< revolved: 1 = one infinite cylinder r = r[0]
  int material = -1;           ///< material index of the wall; −1: the particle's own
};

/// A plane wall through `point` with inward normal `normal` (unit).
inline Wall planeWall(Vec3 point, Vec3 normal) {
  Wall w{};
  w.point = point;
  w.normal = normal;
  w.kind = kWallPlane;
  return w;
}

/// One touch of a sphere with a wall: distance h (m) from the centre to the surface (negative
/// behind a one-sided face), unit normal from the wall towards the centre, the feature touched.
struct WallTouch {
  double h;
  Vec3 n;
  int feature;
};

/// A unit vector perpendicular to the unit vector a (fixed choice: the same on every backend).
DEM_HD Vec3 perpendicularTo(Vec3 a) {
  const Vec3 e = (a.x * a.x < 0.5) ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const Vec3 p = e - dot(e, a) * a;
  return (1.0 / ::sqrt(dot(p, p))) * p;
}

/// The touches of a sphere centred at x with wall w within `reach` (h < reach), written to out
/// (at most kMaxWallTouches, in feature order); returns their number.
DEM_HD int wallTouches(const Wall& w, Vec3 x, double reach, WallTouch* out) {
  if (w.kind == kWallPlane) {
    const double h = dot(x - w.point, w.normal);
    if (!(h < reach))
      return 0;
    out[0] = WallTouch{h, w.normal, 0};
    return 1;
  }
  // Meridian coordinates (t, s) of x and the radial unit vector e_r.
  const Vec3 d = x - w.point;
  const double tx = dot(d, w.normal);
  const Vec3 rv = d - tx * w.normal;
  const double s = ::sqrt(dot(rv, rv));
  const Vec3 er = s > 0.0 ? (1.0 / s) * rv : perpendicularTo(w.normal);
  auto toSpace = [&](double nt, double nr) { return nt * w.normal + nr * er; };
  int count = 0;
  auto faceTouch = [&](double hSigned, double nt, double nr, int feature) {
    // hSigned: distance along the segment's normal (nt, nr) pointing into the particles' side.
    double h = hSigned;
    if (w.side == -1) {
      h = -hSigned, nt = -nt, nr = -nr;
    } else if (w.side == 0 && hSigned < 0.0) {
      h = -hSigned, nt = -nt, nr = -nr;
    }
    // Behind a one-sided face by more than the reach: the far side of the wall, no touch.
    if (h < reach && h > -reach && count < kMaxWallTouches)
      out[count++] = WallTouch{h, toSpace(nt, nr), feature};
  };
  if (w.infinite) {
    // Normal (0, −1) (towards the axis) for side +1.
    faceTouch(w.r[0] - s, 0.0, -1.0, 0);
    return count;
  }
  double lambda[kMaxProfilePoints - 1];
  const int segs = w.points - 1;
  for (int k = 0; k < segs; ++k) {
    const double at = w.t[k], ar = w.r[k];
    const double dt = w.t[k + 1] - at, dr = w.r[k + 1] - ar;
    const double l2 = dt * dt + dr * dr;
    const double pt = tx - at, pr = s - ar;
    lambda[k] = l2 > 0.0 ? (pt * dt + pr * dr) / l2 : -1.0;
    if (!(l2 > 0.0) || lambda[k] < 0.0 || lambda[k] > 1.0)
      continue;
    const double inv = 1.0 / ::sqrt(l2);
    const double nt = dr * inv, nr = -dt * inv;
    faceTouch(pt * nt + pr * nr, nt, nr, k);
  }
  // Interior points: a convex rim, where the centre projects past both adjacent segments.
  for (int k = 1; k < segs; ++k) {
    if (!(lambda[k - 1] > 1.0 && lambda[k] < 0.0))
      continue;
    const double et = tx - w.t[k], es = s - w.r[k];
    const double h = ::sqrt(et * et + es * es);
    if (h < reach && h > 0.0 && count < kMaxWallTouches)
      out[count++] = WallTouch{h, toSpace(et / h, es / h), segs - 1 + k};
  }
  return count;
}

/// Smallest distance (m) from x to the wall's surface (a plane: signed, negative behind it): no
/// touch with reach ≤ this is possible until x moves (a bound for candidate lists).
DEM_HD double wallClearance(const Wall& w, Vec3 x) {
  if (w.kind == kWallPlane)
    return dot(x - w.point, w.normal);
  const Vec3 d = x - w.point;
  const double tx = dot(d, w.normal);
  const Vec3 rv = d - tx * w.normal;
  const double s = ::sqrt(dot(rv, rv));
  if (w.infinite)
    return ::fabs(w.r[0] - s);
  double best = HUGE_VAL;
  for (int k = 0; k + 1 < w.points; ++k) {
    const double dt = w.t[k + 1] - w.t[k], dr = w.r[k + 1] - w.r[k];
    const double l2 = dt * dt + dr * dr;
    const double pt = tx - w.t[k], pr = s - w.r[k];
    double lam = l2 > 0.0 ? (pt * dt + pr * dr) / l2 : 0.0;
    lam = lam < 0.0 ? 0.0 : (lam > 1.0 ? 1.0 : lam);
    const double et = pt - lam * dt, es = pr - lam * dr;
    const double h = ::sqrt(et * et + es * es);
    best = h < best ? h : best;
  }
  return best;
}

/// Force/torque on the particle (radius ri) from a wall touch with overlap deltaN = ri − h > 0
/// and unit normal nw from the wall towards the centre, with contact law Law (contact_law.h;
/// p: Law::contact(row, m_i)).
template <class Law = LinearSpringDashpot>
DEM_HD ContactResult wallContact(const typename Law::template ContactT<double>& p, Vec3 nw,
                                 double deltaN, Vec3 vi, Vec3 wi, double ri, Vec3 deltaTOld,
                                 double dt) {
  const Vec3 n = -nw;
  const double l = ri - deltaN;
  const Vec3 vij = relativeVelocity(vi, Vec3{0, 0, 0}, wi, Vec3{0, 0, 0}, l, 0.0, n);
  return Law::evaluate(p, n, deltaN, vij, l, deltaTOld, dt);
}

} // namespace coredem::dem::kernels
