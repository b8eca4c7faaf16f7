#pragma once
/// @file
/// Nusselt correlations of Gunn's form for fixed and fluidized beds — docs/physics.md §3.1:
///   Nu = (7 − 10 ε + 5 ε²)(1 + a Re^0.2 Pr^(1/3)) + (b − c ε + e ε²) Re^0.7 Pr^(1/3)
/// with Re = ε ρ_g d_p |Δu|/μ_g (superficial slip: `convection_reynolds: with-voidage`, the
/// default):
///   Gunn (1978, experiments):            a = 0.7,  b = 1.33, c = 2.4,  e = 1.2;
///                                        0.35 ≤ ε ≤ 1, Re up to 10^5
///   Deen et al. (2014, PR-DNS fit):      a = 0.17, b = 1.33, c = 2.31, e = 1.16;
///                                        0.5 ≤ ε ≤ 1, Re ≤ 100
///   Tavassoli et al. (2015, PR-DNS fit): a = 0.1,  b = 1.33, c = 2.19, e = 1.15;
///                                        0.5 ≤ ε ≤ 1, Re ≤ 100
/// Nu → 2 at ε = 1, Re = 0 (one sphere in a still gas) for all three. The voidage exponent n of
/// Li–Mason is not used: the ε dependence is the correlation's own.

#include <cmath>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// The shared form; `Coefficients` supplies a, b, c, e (see the file comment).
template <class Coefficients>
struct GunnFormNusselt {
  struct Params {};
  static constexpr auto params() { return noParams<Params>(); }

  /// The gas fraction itself (clipped as for every correlation): the correlation's polynomials
  /// in ε are evaluated per particle.
  DEM_HD static double voidageFactor(const Params&, double eps, double) { return eps; }

  /// Nu from Re, Pr^(1/3) and ε, −.
  DEM_HD static double evaluate(const Params&, double re, double pr13, double eps) {
    const double lo = 7.0 - 10.0 * eps + 5.0 * eps * eps;
    const double hi = Coefficients::b - Coefficients::c * eps + Coefficients::e * eps * eps;
    return lo * (1.0 + Coefficients::a * std::pow(re, 0.2) * pr13) + hi * std::pow(re, 0.7) * pr13;
  }
};

struct GunnCoefficients {
  static constexpr double a = 0.7, b = 1.33, c = 2.4, e = 1.2;
};
struct DeenCoefficients {
  static constexpr double a = 0.17, b = 1.33, c = 2.31, e = 1.16;
};
struct TavassoliCoefficients {
  static constexpr double a = 0.1, b = 1.33, c = 2.19, e = 1.15;
};

struct GunnNusselt : GunnFormNusselt<GunnCoefficients> {
  static constexpr const char* name = "gunn";
  static constexpr const char* doc = "Gunn (1978), fixed and fluidized beds, ε 0.35–1 "
                                     "(kernels/nusselt_gunn.h)";
};

struct DeenNusselt : GunnFormNusselt<DeenCoefficients> {
  static constexpr const char* name = "deen";
  static constexpr const char* doc = "Deen et al. (2014), particle-resolved DNS, ε 0.5–1, "
                                     "Re ≤ 100 (kernels/nusselt_gunn.h)";
};

struct TavassoliNusselt : GunnFormNusselt<TavassoliCoefficients> {
  static constexpr const char* name = "tavassoli";
  static constexpr const char* doc = "Tavassoli et al. (2015), particle-resolved DNS, ε 0.5–1, "
                                     "Re ≤ 100 (kernels/nusselt_gunn.h)";
};

} // namespace coredem::dem::kernels
