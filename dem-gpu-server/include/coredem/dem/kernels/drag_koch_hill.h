#pragma once
/// @file
/// Koch–Hill drag (Hill, Koch & Ladd 2001; Benyahia, Syamlal & O'Brien 2006) in MFiX's form
/// (DRAG_KOCH_HILL), docs/physics.md §2.2.4: a fit of lattice-Boltzmann simulations of random
/// arrays, φ = 1 − ε up to 0.6 (Re from the particle radius, as Hill et al. write it):
///   Re = ½ ε ρ_g d_p |Δu| / μ_g,  w = exp(−10 (0.4 − φ)/φ)
///   F_0 = (1−w) (1 + 3√(φ/2) + (135/64) φ ln φ + 17.14 φ)/(1 + 0.681 φ − 8.48 φ² + 8.16 φ³)
///         + w 10 φ/(1−φ)³                          (0.01 < φ < 0.4; 10 φ/(1−φ)³ for φ ≥ 0.4)
///   F_1 = √(2/φ)/40 (0.01 < φ ≤ 0.1),  0.11 + 5.1e-4 exp(11.6 φ) (φ > 0.1)
///   F_2 = (1−w) (1 + 3√(φ/2) + (135/64) φ ln φ + 17.89 φ)/(1 + 0.681 φ − 11.03 φ² + 15.41 φ³)
///         + w 10 φ/(1−φ)³                          (φ < 0.4; 10 φ/(1−φ)³ for φ ≥ 0.4)
///   F_3 = 0.9351 φ + 0.03667 (φ < 0.0953),  0.0673 + 0.212 φ + 0.0232/(1−φ)⁵ otherwise
///   Re_1 = (F_2 − 1)/(3/8 − F_3),  Re_2 = (F_3 + √(F_3² − 4 F_1 (F_0 − F_2)))/(2 F_1)
///   F = 1 + 3/8 Re (φ ≤ 0.01, Re ≤ Re_1),  F_0 + F_1 Re² (φ > 0.01, Re ≤ Re_2),  F_2 + F_3 Re
///   β = 18 μ_g ε² φ F/d_p²,  i.e. f_d = 3π μ_g d_p ε² F (u_g − v)
/// (MFiX returns 0 at Re = 0; here the limit F_0, or 1 for φ ≤ 0.01.)

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// Koch–Hill's dimensionless drag F(φ, Re), Re on the particle radius.
DEM_HD double kochHillForce(double phi, double re) {
  const double w = ::exp(-10.0 * (0.4 - phi) / phi);
  const double dense = 10.0 * phi / ((1.0 - phi) * (1.0 - phi) * (1.0 - phi));
  const double root = 1.0 + 3.0 * ::sqrt(phi / 2.0) + 135.0 / 64.0 * phi * ::log(phi);
  double f0 = dense, f1 = 0.0, f2 = dense;
  if (phi > 0.01 && phi < 0.4) {
    f0 = (1.0 - w) * (root + 17.14 * phi) /
             (1.0 + 0.681 * phi - 8.48 * phi * phi + 8.16 * phi * phi * phi) +
         w * dense;
  }
  if (phi > 0.01 && phi <= 0.1) {
    f1 = ::sqrt(2.0 / phi) / 40.0;
  } else if (phi > 0.1) {
    f1 = 0.11 + 5.1e-4 * ::exp(11.6 * phi);
  }
  if (phi < 0.4) {
    f2 = (1.0 - w) * (root + 17.89 * phi) /
             (1.0 + 0.681 * phi - 11.03 * phi * phi + 15.41 * phi * phi * phi) +
         w * dense;
  }
  const double s = 1.0 - phi;
  const double f3 =
      phi < 0.0953 ? 0.9351 * phi + 0.03667 : 0.0673 + 0.212 * phi + 0.0232 / (s * s * s * s * s);
  if (phi <= 0.01) {
    const double re1 = (f2 - 1.0) / (3.0 / 8.0 - f3);
    return re <= re1 ? 1.0 + 3.0 / 8.0 * re : f2 + f3 * re;
  }
  const double disc = f3 * f3 - 4.0 * f1 * (f0 - f2);
  const double re2 = disc >= 0.0 ? (f3 + ::sqrt(disc)) / (2.0 * f1) : 0.0;
  return re <= re2 ? f0 + f1 * re * re : f2 + f3 * re;
}

struct KochHillDrag {
  static constexpr const char* name = "koch-hill";
  static constexpr const char* doc = "Koch & Hill (2001), MFiX's form (kernels/drag_koch_hill.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    const double re = 0.5 * eps * rhoG * dp * slip / muG;
    return 18.0 * muG * eps * eps * kochHillForce(1.0 - eps, re) / (dp * dp) * volume;
  }
};

} // namespace coredem::dem::kernels
