// Protocol 1.5 in the DEM core, on every backend (cpu, cuda-sim, cuda; cuda skips without a
// device): the momentum of the mass the particles release (CellSources::momP, the Sources array
// mom_p) and the heat split the gas sends (GasFieldsView::heatToParticles, the GasFields array
// Q_split) given to the particles at the start of the window. Every backend is also compared with
// the cpu run of the same deck (bitwise for cuda-sim).
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/pressure_gradient.h"

using namespace coredem::dem;

namespace {

template <BackendKind K>
struct Backend {
  static constexpr BackendKind kind = K;
};

template <class B>
class ReleasedMassAndHeatSplit : public ::testing::Test {
protected:
  void SetUp() override {
    if constexpr (B::kind == BackendKind::Cuda) {
      if (!cudaBackendBuilt())
        GTEST_SKIP() << "CUDA backend not built";
      const CudaProbe cuda = probeCuda();
      if (!cuda.error.empty())
        FAIL() << cuda.error;
      if (cuda.devices == 0)
        GTEST_SKIP() << "no CUDA device: " << cuda.note;
    }
  }
  static constexpr BackendKind kind = B::kind;
  /// cuda: FMA contraction and another libm move the last bits; cpu and cuda-sim: bitwise.
  static constexpr double kBackendTol = B::kind == BackendKind::Cuda ? 1e-12 : 0.0;
};

using AllBackends = ::testing::Types<Backend<BackendKind::Cpu>, Backend<BackendKind::CudaSim>,
                                     Backend<BackendKind::Cuda>>;
TYPED_TEST_SUITE(ReleasedMassAndHeatSplit, AllBackends);

constexpr double kEdge = 0.02; // coupling cells of 2 cm
constexpr double kCellVolume = kEdge * kEdge * kEdge;

/// Uniform gas on `cells` cells moving at `u`, at T_g, without a pressure gradient.
struct Gas {
  std::vector<double> u, gp, T, rho, mu, kappa, cp, Y, split;
  Gas(std::size_t cells, std::array<double, 3> ug, double tg, int nGas) {
    for (std::size_t c = 0; c < cells; ++c) {
      u.insert(u.end(), ug.begin(), ug.end());
      gp.insert(gp.end(), {0.0, 0.0, 0.0});
      T.push_back(tg);
      rho.push_back(1.1);
      mu.push_back(2e-5);
      kappa.push_back(0.03);
      cp.push_back(1100.0);
      for (int g = 0; g < nGas; ++g)
        Y.push_back(g == 0 ? 1.0 : 0.0);
    }
  }
  void apply(DemSystem& s) const {
    s.setGasFields(GasFieldsView{u, gp, T, rho, mu, kappa, cp, Y, {}, split});
  }
};

ParticleSet placed(double d, double t, std::array<double, 3> x, std::array<double, 3> v = {}) {
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.diameter = d;
  s.density = 2000.0;
  s.temperature = t;
  s.positions = {x[0], x[1], x[2]};
  s.velocities = {v[0], v[1], v[2]};
  return s;
}

/// A material that does not limit Δt_DEM (no contacts here) and does not radiate.
Material quiet() {
  Material m;
  m.kn = 1e-6;
  m.en = 0.9;
  m.mu = 0.0;
  m.cp = 840.0;
  m.emissivity = 0.0;
  return m;
}

/// `nx` cells of 2 cm along x around the origin (cell 0: x in [−1, 1] cm).
CouplingGrid cells(int nx) {
  CouplingGrid g;
  g.origin = {-0.01, -0.01, -0.01};
  g.spacing = {kEdge, kEdge, kEdge};
  g.counts = {nx, 1, 1};
  return g;
}

void expectNear(double a, double b, double rel, const std::string& what) {
  EXPECT_LE(std::fabs(a - b), rel * std::max(std::fabs(a), std::fabs(b)))
      << what << ": " << a << " vs " << b;
}

/// A burning particle (B(s) -> G(g), mass conserved) moving at `up` through gas moving with it
/// (no slip, no pressure gradient, no gravity: no force, its velocity stays u_p exactly).
DemConfig burningParticle(std::array<double, 3> up) {
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {quiet()};
  cfg.gasSpecies = {{"G", 0.015}, {"N2", 0.028}};
  cfg.solidSpecies = {{"B", 0.015}, {"I", 0.020}};
  ParticleSet p = placed(1e-3, 400.0, {0.0, 0.0, 0.0}, up);
  p.composition = {0.7, 0.3};
  cfg.particleSets = {p};
  cfg.grid = cells(1);
  cfg.heat.enabled = false;
  ReactionConfig r;
  r.name = "burn";
  r.terms = {{"B", -1}, {"G", 1}};
  r.law = coredem::dem::kernels::RateLaw::Constant;
  r.A = 2e-6; // mol/s: 3e-8 kg/s of a 1 mg particle
  cfg.chemistry.reactions.push_back(r);
  return cfg;
}

struct MomentumRun {
  std::vector<CellSources> windows;
  std::vector<double> mass; ///< particle mass before the first window and after each
  std::vector<double> velocity;
  ChemistryTotals totals;
};

MomentumRun runBurning(BackendKind kind, std::array<double, 3> up, int windows, double dt,
                       int nSub) {
  DemSystem sys(burningParticle(up), kind, 1);
  const Gas gas(1, up, 400.0, 2);
  MomentumRun r;
  r.mass.push_back(sys.particles().mass[0]);
  for (int w = 0; w < windows; ++w) {
    gas.apply(sys);
    r.windows.push_back(sys.advance(dt, nSub));
    const ParticleData p = sys.particles();
    r.mass.push_back(p.mass[0]);
    r.velocity = p.velocity;
  }
  r.totals = sys.chemistryTotals();
  return r;
}

} // namespace

// A reacting particle moving at u_p releasing gas at ṁ: mom_p = ṁ u_p / V_c (round-off), with ṁ the
// net gas mass released (Σ_k R_species V_c, and the particle's mass loss per Δt).
TYPED_TEST(ReleasedMassAndHeatSplit, ReleasedMassCarriesTheParticleVelocity) {
  const std::array<double, 3> up{0.3, -0.2, 0.125};
  const double dt = 1e-3;
  const MomentumRun r = runBurning(this->kind, up, 3, dt, 4);
  double released[3] = {0, 0, 0};
  for (std::size_t w = 0; w < r.windows.size(); ++w) {
    SCOPED_TRACE("window " + std::to_string(w));
    const CellSources& s = r.windows[w];
    ASSERT_EQ(s.momP.size(), 3u);
    ASSERT_EQ(s.rSpecies.size(), 2u);
    const double rate = s.rSpecies[0] + s.rSpecies[1]; // kg/m3/s released (G; N2 untouched)
    EXPECT_GT(rate, 0.0);
    const double lost = (r.mass[w] - r.mass[w + 1]) / (kCellVolume * dt); // kg/m3/s
    for (int a = 0; a < 3; ++a) {
      expectNear(s.momP[a], rate * up[a], 1e-14, "mom_p vs R_species u_p");
      expectNear(s.momP[a], lost * up[a], 1e-9, "mom_p vs the particle's mass loss");
      released[a] += s.momP[a] * kCellVolume * dt;
    }
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(r.velocity[a], up[a]) << "no force acts: the velocity is kept exactly";
    expectNear(r.totals.releasedMomentum[a], released[a], 1e-13, "ledger");
    expectNear(r.totals.releasedMomentum[a], (r.mass.front() - r.mass.back()) * up[a], 1e-9,
               "ledger vs the particle's mass loss");
  }
  // Against the cpu run of the same deck.
  const MomentumRun ref = runBurning(BackendKind::Cpu, up, 3, dt, 4);
  for (std::size_t w = 0; w < r.windows.size(); ++w)
    for (int a = 0; a < 3; ++a)
      expectNear(r.windows[w].momP[a], ref.windows[w].momP[a], this->kBackendTol, "vs cpu");
}

// A particle at rest releases mass without momentum; no chemistry: mom_p is zero.
TYPED_TEST(ReleasedMassAndHeatSplit, NoMomentumWithoutVelocityOrChemistry) {
  const MomentumRun r = runBurning(this->kind, {0, 0, 0}, 1, 1e-3, 2);
  EXPECT_GT(r.windows[0].rSpecies[0], 0.0);
  for (int a = 0; a < 3; ++a)
    EXPECT_EQ(r.windows[0].momP[a], 0.0);
  DemConfig inert = burningParticle({0.3, 0, 0});
  inert.chemistry.reactions.clear();
  DemSystem sys(inert, this->kind, 1);
  Gas(1, {0.3, 0, 0}, 400.0, 2).apply(sys);
  const CellSources& s = sys.advance(1e-3, 2);
  EXPECT_EQ(s.momP, std::vector<double>(3, 0.0));
}

namespace {

constexpr double kTg = 600.0;
constexpr double kD1 = 1e-3, kD2 = 2e-3;

double mcp(double d) {
  return 2000.0 * coredem::dem::kernels::sphereVolume(0.5 * d) * 840.0;
}

/// Two particles at rest in gas at rest in cell 0 (far apart: no conduction), no radiation; the
/// heat split on; `convection` on or off.
DemConfig twoParticles(std::array<double, 2> t0, bool convection, int nx = 1) {
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {quiet()};
  cfg.particleSets = {placed(kD1, t0[0], {-0.006, 0.0, 0.0}),
                      placed(kD2, t0[1], {0.005, 0.0, 0.0})};
  cfg.grid = cells(nx);
  cfg.heat.convection = convection;
  cfg.heat.lensConduction = false;
  return cfg;
}

/// Temperatures by particle (global id order: the first set, then the second).
std::array<double, 2> temperatures(const DemSystem& s) {
  const ParticleData p = s.particles();
  std::array<double, 2> t{};
  for (std::size_t i = 0; i < p.count; ++i)
    t[static_cast<std::size_t>(p.globalId[i])] = p.temperature[i];
  return t;
}

} // namespace

// A cell with two particles of known conductance: at rest in gas at rest (Re = 0, Nu = 2 for both)
// G_i = 2π κ_g d_i, so R_i = Q V_c d_i/(d_1 + d_2). Each particle starts R_i/(m_i c_p) below T_g:
// the split brings both to T_g exactly (then convection moves nothing), which a split in any other
// proportion would not.
TYPED_TEST(ReleasedMassAndHeatSplit, HeatSplitGoesToTheParticlesInProportionToTheirConductance) {
  const double q = 2.5e4; // J/m3
  const double rc = q * kCellVolume;
  const double r1 = rc * kD1 / (kD1 + kD2), r2 = rc * kD2 / (kD1 + kD2);
  const std::array<double, 2> t0{kTg - r1 / mcp(kD1), kTg - r2 / mcp(kD2)};
  auto run = [&](BackendKind kind, std::array<double, 2>& t, HeatTotals& h, double& dE) {
    DemSystem sys(twoParticles(t0, true), kind, 1);
    const double e0 = sys.thermalEnergy();
    Gas gas(1, {0, 0, 0}, kTg, 0);
    gas.split = {q};
    gas.apply(sys);
    sys.advance(1e-4, 2);
    t = temperatures(sys);
    h = sys.heatTotals();
    dE = sys.thermalEnergy() - e0;
  };
  std::array<double, 2> t{}, tRef{};
  HeatTotals h, hRef;
  double dE = 0, dERef = 0;
  run(this->kind, t, h, dE);
  EXPECT_NEAR(t[0], kTg, 1e-10) << "T_1 from " << t0[0];
  EXPECT_NEAR(t[1], kTg, 1e-10) << "T_2 from " << t0[1];
  // Booked as heat from the gas (the window's convection moved ~nothing more), the particles'
  // energy grew by it, nothing unassigned.
  expectNear(h.convection, rc, 1e-12, "dem.heat_from_gas_J");
  expectNear(dE, h.convection, 1e-10, "particle energy vs booked heat");
  EXPECT_EQ(h.splitUnassigned, 0.0);
  run(BackendKind::Cpu, tRef, hRef, dERef);
  for (int i = 0; i < 2; ++i)
    expectNear(t[i], tRef[i], this->kBackendTol, "vs cpu");
  expectNear(h.convection, hRef.convection, this->kBackendTol, "vs cpu");
}

// Without convection every G_i is 0: the split goes by m_i c_p,i (the same ΔT for all); it is
// given once per setGasFields (a second advance, or evaluateSources, gives nothing); a cell without
// particles books its share as unassigned.
TYPED_TEST(ReleasedMassAndHeatSplit, HeatSplitByHeatCapacityOnceAndUnassignedWithoutParticles) {
  const double q0 = -1.5e4, q1 = 4e3; // J/m3: cell 0 (both particles), cell 1 (none)
  DemSystem sys(twoParticles({500.0, 500.0}, false, 2), this->kind, 1);
  const double e0 = sys.thermalEnergy();
  Gas gas(2, {0, 0, 0}, kTg, 0);
  gas.split = {q0, q1};
  gas.apply(sys);
  sys.evaluateSources(1e-5); // the staggered scheme's S^0: no split given
  EXPECT_EQ(temperatures(sys)[0], 500.0);
  EXPECT_EQ(sys.heatTotals().convection, 0.0);
  sys.advance(1e-4, 2);
  const double dT = q0 * kCellVolume / (mcp(kD1) + mcp(kD2));
  const auto t = temperatures(sys);
  EXPECT_NEAR(t[0], 500.0 + dT, 1e-11);
  EXPECT_NEAR(t[1], 500.0 + dT, 1e-11);
  const HeatTotals h = sys.heatTotals();
  expectNear(h.convection, q0 * kCellVolume, 1e-14, "given");
  expectNear(h.splitUnassigned, q1 * kCellVolume, 1e-14, "unassigned");
  expectNear(sys.thermalEnergy() - e0, q0 * kCellVolume, 1e-10, "particle energy");
  sys.advance(1e-4, 2); // the same gas fields: nothing more
  EXPECT_EQ(temperatures(sys), t);
  EXPECT_EQ(sys.heatTotals().convection, h.convection);
  EXPECT_EQ(sys.heatTotals().splitUnassigned, h.splitUnassigned);
  gas.apply(sys); // sent again: given again
  sys.advance(1e-4, 2);
  EXPECT_NEAR(temperatures(sys)[0], 500.0 + 2 * dT, 1e-11);
  expectNear(sys.heatTotals().splitUnassigned, 2 * q1 * kCellVolume, 1e-14, "unassigned, twice");
}
