// Heat transfer integrated in the DEM sub-step (docs/physics.md §3, §8; docs/heat-coupling.md).
// Every case runs a real DemSystem (cpu backend) and compares with verification/analytic.h.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/drag_gidaspow.h"
#include "coredem/dem/models.h"
#include "coredem/dem/verification/analytic.h"

using namespace coredem::dem;
namespace va = coredem::dem::verification;

namespace {

/// A material with the thermal properties of a verification material. Contact stiffness is
/// negligible (1e-15 N/m): the particles of the two-particle cases stay where they are put
/// (overlap change over 50 s < 1e-11 m, i.e. < 1e-7 relative in r_c).
Material thermal(const va::Material& m, const std::string& name, double kn = 1e-15) {
  Material out;
  out.name = name;
  out.kn = kn;
  out.en = 0.9;
  out.mu = 0.0;
  out.cp = m.cp;
  out.conductivity = m.k;
  out.emissivity = m.emissivity;
  return out;
}

ParticleSet one(int material, double d, double rho, double t, std::array<double, 3> x) {
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.material = material;
  s.diameter = d;
  s.density = rho;
  s.temperature = t;
  s.positions = {x[0], x[1], x[2]};
  return s;
}

/// Temperatures in global-id order.
std::vector<double> temperatures(const DemSystem& sys) {
  const ParticleData p = sys.particles();
  std::vector<double> t(p.count);
  for (std::size_t i = 0; i < p.count; ++i)
    t[static_cast<std::size_t>(p.globalId[i])] = p.temperature[i];
  return t;
}

/// Uniform gas on all cells of a system.
struct Gas {
  std::vector<double> u, gp, T, rho, mu, kappa, cp;
  Gas(std::size_t n, double tg, double rhoG, double muG, double kG, double cpG)
      : u(3 * n, 0.0)
      , gp(3 * n, 0.0)
      , T(n, tg)
      , rho(n, rhoG)
      , mu(n, muG)
      , kappa(n, kG)
      , cp(n, cpG) {}
  void apply(DemSystem& s) const {
    s.setGasFields(GasFieldsView{u, gp, T, rho, mu, kappa, cp, {}, {}, {}});
  }
};

/// Two fixed particles of a verification case along y (no gravity, no walls).
DemConfig twoParticles(const va::TwoParticleCase& c) {
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {thermal(c.m1, "A"), thermal(c.m2, "B")};
  cfg.particleSets.push_back(one(0, c.d1, c.m1.rho, c.t10, {0.0, 0.0, 0.0}));
  cfg.particleSets.push_back(one(1, c.d2, c.m2.rho, c.t20, {0.0, c.l, 0.0}));
  return cfg;
}

double mc(const va::Material& m, double d) {
  return va::sphereMass(m, d) * m.cp;
}

/// Three significant digits for RecordProperty.
std::string sci(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

} // namespace

// docs/physics.md §8.1 seed variant d2 = 3.6 mm, δ = 4e-5 m, in vacuum (no coupling: no gas, so
// only contact conduction acts). Seed tolerance 6e-4 % = 6e-6 relative; Σ m c T to 1e-12.
TEST(HeatStep, TwoTouchingParticlesConserveEnergyAndFollowTheAnalyticSolution) {
  const va::TwoParticleCase c = va::seedContactConductionCase(3.6e-3, 4e-5);
  DemSystem sys(twoParticles(c), BackendKind::Cpu, 1);
  const va::ExchangeCoefficients k = va::contactConductionCoefficients(c);
  const double e0 = sys.thermalEnergy();
  EXPECT_NEAR(e0, mc(c.m1, c.d1) * c.t10 + mc(c.m2, c.d2) * c.t20, 1e-14 * e0);
  const double dt = 1e-4;
  double worst = 0.0, worstEnergy = 0.0;
  for (int w = 1; w <= 500; ++w) { // 50 s in windows of 0.1 s
    sys.advance(0.1, 1000);
    const std::vector<double> t = temperatures(sys);
    const va::TwoTemperatures ref = va::twoParticleExchange(k.a, k.b, c.t10, c.t20, sys.time());
    worst = std::max({worst, std::fabs(t[0] - ref.t1) / ref.t1, std::fabs(t[1] - ref.t2) / ref.t2});
    worstEnergy = std::max(worstEnergy, std::fabs(sys.thermalEnergy() - e0) / e0);
  }
  EXPECT_NEAR(sys.time(), 50.0, 1e-9);
  EXPECT_LT(worst, 6e-6) << "dt " << dt;
  EXPECT_LT(worstEnergy, 1e-12);
  RecordProperty("contact_max_rel_error", sci(worst));
  RecordProperty("contact_energy_drift", sci(worstEnergy));
  // Heated towards T_∞ (not frozen): after 50 s both are within 0.01 K of it.
  const std::vector<double> t = temperatures(sys);
  const double tInf = va::twoParticleEquilibrium(k.a, k.b, c.t10, c.t20);
  EXPECT_NEAR(t[0], tInf, 0.01);
  EXPECT_NEAR(t[1], tInf, 0.01);
  EXPECT_EQ(sys.heatTotals().convection, 0.0);
}

// docs/physics.md §8.2 MFiX-PFP (gap 0.18 mm) through the gas lens, in a coupled cell with κ_g of
// §8.0 and convection off. Seed tolerance 1.5e-4 % = 1.5e-6 relative; energy to 1e-12.
TEST(HeatStep, GasLensPairFollowsTheAnalyticSolution) {
  const va::TwoParticleCase c = va::mfixLensCase();
  DemConfig cfg = twoParticles(c);
  cfg.materials[0].emissivity = cfg.materials[1].emissivity = 0.0; // conduction only
  cfg.grid.origin = {-0.01, -0.01, -0.01};
  cfg.grid.spacing = {0.02, 0.02, 0.02};
  cfg.grid.counts = {1, 1, 1};
  ASSERT_TRUE(applyModelOption(cfg, "convection", "off"));
  ASSERT_TRUE(applyModelOption(cfg, "lens_rel_tol", "1e-10"));
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  Gas(1, 300.0, 1.2, 1.8e-5, va::kMusserLensGasConductivity, 1000.0).apply(sys);
  const va::ExchangeCoefficients k = va::gasLensCoefficients(c);
  const double e0 = sys.thermalEnergy();
  double worst = 0.0, worstEnergy = 0.0;
  for (int w = 1; w <= 100; ++w) { // 10 s
    sys.advance(0.1, 1000);
    const std::vector<double> t = temperatures(sys);
    const va::TwoTemperatures ref = va::twoParticleExchange(k.a, k.b, c.t10, c.t20, sys.time());
    worst = std::max({worst, std::fabs(t[0] - ref.t1) / ref.t1, std::fabs(t[1] - ref.t2) / ref.t2});
    worstEnergy = std::max(worstEnergy, std::fabs(sys.thermalEnergy() - e0) / e0);
  }
  EXPECT_LT(worst, 1.5e-6);
  EXPECT_LT(worstEnergy, 1e-12);
  RecordProperty("lens_max_rel_error", sci(worst));
  RecordProperty("lens_energy_drift", sci(worstEnergy));
  const CellSources& s = sys.advance(0.1, 1000);
  EXPECT_EQ(s.heatH[0], 0.0); // convection off: no exchange with the gas
}

namespace {

/// MFiX-CONV geometry (§8.3): particle B (3.6 mm) alone in a 4 × 4 × 0.36 cm cell, gas at
/// 6 m/s. The pressure gradient is set to cancel the drag exactly, so the particle stays at rest.
struct ConvectionCase {
  DemConfig cfg;
  double tg = 373.15, tp0 = 298.15, u = 6.0;
  va::Material m = va::musserMaterialB();
  double d = 3.6e-3;
  ConvectionCase() {
    cfg.gravity = {0, 0, 0};
    cfg.materials = {thermal(m, "B")};
    cfg.materials[0].emissivity = 0.0;
    cfg.particleSets.push_back(one(0, d, m.rho, tp0, {0.02, 0.02, 0.0018}));
    cfg.grid.origin = {0, 0, 0};
    cfg.grid.spacing = {0.04, 0.04, 0.0036};
    cfg.grid.counts = {1, 1, 1};
  }
  Gas gas() const {
    const kernels::GasState g = va::musserConvectionGas(tg, va::mfixConvectionCellVoidage());
    Gas out(1, tg, g.rho, g.mu, g.k, g.cp);
    out.u[1] = u;
    kernels::GidaspowParams p;
    const double vol = va::sphereVolume(d);
    const double kc = kernels::gidaspowParticleCoefficient(p, va::mfixConvectionCellVoidage(),
                                                           g.rho, g.mu, d, vol, u);
    out.gp[1] = kc * u / vol; // −V_p ∇p = −K u: no net force on a particle at rest
    return out;
  }
};

} // namespace

// docs/physics.md §8.3 with the seed's Li–Mason correlation (Re with ε, ε = 0.995759): T_p(t)
// within 1e-4 relative over 2 s (the Euler error at Δt = 1e-4 s is ~1e-6 of T_g − T_p).
TEST(HeatStep, SingleParticleInHotGasFollowsTheConvectiveHeatingCurve) {
  ConvectionCase cc;
  DemSystem sys(cc.cfg, BackendKind::Cpu, 1);
  cc.gas().apply(sys);
  const kernels::GasState g = va::musserConvectionGas(cc.tg, va::mfixConvectionCellVoidage());
  const double coef = va::convectionCoefficient(kernels::ConvectionParams{}, g, cc.d, cc.m, cc.u);
  EXPECT_NEAR(coef, 0.960850, 2e-6); // docs/physics.md §8.3 table, Li–Mason with ε
  double worst = 0.0, worstDiff = 0.0;
  for (int w = 1; w <= 20; ++w) {
    sys.advance(0.1, 1000);
    const double t = temperatures(sys)[0];
    const double ref = va::convectionTemperature(cc.tg, cc.tp0, coef, sys.time());
    worst = std::max(worst, std::fabs(t - ref) / ref);
    worstDiff = std::max(worstDiff, std::fabs(t - ref) / (cc.tg - ref));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(worstDiff, 2e-4); // relative to T_g − T_p as well (Euler: ≈ k²Δt t/2 = 9e-5)
  RecordProperty("convection_max_rel_error", sci(worst));
  const ParticleData p = sys.particles();
  EXPECT_LT(std::fabs(p.velocity[1]), 1e-12); // the particle did not move
}

// The cell sources are the particles' convective heat gain: Σ_c (H T_g − H_Tp) V_c Δt_CFD =
// Σ_i m_i c_i ΔT_i to round-off (convection only), and HeatTotals records the same energy.
TEST(HeatStep, CellHeatSourcesEqualTheParticlesConvectiveGain) {
  DemConfig cfg;
  cfg.gravity = {0, 0, -9.81};
  Material glass;
  glass.kn = 20.0;
  glass.en = 0.5;
  glass.cp = 840.0;
  cfg.materials = {glass};
  ParticleSet s;
  s.packing = Packing::Lattice;
  s.count = 60;
  s.diameter = 1e-3;
  s.spacing = 2.5e-3;
  s.temperature = 300.0;
  s.regionMin = {0, 0, 0};
  s.regionMax = {0.01, 0.01, 0.01};
  s.velocityJitter = 0.05;
  cfg.particleSets.push_back(s);
  cfg.addBox({0, 0, 0}, {0.01, 0.01, 0.01});
  cfg.grid.spacing = {0.005, 0.005, 0.0025};
  cfg.grid.counts = {2, 2, 4};
  ASSERT_TRUE(applyModelOption(cfg, "contact_conduction", "off"));
  ASSERT_TRUE(applyModelOption(cfg, "lens_conduction", "off"));
  DemSystem sys(cfg, BackendKind::Cpu, 2);
  Gas gas(sys.cellCount(), 600.0, 0.588, 3e-5, 0.046, 1051.0);
  for (std::size_t c = 0; c < sys.cellCount(); ++c) {
    gas.T[c] = 500.0 + 10.0 * static_cast<double>(c);
    gas.u[3 * c + 2] = 0.2;
  }
  gas.apply(sys);
  const double vc = 0.005 * 0.005 * 0.0025;
  const int nSub = 40;
  const double dtCfd = nSub * sys.dtDemMax() * 0.5;
  double totalGain = 0.0;
  for (int w = 0; w < 10; ++w) {
    const double e0 = sys.thermalEnergy();
    const CellSources& src = sys.advance(dtCfd, nSub);
    const double gain = sys.thermalEnergy() - e0;
    double fromCells = 0.0;
    for (std::size_t c = 0; c < sys.cellCount(); ++c) {
      EXPECT_GE(src.heatH[c], 0.0);
      fromCells += (src.heatH[c] * gas.T[c] - src.heatHTp[c]) * vc * dtCfd;
    }
    EXPECT_GT(gain, 0.0);
    EXPECT_NEAR(fromCells, gain, 1e-11 * gain) << "window " << w;
    totalGain += gain;
  }
  EXPECT_NEAR(sys.heatTotals().convection, totalGain, 1e-11 * totalGain);
  EXPECT_EQ(sys.heatTotals().radiation, 0.0); // emissivity 0
}

// docs/physics.md §8.4 MFiX-RAD: A and B in one 1.5 × 1.0 × 0.36 cm cell, gas held at 400 K,
// k_p = 0 and no convection: radiation only, T_env of variant (a). vs RK4 within 2e-7 relative.
TEST(HeatStep, RadiationOfTwoParticlesFollowsTheRk4Reference) {
  const va::RadiationCase rc = va::mfixRadiationCase();
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {thermal(rc.m1, "A"), thermal(rc.m2, "B")};
  cfg.materials[0].conductivity = cfg.materials[1].conductivity = 0.0;
  cfg.particleSets.push_back(one(0, rc.d1, rc.m1.rho, rc.t10, {0.025, 0.0325, 0.0}));
  cfg.particleSets.push_back(one(1, rc.d2, rc.m2.rho, rc.t20, {0.025, 0.0368, 0.0}));
  cfg.grid.origin = {0.0175, 0.0295, -0.0018};
  cfg.grid.spacing = {0.015, 0.010, 0.0036};
  cfg.grid.counts = {1, 1, 1};
  ASSERT_TRUE(applyModelOption(cfg, "convection", "off"));
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  Gas(1, rc.tG, 1.2, 1.8e-5, 0.05, 1000.0).apply(sys);
  std::vector<double> times;
  for (int w = 1; w <= 50; ++w)
    times.push_back(1.0 * w);
  const auto ref = va::radiationReferenceRK4(rc, times);
  double worst = 0.0;
  for (int w = 0; w < 50; ++w) {
    sys.advance(1.0, 20000); // Δt = 5e-5 s
    const std::vector<double> t = temperatures(sys);
    worst = std::max(
        {worst, std::fabs(t[0] - ref[w].t1) / ref[w].t1, std::fabs(t[1] - ref[w].t2) / ref[w].t2});
  }
  EXPECT_LT(worst, 2e-7);
  RecordProperty("radiation_max_rel_error", sci(worst));
  // Radiation is the only heat term: the particles' energy changed by exactly the total.
  const double e = sys.thermalEnergy();
  const double e0 = mc(rc.m1, rc.d1) * rc.t10 + mc(rc.m2, rc.d2) * rc.t20;
  EXPECT_NEAR(e - e0, sys.heatTotals().radiation, 1e-12 * e0);
}

namespace {

/// A settling, touching, heated bed: every heat term is active (conduction, lens, convection,
/// radiation), particles move and the neighbour list is rebuilt.
DemConfig heatedBed() {
  DemConfig cfg;
  cfg.gravity = {0, 0, -9.81};
  Material glass;
  glass.kn = 20.0;
  glass.en = 0.5;
  glass.mu = 0.3;
  glass.cp = 840.0;
  glass.conductivity = 1.0;
  glass.emissivity = 0.9;
  cfg.materials = {glass};
  ParticleSet s;
  s.packing = Packing::Random;
  s.count = 1100; // > 2 OpenMP chunks of 512: both threads get work
  s.diameter = 1e-3;
  s.temperature = 300.0;
  s.regionMin = {0, 0, 0};
  s.regionMax = {0.012, 0.012, 0.016};
  s.seed = 11;
  s.velocityJitter = 0.05;
  cfg.particleSets.push_back(s);
  cfg.addBox({0, 0, 0}, {0.012, 0.012, 0.02});
  cfg.grid.spacing = {0.004, 0.004, 0.004};
  cfg.grid.counts = {3, 3, 5};
  return cfg;
}

struct BedRun {
  std::vector<double> t, x, h, htp;
  HeatTotals totals;
  double e0 = 0, e = 0; ///< Σ m c_p T at the start and the end
};

BedRun runBed(int threads, int windows, const std::string& stateIn = "",
              const std::string& stateOut = "", int writeAfter = -1) {
  DemSystem sys(heatedBed(), BackendKind::Cpu, threads);
  if (!stateIn.empty())
    sys.readState(stateIn);
  Gas gas(sys.cellCount(), 600.0, 0.588, 3e-5, 0.046, 1051.0);
  gas.apply(sys);
  const double dtCfd = 1e-3;
  const int nSub = static_cast<int>(std::ceil(dtCfd / sys.dtDemMax()));
  BedRun r;
  r.e0 = sys.thermalEnergy();
  for (int w = 0; w < windows; ++w) {
    const CellSources& s = sys.advance(dtCfd, nSub);
    r.h = s.heatH;
    r.htp = s.heatHTp;
    if (w + 1 == writeAfter)
      sys.writeState(stateOut);
  }
  const ParticleData p = sys.particles();
  r.t.resize(p.count);
  r.x.resize(3 * p.count);
  for (std::size_t i = 0; i < p.count; ++i) {
    const auto g = static_cast<std::size_t>(p.globalId[i]);
    r.t[g] = p.temperature[i];
    for (int d = 0; d < 3; ++d)
      r.x[3 * g + d] = p.position[3 * i + d];
  }
  r.totals = sys.heatTotals();
  r.e = sys.thermalEnergy();
  return r;
}

} // namespace

TEST(HeatStep, OneAndTwoThreadsAreBitwiseIdenticalWithHeatOn) {
  const BedRun a = runBed(1, 4);
  const BedRun b = runBed(2, 4);
  ASSERT_EQ(a.t.size(), b.t.size());
  for (std::size_t i = 0; i < a.t.size(); ++i) {
    ASSERT_EQ(a.t[i], b.t[i]) << "particle " << i;
    for (int d = 0; d < 3; ++d)
      ASSERT_EQ(a.x[3 * i + d], b.x[3 * i + d]);
  }
  EXPECT_EQ(a.h, b.h);
  EXPECT_EQ(a.htp, b.htp);
  EXPECT_EQ(a.totals.convection, b.totals.convection);
  EXPECT_EQ(a.totals.radiation, b.totals.radiation);
  // The bed heated (every term on): mean T rose, and no particle beyond the gas temperature.
  double mean = 0.0;
  for (double t : a.t) {
    EXPECT_LT(t, 600.0);
    mean += t / static_cast<double>(a.t.size());
  }
  EXPECT_GT(mean, 300.1);
  EXPECT_GT(a.totals.convection, 0.0);
  EXPECT_GT(a.totals.radiation, 0.0);
  // Heat balance of the run: Δ Σ m c_p T = convection + radiation (conduction moves heat
  // between particles only), to round-off.
  EXPECT_NEAR(a.e - a.e0, a.totals.convection + a.totals.radiation, 1e-12 * a.e0);
  RecordProperty("bed_energy_residual_rel",
                 sci((a.e - a.e0 - a.totals.convection - a.totals.radiation) / a.e0));
}

TEST(HeatStep, RestartFromHdf5IsBitwiseWithHeatOn) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("coredem_heat_restart_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string state = (dir / "state.h5").string();
  const BedRun straight = runBed(2, 6, "", state, 3);
  const BedRun resumed = runBed(2, 3, state);
  for (std::size_t i = 0; i < straight.t.size(); ++i) {
    ASSERT_EQ(straight.t[i], resumed.t[i]) << "particle " << i;
    for (int d = 0; d < 3; ++d)
      ASSERT_EQ(straight.x[3 * i + d], resumed.x[3 * i + d]);
  }
  EXPECT_EQ(straight.h, resumed.h);
  EXPECT_EQ(straight.htp, resumed.htp);
  EXPECT_EQ(straight.totals.convection, resumed.totals.convection);
  EXPECT_EQ(straight.totals.radiation, resumed.totals.radiation);
  std::filesystem::remove_all(dir);
}

TEST(HeatStep, HeatOffKeepsTemperaturesAndSendsNoHeat) {
  DemConfig cfg = heatedBed();
  ASSERT_TRUE(applyModelOption(cfg, "heat", "off"));
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  Gas(sys.cellCount(), 600.0, 0.588, 3e-5, 0.046, 1051.0).apply(sys);
  const CellSources& s = sys.advance(1e-3, static_cast<int>(std::ceil(1e-3 / sys.dtDemMax())));
  for (double h : s.heatH)
    EXPECT_EQ(h, 0.0);
  for (double t : temperatures(sys))
    EXPECT_EQ(t, 300.0);
}

TEST(HeatOptions, ParseAndRejectWithAClearMessage) {
  // The heat keys of `models:` go through the model registry (coredem/dem/models.h).
  DemConfig o;
  EXPECT_TRUE(applyModelOption(o, "convection", "ranz-marshall"));
  EXPECT_EQ(o.heat.nusselt, kernels::NusseltModel::RanzMarshall);
  EXPECT_TRUE(applyModelOption(o, "s_min", "4e-10"));
  EXPECT_EQ(o.heat.minSeparation, 4e-10);
  EXPECT_TRUE(applyModelOption(o, "flpc", "0.25"));
  // drag is a model key of its own family, not a heat option.
  ASSERT_NE(findModelOption("drag"), nullptr);
  EXPECT_EQ(findModelOption("drag")->family, "drag");
  try {
    applyModelOption(o, "convection", "nusselt-magic");
    FAIL() << "no error";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("ranz-marshall"), std::string::npos) << e.what();
  }
  EXPECT_THROW(applyModelOption(o, "s_min", "-1"), coredem::UserError);
  EXPECT_THROW(applyModelOption(o, "heat", "maybe"), coredem::UserError);
  // The neighbour-mean radiation environment is not offered: its key is refused by validation.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"radiation_environment", "neighbour-mean"}};
  EXPECT_EQ(validateModels(bad).size(), 1u);
}

// Radiation heat to the gas (protocol 1.3, CellSources::qRad = Sources Q_rad): hot particles
// (900 K, emissivity 0.9) in a cold gas (300 K). Over several CFD steps Σ_steps Σ_c Q_rad V_c
// Δt_CFD equals the radiation heat the particles lost (−dem.heat_radiation_J) to 1e-12 relative,
// and the per-cell arrays are bitwise the same on 1 and 2 threads. With convection and
// conduction off the particles' energy change plus the gas's radiation gain is 0 to round-off
// (what coredem-gas books as gas.heat_radiation_J).
namespace {
struct RadRun {
  std::vector<std::vector<double>> qRad; ///< per step
  double toGas = 0.0;                    ///< Σ_steps Σ_c Q_rad V_c Δt_CFD (J)
  HeatTotals totals;
  double e0 = 0, e = 0;
};

RadRun runHotBed(int threads, int windows, bool radiationOnly) {
  DemConfig cfg = heatedBed();
  cfg.particleSets[0].temperature = 900.0;
  if (radiationOnly) {
    EXPECT_TRUE(applyModelOption(cfg, "convection", "off"));
    EXPECT_TRUE(applyModelOption(cfg, "contact_conduction", "off"));
    EXPECT_TRUE(applyModelOption(cfg, "lens_conduction", "off"));
  }
  DemSystem sys(cfg, BackendKind::Cpu, threads);
  Gas(sys.cellCount(), 300.0, 1.177, 1.85e-5, 0.026, 1007.0).apply(sys);
  const double vc = cfg.grid.spacing[0] * cfg.grid.spacing[1] * cfg.grid.spacing[2];
  const double dtCfd = 1e-3;
  const int nSub = static_cast<int>(std::ceil(dtCfd / sys.dtDemMax()));
  RadRun r;
  r.e0 = sys.thermalEnergy();
  for (int w = 0; w < windows; ++w) {
    const CellSources& s = sys.advance(dtCfd, nSub);
    EXPECT_EQ(s.qRad.size(), sys.cellCount());
    double step = 0.0;
    for (double q : s.qRad)
      step += q * vc * dtCfd;
    r.toGas += step;
    r.qRad.push_back(s.qRad);
  }
  r.totals = sys.heatTotals();
  r.e = sys.thermalEnergy();
  return r;
}
} // namespace

TEST(HeatStep, RadiationHeatToTheGasEqualsTheParticlesRadiationLoss) {
  const RadRun a = runHotBed(1, 4, false);
  const RadRun b = runHotBed(2, 4, false);
  ASSERT_EQ(a.qRad.size(), b.qRad.size());
  for (std::size_t w = 0; w < a.qRad.size(); ++w)
    EXPECT_EQ(a.qRad[w], b.qRad[w]) << "step " << w; // bitwise, 1 vs 2 threads
  EXPECT_EQ(a.totals.radiation, b.totals.radiation);
  EXPECT_LT(a.totals.radiation, 0.0); // hot particles lose heat by radiation
  EXPECT_GT(a.toGas, 0.0);            // which the gas receives
  EXPECT_NEAR(a.toGas, -a.totals.radiation, 1e-12 * std::fabs(a.totals.radiation));
  RecordProperty("radiation_to_gas_rel",
                 sci((a.toGas + a.totals.radiation) / std::fabs(a.totals.radiation)));
  // Every cell that holds particles radiates (T_p > T_env); the empty cells send 0.
  bool anyPositive = false;
  for (double q : a.qRad.back()) {
    EXPECT_GE(q, 0.0);
    anyPositive = anyPositive || q > 0.0;
  }
  EXPECT_TRUE(anyPositive);
}

TEST(HeatStep, RadiationOnlyLedgerClosesWithTheGasRadiationTerm) {
  const RadRun r = runHotBed(1, 3, true);
  EXPECT_EQ(r.totals.convection, 0.0);
  ASSERT_GT(r.toGas, 0.0);
  // Particle energy change + the gas's radiation gain = 0 (nothing else exchanges heat).
  EXPECT_NEAR((r.e - r.e0) + r.toGas, 0.0, 1e-12 * r.e0);
  EXPECT_NEAR(r.e - r.e0, r.totals.radiation, 1e-12 * r.e0);
  RecordProperty("radiation_ledger_residual_rel", sci(((r.e - r.e0) + r.toGas) / r.e0));
}

// The 1-vs-2-thread and restart cases run two OpenMP threads on a machine shared with other
// jobs; libgomp's default spinning barriers then stall on a descheduled thread (docs/
// performance.md "DEM core"). OMP_WAIT_POLICY is read when libgomp starts, so an unset policy
// is set to PASSIVE and the test re-executes itself once. Results do not depend on it.
int main(int argc, char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
    ::setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
    ::execv("/proc/self/exe", argv); // returns only on failure: then run as is
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

// The configuration hash guards restarts against other options. Its heat part moved next to
// HeatOptions (appendHeatHashText); the hashes of earlier configurations must not change, or
// existing checkpoints would be refused. Pinned values: computed by the code before the move.
TEST(HeatOptions, ConfigHashOfEarlierConfigurationsIsUnchanged) {
  DemConfig cfg = heatedBed();
  EXPECT_EQ(DemSystem(cfg, BackendKind::Cpu, 1).configHash(), std::string("73285c92c8a98cbe"));
  cfg.wallTemperature = 400.0;
  cfg.materials.push_back(cfg.materials.front());
  cfg.wallMaterial = 1;
  EXPECT_EQ(DemSystem(cfg, BackendKind::Cpu, 1).configHash(), std::string("d0aa869891a6f856"));
  ASSERT_TRUE(applyModelOption(cfg, "heat", "off"));
  EXPECT_EQ(DemSystem(cfg, BackendKind::Cpu, 1).configHash(), std::string("af0603ba4db2dcd8"));
}
