#pragma once
/// @file
/// Drag laws of the voidage-function form (docs/physics.md §2.2.2): the single-sphere drag at the
/// superficial slip times ε^−χ (Di Felice 1994; Rong, Dong & Yu 2013):
///   Re = ε ρ_g d_p |Δu| / μ_g,   C_D0 = (0.63 + 4.8/√Re)²          (Dallavalle)
///   f_d = ½ C_D0 ρ_g (π d_p²/4) ε² |Δu| Δu ε^−χ
///   Di Felice:  χ = 3.7 − 0.65 exp(−(1.5 − log10 Re)²/2)
///   Rong:       χ = 2.65 (ε + 1) − (5.3 − 3.5 ε) ε² exp(−(1.5 − log10 Re)²/2)
/// so β V_p/(1−ε) = (π/8) C_D0 ρ_g d_p² ε^(2−χ) |Δu|; at zero slip the Stokes limit
/// C_D0 Re → 4.8² gives 3π μ_g d_p ε (4.8²/24) ε^(1−χ) with χ of Re → 0.
/// Valid (their fits): Di Felice 10^-2 < Re < 10^4, ε 0.4–1; Rong Re < 1000, ε 0.4–0.8
/// (packed beds of uniform spheres by lattice Boltzmann).

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// The exponent's bell exp(−(1.5 − log10 Re)²/2); 0 at Re = 0.
DEM_HD double voidageBell(double re) {
  if (re <= 0.0)
    return 0.0;
  const double x = 1.5 - ::log10(re);
  return ::exp(-0.5 * x * x);
}

/// β V_p/(1−ε) (kg/s) of the voidage-function form with exponent chi.
DEM_HD double voidageFunctionCoefficient(double chi, double eps, double rhoG, double muG, double dp,
                                         double slip) {
  const double re = eps * rhoG * dp * slip / muG;
  const double pi = 3.14159265358979323846;
  if (re <= 0.0) { // C_D0 |Δu| → 4.8² μ/(ε ρ d): the creeping-flow limit
    return 0.125 * pi * 4.8 * 4.8 * muG * dp * ::pow(eps, 1.0 - chi);
  }
  const double c = 0.63 + 4.8 / ::sqrt(re);
  return 0.125 * pi * c * c * rhoG * dp * dp * ::pow(eps, 2.0 - chi) * slip;
}

struct DiFeliceDrag {
  static constexpr const char* name = "di-felice";
  static constexpr const char* doc = "Di Felice (1994): single-sphere drag times ε^−χ "
                                     "(kernels/drag_voidage_function.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double chi(double re) { return 3.7 - 0.65 * voidageBell(re); }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double, double slip) {
    return voidageFunctionCoefficient(chi(eps * rhoG * dp * slip / muG), eps, rhoG, muG, dp, slip);
  }
};

struct RongDrag {
  static constexpr const char* name = "rong";
  static constexpr const char* doc = "Rong, Dong & Yu (2013): Di Felice's form with χ(ε, Re) "
                                     "from packed beds (kernels/drag_voidage_function.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }
  DEM_HD static double chi(double eps, double re) {
    return 2.65 * (eps + 1.0) - (5.3 - 3.5 * eps) * eps * eps * voidageBell(re);
  }
  DEM_HD static double coefficient(const Params&, double eps, double rhoG, double muG, double dp,
                                   double, double slip) {
    return voidageFunctionCoefficient(chi(eps, eps * rhoG * dp * slip / muG), eps, rhoG, muG, dp,
                                      slip);
  }
};

} // namespace coredem::dem::kernels
