#pragma once
/// @file
/// Normal damping coefficient from the restitution coefficient — docs/physics.md §2.1, seed Eq. 13
/// (MFiX check_solids_dem.f):
///   η_n = 2 √(k_n m_eff) |ln e_n| / √(π² + ln² e_n)      (e_n = 0 → η_n = 2 √(k_n m_eff))
/// Units: k_n N/m, m_eff kg → η_n kg/s. m_eff = m_i m_j/(m_i+m_j), wall: m_eff = m_i.

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/lanes.h"

namespace coredem::dem::kernels {

/// The m_eff-independent factor c(e_n) = 2|ln e_n|/√(π² + ln² e_n), so η_n = c √(k_n m_eff).
/// @pre 0 <= e_n <= 1.
DEM_HD double dampingFactor(double en) {
  const double pi = 3.14159265358979323846;
  if (en <= 0.0)
    return 2.0;
  const double l = ::log(en);
  return 2.0 * ::fabs(l) / ::sqrt(pi * pi + l * l);
}

/// Eq. 13: η_n (kg/s).
DEM_HD double normalDamping(double kn, double meff, double en) {
  return dampingFactor(en) * ::sqrt(kn * meff);
}

/// Effective mass of a pair (kg); mj <= 0 denotes a wall (m_eff = m_i). S: lanes.h.
template <class S>
DEM_HD S effectiveMass(S mi, S mj) {
  return laneSelect(mj > 0.0, mi * mj / (mi + mj), mi);
}

} // namespace coredem::dem::kernels
