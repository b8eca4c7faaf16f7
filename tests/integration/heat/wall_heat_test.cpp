// Fixed-temperature walls in the DEM heat stage (kernels/wall_conduction.h, heat.h;
// docs/heat-coupling.md "Walls"): one particle resting on a hot wall heats towards the wall
// temperature at the rate the kernel predicts, the wall heat is booked in HeatTotals::wall, and
// adiabatic walls transfer nothing. Real DemSystem runs on the cpu backend.
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/wall_conduction.h"
#include "coredem/dem/models.h"
#include "coredem/dem/triangle_mesh.h"

using namespace coredem::dem;
namespace k = coredem::dem::kernels;

namespace {

constexpr double kD = 1.0e-3, kRho = 2500.0, kCp = 840.0, kKp = 1.0, kKw = 16.0;
constexpr double kDelta = 1.0e-5; // particle–wall overlap (m)
constexpr double kT0 = 293.15, kTw = 363.15;

/// One glass bead resting on the floor z = 0 of a box (walls of material 1, steel-like k), with
/// a negligible contact stiffness (1e-22 N/m) and no gravity, so it stays where it is put (the
/// wall force 1e-27 N moves it by ~1e-21 m in 2 s).
DemConfig bead(double wallTemperature) {
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  Material glass;
  glass.name = "glass";
  glass.kn = 1e-22;
  glass.en = 0.9;
  glass.mu = 0.0;
  glass.cp = kCp;
  glass.conductivity = kKp;
  glass.emissivity = 0.0;
  Material steel = glass;
  steel.name = "steel";
  steel.conductivity = kKw;
  cfg.materials = {glass, steel};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.material = 0;
  s.diameter = kD;
  s.density = kRho;
  s.temperature = kT0;
  s.positions = {5e-3, 5e-3, 0.5 * kD - kDelta};
  cfg.particleSets.push_back(s);
  cfg.addBox({0, 0, 0}, {1e-2, 1e-2, 1e-2});
  cfg.wallTemperature = wallTemperature;
  cfg.wallMaterial = 1;
  return cfg;
}

double massHeatCapacity() {
  return kRho * M_PI * kD * kD * kD / 6.0 * kCp;
}

double onlyTemperature(const DemSystem& s) {
  return s.particles().temperature[0];
}

std::string sci(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

} // namespace

// No gas: contact conduction only, G = 4 kp kw/(kp + kw) r_c, explicit Euler
// T_n = T_w + (T_0 − T_w)(1 − G Δt/(m c))^n. Criteria: the discrete solution to 1e-9 K (the
// round-off of 2·10⁴ additions to T ≈ 300 K, ulp 5.7e-14 K), the continuous one to the Euler
// error (k Δt/2 · k t relative in T − T_w), and the ledger: Σ m c ΔT = HeatTotals::wall to
// 1e-12 of Σ m c T.
TEST(WallHeat, BeadOnHotWallHeatsAtTheKernelRate) {
  DemSystem sys(bead(kTw), BackendKind::Cpu, 1);
  const double g = k::wallContactConductance(kKp, kKw, 0.5 * kD, 0.5 * kD - kDelta);
  ASSERT_GT(g, 0.0);
  const double mc = massHeatCapacity();
  const double rate = g / mc; // 1/s
  const double e0 = sys.thermalEnergy();
  const double dt = 1e-4;
  const int nWin = 20, nSub = 1000; // 2 s
  double worstDiscrete = 0.0, worstContinuous = 0.0;
  for (int w = 1; w <= nWin; ++w) {
    sys.advance(nSub * dt, nSub);
    const double t = onlyTemperature(sys);
    const int n = w * nSub;
    const double discrete = kTw + (kT0 - kTw) * std::pow(1.0 - rate * dt, n);
    const double continuous = kTw + (kT0 - kTw) * std::exp(-rate * n * dt);
    worstDiscrete = std::max(worstDiscrete, std::fabs(t - discrete));
    worstContinuous =
        std::max(worstContinuous, std::fabs(t - continuous) / std::fabs(continuous - kTw));
  }
  EXPECT_LT(worstDiscrete, 1e-9);
  EXPECT_LT(worstContinuous, 0.5 * rate * dt * rate * 2.0 * 1.01);
  const double gain = sys.thermalEnergy() - e0;
  EXPECT_GT(gain, 0.0);
  EXPECT_NEAR(sys.heatTotals().wall, gain, 1e-12 * e0);
  EXPECT_EQ(sys.heatTotals().convection, 0.0);
  RecordProperty("wall_rate_per_s", sci(rate));
  RecordProperty("wall_max_error_vs_euler_K", sci(worstDiscrete));
}

// Adiabatic walls (temperature 0, the default) and fixed-temperature walls with both wall
// switches off transfer nothing.
TEST(WallHeat, AdiabaticWallsTransferNothing) {
  for (int variant = 0; variant < 2; ++variant) {
    DemConfig cfg = bead(variant == 0 ? 0.0 : kTw);
    if (variant == 1) {
      ASSERT_TRUE(applyModelOption(cfg, "wall_conduction", "off"));
      ASSERT_TRUE(applyModelOption(cfg, "wall_lens_conduction", "off"));
    }
    DemSystem sys(cfg, BackendKind::Cpu, 1);
    sys.advance(0.1, 1000);
    EXPECT_EQ(onlyTemperature(sys), kT0) << "variant " << variant;
    EXPECT_EQ(sys.heatTotals().wall, 0.0);
  }
}

// Coupled (one gas cell, convection off): the wall lens adds κ_g I(h) to the contact
// conductance. One window of 100 sub-steps: T follows the Euler recursion with G = G_c + κ_g I
// (to 1e-11 K: 100 additions to T ≈ 300 K), and the ledger closes to 1e-12 of Σ m c T.
TEST(WallHeat, CoupledWallLensAddsToContact) {
  DemConfig cfg = bead(kTw);
  cfg.grid.origin = {0, 0, 0};
  cfg.grid.spacing = {1e-2, 1e-2, 1e-2};
  cfg.grid.counts = {1, 1, 1};
  ASSERT_TRUE(applyModelOption(cfg, "convection", "off"));
  ASSERT_TRUE(applyModelOption(cfg, "lens_conduction", "off"));
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  const double kg = 0.0257;
  std::vector<double> u(3, 0.0), gp(3, 0.0), tg(1, kT0), rho(1, 1.204), mu(1, 1.81e-5),
      kappa(1, kg), cp(1, 1006.0);
  sys.setGasFields(GasFieldsView{u, gp, tg, rho, mu, kappa, cp, {}, {}, {}});
  k::WallConductionParams wp;
  const double h = 0.5 * kD - kDelta;
  const double g =
      k::wallContactConductance(kKp, kKw, 0.5 * kD, h) + kg * k::wallLensIntegral(wp, 0.5 * kD, h);
  const double lensShare = kg * k::wallLensIntegral(wp, 0.5 * kD, h) / g;
  EXPECT_GT(lensShare, 0.05); // the lens matters for a 1 mm bead in air
  const double mc = massHeatCapacity(), dt = 1e-4;
  const double e0 = sys.thermalEnergy();
  sys.advance(100 * dt, 100);
  const double want = kTw + (kT0 - kTw) * std::pow(1.0 - g / mc * dt, 100);
  EXPECT_NEAR(onlyTemperature(sys), want, 1e-11);
  EXPECT_GT(onlyTemperature(sys) - kT0, 0.1);
  EXPECT_NEAR(sys.heatTotals().wall, sys.thermalEnergy() - e0, 1e-12 * e0);
  RecordProperty("wall_lens_share", sci(lensShare));
}

// Every wall type conducts as its tangent plane at the touch's distance h (docs/physics.md
// §3.2 "Walls"): the coupled bead of CoupledWallLensAddsToContact (contact + gas lens) heats at
// the plane formula's rate against the box floor, against the inside of a vertical cylinder of
// radius 1 m (the curvature neglected: the exact lens differs by O(R/R_c) = 5e-4), and against a
// triangulated floor with the bead over a vertex shared by six triangles (one touch, not six),
// with triangles larger than the bead and 20 times finer than it.
// T after 100 sub-steps to 1e-10 K of the plane's Euler recursion.
TEST(WallHeat, CylinderAndTriangleWallsConductAsThePlane) {
  const double h = 0.5 * kD - kDelta;
  const double kg = 0.0257;
  k::WallConductionParams wp;
  const double g =
      k::wallContactConductance(kKp, kKw, 0.5 * kD, h) + kg * k::wallLensIntegral(wp, 0.5 * kD, h);
  const double mc = massHeatCapacity(), dt = 1e-4;
  const double want = kTw + (kT0 - kTw) * std::pow(1.0 - g / mc * dt, 100);
  for (int variant = 0; variant < 4; ++variant) {
    DemConfig cfg = bead(kTw);
    cfg.walls.clear();
    const double c = 5e-3, rc = 1.0;
    if (variant == 0) {
      cfg.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
      cfg.particleSets[0].positions = {c, c, h};
    } else if (variant == 1) {
      const double inf = std::numeric_limits<double>::infinity();
      cfg.walls.push_back(Wall::cylinder({c - h + rc, c, 0}, {0, 0, 1}, rc, -inf, inf));
      cfg.particleSets[0].positions = {c, c, c};
    } else {
      // 4 × 4 squares of 2.5 mm, or 200 × 200 of 0.05 mm: hundreds of triangles within the
      // bead's heat reach, of which the nearest are kept (kernels/mesh_contact.h).
      const int quads = variant == 2 ? 4 : 200;
      const TriangleMesh floor = meshRectangle({0, 0, 0}, {1e-2, 0, 0}, {0, 1e-2, 0}, quads, quads);
      cfg.meshes.push_back(MeshWall{"floor", floor.vertices, floor.triangles});
      cfg.particleSets[0].positions = {c, c, h};
    }
    cfg.grid.origin = {0, 0, 0};
    cfg.grid.spacing = {1e-2, 1e-2, 1e-2};
    cfg.grid.counts = {1, 1, 1};
    ASSERT_TRUE(applyModelOption(cfg, "convection", "off"));
    ASSERT_TRUE(applyModelOption(cfg, "lens_conduction", "off"));
    DemSystem sys(cfg, BackendKind::Cpu, 1);
    std::vector<double> u(3, 0.0), gp(3, 0.0), tg(1, kT0), rho(1, 1.204), mu(1, 1.81e-5),
        kappa(1, kg), cp(1, 1006.0);
    sys.setGasFields(GasFieldsView{u, gp, tg, rho, mu, kappa, cp, {}, {}, {}});
    const double e0 = sys.thermalEnergy();
    sys.advance(100 * dt, 100);
    EXPECT_NEAR(onlyTemperature(sys), want, 1e-10) << "variant " << variant;
    EXPECT_NEAR(sys.heatTotals().wall, sys.thermalEnergy() - e0, 1e-12 * e0);
  }
}
