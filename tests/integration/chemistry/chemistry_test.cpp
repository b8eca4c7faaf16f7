// Chemistry integrated in the DEM sub-step (docs/physics.md §3.5, §4, §6, §8.5;
// docs/thermochemistry.md). Every case runs a real DemSystem (cpu backend) and compares with the
// analytic solution, the kernel values, or an independent RK4 integration of the conversion ODE.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/clg_char_gasification.h"
#include "coredem/dem/kernels/clg_oc_reduction.h"
#include "coredem/dem/kernels/nasa7.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/kernels/wgs.h"

using namespace coredem::dem;
namespace k = coredem::dem::kernels;

namespace {

std::string sci(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3e", v);
  return b;
}

/// A material whose contacts do not limit Δt_DEM (single particles, no walls).
Material soft(double cp = 1000.0) {
  Material m;
  m.kn = 1e-8;
  m.en = 0.9;
  m.mu = 0.0;
  m.cp = cp;
  return m;
}

ParticleSet one(double d, double rho, double t, std::vector<double> comp,
                std::array<double, 3> x = {0, 0, 0}) {
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.diameter = d;
  s.density = rho;
  s.temperature = t;
  s.composition = std::move(comp);
  s.positions = {x[0], x[1], x[2]};
  return s;
}

/// One 2 cm cell around the origin (or nx cells along x).
CouplingGrid cube(int nx = 1) {
  CouplingGrid g;
  g.origin = {-0.01, -0.01, -0.01};
  g.spacing = {0.02, 0.02, 0.02};
  g.counts = {nx, 1, 1};
  return g;
}

/// Uniform gas on every cell: T_g, ρ_g, mass fractions y (gas species order).
struct Gas {
  std::vector<double> u, gp, T, rho, mu, kappa, cp, Y;
  Gas(std::size_t n, double tg, double rhoG, const std::vector<double>& y)
      : u(3 * n, 0.0)
      , gp(3 * n, 0.0)
      , T(n, tg)
      , rho(n, rhoG)
      , mu(n, 4e-5)
      , kappa(n, 0.08)
      , cp(n, 1200.0) {
    for (std::size_t c = 0; c < n; ++c)
      Y.insert(Y.end(), y.begin(), y.end());
  }
  void apply(DemSystem& s) const {
    s.setGasFields(GasFieldsView{u, gp, T, rho, mu, kappa, cp, Y, {}, {}});
  }
};

std::vector<Species> clgGas() {
  using S = k::Species;
  return {{"CO", k::molarMass(S::CO)},
          {"CO2", k::molarMass(S::CO2)},
          {"H2", k::molarMass(S::H2)},
          {"H2O", k::molarMass(S::H2O)},
          {"N2", k::molarMass(S::N2)}};
}

/// Mass fractions from mole fractions (CLG gas order).
std::vector<double> massFractions(const std::vector<double>& x) {
  const auto g = clgGas();
  double mmix = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    mmix += x[i] * g[i].molarMass;
  std::vector<double> y(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    y[i] = x[i] * g[i].molarMass / mmix;
  return y;
}

/// Mixture density of an ideal gas, kg/m³.
double idealRho(double p, const std::vector<double>& x, double t) {
  const auto g = clgGas();
  double mmix = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    mmix += x[i] * g[i].molarMass;
  return p * mmix / (k::kGasConstant * t);
}

// ---------------------------------------------------------------- docs/physics.md §8.5 (MFiX-RC)
constexpr double kMA = 0.025, kMB = 0.015, kMC = 0.030, kMD = 0.025, kMI = 0.020, kOmega = 3.927e-4;

DemConfig reactiveChemistryCase(double dH = 0.0) {
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {soft()};
  cfg.gasSpecies = {{"A", kMA}, {"C", kMC}};
  cfg.solidSpecies = {{"B", kMB}, {"D", kMD}, {"I", kMI}};
  cfg.particleSets.push_back(one(3e-3, 2500.0, 300.0, {0.5, 0.0, 0.5}));
  cfg.grid = cube();
  cfg.heat.enabled = false;
  ReactionConfig r;
  r.name = "rc";
  r.terms = {{"A", -1}, {"B", -2}, {"C", 1}, {"D", 1}};
  r.law = k::RateLaw::Constant;
  r.A = kOmega;
  r.heatOfReaction = dH;
  cfg.chemistry.reactions.push_back(r);
  return cfg;
}

} // namespace

TEST(ChemistryStep, MfixReactiveChemistryCaseFollowsTheAnalyticSolution) {
  DemConfig cfg = reactiveChemistryCase();
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  Gas(1, 300.0, 1.2, {0.5, 0.5}).apply(sys);
  const double m0 = sys.particles().mass[0];
  // A 3 mm sphere at 2500 kg/m³.
  EXPECT_NEAR(m0, 2500.0 * M_PI / 6.0 * 27e-9, 1e-15 * m0);
  const double rB = 2.0 * kMB * kOmega; // −r_B, kg/s
  const double tEnd = m0 * 0.5 / rB;
  auto mass = [&](double t) { return m0 - rB * (1.0 - kMD / (2.0 * kMB)) * std::min(t, tEnd); };
  const double dtCfd = 0.01;
  const int nSub = static_cast<int>(std::ceil(dtCfd / sys.dtDemMax()));
  ASSERT_GE(nSub, 1);
  const double vc = 0.02 * 0.02 * 0.02;
  double gasA = 0.0, gasC = 0.0; // ∫ R_species V_c dt, kg
  double maxMassErr = 0.0, maxXErr = 0.0;
  for (int step = 1; step <= 160; ++step) {
    const CellSources& s = sys.advance(dtCfd, nSub);
    gasA += s.rSpecies[0] * vc * dtCfd;
    gasC += s.rSpecies[1] * vc * dtCfd;
    const double t = step * dtCfd;
    if (step == 50 || step == 100 || step == 160) {
      const ParticleData p = sys.particles();
      const double m = p.mass[0];
      const double ref = mass(t);
      maxMassErr = std::max(maxMassErr, std::fabs(m - ref) / ref);
      EXPECT_LT(std::fabs(m - ref) / ref, 8e-6) << "t = " << t;
      const double burnt = rB * std::min(t, tEnd);
      const double xB = (m0 * 0.5 - burnt) / ref;
      const double xD = (kMD / (2.0 * kMB)) * burnt / ref;
      const double xI = m0 * 0.5 / ref;
      for (auto [got, want] :
           {std::pair{p.species[0], xB}, {p.species[1], xD}, {p.species[2], xI}}) {
        EXPECT_LT(std::fabs(got - want), 3e-5) << "t = " << t;
        maxXErr = std::max(maxXErr, std::fabs(got - want));
      }
      if (step == 100) {
        // Gas sources: A consumed at M_A ω, C produced at M_C ω (1e-10 relative).
        EXPECT_NEAR(gasA, -kMA * kOmega * t, 1e-10 * kMA * kOmega * t);
        EXPECT_NEAR(gasC, kMC * kOmega * t, 1e-10 * kMC * kOmega * t);
      }
      // Radius from mass at constant density (Eq. 32).
      EXPECT_NEAR(p.radius[0], 0.5 * std::cbrt(6.0 * m / (M_PI * 2500.0)), 1e-15);
      // Total mass: particle + gas released (ledger) = m0 (1e-12 relative).
      const ChemistryTotals tot = sys.chemistryTotals();
      EXPECT_NEAR(m + tot.gasProduced[0] + tot.gasProduced[1], m0, 1e-12 * m0) << "t = " << t;
      EXPECT_NEAR(tot.gasProduced[0], gasA, 1e-12 * std::fabs(gasA));
    }
  }
  // Final: X_D = 5/11, X_I = 6/11 (m = m0 (1/2 + 1/2 M_D/(2 M_B)) = 11/12 m0), B exhausted.
  const ParticleData p = sys.particles();
  EXPECT_NEAR(p.species[1], 5.0 / 11.0, 3e-5);
  EXPECT_NEAR(p.species[2], 6.0 / 11.0, 3e-5);
  EXPECT_NEAR(p.mass[0], mass(tEnd), 8e-6 * mass(tEnd));
  EXPECT_NEAR(mass(tEnd), 11.0 / 12.0 * m0, 1e-15 * m0);
  EXPECT_GE(p.species[0], 0.0); // B exhausted, never negative (availability limiter)
  EXPECT_LT(p.species[0], 1e-15);
  RecordProperty("rc_mass_rel_err", sci(maxMassErr));
  RecordProperty("rc_fraction_abs_err", sci(maxXErr));
}

TEST(ChemistryStep, ReactionHeatChangesTheTemperatureAsQOverMcpPredicts) {
  const double dH = -2.0e5; // J/mol, exothermic
  DemConfig cfg = reactiveChemistryCase(dH);
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  Gas(1, 300.0, 1.2, {0.5, 0.5}).apply(sys);
  const double dt = 1e-3;
  sys.advance(dt, 1);
  const ParticleData p = sys.particles();
  // Order: mass first, then T with the new mass: T1 = T0 + Δt (−ΔH ω)/(m1 c_p).
  const double expected = 300.0 + dt * (-dH * kOmega / (p.mass[0] * 1000.0));
  EXPECT_NEAR(p.temperature[0], expected, 1e-13 * expected);
  EXPECT_GT(p.temperature[0], 300.0);
  EXPECT_NEAR(sys.chemistryTotals().reactionHeat, -dH * kOmega * dt,
              1e-13 * std::fabs(dH * kOmega * dt));
  // reaction_heat off: athermal.
  cfg.chemistry.reactionHeat = false;
  DemSystem off(cfg, BackendKind::Cpu, 1);
  Gas(1, 300.0, 1.2, {0.5, 0.5}).apply(off);
  off.advance(dt, 1);
  EXPECT_EQ(off.particles().temperature[0], 300.0);
  EXPECT_EQ(off.chemistryTotals().reactionHeat, 0.0);
}

namespace {

struct ClgParticleRun {
  std::vector<double> t, conversion;
  double firstMdot = 0.0;       ///< Δm_key/Δt of the first sub-step
  std::vector<double> firstGas; ///< R_species V_c of the first step (kg/s)
};

/// One CLG particle at fixed T_p in a fixed gas, advanced with steps dt for tEnd.
ClgParticleRun runClgParticle(const DemConfig& cfg, const Gas& gas, double dt, double tEnd,
                              const std::function<double(const ParticleData&)>& conversion,
                              const std::function<double(const ParticleData&)>& keyMass) {
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  gas.apply(sys);
  ClgParticleRun out;
  const double key0 = keyMass(sys.particles());
  const int steps = static_cast<int>(std::llround(tEnd / dt));
  for (int s = 1; s <= steps; ++s) {
    const CellSources& src = sys.advance(dt, 1);
    const ParticleData p = sys.particles();
    if (s == 1) {
      out.firstMdot = (keyMass(p) - key0) / dt;
      for (double r : src.rSpecies)
        out.firstGas.push_back(r * 0.02 * 0.02 * 0.02);
    }
    out.t.push_back(s * dt);
    out.conversion.push_back(conversion(p));
  }
  return out;
}

/// RK4 of dX/dt = f(X) from X = 0, returning X at the times of `t` (uniform steps h).
std::vector<double> rk4(const std::function<double(double)>& f, double h,
                        const std::vector<double>& t) {
  std::vector<double> out;
  double x = 0.0, time = 0.0;
  std::size_t next = 0;
  while (next < t.size()) {
    const double k1 = f(x), k2 = f(x + 0.5 * h * k1), k3 = f(x + 0.5 * h * k2), k4 = f(x + h * k3);
    x += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    time += h;
    while (next < t.size() && std::fabs(time - t[next]) < 0.5 * h) {
      out.push_back(x);
      ++next;
    }
  }
  return out;
}

} // namespace

/// One particle whose data-defined reaction 2 B(s) -> C(g) releases gas (M_C = 2 M_B: balanced),
/// at T_p in a coupled cell of gas at T_g (c_p,g = 1200 J/(kg K) from Gas), heat transfer off.
DemConfig releasingGasCase(double tp, double dH) {
  DemConfig cfg = reactiveChemistryCase(dH);
  cfg.particleSets[0].temperature = tp;
  cfg.chemistry.reactions[0].terms = {{"B", -2}, {"C", 1}};
  return cfg;
}

TEST(ChemistryStep, ReleasedGasCarriesItsSensibleEnthalpyAtTpIntoQHom) {
  const double tp = 900.0, tg = 300.0, cpg = 1200.0, dt = 0.1, vc = 0.02 * 0.02 * 0.02;
  DemSystem sys(releasingGasCase(tp, -2.0e5), BackendKind::Cpu, 1);
  Gas(1, tg, 1.2, {0.5, 0.5}).apply(sys);
  const double e0 = sys.thermalEnergy();
  const double m0 = sys.particles().mass[0];
  const CellSources& s = sys.advance(dt, 1);
  // Net gas mass produced: ω M_C (kg/s); the gas gets it at T_p instead of T_g (no WGS here).
  const double mGas = kOmega * kMC;
  const double q = mGas * cpg * (tp - tg) / vc;
  ASSERT_EQ(s.qHom.size(), 1u);
  EXPECT_NEAR(s.qHom[0], q, 1e-12 * q);
  EXPECT_NEAR(s.rSpecies[1], mGas / vc, 1e-12 * mGas / vc);
  const ChemistryTotals t = sys.chemistryTotals();
  EXPECT_NEAR(t.gasSensibleHeat, q * vc * dt, 1e-12 * q * vc * dt);
  EXPECT_EQ(t.homogeneousHeat, 0.0);
  // Particle ledger: Δ Σ m c_p T = Q_rxn + Σ Δm c_p T_p (heat transfer off), Δm < 0 here.
  const ParticleData p = sys.particles();
  const double dm = p.mass[0] - m0;
  EXPECT_NEAR(dm, -mGas * dt, 1e-12 * mGas * dt);
  EXPECT_NEAR(t.sensibleMassEnthalpy, dm * 1000.0 * tp, 1e-12 * std::fabs(dm * 1000.0 * tp));
  const double de = sys.thermalEnergy() - e0;
  const double closure = t.reactionHeat + t.sensibleMassEnthalpy;
  // Round-off of the difference of two ~32 J sums: tolerance 1e-12 of |ΔE| (ΔE ≈ 6.8 J).
  EXPECT_NEAR(de, closure, 1e-12 * std::fabs(de)) << "ΔE " << sci(de) << " ledger " << sci(closure);
  EXPECT_GT(t.reactionHeat, 0.0);
  EXPECT_LT(t.sensibleMassEnthalpy, 0.0);
  // Without the new term the ledger is off by far more than round-off.
  EXPECT_GT(std::fabs(de - t.reactionHeat), 1e3 * 1e-12 * std::fabs(de));
}

TEST(ChemistryStep, NoSensibleGasHeatWhenTpEqualsTgButTheParticleLedgerStillCloses) {
  const double t0 = 700.0, dt = 0.1;
  DemSystem sys(releasingGasCase(t0, 0.0), BackendKind::Cpu, 1);
  Gas(1, t0, 1.2, {0.5, 0.5}).apply(sys);
  const double e0 = sys.thermalEnergy();
  const CellSources& s = sys.advance(dt, 1);
  EXPECT_EQ(s.qHom[0], 0.0);
  const ChemistryTotals t = sys.chemistryTotals();
  EXPECT_EQ(t.gasSensibleHeat, 0.0);
  EXPECT_EQ(t.reactionHeat, 0.0);
  EXPECT_EQ(sys.particles().temperature[0], t0); // athermal: mass leaves at T_p, T_p unchanged
  const double de = sys.thermalEnergy() - e0;
  EXPECT_LT(de, 0.0);
  EXPECT_NEAR(de, t.sensibleMassEnthalpy, 1e-12 * std::fabs(de));
}

TEST(ChemistryStep, CharParticleFollowsTheKernelRatesAndTheConversionOde) {
  const double tp = 1400.0, p = 101325.0;
  const std::vector<double> x = {0.05, 0.15, 0.05, 0.5, 0.25}; // CO, CO2, H2, H2O, N2
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {soft(1200.0)};
  cfg.gasSpecies = clgGas();
  cfg.solidSpecies = {{"C", k::molarMass(k::Species::C)}, {"ash", 0.1}};
  cfg.particleSets.push_back(one(2e-3, 1500.0, tp, {0.9, 0.1}));
  cfg.grid = cube();
  cfg.heat.enabled = false;
  cfg.chemistry.clg.charGasification = true;
  cfg.chemistry.reactionHeat = false; // fixed T_p for the ODE comparison
  cfg.chemistry.pressure = p;
  const Gas gas(1, tp, idealRho(p, x, tp), massFractions(x));
  const double m0 = 1500.0 * k::sphereVolume(1e-3);
  const double mC0 = 0.9 * m0;
  const double dt = 1e-3;
  const auto run = runClgParticle(
      cfg, gas, dt, 10.0,
      [&](const ParticleData& d) { return 1.0 - d.mass[0] * d.species[0] / mC0; },
      [](const ParticleData& d) { return d.mass[0] * d.species[0]; });
  // Kernel values at the initial state (partial pressures P_j = x_j p in bar).
  double pBar[k::kGasSpeciesCount];
  for (int g = 0; g < k::kGasSpeciesCount; ++g)
    pBar[g] = x[g] * p * 1e-5;
  const k::CharGasificationParams cp;
  const k::CharGasificationRates r = k::charGasification(cp, tp, pBar, mC0, mC0);
  EXPECT_NEAR(run.firstMdot, r.mdotC, 1e-9 * std::fabs(r.mdotC));
  ASSERT_EQ(run.firstGas.size(), 5u);
  for (int g = 0; g < 4; ++g)
    EXPECT_NEAR(run.firstGas[g], r.mdotGas[g], 1e-12 * std::fabs(r.mdotC)) << g;
  EXPECT_EQ(run.firstGas[4], 0.0);
  // Conversion vs RK4 of dX/dt = (r_CO2 + r_H2O)(1 − X)^(2/3) (fixed gas, fixed T_p).
  const double rate =
      k::charRateCO2(cp, tp, pBar[1], pBar[0]) + k::charRateH2O(cp, tp, pBar[3], pBar[2]);
  const auto ref = rk4([&](double X) { return rate * std::cbrt((1 - X) * (1 - X)); }, 1e-4, run.t);
  double maxErr = 0.0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    maxErr = std::max(maxErr, std::fabs(run.conversion[i] - ref[i]));
  // Explicit Euler, Δt = 1e-3 s: global error ≈ (Δt/2)|dX/dt| ≈ 2e-5; tolerance 5e-5 (X(10 s) ≈
  // 0.3).
  EXPECT_GT(run.conversion.back(), 0.2);
  EXPECT_LT(maxErr, 5e-5);
  RecordProperty("char_conversion_abs_err", sci(maxErr));
}

TEST(ChemistryStep, OxygenCarrierParticleFollowsTheKernelRatesAndTheConversionOde) {
  const double tp = 1223.0, p = 101325.0;
  const std::vector<double> x = {0.1, 0.1, 0.1, 0.2, 0.5};
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {soft(900.0)};
  cfg.gasSpecies = clgGas();
  using S = k::Species;
  cfg.solidSpecies = {{"Fe2O3", k::molarMass(S::Fe2O3)},
                      {"Fe3O4", k::molarMass(S::Fe3O4)},
                      {"Al2O3", k::molarMass(S::Al2O3)}};
  cfg.particleSets.push_back(one(2e-3, 3000.0, tp, {0.6, 0.0, 0.4}));
  cfg.grid = cube();
  cfg.heat.enabled = false;
  cfg.chemistry.clg.ocReduction = true;
  cfg.chemistry.reactionHeat = false;
  cfg.chemistry.pressure = p;
  const double rho = idealRho(p, x, tp);
  const Gas gas(1, tp, rho, massFractions(x));
  const double m0 = 3000.0 * k::sphereVolume(1e-3);
  const double hem = k::molarMass(S::Fe2O3), mag = k::molarMass(S::Fe3O4);
  auto meq = [&](const ParticleData& d) {
    return d.mass[0] * (d.species[0] + d.species[1] * 3 * hem / (2 * mag));
  };
  const double dt = 1e-3;
  const auto run = runClgParticle(
      cfg, gas, dt, 10.0,
      [&](const ParticleData& d) { return 1.0 - d.mass[0] * d.species[0] / meq(d); },
      [](const ParticleData& d) { return d.mass[0] * d.species[0]; });
  const k::OcReductionParams op;
  const double cCO = rho * massFractions(x)[0] / k::molarMass(S::CO);
  const double cH2 = rho * massFractions(x)[2] / k::molarMass(S::H2);
  const double mf[3] = {0.6, 0.0, 0.4};
  const k::OcReductionRates r = k::ocReduction(op, tp, m0, mf, cCO, cH2);
  EXPECT_NEAR(run.firstMdot, r.mdotSolid[0], 1e-9 * std::fabs(r.mdotSolid[0]));
  for (int g = 0; g < 4; ++g)
    EXPECT_NEAR(run.firstGas[g], r.mdotGas[g], 1e-12 * std::fabs(r.mdotSolid[0])) << g;
  const double kSum = k::ocRateCoefficient(op, op.k0CO, op.eCO, op.nCO, tp, cCO) +
                      k::ocRateCoefficient(op, op.k0H2, op.eH2, op.nH2, tp, cH2);
  const auto ref = rk4([&](double X) { return kSum * std::cbrt((1 - X) * (1 - X)); }, 1e-4, run.t);
  double maxErr = 0.0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    maxErr = std::max(maxErr, std::fabs(run.conversion[i] - ref[i]));
  EXPECT_GT(run.conversion.back(), 0.1);
  EXPECT_LT(maxErr, 5e-5);
  RecordProperty("oc_conversion_abs_err", sci(maxErr));
}

TEST(ChemistryStep, WaterGasShiftCellSourcesEqualTheKernelAndDriveTowardsEquilibrium) {
  const double tg = 1000.0, p = 101325.0;
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {soft()};
  cfg.gasSpecies = clgGas();
  cfg.grid = cube(2);
  cfg.chemistry.clg.wgs = true;
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  // Cell 0: reactant-rich (forward); cell 1: product-rich (backward).
  const std::vector<double> x0 = {0.3, 0.05, 0.05, 0.3, 0.3}, x1 = {0.05, 0.3, 0.3, 0.05, 0.3};
  std::vector<std::vector<double>> y = {massFractions(x0), massFractions(x1)};
  std::vector<double> rho = {idealRho(p, x0, tg), idealRho(p, x1, tg)};
  const k::WgsParams wp;
  const double keq = k::wgsEquilibriumConstant(wp, tg);
  auto quotient = [&](const std::vector<double>& yy) {
    const auto g = clgGas();
    return (yy[1] / g[1].molarMass) * (yy[2] / g[2].molarMass) /
           ((yy[0] / g[0].molarMass) * (yy[3] / g[3].molarMass));
  };
  double gap0 = std::fabs(std::log(quotient(y[0]) / keq)),
         gap1 = std::fabs(std::log(quotient(y[1]) / keq));
  // τ = 1/(k_f ΣC) ≈ 500 s at 1000 K: 30 steps of 25 s (explicit relaxation, Δt/τ ≈ 0.05).
  const double dt = 25.0;
  for (int step = 0; step < 30; ++step) {
    Gas gas(2, tg, 1.0, y[0]);
    gas.rho = rho;
    gas.Y.clear();
    for (const auto& yy : y)
      gas.Y.insert(gas.Y.end(), yy.begin(), yy.end());
    gas.apply(sys);
    const CellSources& s = sys.advance(dt, 1);
    for (int c = 0; c < 2; ++c) {
      const k::WgsCellSources w = k::wgsCellSources(wp, tg, 1.0, rho[c], y[c].data(), dt);
      for (int g = 0; g < 5; ++g)
        EXPECT_EQ(s.rSpecies[c * 5 + g], w.massSource[g]) << "cell " << c << " species " << g;
      EXPECT_EQ(s.qHom[c], w.heatSource);
      if (step == 0) {
        EXPECT_LT(s.rSpecies[c * 5 + 0] * (c == 0 ? 1 : -1),
                  0.0);                                // CO consumed in cell 0, produced in cell 1
        EXPECT_GT(s.qHom[c] * (c == 0 ? 1 : -1), 0.0); // exothermic forward
      }
      // The gas of a closed cell at constant ρ: Y += Δt R/ρ (ε_g = 1).
      for (int g = 0; g < 5; ++g)
        y[c][g] += dt * s.rSpecies[c * 5 + g] / rho[c];
    }
    const double n0 = std::fabs(std::log(quotient(y[0]) / keq)),
                 n1 = std::fabs(std::log(quotient(y[1]) / keq));
    EXPECT_LE(n0, gap0);
    EXPECT_LE(n1, gap1);
    gap0 = n0;
    gap1 = n1;
  }
  EXPECT_LT(gap0, 0.5 * std::fabs(std::log(quotient(massFractions(x0)) / keq)));
  EXPECT_LT(gap1, 0.5 * std::fabs(std::log(quotient(massFractions(x1)) / keq)));
}

TEST(ChemistryStep, ShrinkingBelowTheThresholdRemovesTheParticleAndLedgersItsMass) {
  DemConfig cfg;
  cfg.gravity = {0, 0, 0};
  cfg.materials = {soft()};
  cfg.gasSpecies = {{"G", 0.015}};
  cfg.solidSpecies = {{"B", 0.015}, {"I", 0.020}};
  cfg.particleSets.push_back(
      one(2e-3, 2000.0, 300.0, {1.0, 0.0}, {-0.005, 0, 0})); // all B: burns away
  cfg.particleSets.push_back(one(2e-3, 2000.0, 300.0, {0.0, 1.0}, {0.005, 0, 0})); // inert
  cfg.grid = cube();
  cfg.heat.enabled = false;
  ReactionConfig r;
  r.name = "burn";
  r.terms = {{"B", -1}, {"G", 1}};
  r.A = 1e-4; // mol/s: 1.5e-6 kg/s, the particle (8.4e-6 kg) is gone after ≈ 5.6 s
  cfg.chemistry.reactions.push_back(r);
  cfg.chemistry.removalFraction = 0.1;
  DemSystem sys(cfg, BackendKind::Cpu, 1);
  const double m0 = sys.particles().mass[0];
  int steps = 0;
  while (sys.particleCount() == 2 && steps < 1000) {
    sys.advance(0.01, 1);
    ++steps;
  }
  ASSERT_EQ(sys.particleCount(), 1u) << "not removed after " << steps << " steps";
  EXPECT_NEAR(steps * 0.01, m0 / (0.015 * 1e-4), 0.02); // when ≥ 99.9 % of the mass is gone
  const ParticleData p = sys.particles();
  EXPECT_EQ(p.globalId[0], 1); // the inert particle keeps its id
  EXPECT_EQ(p.species[1], 1.0);
  const ChemistryTotals t = sys.chemistryTotals();
  EXPECT_EQ(t.removedCount, 1u);
  EXPECT_GT(t.removedSolid[0], 0.0);
  EXPECT_LT(t.removedSolid[0], std::pow(0.1, 3) * m0);
  // Mass: removed + released to the gas = m0 (1e-12 relative).
  EXPECT_NEAR(t.removedMass() + t.gasProduced[0], m0, 1e-12 * m0);
  // Keeps running without it.
  sys.advance(0.01, 1);
  EXPECT_EQ(sys.particleCount(), 1u);
}

namespace {

/// A small reacting bed: char and oxygen-carrier particles in a box, every model on.
DemConfig reactingBed() {
  DemConfig cfg;
  Material m;
  m.kn = 200.0;
  m.en = 0.9;
  m.mu = 0.3;
  m.cp = 1000.0;
  m.conductivity = 2.0;
  m.emissivity = 0.8;
  cfg.materials = {m};
  cfg.addBox({0, 0, 0}, {0.012, 0.012, 0.024});
  cfg.gasSpecies = clgGas();
  using S = k::Species;
  cfg.solidSpecies = {{"C", k::molarMass(S::C)},
                      {"ash", 0.1},
                      {"Fe2O3", k::molarMass(S::Fe2O3)},
                      {"Fe3O4", k::molarMass(S::Fe3O4)},
                      {"Al2O3", k::molarMass(S::Al2O3)}};
  ParticleSet c;
  c.packing = Packing::Lattice;
  c.regionMin = {0, 0, 0};
  c.regionMax = {0.012, 0.012, 0.008};
  c.count = 18;
  c.diameter = 2e-3;
  c.density = 1500;
  c.temperature = 1300;
  c.composition = {0.9, 0.1, 0, 0, 0};
  c.spacing = 2.05e-3;
  c.velocityJitter = 0.05;
  ParticleSet o = c;
  o.regionMin = {0, 0, 0.012};
  o.regionMax = {0.012, 0.012, 0.020};
  o.density = 3000;
  o.temperature = 1200;
  o.composition = {0, 0, 0.6, 0, 0.4};
  o.seed = 99;
  cfg.particleSets = {c, o};
  cfg.grid.origin = {0, 0, 0};
  cfg.grid.spacing = {0.006, 0.006, 0.006};
  cfg.grid.counts = {2, 2, 4};
  cfg.chemistry.clg.charGasification = true;
  cfg.chemistry.clg.ocReduction = true;
  cfg.chemistry.clg.wgs = true;
  cfg.chemistry.clg.charParams.aH2O = 1e9; // fast, so a few steps change the state
  cfg.chemistry.clg.ocParams.k0CO = 1e-2;
  ReactionConfig r;
  r.name = "extra";
  r.terms = {{"CO2", -1}, {"C", -1}, {"CO", 2}};
  r.law = k::RateLaw::Arrhenius;
  r.A = 1e3;
  r.E = 1.5e5;
  r.orderSpecies = "CO2";
  r.order = 1.0;
  r.heatFromNasa7 = true;
  cfg.chemistry.reactions.push_back(r);
  return cfg;
}

struct BedRun {
  ParticleData p;
  std::vector<double> r, qhom;
  ChemistryTotals tot;
};

BedRun runBed(int threads, int steps, const std::string& readFrom = "",
              const std::string& writeTo = "", int writeAfter = -1) {
  DemSystem sys(reactingBed(), BackendKind::Cpu, threads);
  const double dt = 2e-3;
  // Sub-steps from the initial particles (a restart recomputes Δt_DEM,max from the lighter,
  // reacted particles; the server keeps the nSub of the grant).
  const int nSub = static_cast<int>(std::ceil(dt / sys.dtDemMax()));
  if (!readFrom.empty())
    sys.readState(readFrom);
  const std::vector<double> x = {0.1, 0.2, 0.1, 0.4, 0.2};
  const Gas gas(sys.cellCount(), 1250.0, idealRho(101325.0, x, 1250.0), massFractions(x));
  BedRun out;
  for (int s = 0; s < steps; ++s) {
    gas.apply(sys);
    const CellSources& src = sys.advance(dt, nSub);
    out.r = src.rSpecies;
    out.qhom = src.qHom;
    if (s + 1 == writeAfter && !writeTo.empty())
      sys.writeState(writeTo);
  }
  out.p = sys.particles();
  out.tot = sys.chemistryTotals();
  return out;
}

void expectSame(const BedRun& a, const BedRun& b) {
  ASSERT_EQ(a.p.count, b.p.count);
  EXPECT_EQ(a.p.globalId, b.p.globalId);
  EXPECT_EQ(a.p.position, b.p.position);
  EXPECT_EQ(a.p.mass, b.p.mass);
  EXPECT_EQ(a.p.radius, b.p.radius);
  EXPECT_EQ(a.p.temperature, b.p.temperature);
  EXPECT_EQ(a.p.species, b.p.species);
  EXPECT_EQ(a.p.initialDiameter, b.p.initialDiameter);
  EXPECT_EQ(a.r, b.r);
  EXPECT_EQ(a.qhom, b.qhom);
  EXPECT_EQ(a.tot.gasProduced, b.tot.gasProduced);
  EXPECT_EQ(a.tot.solidChange, b.tot.solidChange);
  EXPECT_EQ(a.tot.reactionHeat, b.tot.reactionHeat);
  EXPECT_EQ(a.tot.homogeneousHeat, b.tot.homogeneousHeat);
  EXPECT_EQ(a.tot.gasSensibleHeat, b.tot.gasSensibleHeat);
  EXPECT_EQ(a.tot.sensibleMassEnthalpy, b.tot.sensibleMassEnthalpy);
}

} // namespace

TEST(ChemistryStep, OneAndTwoThreadsAreBitwiseIdenticalWithChemistryOn) {
  const BedRun a = runBed(1, 4);
  const BedRun b = runBed(2, 4);
  expectSame(a, b);
  // Mass fractions stay in [0, 1] and sum to 1 (limiter; Eq. 31).
  for (std::size_t i = 0; i < a.p.count; ++i) {
    double sum = 0.0;
    for (int k = 0; k < a.p.nSpecies; ++k) {
      const double x = a.p.species[i * a.p.nSpecies + k];
      EXPECT_GE(x, 0.0);
      sum += x;
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
  }
  // Something reacted: char lost carbon, the carrier gained Fe3O4, heat was exchanged.
  EXPECT_LT(a.tot.solidChange[0], 0.0);
  EXPECT_GT(a.tot.solidChange[3], 0.0);
  EXPECT_NE(a.tot.reactionHeat, 0.0);
  EXPECT_NE(a.tot.homogeneousHeat, 0.0);
  EXPECT_NE(a.tot.gasSensibleHeat, 0.0); // T_p (1200/1300 K) ≠ T_g (1250 K)
  EXPECT_NE(a.tot.sensibleMassEnthalpy, 0.0);
  // Mass: Σ solid change + Σ gas released = 0 (balanced reactions; molar masses balance to
  // round-off).
  double s = 0.0, scale = 0.0;
  for (double v : a.tot.solidChange)
    s += v, scale += std::fabs(v);
  for (double v : a.tot.gasProduced)
    s += v;
  EXPECT_LT(std::fabs(s), 1e-12 * scale);
}

TEST(ChemistryStep, RestartFromHdf5IsBitwiseWithChemistryOn) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("coredem_chem_restart_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string state = (dir / "state.h5").string();
  const BedRun straight = runBed(2, 6, "", state, 3);
  const BedRun resumed = runBed(2, 3, state);
  expectSame(straight, resumed);
  std::filesystem::remove_all(dir);
}

TEST(ChemistryConfig, BadChemistryIsRejectedWithAClearMessage) {
  auto expectError = [](DemConfig cfg, const std::string& needle) {
    try {
      DemSystem sys(cfg, BackendKind::Cpu, 1);
      ADD_FAILURE() << "no error, expected one containing '" << needle << "'";
    } catch (const coredem::UserError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  DemConfig bad = reactiveChemistryCase();
  bad.chemistry.reactions[0].terms[0].species = "Q";
  expectError(bad, "unknown species 'Q'");
  bad = reactiveChemistryCase();
  bad.chemistry.removalFraction = 1.5;
  expectError(bad, "removal_fraction");
  bad = reactiveChemistryCase();
  bad.chemistry.clg.charGasification = true;
  expectError(bad, "needs solid species C");
  bad = reactiveChemistryCase();
  bad.chemistry.reactions[0].heatFromNasa7 = true;
  expectError(bad, "NASA-7");
  // The config hash includes chemistry.
  DemSystem a(reactiveChemistryCase(), BackendKind::Cpu, 1);
  DemSystem b(reactiveChemistryCase(1.0), BackendKind::Cpu, 1);
  EXPECT_NE(a.configHash(), b.configHash());
}

// Two-thread cases on a shared machine: see tests/integration/heat/heat_test.cpp (OMP_WAIT_POLICY).
int main(int argc, char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
    ::setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
    ::execv("/proc/self/exe", argv);
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
