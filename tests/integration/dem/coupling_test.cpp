// PCM coupling: ε_g conserves the particle volume; sources are sub-step averages.
#include <gtest/gtest.h>

#include "dem_test_util.h"

using namespace coredem::dem;
using namespace coredem::dem::testing;

namespace {
DemConfig coupledBox(std::size_t n) {
  DemConfig c = agitatedDeck(n, true);
  const auto& p = c.particleSets[0];
  c.gravity = {0, 0, -9.81};
  c.grid.origin = {0, 0, 0};
  c.grid.counts = {3, 3, 4};
  for (int d = 0; d < 3; ++d)
    c.grid.spacing[d] = p.regionMax[d] / c.grid.counts[d];
  return c;
}
} // namespace

TEST(Coupling, GasFractionSumsToParticleVolume) {
  DemSystem sys(coupledBox(512), BackendKind::Cpu, 1);
  const std::size_t nc = sys.cellCount();
  ASSERT_EQ(nc, 36u);
  std::vector<double> ug(3 * nc), gp(3 * nc, 0.0), rho(nc, 1.2), mu(nc, 1.8e-5);
  for (std::size_t k = 0; k < nc; ++k)
    ug[3 * k + 2] = 0.5 + 0.01 * k;
  sys.setGasFields(GasFieldsView{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}});
  const auto& cfg = sys.config().grid;
  const double vc = cfg.spacing[0] * cfg.spacing[1] * cfg.spacing[2];
  const ParticleData p = sys.particles();
  double vp = 0;
  for (std::size_t i = 0; i < p.count; ++i)
    vp += 4.0 / 3.0 * kPi * std::pow(p.radius[i], 3);
  const double dt = sys.dtDemMax();
  for (int k = 0; k < 5; ++k) {
    const CellSources& s = sys.advance(20 * dt, 20);
    double solid = 0, k0 = 0;
    for (std::size_t c = 0; c < nc; ++c) {
      solid += (1 - s.epsG[c]) * vc;
      k0 += s.kSl[c];
      ASSERT_GE(s.epsG[c], 0.0);
      ASSERT_LE(s.epsG[c], 1.0);
    }
    // all particles stay inside the walled grid: Σ (1−ε_g) V_c = Σ V_p (round-off only)
    EXPECT_NEAR(solid, vp, 1e-12 * vp) << "window " << k;
    EXPECT_GT(k0, 0.0);
    EXPECT_EQ(s.heatH.size(), nc);
    EXPECT_EQ(s.kSlUs.size(), 3 * nc);
  }
}

TEST(Coupling, SourcesOfAParticleAtRestMatchTheDragLaw) {
  // One particle at rest in a gas stream, no gravity, one CFD step of one sub-step:
  // K_sl V_c = β V_p/(1−ε) from Gidaspow (dilute branch) with the cell's ε.
  DemConfig c;
  c.gravity = {0, 0, 0};
  c.grid.origin = {0, 0, 0};
  c.grid.spacing = {4e-3, 4e-3, 4e-3};
  c.grid.counts = {2, 1, 1};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {6e-3, 2e-3, 2e-3};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const std::vector<double> ug{0, 0, 0, 0, 0, 1.0}, gp(6, 0.0), rho{1.2, 1.2}, mu{1.8e-5, 1.8e-5};
  sys.setGasFields(GasFieldsView{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}});
  const CellSources& src = sys.advance(sys.dtDemMax(), 1);
  const double vc = 64e-9, vp = kPi / 6 * 1e-9, eps = 1 - vp / vc;
  const double re = eps * 1.2 * 1e-3 * 1.0 / 1.8e-5;
  const double cd = 24 / re * (1 + 0.15 * std::pow(re, 0.687));
  const double beta = 0.75 * cd * eps * (1 - eps) * 1.2 * 1.0 * std::pow(eps, -2.65) / 1e-3;
  EXPECT_DOUBLE_EQ(src.epsG[0], 1.0);
  EXPECT_NEAR(src.epsG[1], eps, 1e-15);
  EXPECT_EQ(src.kSl[0], 0.0);
  EXPECT_NEAR(src.kSl[1] * vc, beta * vp / (1 - eps), 1e-9 * beta * vp / (1 - eps));
  EXPECT_EQ(src.kSlUs[5], 0.0); // v_p = 0 during the only sub-step
}

TEST(Coupling, RejectsBadGasFields) {
  DemSystem sys(coupledBox(8), BackendKind::Cpu, 1);
  std::vector<double> ug(3 * 36, 0.0), gp(3 * 36, 0.0), rho(36, 1.2), mu(36, 1.8e-5),
      shortv(5, 1.0);
  EXPECT_THROW(sys.setGasFields(GasFieldsView{shortv, gp, {}, rho, mu, {}, {}, {}, {}, {}}),
               coredem::UserError);
  rho[3] = -1;
  EXPECT_THROW(sys.setGasFields(GasFieldsView{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}}),
               coredem::UserError);
  rho[3] = 1.2;
  ug[7] = NAN;
  EXPECT_THROW(sys.setGasFields(GasFieldsView{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}}),
               coredem::UserError);
  EXPECT_THROW(sys.advance(10 * sys.dtDemMax(), 1), coredem::UserError); // Δt too large
}

// A coupling cell partly outside the CFD domain (fluid_fraction φ_f = 0.5): the drag law sees the
// gas fraction of the fluid volume, ε = 1 − V_p/(φ_f V_c); the sources stay per coupling-cell
// volume V_c (ε_g = 1 − V_p/V_c, K_sl V_c = β(ε) V_p/(1−ε)), the CFD side divides by φ_f.
TEST(Coupling, FluidFractionGivesTheGasFractionOfTheFluidVolume) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  c.grid.origin = {0, 0, 0};
  c.grid.spacing = {4e-3, 4e-3, 4e-3};
  c.grid.counts = {2, 1, 1};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {6e-3, 2e-3, 2e-3};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const std::vector<double> ug{0, 0, 0, 0, 0, 1.0}, gp(6, 0.0), rho{1.2, 1.2}, mu{1.8e-5, 1.8e-5},
      fluid{1.0, 0.5};
  GasFieldsView view{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}};
  view.fluidFraction = fluid;
  sys.setGasFields(view);
  const CellSources& src = sys.advance(sys.dtDemMax(), 1);
  const double vc = 64e-9, vp = kPi / 6 * 1e-9, eps = 1 - vp / (0.5 * vc);
  const double re = eps * 1.2 * 1e-3 * 1.0 / 1.8e-5;
  const double cd = 24 / re * (1 + 0.15 * std::pow(re, 0.687));
  const double beta = 0.75 * cd * eps * (1 - eps) * 1.2 * 1.0 * std::pow(eps, -2.65) / 1e-3;
  EXPECT_NEAR(src.epsG[1], 1 - vp / vc, 1e-15);
  EXPECT_NEAR(src.kSl[1] * vc, beta * vp / (1 - eps), 1e-9 * beta * vp / (1 - eps));
}

// A particle in a coupling cell without fluid (fluid_fraction 0: outside the CFD domain) is an
// error naming the particle and the cell; a fraction outside [0, 1] is refused.
TEST(Coupling, ParticleInACellWithoutFluidIsRefusedNamingIt) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  c.grid.origin = {0, 0, 0};
  c.grid.spacing = {4e-3, 4e-3, 4e-3};
  c.grid.counts = {2, 1, 1};
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {6e-3, 2e-3, 2e-3};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const std::vector<double> ug(6, 0.0), gp(6, 0.0), rho{1.2, 1.2}, mu{1.8e-5, 1.8e-5};
  GasFieldsView view{ug, gp, {}, rho, mu, {}, {}, {}, {}, {}};
  const std::vector<double> bad{1.0, 1.5};
  view.fluidFraction = bad;
  EXPECT_THROW(sys.setGasFields(view), coredem::UserError);
  const std::vector<double> fluid{1.0, 0.0};
  view.fluidFraction = fluid;
  sys.setGasFields(view);
  try {
    sys.advance(sys.dtDemMax(), 1);
    ADD_FAILURE() << "a particle in a cell without fluid was accepted";
  } catch (const coredem::UserError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("particle 0 at (0.006, 0.002, 0.002) m lies in coupling cell 1"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("no fluid"), std::string::npos) << m;
  }
}
