#pragma once
/// @file
/// Particle–wall conduction with a flat wall held at a fixed temperature T_w: docs/physics.md
/// §3.2–3.3 in the wall limit (the partner sphere becomes a half-space of the wall material) [C].
///
/// Geometry: particle radius R, centre at distance h from the wall plane (overlap δ = R − h).
///
///   contact (Batchelor & O'Brien, Eq. 22 with R_j → ∞, only if h < R):
///     Q_pw = 4 k_p k_w/(k_p + k_w) · r_c · (T_w − T_p),   r_c = √(R² − h²)
///     (r_c is the limit of Eq. 23: the circle in which the sphere cuts the plane)
///   gas lens (Rong & Horio / MFiX, Eqs. 24–26 with the wall as the partner):
///     Q_pfw = κ_g (T_w − T_p) I,   I = ∫_{R_in}^{R_out} 2π r dr / max(h − √(R² − r²), s_min)
///     R_in  = r_c in contact, 0 otherwise (Eq. 25)
///     R_out = min(R, √(R_lens² − h²)),  R_lens = (1 + FLPC) R  — the lens is built around the
///             particle (the larger body, the wall, has no finite radius to build it on) and
///             ends where it meets the wall or at the particle's equator; no lens if h ≥ R_lens.
///
/// The lens integral has a closed form: with u = √(R² − r²) (r dr = −u du), the unclipped part
///   ∫ 2π r dr/(h − u) = 2π [ h ln((h − u_out)/(h − u_a)) − (u_a − u_out) ]
/// and the clipped part (gap < s_min, r < r*, r*² = R² − (h − s_min)²) is π(r*² − R_in²)/s_min.
/// Differences are formed without cancellation: h − u = (h² − R² + r²)/(h + u) and
/// u_a − u_out = (r_out² − r_a²)/(u_a + u_out).
///
/// Heat into the particle is positive. The wall is an infinite reservoir: its heat is booked in
/// the run's energy ledger (HeatTotals::wall), not returned to the gas.

#include <cmath>

#include <coredem/dem/kernels/common.h>

namespace coredem::dem::kernels {

/// Parameters of particle–wall conduction.
struct WallConductionParams {
  bool contact = true;         ///< Batchelor–O'Brien contact conduction to the wall
  bool lens = true;            ///< particle–fluid–wall conduction through the gas lens
  double lensFraction = 0.2;   ///< FLPC: lens radius (1 + FLPC) R
  double minSeparation = 1e-6; ///< s_min (m), > 0
};

/// Radius (m) of the circle in which a sphere of radius r whose centre is at distance h from a
/// plane cuts it; 0 if h ≥ r (no contact), r if h ≤ 0.
DEM_HD double wallContactRadius(double r, double h) {
  if (h >= r)
    return 0.0;
  if (h <= 0.0)
    return r;
  return ::sqrt((r - h) * (r + h));
}

/// Contact conductance (W/K) between a particle (conductivity kp) and a wall half-space (kw):
/// 4 kp kw/(kp + kw) r_c; 0 without contact or if kp + kw = 0.
DEM_HD double wallContactConductance(double kp, double kw, double r, double h) {
  const double rc = wallContactRadius(r, h);
  if (rc <= 0.0 || !(kp + kw > 0.0))
    return 0.0;
  return 4.0 * kp * kw / (kp + kw) * rc;
}

/// h − √(r² − s²) for 0 ≤ s ≤ r, h > 0, without cancellation (m).
DEM_HD double wallGap(double r, double h, double s) {
  const double u = ::sqrt((r - s) * (r + s));
  return ((h - r) * (h + r) + s * s) / (h + u);
}

/// The lens integral I (m) of a particle (radius r, centre at h from the wall); 0 if the lens
/// does not reach the wall. Requires p.minSeparation > 0.
DEM_HD double wallLensIntegral(const WallConductionParams& p, double r, double h) {
  const double rl = (1.0 + p.lensFraction) * r;
  if (h >= rl)
    return 0.0;
  const double smin = p.minSeparation;
  const double rin = wallContactRadius(r, h);
  double rout = r;
  if (h > 0.0) {
    const double w = ::sqrt((rl - h) * (rl + h));
    rout = w < r ? w : r;
  }
  if (!(rout > rin))
    return 0.0;
  // Clipped disc: gap < s_min for r < r*, r*² = R² − (h − s_min)² (all of it if h ≤ s_min).
  double rs2 = r * r;
  if (h > smin) {
    const double hs = h - smin;
    rs2 = (r - hs) * (r + hs);
  }
  const double rin2 = rin * rin, rout2 = rout * rout;
  if (rs2 < rin2)
    rs2 = rin2;
  if (rs2 > rout2)
    rs2 = rout2;
  const double pi = 3.14159265358979323846;
  double value = pi * (rs2 - rin2) / smin;
  if (rs2 < rout2) {
    // Unclipped annulus r* ≤ s ≤ R_out (here h > s_min > 0 and every gap ≥ s_min).
    const double ra = ::sqrt(rs2);
    const double ua = ::sqrt((r - ra) * (r + ra));
    const double uo = ::sqrt((r - rout) * (r + rout));
    const double gapA = wallGap(r, h, ra);
    const double gapO = wallGap(r, h, rout);
    const double du = (rout2 - rs2) / (ua + uo);
    value += 2.0 * pi * (h * ::log(gapO / gapA) - du);
  }
  return value;
}

/// Conductance (W/K) of one particle to a wall: contact (kp, kw) plus lens (κ_g, if kG > 0).
DEM_HD double wallConductance(const WallConductionParams& p, double kp, double kw, double kG,
                              double r, double h) {
  double g = 0.0;
  if (p.contact)
    g += wallContactConductance(kp, kw, r, h);
  if (p.lens && kG > 0.0)
    g += kG * wallLensIntegral(p, r, h);
  return g;
}

/// Heat into the particle from a wall at tWall (W).
DEM_HD double wallConductionHeat(const WallConductionParams& p, double kp, double kw, double kG,
                                 double r, double h, double tWall, double tp) {
  return wallConductance(p, kp, kw, kG, r, h) * (tWall - tp);
}

} // namespace coredem::dem::kernels
