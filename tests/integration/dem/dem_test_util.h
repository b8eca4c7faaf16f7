#pragma once
// Helpers shared by the DEM integration tests.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "coredem/dem/dem_system.h"
#include "coredem/dem/time_handler.h"

namespace coredem::dem::testing {

constexpr double kPi = 3.14159265358979323846;

/// Index of each global id in a ParticleData.
inline std::vector<std::size_t> indexByGid(const ParticleData& p) {
  std::vector<std::size_t> idx(p.count);
  for (std::size_t i = 0; i < p.count; ++i)
    idx[static_cast<std::size_t>(p.globalId[i])] = i;
  return idx;
}

/// Σ m v over all particles (kg m/s), summed in global-id order.
inline std::vector<double> momentum(const ParticleData& p) {
  std::vector<double> s(3, 0.0);
  const auto idx = indexByGid(p);
  for (std::size_t g = 0; g < p.count; ++g)
    for (int d = 0; d < 3; ++d)
      s[d] += p.mass[idx[g]] * p.velocity[3 * idx[g] + d];
  return s;
}

/// What a settled bed rests on: its weight m g (N, g = 9.81), its fastest particle (m/s) and the
/// walls' force on it averaged over `samples` further sub-steps of Δt_DEM,max (residual
/// vibration averages out; the mean differs from the weight by Δ(momentum)/T).
struct RestingLoad {
  double weight = 0.0;
  double vmax = 0.0;
  std::array<double, 3> wallForce{0.0, 0.0, 0.0};
};
inline RestingLoad restingLoad(DemSystem& sys, int samples = 200) {
  const ParticleData p = sys.particles();
  RestingLoad out;
  for (std::size_t i = 0; i < p.count; ++i) {
    out.weight += p.mass[i] * 9.81;
    out.vmax = std::max(
        out.vmax, std::hypot(p.velocity[3 * i], p.velocity[3 * i + 1], p.velocity[3 * i + 2]));
  }
  for (int k = 0; k < samples; ++k) {
    sys.advance(sys.dtDemMax(), 1);
    const auto f = sys.wallForce();
    for (int q = 0; q < 3; ++q)
      out.wallForce[q] += f[q] / samples;
  }
  return out;
}

/// The `agitated` deck of bench/decks.md with n particles (box walls optional).
inline DemConfig agitatedDeck(std::size_t n, bool walls, std::uint64_t seed = 2024) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  const double d = 1e-3, s = 1.2 * d;
  const long long nx = std::llround(std::cbrt(static_cast<double>(n)));
  const long long nz = (static_cast<long long>(n) + nx * nx - 1) / (nx * nx);
  ParticleSet p;
  p.packing = Packing::Lattice;
  p.spacing = s;
  p.count = n;
  p.diameter = d;
  p.regionMin = {0, 0, 0};
  p.regionMax = {nx * s, nx * s, nz * s};
  p.velocityJitter = 0.5;
  p.seed = seed;
  c.particleSets.push_back(p);
  if (walls)
    c.addBox({0, 0, 0}, p.regionMax);
  return c;
}

} // namespace coredem::dem::testing
