#pragma once
/// @file
/// Particle–particle contact conduction (docs/physics.md §3.2, seed Eqs. 22–23; Batchelor & O'Brien
/// 1977 as modified in MFiX `des_thermo_cond.f`).
///
///   (22) Q_pp,ij = 4 k_i k_j/(k_i + k_j) · r_c,ij · (T_j − T_i)     W, heat into i, if l < R_i+R_j
///   (23) r_c,ij  = √( R_L² − ((R_L² − R_S² + l²)/(2 l))² )          m, radius of the circle in
///                  which the two sphere surfaces intersect (symmetric in i, j)
///
/// The errata of docs/physics.md §0.3 apply: the factor is 4 (not 2), and the sign is (T_j − T_i).
///
/// Exact antisymmetry: the conductance G_ij is computed from expressions that are bitwise
/// symmetric in (i, j) (products/sums of the two k's, sorted radii), so
/// contactConductionHeat(i, j) == −contactConductionHeat(j, i) exactly in IEEE arithmetic,
/// whichever particle evaluates the pair. Callers that sum pair terms once per pair (canonical
/// i < j) and add ±Q get exact energy conservation up to the rounding of the sums.

#include <cmath>

#include <coredem/dem/kernels/common.h>

namespace coredem::dem::kernels {

/// Radius (m) of the circle where two spheres of radii ra, rb with centre distance l
/// intersect (Eq. 23). Returns 0 when they do not intersect (l ≥ ra + rb) and the smaller
/// radius when one sphere lies inside the other (l ≤ |ra − rb|) [C].
///
/// Computed as 2·Area/l of the triangle (ra, rb, l) with Kahan's cancellation-free Heron
/// formula, accurate to a few ulp even for overlaps of 1e-12 R (the textbook form loses
/// ~log10(R/r_c)² digits). Bitwise symmetric in (ra, rb).
DEM_HD double intersectionCircleRadius(double ra, double rb, double l) {
  const double big = ra > rb ? ra : rb;
  const double small = ra > rb ? rb : ra;
  if (l >= big + small) {
    return 0.0;
  }
  if (l <= big - small) {
    return small;
  }
  // Sort the three sides a ≥ b ≥ c.
  double a = big, b = small, c = l;
  if (c > a) {
    const double t = a;
    a = c;
    c = t;
  }
  if (c > b) {
    const double t = b;
    b = c;
    c = t;
  }
  if (b > a) {
    const double t = a;
    a = b;
    b = t;
  }
  const double p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
  const double area = 0.25 * std::sqrt(p > 0.0 ? p : 0.0);
  return 2.0 * area / l;
}

/// intersectionCircleRadius(r, r, l) for two spheres of the same radius r with r ≤ l < 2r, the
/// pair loop's common case: r_c = √((r − l/2)(r + l/2)), where r − l/2 is exact (Sterbenz), so
/// r_c is within 1 ulp of the exact radius (the Heron form: a few ulp). @pre r ≤ l < 2r.
DEM_HD double intersectionCircleRadiusEqual(double r, double l) {
  const double h = 0.5 * l;
  return std::sqrt((r - h) * (r + h));
}

/// Effective contact conductivity 4 k_i k_j/(k_i + k_j), W/(m K) (bitwise symmetric).
DEM_HD double contactConductivity(double ki, double kj) {
  return 4.0 * (ki * kj) / (ki + kj);
}

/// Contact conductance G_ij = 4 k_i k_j/(k_i+k_j) r_c, W/K; 0 when not in contact.
/// Radii ri, rj and centre distance l in m; conductivities in W/(m K).
DEM_HD double contactConductance(double ki, double kj, double ri, double rj, double l) {
  if (!(l < ri + rj)) {
    return 0.0;
  }
  return contactConductivity(ki, kj) * intersectionCircleRadius(ri, rj, l);
}

/// Heat into particle i from contact with j, W (Eq. 22). Antisymmetric bitwise.
DEM_HD double contactConductionHeat(double ki, double kj, double ri, double rj, double l, double ti,
                                    double tj) {
  return contactConductance(ki, kj, ri, rj, l) * (tj - ti);
}

} // namespace coredem::dem::kernels
