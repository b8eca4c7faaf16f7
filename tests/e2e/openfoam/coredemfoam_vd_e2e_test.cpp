// End-to-end tests of coredemFoam's variable-density gas (a low-Mach ideal-gas mixture, chosen by
// constant/thermophysicalProperties; docs/coredemFoam.md "Variable-density gas"), run by
// `coredem` with the real DEM server in the 1 x 4 x 1 cm column of tests/e2e/openfoam/cases/column
// (y vertical, inlet at the bottom). The case is the template with p in Pa, a field N2 = 1 and
// `gas_properties: {model: ideal_gas}` in case.yaml: coredem writes the thermophysicalProperties
// of pure N2 (JANAF coefficients of the DEM's table, Sutherland transport) into the run's copy:
//   (a) hot walls, no particles to speak of: the gas heats up and leaves faster, as an ideal gas
//       at constant pressure must (u_out = u_in T_out/T_in);
//   (b) a packed bed: the pressure drop is Ergun's with the thermo's density and viscosity;
//   (c) hot gas through a fixed bed: the heat the gas receives from the particles equals the heat
//       the particles lost, to round-off, once the split booked for the next step is counted;
//   (d) impossible start states are refused naming the cell, the field and the value;
//   (e) a restart of the variable-density gas continues bit for bit;
//   (f) char gasification in a nearly closed column: the gas volume gained is one ideal-gas
//       molar volume R T/p_ref per mol of gas produced;
//   (g) a decomposed run agrees with the serial one;
// and, without thermophysicalProperties, the constant-property solver gives the numbers it gave
// before the variable-density gas existed.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem_e2e.h"
#include "foam_e2e.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kTemplate = COREDEM_FOAM_E2E_TEMPLATE;

using coredem::e2e::readAll;
using coredem::e2e::readTimeseries;
using coredem::e2e::replaceAll;
using coredem::e2e::writeAll;
using coredem::e2e::foam::copyColumnTemplate;
using coredem::e2e::foam::logTail;
using coredem::e2e::foam::runCoredem;
using coredem::e2e::foam::runOnRanks;
using coredem::e2e::foam::runStraightAndResumed;

constexpr double kPRef = 101325.0;
// N2: molar mass (g/mol, the DEM's table that coredem writes), Sutherland coefficients (White,
// Viscous Fluid Flow, Table 1-2: mu0 1.663e-5 Pa s at T0 273 K, S 107 K -> As = mu0 (T0 +
// S)/T0^1.5).
constexpr double kMolarMass = 28.014, kTs = 107.0;
const double kAs = 1.663e-5 * (273.0 + kTs) / std::pow(273.0, 1.5);
// OpenFOAM's universal gas constant (J/kmol/K, v1912: 1e3 NA k).
constexpr double kRR = 1e3 * 6.0221417930e+23 * 1.38065e-23;

double idealGasDensity(double t) {
  return kPRef * kMolarMass / (kRR * t);
}
double sutherland(double t) {
  return kAs * std::sqrt(t) / (1.0 + kTs / t);
}

const char* kFoamHeader = R"(FoamFile
{
    version     2.0;
    format      ascii;
    class       %CLASS%;
    location    "%LOC%";
    object      %NAME%;
}
)";

std::string foamHeader(const std::string& cls, const std::string& loc, const std::string& name) {
  return replaceAll(replaceAll(replaceAll(kFoamHeader, "%CLASS%", cls), "%LOC%", loc), "%NAME%",
                    name);
}

struct VdCase {
  double uIn = 0.3;    // inlet velocity, m/s
  double tIn = 293.15; // inlet temperature, K
  double t0 = 293.15;  // initial gas temperature, K
  double tWall = -1;   // > 0: walls held at this temperature (else zero gradient)
  double gravity = -9.81;
  std::string body; // time, materials, particles, models of case.yaml
  std::string species = "species: [{name: N2, molar_mass: 0.028014}]\n";
};

/// A case folder in `dir`: the column template turned into a variable-density case.
fs::path makeVdCase(const fs::path& dir, const VdCase& v) {
  const fs::path c = dir / "case";
  const fs::path of = c / "openfoam";
  fs::create_directories(c);
  copyColumnTemplate(kTemplate, of, v.uIn, v.tIn);
  // p in Pa, the outlet at pRef.
  std::string p = readAll(of / "0" / "p");
  p = replaceAll(p, "[0 2 -2 0 0 0 0]", "[1 -1 -2 0 0 0 0]");
  p = replaceAll(p, "uniform 0", "uniform 101325");
  writeAll(of / "0" / "p", p);
  std::string t = readAll(of / "0" / "T");
  if (v.t0 != 293.15) {
    t = replaceAll(t, "uniform 293.15;", "uniform " + std::to_string(v.t0) + ";");
  }
  if (v.tWall > 0) {
    t = replaceAll(t, "walls   { type zeroGradient; }",
                   "walls   { type fixedValue; value uniform " + std::to_string(v.tWall) + "; }");
  }
  writeAll(of / "0" / "T", t);
  std::string g = readAll(of / "constant" / "g");
  g = std::regex_replace(g, std::regex(R"(value\s+\([^)]*\);)"),
                         "value           (0 " + std::to_string(v.gravity) + " 0);");
  writeAll(of / "constant" / "g", g);
  writeAll(of / "0" / "N2", foamHeader("volScalarField", "0", "N2") + R"(
dimensions      [0 0 0 0 0 0 0];
internalField   uniform 1;
boundaryField
{
    inlet   { type fixedValue; value uniform 1; }
    outlet  { type inletOutlet; inletValue uniform 1; value uniform 1; }
    walls   { type zeroGradient; }
}
)");
  // The template's transportProperties stays: coredemFoam takes pressureDropPatches from it.
  std::ostringstream t0;
  t0.precision(17);
  t0 << v.t0;
  writeAll(c / "case.yaml", std::string(R"(name: column-vd
grid: {origin: [0, 0, 0], spacing: [0.002, 0.002, 0.002], cells: [5, 20, 5]}
gravity: [0.0, )") + std::to_string(v.gravity) +
                                R"(, 0.0]
gas_properties: {model: ideal_gas, temperature: )" +
                                t0.str() + R"(, pressure: 101325.0}
)" + v.species + R"(walls:
  box: {min: [0.0, 0.0, 0.0], max: [0.01, 0.04, 0.01]}
  planes: [{point: [0.0, 0.004, 0.0], normal: [0.0, 1.0, 0.0]}]
cfd: {participant: coredemFoam, case: openfoam, timeout_s: 120}
dem: {backend: cpu, threads: 1, timeout_s: 120}
)" + v.body);
  return c;
}

/// The cell values of an ascii volScalarField (components = 1) or volVectorField (3) as written
/// by coredemFoam; a uniform internal field gives nCells copies.
std::vector<double> readCellValues(const fs::path& file, int components, std::size_t nCells) {
  const std::string s = readAll(file);
  std::vector<double> out;
  const std::regex uniform(R"(internalField\s+uniform\s+\(?([^;)]*)\)?;)");
  std::smatch m;
  if (std::regex_search(s, m, uniform)) {
    std::istringstream in(m[1].str());
    std::vector<double> one(components);
    for (double& x : one) {
      in >> x;
    }
    for (std::size_t c = 0; c < nCells; ++c) {
      out.insert(out.end(), one.begin(), one.end());
    }
    return out;
  }
  const auto at = s.find("internalField");
  const auto open = s.find('(', s.find("List<", at));
  std::string body = s.substr(open + 1);
  for (char& ch : body) {
    if (ch == '(' || ch == ')') {
      ch = ' ';
    }
  }
  std::istringstream in(body);
  double x = 0;
  while (out.size() < nCells * components && in >> x) {
    out.push_back(x);
  }
  return out;
}

// The packed lattice bed of several tests: 1600 glass beads of 1 mm at 293.15 K, a soft spring
// (k_n = 10 N/m: a bed at rest needs no more), 16 mm of bed above the distributor.
const char* kColdBed = R"(materials:
  - {name: glass, density: 2500.0, k_n: 10.0, e_n: 0.5, friction: 0.3, cp: 840.0}
particles:
  - {name: bed, material: glass, count: 1600, diameter: 1.0e-3, packing: lattice,
     temperature: 293.15, region: {min: [0.0, 0.004, 0.0], max: [0.01, 0.020, 0.01]}}
)";

class CoredemFoamVdE2E : public coredem::e2e::RunFolderTest {
protected:
  CoredemFoamVdE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredemFoam"}, "coredemfoam-vd-e2e") {}
};

// One frozen 0.1 mm bead in a corner near the inlet (the case needs particles) with heat exchange
// off: the column is empty for the gas (the bead's drag slows the gas of its cell, 16 rows below
// the outlet, by a few per cent). No gravity (buoyancy would stir the heated gas).
const char* kEmptyColumn = R"(materials:
  - {name: glass, density: 2500.0, k_n: 100.0, e_n: 0.5, friction: 0.3}
particles:
  - {name: bead, material: glass, count: 1, diameter: 1.0e-4, packing: lattice,
     region: {min: [0.0, 0.0042, 0.0], max: [0.0004, 0.0046, 0.0004]}}
models: {heat: "off", motion: frozen}
)";

// (a) N2 enters at 300 K and 0.02 m/s between walls held at 600 K. The gas reaches the wall
// temperature well before the outlet (lateral diffusion time ~0.2 s, residence ~1.3 s) and, at
// steady state, leaves with the mass flux it entered with: rho_in u_in = rho_out u_out with
// rho = pRef M/(R T), so u_out = u_in T_out/T_in (here 2x). Checked on the outlet row of cells
// after 5 s (about four residence times) against the row's mean temperature and against the wall
// temperature, within 0.5% (issue 17; observed ~2e-5); the outlet velocity is uniform within 0.5%.
TEST_F(CoredemFoamVdE2E, HotGasThroughAnEmptyHeatedColumnExpandsAsAnIdealGas) {
  VdCase v;
  v.uIn = 0.02;
  v.tIn = 300.0;
  v.t0 = 300.0;
  v.tWall = 600.0;
  v.gravity = 0.0;
  v.body = std::string("time: {end: 5.0, dt: 1.0e-3, adaptive: {courant: 0.5, dt_min: 1.0e-5, "
                       "dt_max: 0.02}}\n") +
           kEmptyColumn;
  const fs::path c = makeVdCase(dir, v);
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  EXPECT_NE(readAll(run / "logs" / "cfd.log").find("ideal-gas mixture of 1(N2)"), std::string::npos)
      << "coredemFoam did not run the variable-density gas";
  const fs::path last = run / "openfoam" / "5";
  ASSERT_TRUE(fs::exists(last / "U")) << "no fields written at t = 5 s";
  constexpr std::size_t nx = 5, ny = 20, nz = 5, n = nx * ny * nz;
  const auto u = readCellValues(last / "U", 3, n);
  const auto t = readCellValues(last / "T", 1, n);
  const auto rho = readCellValues(last / "rho", 1, n);
  ASSERT_EQ(u.size(), 3 * n);
  ASSERT_EQ(t.size(), n);
  ASSERT_EQ(rho.size(), n);
  double uOut = 0, tOut = 0, uMin = 1e30, uMax = -1e30, flux = 0;
  const std::size_t j = ny - 1;
  for (std::size_t k = 0; k < nz; ++k) {
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t cell = k * nx * ny + j * nx + i;
      uOut += u[3 * cell + 1] / (nx * nz);
      tOut += t[cell] / (nx * nz);
      flux += rho[cell] * u[3 * cell + 1] / (nx * nz);
      uMin = std::min(uMin, u[3 * cell + 1]);
      uMax = std::max(uMax, u[3 * cell + 1]);
    }
  }
  std::cout << "heated column: u_out " << uOut << " m/s at T_out " << tOut << " K; u_in T_out/T_in "
            << v.uIn * tOut / v.tIn << " m/s (" << 100.0 * (uOut / (v.uIn * tOut / v.tIn) - 1.0)
            << " %); mass flux out/in " << flux / (idealGasDensity(v.tIn) * v.uIn) << "\n";
  EXPECT_NEAR(tOut / v.tWall, 1.0, 0.005) << "the gas did not reach the wall temperature";
  EXPECT_NEAR(uOut / (v.uIn * tOut / v.tIn), 1.0, 0.005);
  EXPECT_NEAR(uOut / (v.uIn * v.tWall / v.tIn), 1.0, 0.005);
  EXPECT_LT((uMax - uMin) / uOut, 0.005);
  // The density written is the ideal gas's at the cell temperature (pRef, M of N2).
  for (std::size_t cell = 0; cell < n; cell += 37) {
    EXPECT_NEAR(rho[cell] / idealGasDensity(t[cell]), 1.0, 1e-6) << "cell " << cell;
  }
}

// (b) The packed lattice bed of CoredemFoamE2E.PackedBedPressureDropMatchesErgun (voidage
// 1 - pi/6, 0.3 m/s superficial, 293.15 K) with the variable-density gas: the pressure drop (p in
// Pa) is Ergun's with the thermo's density and viscosity of N2 at 293.15 K (ideal gas at pRef;
// Sutherland) plus the gas column's rho g H, within 5% (issue 6's tolerance). The DEM server gets
// the same rho and mu per cell (its drag is what the gas feels).
TEST_F(CoredemFoamVdE2E, PackedBedPressureDropMatchesErgunWithTheThermosProperties) {
  VdCase v;
  v.uIn = 0.3;
  v.body = R"(time: {end: 0.012, dt: 1.0e-3}
materials:
  - {name: glass, density: 2500.0, k_n: 100.0, e_n: 0.5, friction: 0.3}
particles:
  - {name: bed, material: glass, count: 1600, diameter: 1.0e-3, packing: lattice,
     region: {min: [0.0, 0.004, 0.0], max: [0.01, 0.020, 0.01]}}
)";
  const fs::path c = makeVdCase(dir, v);
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const auto& dp = ts["gas.pressure_drop_Pa"];
  ASSERT_EQ(dp.size(), 12u);
  EXPECT_LT(ts["dem.kinetic_energy_J"].back(), 1e-7);
  const double rhoG = idealGasDensity(293.15), muG = sutherland(293.15);
  const double eps = 1.0 - std::numbers::pi / 6.0, s = 1.0 - eps, d = 1.0e-3, u = v.uIn;
  const double ergun = 150.0 * s * s * muG * u / (eps * eps * eps * d * d) +
                       1.75 * s * rhoG * u * u / (eps * eps * eps * d);
  const double expected = ergun * 0.016 + rhoG * 9.81 * 0.04;
  const double measured = (dp[9] + dp[10] + dp[11]) / 3.0;
  std::cout << "packed bed (N2, rho " << rhoG << " kg/m3, mu " << muG << " Pa s): measured "
            << measured << " Pa, Ergun + gas column " << expected << " Pa ("
            << 100.0 * (measured / expected - 1.0) << " %)\n";
  EXPECT_NEAR(measured / expected, 1.0, 0.05);
  EXPECT_NEAR(dp[9] / dp[11], 1.0, 0.01);
}

// (c) Hot N2 (400 K) through the packed lattice bed at 293.15 K (CoredemFoamE2E's
// HotGasThroughFixedBedEnergyLedgerCloses with the variable-density gas). The DEM server
// integrates the exchange with the gas temperature of the start of the step, the gas takes it
// implicitly at the end; the difference H (T_new - T_start) dt of each step is given to the gas in
// the next one and reported meanwhile as gas.heat_in_flight_J. Then, cumulatively and to
// round-off, dem.heat_from_gas_J + gas.heat_from_particles_J = gas.heat_in_flight_J: checked at
// every step within 1e-9 of the heat exchanged so far plus 1e-12 of the final one (the first
// steps exchange ~1e-10 J: their residual, ~1e-19 J, is round-off of the final sums' size);
// observed ~1e-16 relative at the end.
TEST_F(CoredemFoamVdE2E, ParticleHeatReachesTheGasExactlyWithTheBookedSplit) {
  VdCase v;
  v.uIn = 0.3;
  v.tIn = 400.0;
  v.body = std::string("time: {end: 0.02, dt: 2.5e-4}\n") + kColdBed;
  const fs::path c = makeVdCase(dir, v);
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const auto& dem = ts["dem.heat_from_gas_J"];
  const auto& gas = ts["gas.heat_from_particles_J"];
  const auto& inFlight = ts["gas.heat_in_flight_J"];
  ASSERT_EQ(dem.size(), 80u);
  ASSERT_EQ(gas.size(), 80u);
  ASSERT_EQ(inFlight.size(), 80u);
  ASSERT_GT(dem.back(), 1e-3) << "the particles were not heated";
  double worst = 0;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    const double residual = dem[i] + gas[i] - inFlight[i];
    const double scale = std::max(std::abs(dem[i]), std::abs(gas[i]));
    worst = std::max(worst, std::abs(residual) / scale);
    EXPECT_LT(std::abs(residual), 1e-9 * scale + 1e-12 * dem.back()) << "step " << i + 1;
  }
  std::cout << "particles gained " << dem.back() << " J, the gas gave " << -gas.back()
            << " J, in flight " << inFlight.back() << " J; worst relative residual " << worst
            << "\n";
  // The booking matters: the step's split is not negligible.
  EXPECT_GT(std::abs(inFlight.back()), 1e-6 * dem.back());
}

// (c1) The split given to the particles (issue 38 item 2): N2 at 400 K at rest around a bed at
// 293.15 K filling the column above its floor, no gravity, motion frozen, Δt = 0.025 s: the
// exchange's λ = H Δt/(α ρ c_p) is ~10 (H = 6 (1 - ε) h/d with Nu = 2). Booking the split to the
// gas in the next step, as before protocol 1.5, made every bed cell follow (1+λ) e^{n+1} =
// (1+λ) e^n - λ e^{n-1}, an oscillation about the particles' temperature (|z| ≈ 0.95 per step);
// given to the particles, the gas cools monotonically (its enthalpy falls at every step; the
// particles, which took the exchange at the start temperature, give back the split of step 1 in
// step 2) and the heat balance closes to round-off.
TEST_F(CoredemFoamVdE2E, StiffExchangeCoolsTheGasMonotonically) {
  VdCase v;
  v.uIn = 0.0;
  v.tIn = 400.0;
  v.t0 = 400.0;
  v.gravity = 0.0;
  v.body = R"(time: {end: 0.5, dt: 0.025}
materials:
  - {name: glass, density: 2500.0, k_n: 10.0, e_n: 0.5, friction: 0.3, cp: 840.0}
particles:
  - {name: bed, material: glass, count: 3600, diameter: 1.0e-3, packing: lattice,
     temperature: 293.15, region: {min: [0.0, 0.004, 0.0], max: [0.01, 0.040, 0.01]}}
models: {motion: frozen, radiation: "off"}
)";
  const fs::path c = makeVdCase(dir, v);
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const auto& gas = ts["gas.enthalpy_J"];
  const auto& particles = ts["dem.thermal_energy_J"];
  const auto& residual = ts["balance.heat_residual_J"];
  const auto& conv = ts["dem.heat_from_gas_J"];
  ASSERT_EQ(gas.size(), 20u);
  ASSERT_EQ(particles.size(), 20u);
  ASSERT_GT(conv.back(), 1e-4) << "the particles were not heated";
  // Row 0 is after step 1: the particles' energy at the start is row 0's less what they got.
  EXPECT_GT(particles.back(), particles.front() - conv.front());
  for (std::size_t i = 1; i < gas.size(); ++i) {
    EXPECT_LT(gas[i], gas[i - 1]) << "the gas enthalpy rose at step " << i + 1;
  }
  for (std::size_t i = 0; i < residual.size(); ++i) {
    EXPECT_LT(std::abs(residual[i]), 1e-9 * std::abs(conv[i]) + 1e-18) << "row " << i;
  }
  std::cout << "stiff exchange: gas enthalpy " << gas.front() << " -> " << gas.back()
            << " J, particles gained " << conv.back() << " J, residual " << residual.back()
            << " J\n";
}

// (c2) A hot bed in cold gas, every heat path on: 1600 beads at 600 K (emissivity 0.9, radiation
// to the cell's environment) cooled by N2 entering at 300 K, 20 steps. The coupled energy ledger
// closes at every step:
//  * particles: their energy change is what they got by convection and radiation (adiabatic walls),
//    to 1e-10 of their energy;
//  * convection: what the particles lost is what the gas received, once the split booked for the
//    next step (gas.heat_in_flight_J) is counted: balance.heat_residual_J within 1e-9 of the heat
//    exchanged;
//  * radiation (protocol 1.3): what the particles radiated is what the gas received
//    (balance.radiation_residual_J) within 1e-12 of it;
//  * the gas's own ledger: its enthalpy change (sum V alpha rho h_s) is the enthalpy advected and
//    conducted in plus the heat received from the particles plus the enthalpy of its mass-balance
//    residual (gas.enthalpy_mass_residual_J), within 1e-6 of that heat (issue 38 item 3). The
//    temperature form with the cell's cp used before missed 6.6 % after the first step, 1-3 %
//    later (the cold gas entering the 600 K bed warms by ~300 K in one step while N2's cp grows
//    3 %), and this test allowed 10 %.
TEST_F(CoredemFoamVdE2E, HotBedInColdGasClosesTheCoupledEnergyLedger) {
  VdCase v;
  v.uIn = 0.3;
  v.tIn = 300.0;
  v.t0 = 300.0;
  v.body = R"(time: {end: 0.005, dt: 2.5e-4}
materials:
  - {name: glass, density: 2500.0, k_n: 10.0, e_n: 0.5, friction: 0.3, cp: 840.0,
     emissivity: 0.9}
particles:
  - {name: bed, material: glass, count: 1600, diameter: 1.0e-3, packing: lattice,
     temperature: 600.0, region: {min: [0.0, 0.004, 0.0], max: [0.01, 0.020, 0.01]}}
)";
  const fs::path c = makeVdCase(dir, v);
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const auto& energy = ts["dem.thermal_energy_J"];
  const auto& conv = ts["dem.heat_from_gas_J"];
  const auto& rad = ts["dem.heat_radiation_J"];
  const auto& wall = ts["dem.heat_wall_J"];
  const auto& heatResidual = ts["balance.heat_residual_J"];
  const auto& radResidual = ts["balance.radiation_residual_J"];
  const auto& gasContent = ts["gas.enthalpy_J"];
  const auto& gasInflow = ts["gas.enthalpy_inflow_J"];
  const auto& gasConv = ts["gas.heat_from_particles_J"];
  const auto& gasRad = ts["gas.heat_radiation_J"];
  const auto& gasHom = ts["gas.heat_homogeneous_J"];
  const auto& gasMassResidual = ts["gas.enthalpy_mass_residual_J"];
  ASSERT_EQ(gasMassResidual.size(), 20u);
  ASSERT_EQ(energy.size(), 20u);
  for (const auto* column : {&conv, &rad, &wall, &heatResidual, &radResidual, &gasContent,
                             &gasInflow, &gasConv, &gasRad, &gasHom}) {
    ASSERT_EQ(column->size(), 20u);
  }
  ASSERT_LT(conv.back(), -1e-3) << "the bed did not heat the gas";
  ASSERT_LT(rad.back(), -1e-6) << "the bed did not radiate";
  // The DEM's ledgers start at 0 with the particles' energy of step 0: recover it from row 0.
  const double energy0 = energy[0] - conv[0] - rad[0] - wall[0];
  double worstGas = 0;
  for (std::size_t i = 0; i < energy.size(); ++i) {
    EXPECT_NEAR(energy[i] - energy0, conv[i] + rad[i] + wall[i], 1e-10 * energy0) << "row " << i;
    EXPECT_EQ(wall[i], 0.0);
    EXPECT_LT(std::abs(heatResidual[i]), 1e-9 * std::abs(conv[i])) << "row " << i;
    EXPECT_LT(std::abs(radResidual[i]), 1e-12 * std::abs(rad[i]) + 1e-18) << "row " << i;
    if (i > 0) {
      const double received =
          (gasConv[i] - gasConv[0]) + (gasRad[i] - gasRad[0]) + (gasHom[i] - gasHom[0]);
      const double gasResidual = (gasContent[i] - gasContent[0]) - (gasInflow[i] - gasInflow[0]) -
                                 received - (gasMassResidual[i] - gasMassResidual[0]);
      worstGas = std::max(worstGas, std::abs(gasResidual) / std::abs(received));
      EXPECT_LT(std::abs(gasResidual), 1e-6 * std::abs(received)) << "row " << i;
    }
  }
  std::cout << "hot bed in cold gas: particles gave the gas " << -conv.back() << " J by "
            << "convection and " << -rad.back() << " J by radiation; residuals: convection "
            << heatResidual.back() << " J, radiation " << radResidual.back()
            << " J; gas enthalpy ledger worst " << worstGas << " of the heat received\n";
}

/// A non-uniform version of the uniform internalField of an ascii field file of `n` cells, with
/// `value` in cell `cell` (pre-flight reads uniform values only: these reach coredemFoam).
std::string withOneCell(const std::string& file, const std::string& uniform, std::size_t n,
                        std::size_t cell, const std::string& value) {
  std::string list = "internalField   nonuniform List<scalar> " + std::to_string(n) + "(";
  for (std::size_t c = 0; c < n; ++c) {
    list += (c ? " " : "") + (c == cell ? value : uniform);
  }
  return replaceAll(file, "internalField   uniform " + uniform + ";", list + ");");
}

// (d) Impossible start states are refused before the first step, with nothing of a step written:
// uniform values in the case's 0/ by `coredem`'s pre-flight (exit 2, naming the file and the
// value), a single bad cell of a non-uniform field by coredemFoam (naming the cell, the field and
// the value), and a kinematic pressure (m2/s2, here not a zero gauge) where the variable-density
// gas needs Pa, by the pre-flight.
TEST_F(CoredemFoamVdE2E, ImpossibleGasStatesAreRefusedNamingTheCell) {
  constexpr std::size_t n = 500;
  struct Bad {
    const char* name;
    const char* file;
    std::function<std::string(const std::string&)> edit;
    bool preflight; // refused by coredem before any participant starts
    const char* expect;
  };
  const std::vector<Bad> cases = {
      {"negative T", "0/T",
       [](const std::string& f) {
         return replaceAll(f, "internalField   uniform 293.15;", "internalField   uniform -10;");
       },
       true, "T = -10 K: the gas temperature must be > 0 K"},
      {"Y above 1", "0/N2",
       [](const std::string& f) {
         return replaceAll(f, "internalField   uniform 1;", "internalField   uniform 1.5;");
       },
       true, "mass fraction N2 = 1.5: must lie in [0, 1]"},
      {"negative T in a cell", "0/T",
       [](const std::string& f) { return withOneCell(f, "293.15", n, 7, "-10"); }, false,
       "gas temperature T = -10 K in cell 7"},
      {"Y above 1 in a cell", "0/N2",
       [](const std::string& f) { return withOneCell(f, "1", n, 3, "1.5"); }, false,
       "mass fraction N2 = 1.5 in cell 3"},
      {"kinematic p", "0/p",
       [](const std::string& f) { return replaceAll(f, "[1 -1 -2 0 0 0 0]", "[0 2 -2 0 0 0 0]"); },
       true, "is the constant model's kinematic pressure"},
  };
  for (const Bad& b : cases) {
    const fs::path sub = dir / std::regex_replace(b.name, std::regex(" "), "-");
    VdCase v;
    v.body = std::string("time: {end: 0.002, dt: 1.0e-3}\n") + kEmptyColumn;
    const fs::path c = makeVdCase(sub, v);
    const fs::path f = c / "openfoam" / b.file;
    const std::string before = readAll(f);
    writeAll(f, b.edit(before));
    ASSERT_NE(readAll(f), before) << b.name << ": the test did not change " << f;
    const fs::path run = sub / "run";
    const int rc = runCoredem({"run", c.string(), "--out", run.string()}, sub / "coredem.log");
    if (b.preflight) {
      EXPECT_EQ(rc, 2) << b.name << ": not refused by the pre-flight";
      const std::string log = readAll(sub / "coredem.log");
      EXPECT_NE(log.find(b.expect), std::string::npos)
          << b.name << ": coredem does not say '" << b.expect << "':\n"
          << log;
      EXPECT_FALSE(fs::exists(run / "logs" / "cfd.log")) << b.name << ": coredemFoam started";
    } else {
      EXPECT_NE(rc, 0) << b.name << " was accepted";
      const std::string log = readAll(run / "logs" / "cfd.log");
      EXPECT_NE(log.find(b.expect), std::string::npos)
          << b.name << ": cfd.log does not say '" << b.expect << "':\n"
          << logTail(run);
    }
    EXPECT_FALSE(fs::exists(run / "openfoam" / "0.001")) << b.name << ": a step was written";
  }
}

// (e) 12 steps, stop, `coredem resume`, 12 more of the hot bed of (c) give the same checkpoint
// files (U, p, T, phi, alphac, N2 and the booked split QsplitJ) and ledgers as 24 straight steps,
// bit for bit: rho, mu, kappa, cp are recomputed from the restored T and Y.
TEST_F(CoredemFoamVdE2E, RestartContinuesBitwise) {
  VdCase v;
  v.uIn = 0.3;
  v.tIn = 400.0;
  v.body = std::string("time: {end: 0.006, dt: 2.5e-4}\ncheckpoint: {every_steps: 12, keep: 3}\n") +
           kColdBed;
  const fs::path c = makeVdCase(dir, v);
  const auto [a, b] = runStraightAndResumed(dir, c, 12);
  ASSERT_FALSE(HasFailure());
  const fs::path ca = a / "checkpoints" / "00000024", cb = b / "checkpoints" / "00000024";
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(ca / "openfoam")) {
    if (e.is_regular_file()) {
      files.push_back(fs::relative(e.path(), ca));
    }
  }
  std::vector<std::string> names;
  for (const auto& f : files) {
    names.push_back(f.filename().string());
    EXPECT_TRUE(readAll(ca / f) == readAll(cb / f)) << f << " differs after the restart";
  }
  for (const char* needed : {"U", "p", "T", "phi", "alphac", "N2", "QsplitJ"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), needed), names.end())
        << "the checkpoint has no " << needed;
  }
  auto ta = readTimeseries(a), tb = readTimeseries(b);
  for (const char* column : {"gas.pressure_drop_Pa", "gas.heat_from_particles_J",
                             "gas.heat_in_flight_J", "gas.enthalpy_J", "dem.heat_from_gas_J"}) {
    ASSERT_EQ(ta[column].size(), 24u) << column;
    ASSERT_EQ(tb[column].size(), 24u) << column;
    for (std::size_t i = 0; i < 24; ++i) {
      EXPECT_EQ(ta[column][i], tb[column][i]) << column << ", step " << i + 1;
    }
  }
}

// Without thermophysicalProperties coredemFoam is the constant-property solver it was: the hot
// packed bed of CoredemFoamE2E.HotGasThroughFixedBedEnergyLedgerCloses over 20 steps of 0.25 ms
// gives the figures the solver gave before the variable-density gas was added (commit 8ba9c52,
// same machine image; they agreed bit for bit with the binary of that commit on this case and on
// a fluidized hot bed). Tolerance 1e-9 relative: any change of the constant-property model shows,
// a change of the summation order does not. A deliberate change of the model (or of the DEM's
// drag and heat closures) updates these figures. Why a snapshot: it is the one check that the
// constant-property path is untouched by the variable-density code, which no physical bound can
// say at 1e-9. The physics of this deck is checked against independent references by
// coredemfoam_e2e_test.cpp: HotGasThroughFixedBedEnergyLedgerCloses runs the same hot bed (gas
// ledger to 1e-6, particle vs gas heat to 1 %), PackedBedPressureDropMatchesErgun the pressure
// drop of a packed bed; a snapshot update that breaks the physics fails there.
TEST_F(CoredemFoamVdE2E, ConstantPropertySolverGivesTheFiguresItGaveBefore) {
  const fs::path c = dir / "case";
  fs::create_directories(c);
  copyColumnTemplate(kTemplate, c / "openfoam", 0.3, 400.0);
  writeAll(c / "case.yaml", R"(name: column
grid: {origin: [0, 0, 0], spacing: [0.002, 0.002, 0.002], cells: [5, 20, 5]}
gravity: [0.0, -9.81, 0.0]
gas_properties: {density: 1.204, viscosity: 1.81e-5, conductivity: 0.0257, cp: 1006.0,
                 temperature: 293.15, pressure: 101325.0}
walls:
  box: {min: [0.0, 0.0, 0.0], max: [0.01, 0.04, 0.01]}
  planes: [{point: [0.0, 0.004, 0.0], normal: [0.0, 1.0, 0.0]}]
cfd: {participant: coredemFoam, case: openfoam, timeout_s: 120}
dem: {backend: cpu, threads: 1, timeout_s: 120}
time: {end: 0.005, dt: 2.5e-4}
)" + std::string(kColdBed));
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  EXPECT_EQ(readAll(run / "logs" / "cfd.log").find("ideal-gas"), std::string::npos);
  auto ts = readTimeseries(run);
  const std::vector<std::pair<const char*, double>> before = {
      {"gas.pressure_drop_Pa", 50.16086554920648},
      {"gas.enthalpy_J", 1.1429164220228751},
      {"gas.heat_from_particles_J", -0.00020160079719371544},
      {"gas.enthalpy_inflow_J", 0.02029977280815462},
      {"dem.heat_from_gas_J", 0.00016928288188170783},
  };
  for (const auto& [column, value] : before) {
    ASSERT_EQ(ts[column].size(), 20u) << column;
    EXPECT_NEAR(ts[column].back(), value, 1e-9 * std::abs(value)) << column;
  }
  EXPECT_EQ(ts.count("gas.heat_in_flight_J"), 0u) << "the constant-property path reports the "
                                                     "variable-density gas's ledgers";
}

// (f) Char gasification in a nearly closed column: 500 frozen char beads (0.48 mm, pure C,
// 1173 K) in H2O/N2 1:1 (molar) at 1173 K entering at 0.1 m/s, C + H2O -> CO + H2 only (R1 of the
// DEM's chemistry; carrier reduction and shift off, no reaction heat, no particle heat exchange:
// the gas stays at 1173 K). Each mol of gas produced either leaves the column or stays in it:
// over steps 2..20 the molar outflow minus inflow (gas.outflow/inflow.<k>_kg_per_s / M_k) plus the
// change of the moles in the gas (gas.mass.<k>_kg / M_k: the gas at its local absolute pressure,
// the char's shrinking volume filled) equals the moles produced (gas.species.<k>_kg / M_k), within
// 1e-6 of the moles produced (observed ~1e-7 with 3 PIMPLE outer correctors; with one the species
// are solved with the last iteration's mass flux and the balance is off by ~1e-3). With
// p_abs = p_ref the moles in the gas would change by p_ref dV_solid/(R T) only; the pressure drop
// of the growing flow adds to it (both printed).
// The case's five gas species are the thermo's (coredem writes the dictionary from case.yaml; the
// NASA-7 coefficients are the DEM's table).
TEST_F(CoredemFoamVdE2E, CharGasificationBalancesEveryMolProducedWithTheGasLeavingOrStored) {
  VdCase v;
  v.uIn = 0.1;
  v.tIn = 1173.0;
  v.t0 = 1173.0;
  v.gravity = 0.0;
  v.species = R"(species:
  - {name: CO, molar_mass: 0.028010}
  - {name: CO2, molar_mass: 0.044009}
  - {name: H2, molar_mass: 0.002016}
  - {name: H2O, molar_mass: 0.018015}
  - {name: N2, molar_mass: 0.028014}
)";
  v.body = R"(solid_species:
  - {name: C, molar_mass: 0.012011}
time: {end: 0.02, dt: 1.0e-3, dt_dem: 1.0e-3}
materials:
  - {name: char, density: 1540.0, k_n: 100.0, e_n: 0.9, friction: 0.3, cp: 1300.0}
particles:
  - {name: char, material: char, count: 500, diameter: 4.8e-4, temperature: 1173.0,
     composition: {C: 1.0}, packing: lattice,
     region: {min: [0.0, 0.01, 0.0], max: [0.01, 0.02, 0.01]}}
chemistry:
  clg: {char_gasification: "on", oc_reduction: "off", wgs: "off"}
  reaction_heat: "off"
models: {heat: "off", motion: frozen, radiation: "off"}
)";
  const fs::path c = makeVdCase(dir, v);
  const fs::path of = c / "openfoam";
  const std::vector<std::pair<std::string, double>> molarMass = {
      {"CO", 0.028010}, {"CO2", 0.044009}, {"H2", 0.002016}, {"H2O", 0.018015}, {"N2", 0.028014}};
  // H2O/N2 1:1 molar as mass fractions (they sum to 1 within 1e-16).
  const double yH2O = 0.018015 / (0.018015 + 0.028014);
  for (const auto& [name, m] : molarMass) {
    const double y = name == "H2O" ? yH2O : name == "N2" ? 1.0 - yH2O : 0.0;
    std::ostringstream value;
    value.precision(17);
    value << "uniform " << y;
    writeAll(of / "0" / name, foamHeader("volScalarField", "0", name) +
                                  "dimensions [0 0 0 0 0 0 0];\ninternalField " + value.str() +
                                  ";\nboundaryField\n{\n    inlet  { type fixedValue; value " +
                                  value.str() + "; }\n    outlet { type inletOutlet; inletValue " +
                                  value.str() + "; value " + value.str() +
                                  "; }\n    walls  { type zeroGradient; }\n}\n");
  }
  std::string sol = readAll(of / "system" / "fvSolution");
  sol = std::regex_replace(sol, std::regex(R"(nOuterCorrectors\s+\d+;)"), "nOuterCorrectors 3;");
  writeAll(of / "system" / "fvSolution", sol);

  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const double t = 1173.0, r = kRR / 1000.0;
  const auto& dt = ts["dt"];
  ASSERT_EQ(dt.size(), 20u);
  double netOut = 0, produced = 0, stored = 0;
  for (std::size_t i = 1; i < dt.size(); ++i) {
    double out = 0;
    for (const auto& [name, m] : molarMass) {
      out +=
          (ts["gas.outflow." + name + "_kg_per_s"][i] - ts["gas.inflow." + name + "_kg_per_s"][i]) /
          m;
      produced +=
          (ts["gas.species." + name + "_kg"][i] - ts["gas.species." + name + "_kg"][i - 1]) / m;
      stored += (ts["gas.mass." + name + "_kg"][i] - ts["gas.mass." + name + "_kg"][i - 1]) / m;
    }
    netOut += dt[i] * out;
  }
  const auto& vs = ts["gas.solid_volume_m3"];
  const double intoVoid = kPRef * (vs.back() - vs.front()) / (r * t); // < 0: the char shrank
  std::cout << "char gasification: " << produced << " mol of gas produced, " << netOut
            << " mol left (net), " << stored << " mol more in the gas (" << -intoVoid
            << " mol at p_ref into the char's lost volume); balance "
            << (netOut + stored - produced) / produced << " relative\n";
  ASSERT_GT(produced, 1e-8) << "no gas was produced";
  EXPECT_NEAR(netOut + stored, produced, 1e-6 * produced);
  // C + H2O -> CO + H2: as many mol of CO as of H2, one H2O consumed per CO.
  const double co = ts["gas.species.CO_kg"].back() / 0.028010;
  const double h2 = ts["gas.species.H2_kg"].back() / 0.002016;
  const double h2o = ts["gas.species.H2O_kg"].back() / 0.018015;
  EXPECT_NEAR(h2 / co, 1.0, 1e-6);
  EXPECT_NEAR(-h2o / co, 1.0, 1e-6);
  // Species: what the particles released is what the gas received, per species (1e-10 of the
  // largest); elements: the carbon the char lost is the carbon of the CO and CO2 produced, and
  // the O and H of the gas are conserved (the H2O consumed gives the O of CO and the H of H2),
  // each within 1e-10 of the moles produced.
  double largest = 0;
  for (const auto& [name, m] : molarMass) {
    largest = std::max(largest, std::abs(ts["gas.species." + name + "_kg"].back()));
  }
  for (const auto& [name, m] : molarMass) {
    EXPECT_NEAR(ts["dem.species_to_gas." + name + "_kg"].back(),
                ts["gas.species." + name + "_kg"].back(), 1e-10 * largest)
        << name;
  }
  const double co2 = ts["gas.species.CO2_kg"].back() / 0.044009;
  const auto& solid = ts["dem.particle_mass_kg"];
  // Row 0 is after step 1: the carbon lost since then against the gas produced since then.
  const double carbonLost = (solid.front() - solid.back()) / 0.012011;
  const double carbonGas =
      co + co2 -
      (ts["gas.species.CO_kg"].front() / 0.028010 + ts["gas.species.CO2_kg"].front() / 0.044009);
  // The carbon lost is a difference of particle-mass sums whose 500 terms are each rounded at
  // every sub-step: 100 ulps of the solid mass on top (measured 30).
  const double massUlps = 100.0 * std::numeric_limits<double>::epsilon() * solid.front() / 0.012011;
  EXPECT_NEAR(carbonGas, carbonLost, 1e-10 * co + massUlps) << "carbon";
  EXPECT_NEAR(co + 2.0 * co2 + h2o, 0.0, 1e-10 * co) << "oxygen";
  EXPECT_NEAR(2.0 * h2 + 2.0 * h2o, 0.0, 1e-10 * co) << "hydrogen";
}

// (h) A tall column at rest: the column of (a) scaled 250x (10 m of N2 at 293.15 K in 5 x 20 x 5
// cells of 0.5 m, closed at the bottom, the outlet at p_ref on top, one frozen bead), gravity
// 9.81 m/s2, 3 s. The gas settles into the isothermal atmosphere: the density follows the local
// absolute pressure, rho(y) = rho_top exp(g (H - y) M/(R T)), 1.13e-3 higher at the bottom than at
// the top (issue 38 item 4: with rho = psi p_ref everywhere it was uniform). Checked per cell row
// within 2e-7 of rho (the discrete hydrostatic balance and the outlet's half cell: observed ~4e-8),
// the gas at rest (|u| < 1e-6 m/s), and p - p_ref = the weight of the gas above over the area
// (1e-4).
TEST_F(CoredemFoamVdE2E, TallColumnAtRestHasTheDensityOfItsHydrostaticPressure) {
  VdCase v;
  v.uIn = 0.0;
  v.body = std::string("time: {end: 3.0, dt: 0.02, dt_dem: 0.02}\n") + kEmptyColumn;
  const fs::path c = makeVdCase(dir, v);
  const fs::path of = c / "openfoam";
  std::string mesh = readAll(of / "system" / "blockMeshDict");
  mesh = std::regex_replace(mesh, std::regex(R"(scale\s+1;)"), "scale 250;");
  writeAll(of / "system" / "blockMeshDict", mesh);
  std::string yaml = readAll(c / "case.yaml");
  yaml = replaceAll(yaml, "spacing: [0.002, 0.002, 0.002]", "spacing: [0.5, 0.5, 0.5]");
  yaml = replaceAll(yaml, "max: [0.01, 0.04, 0.01]", "max: [2.5, 10.0, 2.5]");
  yaml = replaceAll(yaml, "point: [0.0, 0.004, 0.0]", "point: [0.0, 1.0, 0.0]");
  yaml = replaceAll(yaml, "min: [0.0, 0.0042, 0.0], max: [0.0004, 0.0046, 0.0004]",
                    "min: [0.0, 1.05, 0.0], max: [0.1, 1.15, 0.1]");
  writeAll(c / "case.yaml", yaml);
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  const fs::path last = run / "openfoam" / "3";
  ASSERT_TRUE(fs::exists(last / "rho")) << "no fields written at t = 3 s";
  constexpr std::size_t nx = 5, ny = 20, nz = 5, n = nx * ny * nz;
  const auto u = readCellValues(last / "U", 3, n);
  const auto p = readCellValues(last / "p", 1, n);
  const auto rho = readCellValues(last / "rho", 1, n);
  ASSERT_EQ(rho.size(), n);
  ASSERT_EQ(p.size(), n);
  ASSERT_EQ(u.size(), 3 * n);
  const double h = 10.0, dy = 0.5, g = 9.81, k = g * kMolarMass / (kRR * 293.15); // 1/m
  const double rhoTop = idealGasDensity(293.15);
  double worst = 0, uMax = 0;
  for (std::size_t cell = 0; cell < n; ++cell) {
    const double y = (static_cast<double>((cell / nx) % ny) + 0.5) * dy;
    const double expected = rhoTop * std::exp(k * (h - y));
    worst = std::max(worst, std::abs(rho[cell] / expected - 1.0));
    for (int a = 0; a < 3; ++a) {
      uMax = std::max(uMax, std::abs(u[3 * cell + a]));
    }
    // The state equation at the cell's own absolute pressure (p is absolute here: the outlet is
    // at 101325 = p_ref), within 1e-7: observed 1.1e-8 in every cell alike, the thermo's
    // constants against the test's.
    EXPECT_NEAR(rho[cell] / (p[cell] * kMolarMass / (kRR * 293.15)), 1.0, 1e-7) << "cell " << cell;
  }
  const double bottom = rho[0], top = rho[(ny - 1) * nx];
  // The weight of the gas column above the bottom cell's centre, per area.
  const double weight = rhoTop / k * (std::exp(k * (h - 0.5 * dy)) - 1.0) * g;
  std::cout << "tall column: rho bottom/top " << bottom / top << " (exp(k dy (ny-1)) "
            << std::exp(k * dy * (ny - 1)) << "), worst relative error " << worst << ", |u| max "
            << uMax << " m/s, p bottom - p_ref " << p[0] - kPRef << " Pa (weight " << weight
            << " Pa)\n";
  EXPECT_LT(worst, 2e-7);
  EXPECT_NEAR(bottom / top, std::exp(k * dy * (ny - 1)), 2e-7);
  EXPECT_LT(uMax, 1e-6) << "the gas has not settled";
  EXPECT_NEAR(p[0] - kPRef, weight, 1e-4 * weight);
}

// (g) Decomposed: the hot bed of (c) on 1 and 2 ranks, 8 steps. The pressure drop, the gas
// ledgers (heat from the particles, heat in flight, enthalpy, inflow) and the DEM's heat agree
// within 1e-4 of each column's largest magnitude, 5e-4 for the heat exchanged (not bitwise: the
// decomposed solves stop at their relative tolerances at other iterates, as for the
// constant-property gas). The heat columns rest on the split H (T_x - T_start), a difference of
// two close temperatures that the decomposed enthalpy solve perturbs most: measured 1.4e-4
// (heat from the particles), 2.4e-4 (in flight) at step 8, with the heat balance of each run
// closed to round-off (balance.heat_residual_J < 1e-18 J).
TEST_F(CoredemFoamVdE2E, HotBedOnTwoRanksAgreesWithOneRank) {
  std::map<int, std::map<std::string, std::vector<double>>> series;
  for (int ranks : {1, 2}) {
    VdCase v;
    v.uIn = 0.3;
    v.tIn = 400.0;
    v.body = std::string("time: {end: 0.002, dt: 2.5e-4}\n") + kColdBed;
    const fs::path d = dir / ("ranks" + std::to_string(ranks));
    series[ranks] = runOnRanks(d, makeVdCase(d, v), ranks);
    ASSERT_FALSE(HasFailure()) << ranks << " ranks";
  }
  for (const char* key :
       {"gas.pressure_drop_Pa", "gas.heat_from_particles_J", "gas.heat_in_flight_J",
        "gas.enthalpy_J", "gas.enthalpy_inflow_J", "dem.heat_from_gas_J"}) {
    const auto& one = series[1][key];
    const auto& two = series[2][key];
    ASSERT_EQ(one.size(), 8u) << key;
    ASSERT_EQ(two.size(), 8u) << key;
    double scale = 0;
    for (double x : one) {
      scale = std::max(scale, std::abs(x));
    }
    ASSERT_GT(scale, 0.0) << key;
    const double bound = std::string(key).find("heat") != std::string::npos ? 5e-4 : 1e-4;
    for (std::size_t i = 0; i < 8; ++i) {
      EXPECT_LE(std::abs(one[i] - two[i]), bound * scale) << key << ", step " << i + 1;
    }
  }
}

} // namespace
