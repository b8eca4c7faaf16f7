#pragma once
/// @file
/// Gravity body force — docs/physics.md §2, Eq. 6: f_g = m_i g (N).

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// S = double, or a lane type of lanes.h (one particle per lane; g is the same for all).
template <class S>
DEM_HD Vec3T<S> gravityForce(S mass, Vec3 g) {
  return {mass * g.x, mass * g.y, mass * g.z};
}

} // namespace coredem::dem::kernels
