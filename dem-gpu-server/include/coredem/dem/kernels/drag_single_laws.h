#pragma once
/// @file
/// Wen–Yu, Ergun and the smooth Huilin–Gidaspow blend of the two (docs/physics.md §2.2.1), the
/// laws the Gidaspow switch (drag_gidaspow.h) is made of, each usable alone:
///   Re_p = ε ρ_g d_p |Δu| / μ_g                           (superficial slip)
///   Wen–Yu (1966), valid for dilute suspensions (ε ≳ 0.8):
///     β = ¾ C_D ε (1−ε) ρ_g |Δu| ε^−2.65 / d_p,  C_D = 24/Re (1 + 0.15 Re^0.687) (Re < 1000),
///     0.44 above
///   Ergun (1952), valid for dense packed beds (ε ≲ 0.8):
///     β = 150 (1−ε)² μ_g/(ε d_p²) + 1.75 (1−ε) ρ_g |Δu|/d_p
///   Huilin & Gidaspow (2003) blend (MFiX GIDASPOW_BLEND): φ = ½ + arctan(262.5 (ε_s − 0.2))/π,
///     ε_s = 1 − ε, β = (1 − φ) β_Wen–Yu + φ β_Ergun: continuous where Gidaspow switches.
/// Each returns β V_p/(1−ε) (kg/s), ε already clipped to [ε_min, 1) (kernels/drag.h).

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/drag_gidaspow.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// β/(1−ε) of Wen–Yu (kg/m³/s); the Stokes limit 18 μ ε^−2.65/d² at zero slip.
DEM_HD double wenYuBetaOverSolid(double eps, double rhoG, double muG, double dp, double slip) {
  const double re = reynoldsParticle(eps, rhoG, dp, slip, muG);
  return re <= 0.0 ? 18.0 * muG * ::pow(eps, -2.65) / (dp * dp)
                   : 0.75 * dragCoefficientWenYu(re) * eps * rhoG * slip * ::pow(eps, -2.65) / dp;
}

/// β/(1−ε) of Ergun (kg/m³/s).
DEM_HD double ergunBetaOverSolid(double eps, double rhoG, double muG, double dp, double slip) {
  return 150.0 * (1.0 - eps) * muG / (eps * dp * dp) + 1.75 * rhoG * slip / dp;
}

struct WenYuDrag {
  static constexpr const char* name = "wen-yu";
  static constexpr const char* doc = "Wen & Yu (1966) at every ε: dilute suspensions "
                                     "(kernels/drag_single_laws.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    return wenYuBetaOverSolid(eps, rhoG, muG, dp, slip) * volume;
  }
};

struct ErgunDrag {
  static constexpr const char* name = "ergun";
  static constexpr const char* doc = "Ergun (1952) at every ε: packed beds "
                                     "(kernels/drag_single_laws.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    return ergunBetaOverSolid(eps, rhoG, muG, dp, slip) * volume;
  }
};

/// The blend's weight φ of Ergun (MFiX: atan(150·1.75·(ε_s − 0.2))/π + ½).
DEM_HD double huilinGidaspowWeight(double eps) {
  return 0.5 + ::atan(262.5 * ((1.0 - eps) - 0.2)) / 3.14159265358979323846;
}

struct GidaspowBlendDrag {
  static constexpr const char* name = "gidaspow-blend";
  static constexpr const char* doc = "Huilin & Gidaspow (2003): Wen–Yu and Ergun blended "
                                     "smoothly about ε = 0.8 (kernels/drag_single_laws.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double volume, double slip) {
    const double phi = huilinGidaspowWeight(eps);
    return ((1.0 - phi) * wenYuBetaOverSolid(eps, rhoG, muG, dp, slip) +
            phi * ergunBetaOverSolid(eps, rhoG, muG, dp, slip)) *
           volume;
  }
};

} // namespace coredem::dem::kernels
