#pragma once
/// @file
/// Syamlal–O'Brien (1987) and Beetstra–van der Hoef–Kuipers (2007) drag (docs/physics.md
/// §2.2.3), in MFiX's forms (DRAG_SYAM_OBRIEN, DRAG_BVK):
///   Syamlal–O'Brien, from the terminal velocity ratio V_r of a suspension (Richardson–Zaki
///   data; default calibration c1 = 0.8, d1 = 2.65, MFiX's drag_c1, drag_d1: parameters
///   `drag.syamlal-obrien.c1`, `.d1`, or calibrated to a measured U_mf, docs/physics.md §2.2.3):
///     Re = ρ_g d_p |Δu| / μ_g              (interstitial slip, no ε)
///     A = ε^4.14,  B = c1 ε^1.28 (ε ≤ 0.85), ε^d1 (ε > 0.85)
///     V_r = ½ (A − 0.06 Re + √((0.06 Re)² + 0.12 Re (2B − A) + A²))
///     C_D Re = (0.63 √Re + 4.8 √V_r)²      (Dallavalle at Re/V_r)
///     β/(1−ε) = ¾ μ_g ε (C_D Re)/(V_r² d_p²)
///   (MFiX sets the coefficient to 0 at Re = 0; here its continuous limit 17.28 μ ε/(A d²).)
///   Beetstra et al. (2007), a fit of lattice-Boltzmann simulations of monodisperse random
///   arrays, 0.1 ≲ φ ≲ 0.6 (φ = 1 − ε), Re ≲ 1000:
///     Re = ε ρ_g d_p |Δu| / μ_g            (superficial slip)
///     F = 10 φ/ε² + ε² (1 + 1.5 √φ)
///         + 0.413 Re/(24 ε²) (1/ε + 3 ε φ + 8.4 Re^−0.343)/(1 + 10^(3φ) Re^−(1+4φ)/2)
///     β/(1−ε) = 18 μ_g ε F/d_p²,  i.e. f_d = 3π μ_g d_p ε F (u_g − v)
/// Each returns β V_p/(1−ε) (kg/s), ε already clipped to [ε_min, 1) (kernels/drag.h).

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// Syamlal–O'Brien's ratio of the suspension's terminal velocity to a single particle's, with the
/// calibration constants c1, d1 of B.
DEM_HD double syamlalVelocityRatio(double eps, double re, double c1 = 0.8, double d1 = 2.65) {
  const double a = ::pow(eps, 4.14);
  const double b = eps <= 0.85 ? c1 * ::pow(eps, 1.28) : ::pow(eps, d1);
  return 0.5 * (a - 0.06 * re + ::sqrt(0.0036 * re * re + 0.12 * re * (2.0 * b - a) + a * a));
}

struct SyamlalObrienDrag {
  static constexpr const char* name = "syamlal-obrien";
  static constexpr const char* doc = "Syamlal & O'Brien (1987), MFiX's default "
                                     "(kernels/drag_syamlal_beetstra.h)";
  struct Params {
    double c1 = 0.8;  ///< B = c1 ε^1.28 at ε ≤ 0.85
    double d1 = 2.65; ///< B = ε^d1 at ε > 0.85
  };
  static constexpr auto params() {
    return std::array{ModelParam<Params>{"c1", &Params::c1, 0.0, 1.2, true, "-",
                                         "calibration constant of B below ε = 0.85 (MFiX drag_c1)"},
                      ModelParam<Params>{"d1", &Params::d1, 0.0, 60.0, true, "-",
                                         "exponent of B above ε = 0.85 (MFiX drag_d1)"}};
  }
  DEM_HD static double coefficient(const Params& p, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    const double re = rhoG * dp * slip / muG;
    const double vr = syamlalVelocityRatio(eps, re, p.c1, p.d1);
    const double s = 0.63 * ::sqrt(re) + 4.8 * ::sqrt(vr);
    return 0.75 * muG * eps * s * s / (vr * vr * dp * dp) * volume;
  }
};

/// Beetstra's dimensionless drag F(φ, Re) (Re on the superficial slip); F(0, 0) = 1 (Stokes).
DEM_HD double beetstraForce(double eps, double re) {
  const double phi = 1.0 - eps;
  double f = 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * ::sqrt(phi));
  if (re > 0.0) {
    f += 0.413 * re / (24.0 * eps * eps) * (1.0 / eps + 3.0 * eps * phi + 8.4 * ::pow(re, -0.343)) /
         (1.0 + ::pow(10.0, 3.0 * phi) * ::pow(re, -(0.5 + 2.0 * phi)));
  }
  return f;
}

struct BeetstraDrag {
  static constexpr const char* name = "beetstra";
  static constexpr const char* doc = "Beetstra, van der Hoef & Kuipers (2007), monodisperse "
                                     "(kernels/drag_syamlal_beetstra.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    const double re = eps * rhoG * dp * slip / muG;
    return 18.0 * muG * eps * beetstraForce(eps, re) / (dp * dp) * volume;
  }
};

} // namespace coredem::dem::kernels
