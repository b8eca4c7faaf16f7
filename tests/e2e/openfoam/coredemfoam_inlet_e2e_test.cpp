// End-to-end tests of case.yaml's inlets and outlets (docs/case-schema.md "Inlets and outlets")
// with coredemFoam, the real DEM server and the orchestrator, in the 1 x 4 x 1 cm column of the
// coredemFoam e2e tests (tests/e2e/openfoam/cases/column): the OpenFOAM case's own inlet is
// overridden by case.yaml's, the inflow is the superficial velocity whether or not particles fill
// the inlet cells (Ergun's pressure drop), and a fluidization curve is one campaign sweeping the
// inlet velocity by key.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/model_list.h"
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

// Air at 20 °C and the 1 mm glass beads of the column tests.
constexpr double kRhoG = 1.204, kMuG = 1.81e-5, kG = 9.81, kDp = 1.0e-3, kHeight = 0.04;

/// Ergun's pressure gradient (Pa/m) of a packed bed: voidage eps, superficial velocity u.
double ergunGradient(double eps, double u) {
  const double s = 1.0 - eps;
  return 150.0 * s * s * kMuG * u / (eps * eps * eps * kDp * kDp) +
         1.75 * s * kRhoG * u * u / (eps * eps * eps * kDp);
}

/// The column with its template inlet at 5 m/s (what case.yaml's inlet must override) and a
/// simple-cubic lattice of 1600 beads 16 mm high from `bedBottom` (voidage 1 - pi/6 in every bed
/// cell); with `plate` a DEM distributor plane at 4 mm keeps the beads off the inlet cells.
fs::path makeCase(const fs::path& dir, double u, double bedBottom, bool plate) {
  const fs::path c = dir / "case";
  fs::create_directories(c);
  copyColumnTemplate(kTemplate, c / "openfoam", 5.0, 293.15);
  std::string text = R"(name: column
time: {end: 0.012, dt: 1.0e-3}
grid: {origin: [0, 0, 0], spacing: [0.002, 0.002, 0.002], cells: [5, 20, 5]}
gravity: [0.0, -9.81, 0.0]
gas_properties: {density: 1.204, viscosity: 1.81e-5, conductivity: 0.0257, cp: 1006.0,
                 temperature: 293.15, pressure: 101325.0}
materials:
  - {name: glass, density: 2500.0, k_n: 100.0, e_n: 0.5, friction: 0.3}
particles:
  - {name: bed, material: glass, count: 1600, diameter: 1.0e-3, packing: lattice,
     region: {min: [0.0, @BOTTOM@, 0.0], max: [0.01, @TOP@, 0.01]}}
walls:
  box: {min: [0.0, 0.0, 0.0], max: [0.01, 0.04, 0.01]}
@PLATE@cfd: {participant: coredemFoam, case: openfoam, timeout_s: 120}
dem: {backend: cpu, threads: 1, timeout_s: 120}
inlets:
  - patch: inlet
    superficial_velocity: [0.0, @U@, 0.0]
outlets:
  - patch: outlet
)";
  const auto num = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  text = replaceAll(text, "@BOTTOM@", num(bedBottom));
  text = replaceAll(text, "@TOP@", num(bedBottom + 0.016));
  text = replaceAll(text, "@U@", num(u));
  text =
      replaceAll(text, "@PLATE@",
                 plate ? "  planes: [{point: [0.0, 0.004, 0.0], normal: [0.0, 1.0, 0.0]}]\n" : "");
  writeAll(c / "case.yaml", text);
  return c;
}

/// Mean of the last three pressure drops of a run (the packed bed is steady within 5 steps).
double lastPressureDrop(const fs::path& run) {
  auto ts = readTimeseries(run);
  const auto& dp = ts["gas.pressure_drop_Pa"];
  EXPECT_GE(dp.size(), 12u);
  return dp.size() < 3 ? 0.0 : (dp[dp.size() - 1] + dp[dp.size() - 2] + dp[dp.size() - 3]) / 3.0;
}

/// `coredem ARGS...` (check, campaign) with output into `log`; its exit code.
int runCli(const std::vector<std::string>& args, const fs::path& log,
           std::chrono::seconds timeout = 60s) {
  return coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem", args, log), timeout);
}

class CoredemFoamInletE2E : public coredem::e2e::RunFolderTest {
protected:
  CoredemFoamInletE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredemFoam"}, "coredemfoam-inlet-e2e") {}
};

} // namespace

// The same packed bed (0.3 m/s superficial, well below minimum fluidization) twice: on the
// distributor plate (inlet cells free) and from the floor (the inlet cells packed, gas fraction
// 1 - pi/6 at the inlet face). case.yaml's inlet replaces the template's 5 m/s in the run's copy
// only, and in both runs the pressure drop is Ergun's at 0.3 m/s over the bed above the first
// cell centre plus the gas column, within 5 % as the coredemFoam Ergun test (measured -0.7 % and
// -0.8 %): the inflow is the superficial velocity. A fixedValue of 0.3 m/s at the face (the
// interstitial velocity) lets in only eps x 0.3 m/s through the packed inlet cells: the floor
// run then measured 18.4 Pa, -59 %.
TEST_F(CoredemFoamInletE2E, InletFromTheCaseFileIsTheSuperficialVelocityWithParticlesAtTheInlet) {
  const double u = 0.3, eps = 1.0 - std::numbers::pi / 6.0;
  for (const bool plate : {true, false}) {
    // The inlet face's pressure is its cell's (fixedFluxPressure under a fixed inflow has no
    // normal gradient), so the drop is measured from the first cell's centre: with the bed on the
    // floor the half cell below it (1 mm of the 16 mm bed) is not in it.
    const double bed = plate ? 0.016 : 0.015;
    const double expected = ergunGradient(eps, u) * bed + kRhoG * kG * kHeight;
    const fs::path sub = dir / (plate ? "plate" : "floor");
    const fs::path c = makeCase(sub, u, plate ? 0.004 : 0.0, plate);
    const fs::path run = sub / "run";
    ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, sub / "coredem.log"), 0)
        << readAll(sub / "coredem.log") << logTail(run);
    const std::string written = readAll(run / "openfoam" / "0" / "U");
    EXPECT_NE(written.find("// coredem: inlets[0] of case.yaml, superficial velocity (0 0.3 0) "
                           "m/s\n        type            interstitialInletVelocity;"),
              std::string::npos)
        << written;
    EXPECT_NE(readAll(c / "openfoam" / "0" / "U").find("(0 5.000000 0)"), std::string::npos)
        << "cfd.case itself was changed";
    const double measured = lastPressureDrop(run);
    std::cout << (plate ? "bed on the plate" : "bed on the floor (inlet cells packed)")
              << ": pressure drop " << measured << " Pa, Ergun + gas column " << expected << " Pa ("
              << 100.0 * (measured / expected - 1.0) << " %)\n";
    EXPECT_NEAR(measured / expected, 1.0, 0.05) << (plate ? "plate" : "floor");
  }
}

// A fluidization-curve study as one campaign: the inlet's superficial velocity swept by key
// (three values below minimum fluidization), the pressure drop averaged over a window that
// leaves the start-up out, a numeric axis with its unit. Each member's pressure drop is Ergun's
// at its velocity within 5 %, so it grows with the velocity as Ergun's does.
TEST_F(CoredemFoamInletE2E, FluidizationCurveIsOneCampaignSweepingTheInletVelocity) {
  const fs::path c = makeCase(dir, 0.3, 0.004, true);
  writeAll(dir / "sweep.yaml", R"(name: fluidization-curve
base_case: case
concurrency: 1
grid:
  inlets[0].superficial_velocity[1]: [0.1, 0.2, 0.4]
collect:
  scalars: [mean@0.006..:gas.pressure_drop_Pa]
  units:
    inlets[0].superficial_velocity[1]: m/s
  plot:
    x: inlets[0].superficial_velocity[1]
    y: mean@0.006..:gas.pressure_drop_Pa
)");
  ASSERT_EQ(runCli({"check", (dir / "sweep.yaml").string()}, dir / "check.log"), 0)
      << readAll(dir / "check.log");
  EXPECT_NE(readAll(dir / "check.log").find("valid sweep (3 members"), std::string::npos)
      << readAll(dir / "check.log");
  const fs::path out = dir / "campaign";
  ASSERT_EQ(runCli({"campaign", "run", (dir / "sweep.yaml").string(), "--out", out.string()},
                   dir / "campaign.log", 400s),
            0)
      << readAll(dir / "campaign.log");
  ASSERT_EQ(runCli({"campaign", "collect", out.string()}, dir / "collect.log"), 0)
      << readAll(dir / "collect.log");
  std::istringstream summary(readAll(out / "summary.csv"));
  std::string header, line;
  std::getline(summary, header);
  EXPECT_NE(header.find("inlets[0].superficial_velocity[1]"), std::string::npos) << header;
  const double eps = 1.0 - std::numbers::pi / 6.0;
  int rows = 0;
  while (std::getline(summary, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string s; std::getline(fields, s, ',');) {
      f.push_back(s);
    }
    ASSERT_GE(f.size(), 4u) << line;
    EXPECT_EQ(f[1], "done") << line;
    const double u = std::stod(f[2]), dp = std::stod(f[3]);
    const double expected = ergunGradient(eps, u) * 0.016 + kRhoG * kG * kHeight;
    std::cout << "U = " << u << " m/s: mean pressure drop " << dp << " Pa, Ergun + gas column "
              << expected << " Pa\n";
    EXPECT_NEAR(dp / expected, 1.0, 0.05) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 3);
}

// A liquid as the fluid (docs/physics.md §2.2.5): the shipped water-fluidized bed
// (cases/liquid-fluidized-bed, Di Felice drag, 0.04 m/s) shortened to 0.8 s. The poured beads sink
// through the water and settle into an expanded bed; its voidage from bed_height_m, averaged over
// (0.5, 0.8] s, is Richardson & Zaki's (U_t 0.1461 m/s from Schiller–Naumann, n 2.944 from
// Garside & Al-Dibouni: ε 0.644) within 0.05 — bed_height_m stops at the 95th percentile of the
// centres, so it reads ε 0.01–0.03 low (the 1.2 s run gave 0.615; the snapshot analysis of
// docs/validation.md 0.631). The pressure drop is the water column plus the beads' buoyant
// weight within 5 %, so the buoyancy (40 % of the weight in water) is carried by −V_p ∇p.
TEST_F(CoredemFoamInletE2E, LiquidFluidizedBedExpandsAsRichardsonZaki) {
  const fs::path c = dir / "liquid";
  fs::copy(fs::path(COREDEM_SOURCE_DIR) / "cases" / "liquid-fluidized-bed", c,
           fs::copy_options::recursive);
  const std::string text = readAll(c / "case.yaml");
  ASSERT_NE(text.find("  end: 1.2 "), std::string::npos);
  writeAll(c / "case.yaml", replaceAll(text, "  end: 1.2 ", "  end: 0.8 "));
  const fs::path run = dir / "run";
  ASSERT_EQ(
      runCoredem({"run", c.string(), "--out", run.string(), "--no-plots"}, dir / "coredem.log"), 0)
      << readAll(dir / "coredem.log") << logTail(run);
  auto ts = readTimeseries(run);
  const auto& t = ts["t"];
  const auto& h = ts["bed_height_m"];
  const auto& dp = ts["gas.pressure_drop_Pa"];
  double sumH = 0.0, sumDp = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] > 0.5) {
      sumH += h[i];
      sumDp += dp[i];
      ++n;
    }
  }
  ASSERT_GT(n, 50);
  const double rhoF = 998.2, rhoP = 2500.0, area = 0.012 * 0.012;
  const double solid = 2000.0 * std::numbers::pi / 6.0 * 1e-9;
  const double eps = 1.0 - solid / (area * sumH / n);
  const double rz = std::pow(0.04 / 0.1461, 1.0 / 2.944);
  const double expectedDp = rhoF * kG * 0.072 + solid * (rhoP - rhoF) * kG / area;
  std::cout << "water at 0.04 m/s: bed voidage " << eps << " (Richardson-Zaki " << rz
            << "), pressure drop " << sumDp / n << " Pa (water column + buoyant weight "
            << expectedDp << " Pa)\n";
  EXPECT_NEAR(eps, rz, 0.05);
  EXPECT_NEAR(sumDp / n / expectedDp, 1.0, 0.05);
}

// Every drag law in the coupled solve (issue 44's packed-bed check, fast variant): the column's
// lattice bed (voidage 1 − π/6 in every bed cell) on the distributor at 0.3 m/s, once per law of
// kernels/drag.h. The pressure drop over the bed is the law's own β U/ε² — computed here from the
// same kernel the DEM runs, with the cell's gas state — times the bed height, plus the gas column,
// within 3 % (measured −0.3 … −1.4 %, 5 Dec 2026): each law's coefficient reaches the CFD's
// momentum equation as it should, whatever its form.
TEST_F(CoredemFoamInletE2E, EveryDragLawGivesItsOwnPackedBedPressureDrop) {
  namespace k = coredem::dem::kernels;
  const double u = 0.3, eps = 1.0 - std::numbers::pi / 6.0;
  const double volume = std::numbers::pi / 6.0 * kDp * kDp * kDp;
  int laws = 0;
  k::forEachModel(k::DragLaws{}, [&]<class Law>() {
    const fs::path sub = dir / Law::name;
    const fs::path c = makeCase(sub, u, 0.004, true);
    writeAll(c / "case.yaml",
             readAll(c / "case.yaml") + "models: {drag: " + std::string(Law::name) + "}\n");
    const fs::path run = sub / "run";
    ASSERT_EQ(runCoredem({"run", c.string(), "--out", run.string()}, sub / "coredem.log"), 0)
        << Law::name << "\n"
        << readAll(sub / "coredem.log") << logTail(run);
    // β U/ε² from the per-particle coefficient C = β V_p/(1−ε) at the interstitial slip U/ε.
    const double coefficient =
        Law::coefficient(typename Law::Params{}, eps, kRhoG, kMuG, kDp, volume, u / eps);
    const double gradient = coefficient * (1.0 - eps) / volume * u / (eps * eps);
    const double expected = gradient * 0.016 + kRhoG * kG * kHeight;
    const double measured = lastPressureDrop(run);
    std::cout << Law::name << ": pressure drop " << measured << " Pa, the law's own " << expected
              << " Pa (" << 100.0 * (measured / expected - 1.0) << " %)\n";
    EXPECT_NEAR(measured / expected, 1.0, 0.03) << Law::name;
    ++laws;
  });
  EXPECT_EQ(laws, coredem::dem::kernels::DragLaws::size);
}
