#pragma once
/// @file
/// Pressure-gradient force — docs/physics.md §2, Eq. 6 ("Model A", §1): f_∇p = −V_p ∇p (N), with
/// ∇p the value of the particle's coupling cell (PCM) and V_p = π d_p³/6.

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// Sphere volume from its radius (m³).
DEM_HD double sphereVolume(double r) {
  return 4.0 / 3.0 * 3.14159265358979323846 * r * r * r;
}

DEM_HD Vec3 pressureGradientForce(double volume, Vec3 gradP) {
  return -volume * gradP;
}

} // namespace coredem::dem::kernels
