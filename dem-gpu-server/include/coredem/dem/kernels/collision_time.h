#pragma once
/// @file
/// LSD collision time — docs/physics.md §2.1, seed Eq. 12 (MFiX check_solids_dem.f):
///   t_col = π / √( k_n/m_eff − η_n²/(4 m_eff²) )        (s)
/// With η_n from Eq. 13 this equals √(m_eff/k_n)·√(π² + ln² e_n). Δt_DEM,max = t_col,min /
/// dt_factor over the material pairs: coredem::dem::dtDemMax (models.h), the one place it is
/// computed.

#include <math.h>

#include "coredem/dem/kernels/common.h"

namespace coredem::dem::kernels {

/// Eq. 12 for given k_n (N/m), m_eff (kg), η_n (kg/s). Returns +inf when overdamped.
DEM_HD double collisionTime(double kn, double meff, double etan) {
  const double pi = 3.14159265358979323846;
  const double w2 = kn / meff - etan * etan / (4.0 * meff * meff);
  return w2 > 0.0 ? pi / ::sqrt(w2) : HUGE_VAL;
}

} // namespace coredem::dem::kernels
