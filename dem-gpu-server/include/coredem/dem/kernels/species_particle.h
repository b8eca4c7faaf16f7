#pragma once
/// @file
/// Particle mass, species mass fractions and size (docs/physics.md §4, seed Eqs. 31–32), the
/// removal criterion (§1.1), and gas-composition helpers used by the reaction kernels.
///
///   (31) dm_i/dt = Σ_{n∈solids} ṁ_sn,i,   d(X_sn,i m_i)/dt = ṁ_sn,i     (kg/s)
///   (32) d_p,i = (6 m_i / (π ρ_p,i))^(1/3),  ρ_p,i constant (shrinking particle)
///   removal: d_p,i < threshold · d_p0,i, threshold = 0.1 [C]
///
/// Update order in the DEM step [S]: rates → mass/diameter → motion → temperature.

#include <cmath>

#include <coredem/dem/kernels/common.h>

namespace coredem::dem::kernels {

/// Max number of solid species carried per particle (char: C, ash; OC: Fe2O3, Fe3O4, Al2O3).
inline constexpr int kMaxSolidSpecies = 4;

/// Explicit Euler update of Eq. 31 over dt (s): m_k = X_k m + dt ṁ_k, clamped at 0;
/// m = Σ m_k; X_k = m_k/m. Returns the mass (kg) added by clamping negative species masses
/// (0 unless a rate overshoots; rate limiters keep it at round-off). If every species is
/// consumed, m = 0 and the fractions are left unchanged.
DEM_HD double updateParticleSpecies(double& m, double* massFraction, const double* mDot, int n,
                                    double dt) {
  double mk[kMaxSolidSpecies];
  double clamped = 0.0;
  double total = 0.0;
  for (int k = 0; k < n; ++k) {
    mk[k] = massFraction[k] * m + dt * mDot[k];
    if (mk[k] < 0.0) {
      clamped -= mk[k];
      mk[k] = 0.0;
    }
    total += mk[k];
  }
  m = total;
  if (total > 0.0) {
    for (int k = 0; k < n; ++k) {
      massFraction[k] = mk[k] / total;
    }
  }
  return clamped;
}

/// Diameter of a shrinking particle of constant density (Eq. 32), m.
DEM_HD double shrinkingDiameter(double m, double rho) {
  constexpr double pi = 3.141592653589793;
  return std::cbrt(6.0 * m / (pi * rho));
}

/// Removal criterion of §1.1: true if d < threshold · d0 (threshold default 0.1 [C]).
DEM_HD bool particleShouldBeRemoved(double d, double d0, double threshold = 0.1) {
  return d < threshold * d0;
}

/// Mole fractions x_n from mass fractions Y_n and molar masses M_n (kg/mol); returns the
/// mixture molar mass M_mix = 1 / Σ(Y_n/M_n), kg/mol.
DEM_HD double moleFractionsFromMassFractions(const double* y, const double* molar, int n,
                                             double* x) {
  double s = 0.0;
  for (int k = 0; k < n; ++k) {
    s += y[k] / molar[k];
  }
  for (int k = 0; k < n; ++k) {
    x[k] = (y[k] / molar[k]) / s;
  }
  return 1.0 / s;
}

/// Molar concentration C = ρ Y / M, mol/m³.
DEM_HD double molarConcentration(double rho, double y, double molar) {
  return rho * y / molar;
}

/// One cell's gas state, the only one the DEM's rates use (docs/thermochemistry.md "Gas state"):
/// from the cell's density ρ (the per-cell ρ_g the CFD sends) and mass fractions Y_k of the
/// case's n gas species with molar masses M_k,
///   M_mix = 1/Σ_k (Y_k/M_k),   x_k = Y_k M_mix/M_k,   c_k = ρ Y_k/M_k  (mol/m³).
/// Returns M_mix (kg/mol); 0 and x = 0 when Σ Y_k/M_k ≤ 0 (no gas species in the cell). When ρ
/// is the ideal-gas density p M_mix/(R T), c_k = x_k p/(R T): the rates that use c_k and those
/// that use x_k p see the same gas.
DEM_HD double cellGasState(double rho, const double* y, const double* molar, int n, double* x,
                           double* c) {
  double s = 0.0;
  for (int k = 0; k < n; ++k) {
    s += y[k] / molar[k];
  }
  const double mMix = s > 0.0 ? 1.0 / s : 0.0;
  for (int k = 0; k < n; ++k) {
    x[k] = s > 0.0 ? y[k] * mMix / molar[k] : 0.0;
    c[k] = rho * y[k] / molar[k];
  }
  return mMix;
}

/// Ideal-gas density ρ = p M_mix / (R T), kg/m³ (R = 8.314462618 J/(mol K)).
DEM_HD double idealGasDensity(double p, double molarMix, double t) {
  return p * molarMix / (8.314462618 * t);
}

} // namespace coredem::dem::kernels
