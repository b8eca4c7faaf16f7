#pragma once
/// @file
/// Particle centroid method (PCM) on a uniform Cartesian coupling grid — docs/physics.md §1.1, seed
/// Eq. 5: a particle belongs entirely to the cell that holds its centre;
///   ε_g,c = 1 − (1/V_c) Σ_{i∈c} V_p,i.
/// Cells are numbered c = i + nx (j + ny k); O(1) lookup.

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

struct GridParams {
  Vec3 origin;     ///< m
  Vec3 invSpacing; ///< 1/Δx, 1/Δy, 1/Δz (1/m)
  int nx, ny, nz;
};

/// Cell index of point x, or −1 when x lies outside the grid.
DEM_HD long long pcmCell(const GridParams& g, Vec3 x) {
  const double fx = (x.x - g.origin.x) * g.invSpacing.x;
  const double fy = (x.y - g.origin.y) * g.invSpacing.y;
  const double fz = (x.z - g.origin.z) * g.invSpacing.z;
  if (!(fx >= 0.0 && fy >= 0.0 && fz >= 0.0))
    return -1; // also rejects NaN
  const long long i = static_cast<long long>(::floor(fx));
  const long long j = static_cast<long long>(::floor(fy));
  const long long k = static_cast<long long>(::floor(fz));
  if (i >= g.nx || j >= g.ny || k >= g.nz)
    return -1;
  return i + static_cast<long long>(g.nx) * (j + static_cast<long long>(g.ny) * k);
}

/// ε_g of a cell from the solid volume it holds (PCM). Not clipped here (drag clips).
DEM_HD double pcmGasFraction(double solidVolume, double cellVolume) {
  return 1.0 - solidVolume / cellVolume;
}

} // namespace coredem::dem::kernels
