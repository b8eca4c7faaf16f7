#pragma once
/// @file
/// The DEM benchmark decks of bench/decks.md, shared by `coredem-bench dem` and
/// `coredem-bench thermochem` (and mirrored by bench/peers/liggghts/make_deck.py).

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "coredem/dem/dem_system.h"

namespace coredem::bench {

/// The decks of bench/decks.md (material: Patil glass, docs/physics.md §7).
inline coredem::dem::DemConfig deck(const std::string& name, std::size_t n) {
  using namespace coredem::dem;
  DemConfig c;
  c.materials[0] = Material{"glass", 1000.0, 0.97, 0.1, 2.0 / 7.0, 0.5};
  const double d = 1e-3;
  const bool packed = name == "packed";
  const double s = packed ? 0.9999 * d : 1.2 * d;
  const long long nx = std::llround(std::cbrt(static_cast<double>(n)));
  const long long ny = nx;
  const long long nz = (static_cast<long long>(n) + nx * ny - 1) / (nx * ny);
  ParticleSet p;
  p.name = name;
  p.packing = Packing::Lattice;
  p.spacing = s;
  p.count = n;
  p.diameter = d;
  p.density = 2500.0;
  p.regionMin = {0, 0, 0};
  p.regionMax = {nx * s, ny * s, nz * s};
  if (packed) {
    c.gravity = {0, 0, -9.81};
    c.addBox({0, 0, 0}, {nx * s, ny * s, 2.0 * nz * s});
  } else {
    c.gravity = {0, 0, 0};
    p.velocityJitter = 0.5;
    p.seed = 20240611;
    c.addBox({0, 0, 0}, {nx * s, ny * s, nz * s});
  }
  c.particleSets.push_back(p);
  // Mechanics only, as the peer decks (LIGGGHTS runs no heat transfer): `coredem-bench dem
  // --heat` and `coredem-bench thermochem` switch the heat module on.
  c.heat.enabled = false;
  return c;
}

/// A PCM coupling grid over the deck's box with cells of about `cell` metres (docs/physics.md §1.1:
/// Δx ≈ 3–5 d_p). addBox order of the walls: x lo/hi, y lo/hi, z lo/hi.
inline void addCouplingGrid(coredem::dem::DemConfig& cfg, double cell) {
  const std::array<double, 3> hi{cfg.walls[1].point[0], cfg.walls[3].point[1],
                                 cfg.walls[5].point[2]};
  for (int d = 0; d < 3; ++d) {
    cfg.grid.counts[d] = std::max(1, static_cast<int>(hi[d] / cell));
    cfg.grid.spacing[d] = hi[d] / cfg.grid.counts[d];
  }
}

/// Uniform gas fields for the benchmarks: air at T_g rising at `uz` m/s, hydrostatic ∇p.
/// Translational kinetic energy ½ Σ m v² (J), as LIGGGHTS' thermo `ke` with `norm no` (the
/// peer scripts compare it to check that both codes start from the same particles).
inline double kineticEnergy(const coredem::dem::DemSystem& sys) {
  const coredem::dem::ParticleData p = sys.particles();
  double e = 0;
  for (std::size_t i = 0; i < p.count; ++i)
    e += 0.5 * p.mass[i] *
         (p.velocity[3 * i] * p.velocity[3 * i] + p.velocity[3 * i + 1] * p.velocity[3 * i + 1] +
          p.velocity[3 * i + 2] * p.velocity[3 * i + 2]);
  return e;
}

struct BenchGas {
  std::vector<double> ug, gradP, Tg, rho, mu, kappa, cp;
  BenchGas(std::size_t cells, double uz, double tg) {
    ug.assign(3 * cells, 0.0);
    gradP.assign(3 * cells, 0.0);
    for (std::size_t c = 0; c < cells; ++c) {
      ug[3 * c + 2] = uz;
      gradP[3 * c + 2] = -1.204 * 9.81;
    }
    Tg.assign(cells, tg);
    rho.assign(cells, 1.204 * 293.15 / tg);
    mu.assign(cells, 1.81e-5);
    kappa.assign(cells, 0.0257);
    cp.assign(cells, 1005.0);
  }
  coredem::dem::GasFieldsView view() const {
    return coredem::dem::GasFieldsView{ug, gradP, Tg, rho, mu, kappa, cp, {}, {}, {}};
  }
};

} // namespace coredem::bench
