#pragma once
/// @file
/// Ranz–Marshall Nusselt correlation (MFiX `des_thermo_conv.f`) — docs/physics.md §3.1:
///   Nu = 2 + 0.6 Re^0.5 Pr^(1/3)
/// (no voidage correction: the voidage exponent is ignored).

#include <cmath>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// The Ranz–Marshall correlation as registered in kernels/convection.h (NusseltModels).
struct RanzMarshallNusselt {
  static constexpr const char* name = "ranz-marshall";
  static constexpr const char* doc = "Ranz–Marshall, Nu = 2 + 0.6 Re^½ Pr^⅓ (MFiX)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  /// No voidage factor: 1.
  DEM_HD static double voidageFactor(const Params&, double, double) { return 1.0; }

  /// Nu from Re and Pr^(1/3), −.
  DEM_HD static double evaluate(const Params&, double re, double pr13, double) {
    return 2.0 + 0.6 * std::sqrt(re) * pr13;
  }
};

/// Ranz–Marshall Nusselt number, −.
DEM_HD double nusseltRanzMarshall(double re, double pr) {
  return RanzMarshallNusselt::evaluate({}, re, std::cbrt(pr), 1.0);
}

} // namespace coredem::dem::kernels
