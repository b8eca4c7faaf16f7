#pragma once
/// @file
/// Li & Mason (2000) Nusselt correlation, as used by Zhou, Yu & Zulli (2009) — docs/physics.md
/// §3.1, seed Eq. 21 (n = 3.5 dilute, 4.75 dense):
///   Nu = 2 + 0.6 εⁿ Re^0.5 Pr^(1/3)                             Re < 200
///   Nu = 2 + 0.5 εⁿ Re^0.5 Pr^(1/3) + 0.02 εⁿ Re^0.8 Pr^(1/3)    200 ≤ Re < 1500
///   Nu = 2 + 4.5e-5 εⁿ Re^1.8                                   Re ≥ 1500
/// n is the family's voidage exponent (`models: {nusselt_exponent: …}`, ConvectionParams).

#include <cmath>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// The Li–Mason correlation as registered in kernels/convection.h (NusseltModels).
struct LiMasonNusselt {
  static constexpr const char* name = "li-mason";
  static constexpr const char* doc = "Li & Mason (2000), Nu = 2 + 0.6 εⁿ Re^½ Pr^⅓ (Re < 200) …";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  /// εⁿ: the factor that depends on the gas state only (once per cell and CFD step), −.
  DEM_HD static double voidageFactor(const Params&, double eps, double n) {
    return std::pow(eps, n);
  }

  /// Nu from Re, Pr^(1/3) and en = voidageFactor(), −.
  DEM_HD static double evaluate(const Params&, double re, double pr13, double en) {
    if (re < 200.0) {
      return 2.0 + 0.6 * en * std::sqrt(re) * pr13;
    }
    if (re < 1500.0) {
      return 2.0 + en * (0.5 * std::sqrt(re) + 0.02 * std::pow(re, 0.8)) * pr13;
    }
    return 2.0 + 4.5e-5 * en * std::pow(re, 1.8);
  }
};

/// Li–Mason Nusselt number (Eq. 21), −.
DEM_HD double nusseltLiMason(double re, double pr, double eps, double n) {
  const double en = LiMasonNusselt::voidageFactor({}, eps, n);
  return LiMasonNusselt::evaluate({}, re, std::cbrt(pr), en);
}

} // namespace coredem::dem::kernels
