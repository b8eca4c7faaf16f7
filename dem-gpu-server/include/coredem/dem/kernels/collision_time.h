#pragma once
/// @file
/// Contact time scales and the DEM step — docs/physics.md §2.1, Eq. 12 and the step limits:
///   t_col = π / √( k_n/m_eff − η_n²/(4 m_eff²) )    damped contact duration (s), seed Eq. 12
///                                                   (MFiX check_solids_dem.f); with η_n from
///                                                   Eq. 13, √(m_eff/k_n)·√(π² + ln² e_n)
///   t_0   = π √(m_eff/k)                            undamped half period (s)
///   Δt_s  = 2 (√(1 + ζ²) − ζ) / ω_0,  ω_0 = √(k/m), ζ = η / (2 √(k m))
/// Δt_s is the stability limit of the DEM's integrator (symplectic Euler, kernels/motion.h) on
/// the damped oscillator m ẍ = −k x − η ẋ: one step maps (v, x) by the matrix
/// [[1 − 2ζω_0Δt, −ω_0²Δt], [Δt (1 − 2ζω_0Δt), 1 − ω_0²Δt²]], of determinant 1 − 2ζω_0Δt and
/// trace 2 − 2ζω_0Δt − ω_0²Δt²; both eigenvalues lie inside the unit circle iff
/// ω_0²Δt² + 4ζω_0Δt < 4, i.e. Δt < Δt_s (the determinant's bound ζω_0Δt < 1 is then met).
/// t_col grows without bound as e_n → 0 (ζ → 1) while t_0 and Δt_s do not: Δt_DEM,max is taken
/// from t_0 and Δt_s (coredem::dem::dtDemMax, models.h, the one place it is computed).

#include <math.h>

#include "coredem/dem/kernels/common.h"

namespace coredem::dem::kernels {

/// Eq. 12 for given k_n (N/m), m_eff (kg), η_n (kg/s). Returns +inf when overdamped.
DEM_HD double collisionTime(double kn, double meff, double etan) {
  const double pi = 3.14159265358979323846;
  const double w2 = kn / meff - etan * etan / (4.0 * meff * meff);
  return w2 > 0.0 ? pi / ::sqrt(w2) : HUGE_VAL;
}

/// Undamped half period t_0 = π √(m/k) (s) of stiffness k (N/m) and mass m (kg).
DEM_HD double undampedCollisionTime(double k, double m) {
  const double pi = 3.14159265358979323846;
  return pi * ::sqrt(m / k);
}

/// Δt_s (s): the largest step for which symplectic Euler keeps the oscillator of stiffness k
/// (N/m), mass m (kg) and damping η (kg/s) from growing (the file comment).
DEM_HD double dampedStepLimit(double k, double m, double eta) {
  const double w0 = ::sqrt(k / m);
  const double zeta = eta / (2.0 * ::sqrt(k * m));
  return 2.0 / ((::sqrt(1.0 + zeta * zeta) + zeta) * w0); // = 2 (√(1 + ζ²) − ζ) / ω_0
}

} // namespace coredem::dem::kernels
