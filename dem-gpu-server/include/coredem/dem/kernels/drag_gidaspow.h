#pragma once
/// @file
/// Gidaspow drag (Ergun for ε ≤ 0.8, Wen–Yu above) — docs/physics.md §2.2, seed Eqs. 14–17
/// (MFiX drag_gs.f, des/drag_gp_des.f):
///   Re_p = ε ρ_g d_p |u_g − v| / μ_g
///   ε ≤ 0.8:  β = 150 (1−ε)² μ_g/(ε d_p²) + 1.75 (1−ε) ρ_g |Δu|/d_p
///   ε > 0.8:  β = ¾ C_D ε (1−ε) ρ_g |Δu| ε^−2.65 / d_p,
///             C_D = 24/Re (1 + 0.15 Re^0.687) for Re < 1000, else 0.44
///   f_d = β V_p/(1−ε) (u_g − v)       (N);  the coefficient β V_p/(1−ε) (kg/s) is what
///   the cell source K_sl sums (PCM, §1.1). ε is clipped to ≥ ε_min (0.35) first [C].

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

struct GidaspowParams {
  double epsMin = 0.35; ///< ε clip of gidaspowParticleCoefficient (the engine: DragParams::epsMin)
  double epsSwitch = 0.8; ///< Ergun / Wen–Yu switch
};

/// Particle Reynolds number with ε included (-).
DEM_HD double reynoldsParticle(double eps, double rhoG, double dp, double slip, double muG) {
  return eps * rhoG * dp * slip / muG;
}

/// Wen–Yu single-sphere drag coefficient (Schiller–Naumann below Re = 1000). Re = 0 → +inf.
DEM_HD double dragCoefficientWenYu(double re) {
  if (re >= 1000.0)
    return 0.44;
  if (re <= 0.0)
    return HUGE_VAL;
  return 24.0 / re * (1.0 + 0.15 * ::pow(re, 0.687));
}

/// The Gidaspow law as registered in kernels/drag.h (DragLaws): the model declaration.
struct GidaspowDrag {
  static constexpr const char* name = "gidaspow";
  static constexpr const char* doc = "Ergun for ε ≤ 0.8, Wen–Yu above (kernels/drag_gidaspow.h)";
  using Params = GidaspowParams;
  static constexpr auto params() { return noParams<Params>(); }

  /// β V_p/(1−ε) (kg/s) for ε already clipped to [ε_min, 1) (kernels/drag.h does that for every
  /// law). Near ε = 1 both branches stay finite since β ∝ (1−ε).
  DEM_HD static double coefficient(const Params& p, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    const double s = 1.0 - eps;
    double betaOverS;
    if (eps <= p.epsSwitch) {
      betaOverS = 150.0 * s * muG / (eps * dp * dp) + 1.75 * rhoG * slip / dp;
    } else {
      const double re = reynoldsParticle(eps, rhoG, dp, slip, muG);
      betaOverS =
          re <= 0.0 ? 18.0 * muG * ::pow(eps, -2.65) / (dp * dp)
                    : 0.75 * dragCoefficientWenYu(re) * eps * rhoG * slip * ::pow(eps, -2.65) / dp;
    }
    return betaOverS * volume;
  }
};

/// Per-particle drag coefficient β V_p/(1−ε) (kg/s) for gas fraction epsCell, clipped to
/// p.epsMin (and below 1: the dilute limit).
DEM_HD double gidaspowParticleCoefficient(const GidaspowParams& p, double epsCell, double rhoG,
                                          double muG, double dp, double volume, double slip) {
  double eps = epsCell < p.epsMin ? p.epsMin : epsCell;
  if (eps >= 1.0)
    eps = 1.0 - 1e-12; // no particle volume in the cell: dilute limit
  return GidaspowDrag::coefficient(p, eps, rhoG, muG, dp, volume, slip);
}

/// f_d = coefficient·(u_g − v) (N).
DEM_HD Vec3 dragForce(double coefficient, Vec3 ug, Vec3 v) {
  return coefficient * (ug - v);
}

} // namespace coredem::dem::kernels
