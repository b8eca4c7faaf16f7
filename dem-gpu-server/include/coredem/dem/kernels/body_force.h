#pragma once
/// @file
/// Gravity body force — docs/physics.md §2, Eq. 6: f_g = m_i g (N).

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

DEM_HD Vec3 gravityForce(double mass, Vec3 g) {
  return mass * g;
}

} // namespace coredem::dem::kernels
