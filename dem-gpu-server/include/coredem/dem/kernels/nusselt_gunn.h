#pragma once
/// @file
/// Gunn (1978) Nusselt correlation for fixed and fluidized beds — docs/physics.md §3.1:
///   Nu = (7 − 10 ε + 5 ε²)(1 + 0.7 Re^0.2 Pr^(1/3)) + (1.33 − 2.4 ε + 1.2 ε²) Re^0.7 Pr^(1/3)
/// with Re = ε ρ_g d_p |Δu|/μ_g (superficial slip: `convection_reynolds: with-voidage`, the
/// default); 0.35 ≤ ε ≤ 1, Re up to 10^5. Nu → 2 at ε = 1, Re = 0 (one sphere in a still gas).
/// The voidage exponent n of Li–Mason is not used: the ε dependence is the correlation's own.

#include <cmath>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

struct GunnNusselt {
  static constexpr const char* name = "gunn";
  static constexpr const char* doc = "Gunn (1978), fixed and fluidized beds, ε 0.35–1 "
                                     "(kernels/nusselt_gunn.h)";
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  /// The gas fraction itself (clipped as for every correlation): the correlation's polynomials
  /// in ε are evaluated per particle.
  DEM_HD static double voidageFactor(const Params&, double eps, double) { return eps; }

  /// Nu from Re, Pr^(1/3) and ε, −.
  DEM_HD static double evaluate(const Params&, double re, double pr13, double eps) {
    const double a = 7.0 - 10.0 * eps + 5.0 * eps * eps;
    const double b = 1.33 - 2.4 * eps + 1.2 * eps * eps;
    return a * (1.0 + 0.7 * std::pow(re, 0.2) * pr13) + b * std::pow(re, 0.7) * pr13;
  }
};

} // namespace coredem::dem::kernels
