#pragma once
/// @file
/// Syamlal–O'Brien drag calibrated to a measured minimum fluidization velocity (docs/physics.md
/// §2.2.3; Syamlal & O'Brien 2003, MFiX's drag_c1/drag_d1): the constant c1 of B = c1 ε^1.28 is
/// chosen so that at ε_mf and the superficial velocity U_mf the law's drag carries the bed's
/// buoyant weight,
///   C(ε_mf, U_mf/ε_mf) · U_mf / ε_mf² = V_p (ρ_p − ρ_g) |g|,   i.e.  β U_mf/ε_mf² =
///   (1−ε_mf)(ρ_p−ρ_g)|g|
/// (C = β V_p/(1−ε), the kernel's per-particle coefficient; the same balance gives Ergun's
/// equation for the Ergun law), and d1 keeps B continuous at ε = 0.85:
///   c1 · 0.85^1.28 = 0.85^d1,  d1 = 1.28 + ln c1 / ln 0.85.
/// Host code (the case reader); the kernel is the one the engine runs.

#include <cmath>
#include <optional>

#include "coredem/dem/kernels/drag_syamlal_beetstra.h"

namespace coredem::dem {

struct SyamlalCalibration {
  double c1 = 0.8, d1 = 2.65;
};

/// The bed's drag at U_mf over its buoyant weight, minus 1, for constants c1 (d1 continuous).
inline double syamlalBalance(double c1, double uMf, double epsMf, double dp, double rhoP,
                             double rhoG, double muG, double g) {
  const double volume = M_PI / 6.0 * dp * dp * dp;
  const kernels::SyamlalObrienDrag::Params p{c1, 1.28 + std::log(c1) / std::log(0.85)};
  const double coefficient =
      kernels::SyamlalObrienDrag::coefficient(p, epsMf, rhoG, muG, dp, volume, uMf / epsMf);
  return coefficient * uMf / (epsMf * epsMf) / (volume * (rhoP - rhoG) * g) - 1.0;
}

/// c1 and d1 for which the law fluidizes at U_mf with voidage ε_mf (0 < ε_mf ≤ 0.85), by
/// bisection on ln c1 over [1e-3, 1.2] (d1 > 0 needs c1 < 0.85^-1.28 = 1.23; a larger c1 gives a
/// larger V_r and less drag); nullopt when no c1 in that range does (U_mf far outside what the
/// correlation can give).
inline std::optional<SyamlalCalibration> calibrateSyamlal(double uMf, double epsMf, double dp,
                                                          double rhoP, double rhoG, double muG,
                                                          double g) {
  double lo = std::log(1e-3), hi = std::log(1.2);
  auto f = [&](double lnC1) {
    return syamlalBalance(std::exp(lnC1), uMf, epsMf, dp, rhoP, rhoG, muG, g);
  };
  if (!(f(lo) > 0.0 && f(hi) < 0.0)) {
    return std::nullopt;
  }
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > 0.0 ? lo : hi) = mid;
  }
  const double c1 = std::exp(0.5 * (lo + hi));
  return SyamlalCalibration{c1, 1.28 + std::log(c1) / std::log(0.85)};
}

} // namespace coredem::dem
