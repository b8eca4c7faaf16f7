// End-to-end: the momentum of the mass the particles release (protocol 1.5 mom_p) reaches
// coredemFoam's gas (constant-property path, UEqn.H), run by `coredem` with the real DEM server
// in the column of tests/e2e/openfoam/cases/column: 8 burning steel beads (B(s) -> N2(g) at a
// constant rate) move at 5 cm/s through N2 at rest, without gravity. Checked at every step:
//   - the gas books the released momentum the DEM booked (gas.momentum_released_x_Ns =
//     dem.momentum_released_x_Ns to 1e-10), and it is inside gas.momentum_from_particles_x_Ns;
//   - it is ∫ ṁ u_p dt: over steps 2..n, Σ_n (M_{n-1} − M_n) (u_{n-1} + u_n)/2 from the DEM's
//     particle mass and kinetic energy (u = √(2 KE/M), the beads move together), within 1e-3.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem_e2e.h"
#include "foam_e2e.h"

namespace fs = std::filesystem;

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

constexpr double kUp = 0.05; // m/s, the beads' initial velocity along x

/// The column with the gas at rest (inlet velocity 0), no gravity, the species N2 (Y = 1).
fs::path makeCase(const fs::path& dir, const std::string& body) {
  const fs::path c = dir / "case";
  const fs::path of = c / "openfoam";
  fs::create_directories(c);
  copyColumnTemplate(kTemplate, of, 0.0, 293.15);
  writeAll(of / "constant" / "g",
           replaceAll(readAll(of / "constant" / "g"), "(0 -9.81 0)", "(0 0 0)"));
  writeAll(of / "0" / "N2", R"(FoamFile
{
    version     2.0;
    format      ascii;
    class       volScalarField;
    location    "0";
    object      N2;
}
dimensions      [0 0 0 0 0 0 0];
internalField   uniform 1;
boundaryField
{
    inlet   { type fixedValue; value uniform 1; }
    outlet  { type inletOutlet; inletValue uniform 1; value uniform 1; }
    walls   { type zeroGradient; }
}
)");
  writeAll(c / "case.yaml", std::string(R"(name: column-burning
grid: {origin: [0, 0, 0], spacing: [0.002, 0.002, 0.002], cells: [5, 20, 5]}
gravity: [0.0, 0.0, 0.0]
gas_properties: {model: constant, density: 1.204, viscosity: 1.81e-5, conductivity: 0.0257, cp: 1006.0,
                 temperature: 293.15, pressure: 101325.0}
species: [{name: N2, molar_mass: 0.028}]
walls:
  box: {min: [0.0, 0.0, 0.0], max: [0.01, 0.04, 0.01]}
cfd: {participant: coredemFoam, case: openfoam, timeout_s: 120}
dem: {backend: cpu, threads: 1, timeout_s: 120}
)") + body);
  return c;
}

class CoredemFoamMomentumE2E : public coredem::e2e::RunFolderTest {
protected:
  CoredemFoamMomentumE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredemFoam"}, "coredemfoam-momentum-e2e") {
  }
};

} // namespace

TEST_F(CoredemFoamMomentumE2E, ReleasedMassBringsTheParticleMomentumToTheGas) {
  // 2 mm steel beads (33.5 mg, half of it B) 3 mm apart; ω = 4.5e-5 mol/s releases 1.26 mg/s of
  // N2 per bead (0.2 % of B over the run). The gas of their cells (~10⁴ times lighter) is soon
  // carried along: the beads keep ~99.9 % of their speed over the 20 ms.
  const fs::path c =
      makeCase(dir, R"(solid_species: [{name: B, molar_mass: 0.028}, {name: I, molar_mass: 0.020}]
reactions:
  - {name: burn, terms: [{species: B, nu: -1}, {species: N2, nu: 1}],
     rate: {law: constant, A: 4.5e-5}}
time: {end: 0.02, dt: 1.0e-3}
materials:
  - {name: steel, density: 8000.0, k_n: 100.0, e_n: 0.9, friction: 0.3, cp: 500.0}
particles:
  - {name: beads, material: steel, diameter: 2.0e-3, composition: {B: 0.5, I: 0.5},
     velocity: [0.05, 0.0, 0.0],
     positions: [[0.0035, 0.010, 0.0035], [0.0065, 0.010, 0.0035], [0.0035, 0.013, 0.0035],
                 [0.0065, 0.013, 0.0035], [0.0035, 0.010, 0.0065], [0.0065, 0.010, 0.0065],
                 [0.0035, 0.013, 0.0065], [0.0065, 0.013, 0.0065]]}
models: {heat: "off"}
)");
  const fs::path run = dir / "run";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const auto& gasReleased = ts["gas.momentum_released_x_Ns"];
  const auto& demReleased = ts["dem.momentum_released_x_Ns"];
  const auto& fromParticles = ts["gas.momentum_from_particles_x_Ns"];
  const auto& mass = ts["dem.particle_mass_kg"];
  const auto& kinetic = ts["dem.kinetic_energy_J"];
  ASSERT_EQ(gasReleased.size(), 20u) << "no gas.momentum_released_x_Ns column";
  ASSERT_EQ(demReleased.size(), 20u) << "no dem.momentum_released_x_Ns column";
  ASSERT_EQ(mass.size(), 20u);
  const double total = demReleased.back();
  ASSERT_GT(total, 0.0);
  for (std::size_t i = 0; i < gasReleased.size(); ++i) {
    EXPECT_NEAR(gasReleased[i], demReleased[i], 1e-10 * total) << "step " << i + 1;
    // The drag impulse (what remains) pushes the gas along x too: the beads are faster.
    EXPECT_GT(fromParticles[i] - gasReleased[i], 0.0) << "step " << i + 1;
  }
  double expected = 0.0;
  for (std::size_t i = 1; i < mass.size(); ++i) {
    const double u0 = std::sqrt(2.0 * kinetic[i - 1] / mass[i - 1]);
    const double u1 = std::sqrt(2.0 * kinetic[i] / mass[i]);
    expected += (mass[i - 1] - mass[i]) * 0.5 * (u0 + u1);
  }
  const double got = demReleased.back() - demReleased.front();
  std::cout << "released momentum " << got << " N s, integral of mdot u_p " << expected << " N s ("
            << (got - expected) / expected << " relative); beads from "
            << std::sqrt(2.0 * kinetic.front() / mass.front()) << " to "
            << std::sqrt(2.0 * kinetic.back() / mass.back()) << " m/s (started at " << kUp << ")\n";
  EXPECT_NEAR(got, expected, 1e-3 * expected);
  for (const char* axis : {"y", "z"}) {
    EXPECT_LE(std::abs(ts[std::string("gas.momentum_released_") + axis + "_Ns"].back()),
              1e-3 * total)
        << axis;
  }
}
