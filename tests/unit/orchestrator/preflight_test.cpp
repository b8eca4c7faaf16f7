// Pre-flight consistency (preflight.h): each check fails (CaseError with file:line:col and both
// values) or warns as documented; the OpenFOAM participant's gravity and gas properties are
// compared with the fluidized-bed-cooling case's OpenFOAM folder; every case under cases/
// passes; the --walltime decision and the divergence hint (session.h).
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/preflight.h>
#include <coredem/orchestrator/session.h>
#include <coredem/participant/foam_vessel.h>

#include "case_text.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = COREDEM_SOURCE_DIR;

// Line numbers matter: the tests check file:line:col.
const char* kCase = R"(name: preflight
time: {end: 0.01, dt: 1.0e-4}
grid: {spacing: [0.01, 0.01, 0.01], cells: [2, 2, 4]}
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - material: glass
    count: 10
    diameter: 2.0e-3
    temperature: 300.0
    packing: random
    region: {min: [0, 0, 0.01], max: [0.02, 0.02, 0.02]}
walls:
  box: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}
  planes:
    - {point: [0, 0, 0.005], normal: [0, 0, 1]}
gas:
  T_g: 500.0
  u_g: [0, 0, 0.1]
)";

CaseConfig parse(const std::string& text, const fs::path& caseDir = fs::temp_directory_path()) {
  return parseCase(text, caseDir / "case.yaml", caseDir);
}

/// The CaseError of checkCaseConsistency ("" when it passes).
std::string failureOf(const std::string& text) {
  try {
    checkCaseConsistency(parse(text));
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

} // namespace

TEST(Preflight, ConsistentCasePassesWithoutWarnings) {
  EXPECT_EQ(failureOf(kCase), "");
  EXPECT_TRUE(checkCaseConsistency(parse(kCase)).empty());
}

TEST(Preflight, ParticlesBeyondTheGridFail) {
  const std::string e = failureOf(
      replace(kCase, "max: [0.02, 0.02, 0.02]}\nwalls", "max: [0.02, 0.03, 0.02]}\nwalls"));
  EXPECT_TRUE(contains(e, "case.yaml:12:13: particles[0].region:")) << e;
  EXPECT_TRUE(contains(e, "beyond the coupling grid")) << e;
  EXPECT_TRUE(contains(e, "y = 0.03 m > 0.02 m")) << e;
}

TEST(Preflight, WallsBeyondTheGridFail) {
  const std::string e =
      failureOf(replace(kCase, "max: [0.02, 0.02, 0.04]}", "max: [0.02, 0.02, 0.05]}"));
  EXPECT_TRUE(contains(e, "case.yaml:14:8: walls.box:")) << e;
  EXPECT_TRUE(contains(e, "z = 0.05 m > 0.04 m")) << e;
}

TEST(Preflight, ParticlesOutsideTheWallBoxFail) {
  // Grid and walls both shrunk in x, the region not.
  std::string t = replace(kCase, "cells: [2, 2, 4]", "cells: [4, 2, 4]");
  t = replace(t, "spacing: [0.01, 0.01, 0.01]", "spacing: [0.01, 0.01, 0.01]");
  t = replace(t, "max: [0.02, 0.02, 0.02]}\nwalls", "max: [0.03, 0.02, 0.02]}\nwalls");
  const std::string e = failureOf(t);
  EXPECT_TRUE(contains(e, "particles[0].region:")) << e;
  EXPECT_TRUE(contains(e, "outside the walls")) << e;
  EXPECT_TRUE(contains(e, "x = 0.03 m > 0.02 m")) << e;
}

TEST(Preflight, ParticlesBehindAPlaneFail) {
  // The region starts at z = 0.004, the plane keeps z >= 0.005 + r.
  const std::string e =
      failureOf(replace(kCase, "min: [0, 0, 0.01], max", "min: [0, 0, 0.004], max"));
  EXPECT_TRUE(contains(e, "case.yaml:12:13: particles[0].region:")) << e;
  EXPECT_TRUE(contains(e, "walls.planes[0]")) << e;
  EXPECT_TRUE(contains(e, "less than the radius 0.001 m")) << e;
  // A particle resting on the plane (centre at r above it) passes.
  EXPECT_EQ(failureOf(replace(kCase, "min: [0, 0, 0.01], max", "min: [0, 0, 0.005], max")), "");
}

TEST(Preflight, LatticeRegionTooSmallFails) {
  std::string t = replace(kCase, "packing: random", "packing: lattice");
  t = replace(t, "count: 10", "count: 1001"); // 10 x 10 x 5 = 500 sites of 2 mm
  const std::string e = failureOf(t);
  EXPECT_TRUE(contains(e, "case.yaml:8:12: particles[0].count:")) << e;
  EXPECT_TRUE(contains(e, "500 lattice sites")) << e;
  EXPECT_TRUE(contains(e, "count = 1001")) << e;
}

TEST(Preflight, RandomPackingTooDenseFailsAndDenseWarns) {
  // Region 4e-6 m3; a 2 mm sphere is 4.19e-9 m3: 640 spheres = 0.67 > 0.64.
  const std::string e = failureOf(replace(kCase, "count: 10", "count: 640"));
  EXPECT_TRUE(contains(e, "particles[0].count:")) << e;
  EXPECT_TRUE(contains(e, "fill 0.67 of the region")) << e;
  // 420 spheres = 0.44: a warning.
  const auto w = checkCaseConsistency(parse(replace(kCase, "count: 10", "count: 420")));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(contains(w[0], "case.yaml:8:12: particles[0].count:")) << w[0];
  EXPECT_TRUE(contains(w[0], "solid fraction 0.44")) << w[0];
}

TEST(Preflight, StaggeredSchemeChecksTheStepAgainstTheParticleResponseTime) {
  // τ_p = ε_s ρ_p/K_sl, Ergun at ε_g = 0.4 with μ_g = 1.81e-5 Pa s, ρ_g = 1.204 kg/m³ (default
  // gas_properties) and slip 0.1 m/s (the prescribed u_g; larger than the fluidization slip of
  // these beads): 10 µm glass beads τ_p = 6.136e-5 s < Δt = 1e-4 s: refused; 20 µm beads
  // τ_p = 2.45e-4 s, Δt/τ_p = 0.41: a warning; the 2 mm beads of the base case (τ_p = 0.45 s)
  // pass; the sequential scheme is not checked.
  const std::string staggered = std::string(kCase) + "coupling: {scheme: staggered}\n";
  EXPECT_TRUE(checkCaseConsistency(parse(staggered)).empty());
  const std::string e = failureOf(replace(staggered, "diameter: 2.0e-3", "diameter: 1.0e-5"));
  EXPECT_TRUE(contains(e, "case.yaml:2:")) << e;
  EXPECT_TRUE(contains(e, "time.dt:")) << e;
  EXPECT_TRUE(contains(e, "slip 0.1 m/s, τ_p = ε_s ρ_p/K_sl = 6.136e-05 s")) << e;
  EXPECT_TRUE(contains(e, "coupling.scheme sequential")) << e;
  const auto w =
      checkCaseConsistency(parse(replace(staggered, "diameter: 2.0e-3", "diameter: 2.0e-5")));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(contains(w[0], "Δt_CFD/τ_p = 0.41 > 0.1")) << w[0];
  EXPECT_EQ(failureOf(replace(kCase, "diameter: 2.0e-3", "diameter: 1.0e-5")), "");
}

TEST(Preflight, StaggeredCheckIncludesTheInertialDragAndThePrescribedGas) {
  // 1 mm glass beads in air: the viscous term alone gives τ_p = ρ_p d²/(225 μ_g) = 0.614 s; the
  // bed is carried at a slip of 2.58 m/s (K_sl s = ε_s (ρ_p − ρ_g) g), where the inertial term
  // more than doubles K_sl: τ_p = 0.263 s < Δt = 0.3 s, refused (the viscous estimate only
  // warned, Δt/τ_p = 0.49).
  // (k_n 10 N/m: 0.3 s is 18,663 DEM sub-steps, within the server's 100,000; τ_p does not
  // depend on k_n.)
  const std::string staggered =
      replace(replace(replace(std::string(kCase), "time: {end: 0.01, dt: 1.0e-4}",
                              "time: {end: 3.0, dt: 0.3}"),
                      "diameter: 2.0e-3", "diameter: 1.0e-3"),
              "k_n: 1000,", "k_n: 10,") +
      "coupling: {scheme: staggered}\n";
  const std::string e = failureOf(staggered);
  EXPECT_TRUE(contains(e, "slip 2.58 m/s, τ_p = ε_s ρ_p/K_sl = 0.263 s is shorter than one step"))
      << e;
  // The prescribed gas's largest viscosity (here a region's table reaching 5e-5 Pa s) is the
  // one checked: 20 µm beads at Δt = 1e-4 s, τ_p = 8.9e-5 s, are refused (2.45e-4 s with the
  // default 1.81e-5 Pa s: a warning).
  const std::string hot = replace(std::string(kCase), "diameter: 2.0e-3", "diameter: 2.0e-5") +
                          "  regions:\n    - box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}\n"
                          "      mu_g: {table: [[0.0, 1.81e-5], [0.005, 5.0e-5]]}\n"
                          "coupling: {scheme: staggered}\n";
  const std::string h = failureOf(hot);
  EXPECT_TRUE(contains(h, "μ_g = 5e-05 Pa s")) << h;
  EXPECT_TRUE(contains(h, "is shorter than one step")) << h;
}

// What the DEM server and the participants refuse is refused by pre-flight, from the same table
// (coredem/common/limits.h; issue 39 item 2): each of these passed `coredem check` before and
// the run then failed.
TEST(Preflight, TheServersLimitsAreCheckedBeforeTheRun) {
  // k_n 2e21 N/m: Δt_DEM = π √(m/2/k_n)/50 = 1.4e-13 s, ~7e8 sub-steps of Δt = 1e-4 s.
  std::string e = failureOf(replace(kCase, "k_n: 1000,", "k_n: 2.0e21,"));
  EXPECT_TRUE(contains(e, "case.yaml:2:")) << e;
  EXPECT_TRUE(contains(e, "DEM sub-steps of")) << e;
  EXPECT_TRUE(contains(e, "grants at most 100000 per CFD step")) << e;
  EXPECT_EQ(failureOf(kCase), "");
  // 1025 materials (the server's admission limit is 1024).
  std::string many = "materials:\n  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}\n";
  for (int i = 0; i < 1024; ++i) {
    many += "  - {name: m" + std::to_string(i) + ", density: 2500, k_n: 1000, e_n: 0.9}\n";
  }
  e = failureOf(
      replace(kCase, "materials:\n  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}\n", many));
  EXPECT_TRUE(contains(e, "materials: 1025 materials: the DEM server admits at most 1024")) << e;
  // A constant gas viscosity of 1e-320 Pa s (the DEM refuses mu_g outside [1e-7, 1] Pa s).
  e = failureOf(std::string(kCase) + "gas_properties: {model: constant, viscosity: 1.0e-320}\n");
  EXPECT_TRUE(contains(e, "Pa s is outside [1e-07, 1] Pa s")) << e;
  EXPECT_TRUE(contains(e, "gas_properties.viscosity: ")) << e;
  // The same in the prescribed gas (coredem-gas sends it as given), in a region's table too.
  e = failureOf(std::string(kCase) + "  mu_g: 1.0e-320\n");
  EXPECT_TRUE(contains(e, "gas.mu_g: ")) << e;
  EXPECT_TRUE(contains(e, "is outside [1e-07, 1] Pa s")) << e;
  e = failureOf(std::string(kCase) +
                "  regions:\n    - box: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}\n"
                "      rho_g: {table: [[0.0, 1.2], [0.005, 1.0e9]]}\n");
  EXPECT_TRUE(contains(e, "gas.regions[0].rho_g.table[1][1]: 1e+09 kg/m3 is outside")) << e;
}

TEST(Preflight, ExplicitOverlapBeyondTheFractionFails) {
  const std::string base = R"(name: explicit
time: {end: 0.01, dt: 1.0e-4}
grid: {spacing: [0.01, 0.01, 0.01], cells: [2, 2, 2]}
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - material: glass
    diameter: 2.0e-3
    positions:
      - [0.010, 0.01, 0.01]
      - [0.0115, 0.01, 0.01]
gas: {T_g: 300.0}
)";
  // 0.5 mm overlap = 0.25 of the diameter.
  const std::string e = failureOf(base);
  EXPECT_TRUE(contains(e, "case.yaml:11:9: particles[0].positions[1]:")) << e;
  EXPECT_TRUE(contains(e, "overlaps particles[0].positions[0]")) << e;
  EXPECT_TRUE(contains(e, "0.25 of the smaller diameter (at most 0.05 allowed)")) << e;
  // A centre outside the grid (the particle is coupled to the cell of its centre).
  const std::string g = failureOf(replace(base, "[0.010, 0.01, 0.01]", "[0.010, 0.01, 0.021]"));
  EXPECT_TRUE(contains(g, "case.yaml:10:7: particles[0].positions:")) << g;
  EXPECT_TRUE(contains(g, "centres span")) << g;
  EXPECT_TRUE(contains(g, "z = 0.021 m > 0.02 m")) << g;
  // 0.05 mm = 0.025 of the diameter (as the contact verification cases): accepted.
  EXPECT_EQ(failureOf(replace(base, "[0.0115, 0.01, 0.01]", "[0.01195, 0.01, 0.01]")), "");
}

TEST(Preflight, IntersectingRegionsWarn) {
  const std::string t = replace(kCase, "walls:", R"(  - material: glass
    count: 5
    diameter: 2.0e-3
    region: {min: [0, 0, 0.015], max: [0.01, 0.01, 0.03]}
walls:)");
  const auto w = checkCaseConsistency(parse(t));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(contains(w[0], "particles[1]:")) << w[0];
  EXPECT_TRUE(contains(w[0], "intersects")) << w[0];
}

// Many intersecting sets: at most 10 warnings and one line for the rest (1,001 sets gave 500,500
// lines before); a set with the placement of another is refused (coincident centres, NaN at the
// first step; it only warned before).
TEST(Preflight, ManyIntersectingSetsWarnBrieflyAndCoincidentSetsAreRefused) {
  std::string sets;
  for (int k = 0; k < 1000; ++k) {
    sets += "  - material: glass\n    count: 1\n    diameter: 2.0e-3\n    packing: random\n"
            "    seed: " +
            std::to_string(k + 2) + "\n    region: {min: [0, 0, 0.015], max: [0.01, 0.01, 0.03]}\n";
  }
  const auto w = checkCaseConsistency(parse(replace(kCase, "walls:", sets + "walls:")));
  ASSERT_EQ(w.size(), 11u);
  EXPECT_TRUE(contains(w[10], "500490 more pairs of placed sets intersect (the first 10 are "
                              "listed above)"))
      << w[10];
  const std::string twin = replace(kCase, "walls:", R"(  - material: glass
    count: 10
    diameter: 2.0e-3
    temperature: 300.0
    packing: random
    region: {min: [0, 0, 0.01], max: [0.02, 0.02, 0.02]}
walls:)");
  const std::string e = failureOf(twin);
  EXPECT_TRUE(contains(e, "particles[1]: particles[1] (set1) has the placement of particles[0] "
                          "(set0) (random packing of 10 particles"))
      << e;
  EXPECT_TRUE(contains(e, "same seed): their particles would sit on the same centres")) << e;
  EXPECT_EQ(failureOf(replace(twin, "    packing: random\n    region: {min: [0, 0, 0.01]",
                              "    packing: random\n    seed: 7\n    region: {min: [0, 0, 0.01]")),
            "");
}

TEST(Preflight, CelsiusTemperaturesWarn) {
  // Between the DEM's lower bound (100 K) and 200 K: plausible °C, warned about.
  std::string t = replace(kCase, "temperature: 300.0", "temperature: 90.0");
  t = replace(t, "T_g: 500.0", "T_g: 150.0");
  t = replace(t, "walls:\n", "gas_properties: {temperature: 150}\nwalls:\n");
  const auto w = checkCaseConsistency(parse(t));
  ASSERT_EQ(w.size(), 3u);
  EXPECT_TRUE(contains(w[0], "case.yaml:10:18: particles[0].temperature: 90 K is below 200 K: "
                             "°C given?"))
      << w[0];
  EXPECT_TRUE(contains(w[1], "gas_properties.temperature: 150 K")) << w[1];
  EXPECT_TRUE(contains(w[2], "gas.T_g: 150 K")) << w[2];
  // Warnings, not failures.
  EXPECT_EQ(failureOf(t), "");
}

// walls.material with adiabatic walls and a second material: easily taken for the walls' contact
// material (it is the conduction material of fixed-temperature walls), so it is warned about,
// naming the per-wall key that does set it; one material, or a wall's own material, is silent.
TEST(Preflight, WallsMaterialWithAdiabaticWallsIsNotAContactMaterial) {
  const std::string two = replace(kCase, "materials:\n",
                                  "materials:\n  - {name: smooth, density: 2500, k_n: 1000, "
                                  "e_n: 0.9, friction: 0.0}\n");
  const std::string t = replace(two, "walls:\n", "walls:\n  material: smooth\n");
  const auto w = checkCaseConsistency(parse(t));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(contains(w[0], "walls.material: 'smooth' has no effect here")) << w[0];
  EXPECT_TRUE(contains(w[0], "walls.box.material")) << w[0];
  EXPECT_EQ(failureOf(t), "");
  EXPECT_TRUE(checkCaseConsistency(parse(replace(kCase, "walls:\n", "walls:\n  material: glass\n")))
                  .empty());
  EXPECT_TRUE(
      checkCaseConsistency(
          parse(replace(two, "box: {min: [0, 0, 0], max: [0.02, 0.02, 0.04]}",
                        "box: {min: [0, 0, 0], max: [0.02, 0.02, 0.04], material: smooth}")))
          .empty());
}

TEST(Preflight, GasTemperatureOutsideTheDemRangeIsRefused) {
  // The DEM server refuses a gas state below 100 K at the first exchange (common/limits.h);
  // coredem-gas refused T_g = -5 K when the member started: check refuses both now.
  const std::string prescribed = failureOf(replace(kCase, "T_g: 500.0", "T_g: -5.0"));
  EXPECT_TRUE(contains(prescribed, "gas.T_g: -5 K is outside [100, 6000] K")) << prescribed;
  const std::string table =
      failureOf(replace(kCase, "T_g: 500.0", "T_g: {table: [[0, 300], [1, 20]]}"));
  EXPECT_TRUE(contains(table, "20 K is outside [100, 6000] K")) << table;
  const std::string constant = failureOf(
      replace(kCase, "walls:\n", "gas_properties: {model: constant, temperature: 20}\nwalls:\n"));
  EXPECT_TRUE(contains(constant, "gas_properties.temperature: 20 K is outside [100, 6000] K"))
      << constant;
  EXPECT_EQ(failureOf(replace(kCase, "T_g: 500.0", "T_g: 100.0")), "");
}

// ------------------------------------------------------------------ the OpenFOAM participant

namespace {

/// cases/fluidized-bed-cooling with its OpenFOAM folder copied to a temp folder.
fs::path foamCaseCopy(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("coredem-preflight-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  const fs::path src = kSource / "cases" / "fluidized-bed-cooling";
  fs::copy(src / "openfoam", d / "openfoam", fs::copy_options::recursive);
  fs::copy_file(src / "case.yaml", d / "case.yaml");
  return d;
}

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeText(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

/// The copy's gas with constant properties, those of openfoam/constant/transportProperties
/// (model: constant, air at 20 °C; 3 lines more).
void makeConstantGas(const fs::path& d) {
  writeText(d / "case.yaml",
            replace(readText(d / "case.yaml"), "  model: ideal_gas\n",
                    "  model: constant\n  density: 1.204\n  viscosity: 1.81e-5\n  conductivity: "
                    "0.0257\n  cp: 1006.0\n"));
  writeText(d / "case.yaml", replace(readText(d / "case.yaml"), "  diffusivity: 2.0e-5\n", ""));
}

/// The pre-flight of the coredemFoam row of the participant table ("" when it passes).
std::string foamFailureOf(const fs::path& dir) {
  const CaseConfig c = parse(readText(dir / "case.yaml"), dir);
  const ParticipantDescriptor& p = participant(c.cfd.participant);
  EXPECT_NE(p.preflight, nullptr);
  try {
    p.preflight(c);
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(PreflightOpenFoam, FluidizedBedCoolingIsConsistent) {
  const fs::path d = foamCaseCopy("ok");
  EXPECT_EQ(foamFailureOf(d), "");
  fs::remove_all(d);
}

// The coupling grid must cover the CFD mesh (points of constant/polyMesh, or the blockMeshDict's
// vertices before meshing): a grid one cell short in y is refused naming the axis and both spans.
TEST(PreflightOpenFoam, GridNotCoveringTheMeshNamesTheAxis) {
  const fs::path d = foamCaseCopy("grid");
  writeText(d / "case.yaml",
            replace(readText(d / "case.yaml"), "cells: [10, 30, 2]", "cells: [10, 29, 2]"));
  const std::string e = foamFailureOf(d);
  EXPECT_TRUE(contains(e, "grid: the coupling grid spans y = [0, 0.058] m but the CFD mesh")) << e;
  EXPECT_TRUE(contains(e, "blockMeshDict) spans [0, 0.06] m")) << e;
  EXPECT_TRUE(contains(e, "must cover the fluid domain")) << e;
  // A grid up to one cell larger than the mesh is fine (coupling cells without fluid).
  writeText(d / "case.yaml",
            replace(readText(d / "case.yaml"), "cells: [10, 29, 2]", "cells: [10, 31, 3]"));
  EXPECT_EQ(foamFailureOf(d), "");
  // More is not (issue 39 item 1): a spacing 20 % too large, or 2^31 m, ran before and left
  // hundreds of coupling cells outside the fluid.
  const std::string fitting = readText(d / "case.yaml");
  const auto sp = fitting.find("spacing: [");
  ASSERT_NE(sp, std::string::npos) << fitting;
  const std::string spacing = fitting.substr(sp, fitting.find(']', sp) - sp + 1);
  writeText(d / "case.yaml", replace(fitting, spacing, "spacing: [0.0024, 0.0024, 0.0024]"));
  std::string big = foamFailureOf(d);
  EXPECT_TRUE(contains(big, "grid: the coupling grid spans x = [0, 0.024] m, more than one grid "
                            "cell (0.0024 m) beyond the CFD mesh"))
      << big;
  EXPECT_TRUE(contains(big, "fit grid.spacing, grid.cells and grid.origin to the mesh")) << big;
  writeText(d / "case.yaml", replace(fitting, spacing, "spacing: [2147483648, 0.002, 0.002]"));
  big = foamFailureOf(d);
  EXPECT_TRUE(contains(big, "more than one grid cell (2.14748e+09 m) beyond the CFD mesh")) << big;
  writeText(d / "case.yaml", fitting);
  // Particle walls beyond the mesh are not: particles there would get no gas.
  const std::string yaml = readText(d / "case.yaml");
  const auto box = yaml.find("max: [0.02, 0.06, 0.004]");
  ASSERT_NE(box, std::string::npos) << yaml;
  writeText(d / "case.yaml", replace(yaml, "max: [0.02, 0.06, 0.004]", "max: [0.02, 0.06, 0.005]"));
  const std::string w = foamFailureOf(d);
  EXPECT_TRUE(contains(w, "walls.box: the particle walls span z = [0, 0.005] m but the CFD mesh"))
      << w;
  fs::remove_all(d);
}

TEST(PreflightOpenFoam, GravityMismatchNamesBothValues) {
  const fs::path d = foamCaseCopy("gravity");
  writeText(d / "case.yaml", replace(readText(d / "case.yaml"), "gravity: [0.0, -9.81, 0.0]",
                                     "gravity: [0.0, 0.0, -9.81]"));
  const std::string e = foamFailureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:19:10: gravity: [0, 0, -9.81] m/s2")) << e;
  EXPECT_TRUE(contains(e, "openfoam/constant/g:16 gives (0 -9.81 0)")) << e;
  fs::remove_all(d);
}

TEST(PreflightOpenFoam, GasPropertyMismatchNamesBothValues) {
  const fs::path d = foamCaseCopy("gas");
  makeConstantGas(d);
  writeText(d / "case.yaml",
            replace(readText(d / "case.yaml"), "viscosity: 1.81e-5", "viscosity: 1.85e-5"));
  std::string e = foamFailureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:24:14: gas_properties.viscosity: 1.85e-05 Pa s")) << e;
  EXPECT_TRUE(contains(e, "constant/transportProperties:17 gives nu·rho = 1.5033e-05·1.204 = "
                          "1.80997e-05 Pa s"))
      << e;
  // The OpenFOAM side changed instead: cp.
  writeText(d / "case.yaml",
            replace(readText(d / "case.yaml"), "viscosity: 1.85e-5", "viscosity: 1.81e-5"));
  writeText(d / "openfoam/constant/transportProperties",
            replace(readText(d / "openfoam/constant/transportProperties"), "cp              1006;",
                    "cp              1000;"));
  e = foamFailureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:26:7: gas_properties.cp: 1006 J/kg/K")) << e;
  EXPECT_TRUE(contains(e, "gives cp = 1000 J/kg/K")) << e;
  fs::remove_all(d);
}

// Every case under cases/ passes the consistency checks (and its participant's pre-flight).
TEST(Preflight, EveryShippedCasePasses) {
  std::size_t checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(kSource / "cases")) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".yaml" || name.rfind("sweep", 0) == 0 || // sweep*.yaml
        name == "verify.yaml") {
      continue;
    }
    if (name == "vessel.yaml") { // a vessel description (coredem mesh), checked by it
      const VesselSpec v = readVesselSpec(e.path());
      EXPECT_GT(vesselFiles(v, name).cells, 0);
      continue;
    }
    SCOPED_TRACE(e.path().string());
    CaseConfig c;
    try {
      c = loadCase(e.path());
    } catch (const CaseError& err) {
      ADD_FAILURE() << err.what();
      continue;
    }
    EXPECT_NO_THROW({
      const ParticipantDescriptor& p = participant(c.cfd.participant);
      if (p.preflight != nullptr) {
        p.preflight(c);
      }
      for (const auto& w : checkCaseConsistency(c)) {
        // The constant-property twins of the gas-model comparison keep their gas on purpose.
        const bool twin = name.find("-constant-gas.yaml") != std::string::npos &&
                          contains(w, "gas_properties.model: constant gas properties");
        if (!twin) {
          ADD_FAILURE() << "warning: " << w;
        }
      }
    });
    ++checked;
  }
  EXPECT_GE(checked, 30u);
}

// ------------------------------------------------------------------ stopping early

TEST(Stopping, WalltimeStopsWhenTheNextCheckpointWouldNotFit) {
  // Reserve for 1000 s: 5 + 20 = 25 s.
  EXPECT_DOUBLE_EQ(walltimeReserve(1000.0), 25.0);
  // 900 s elapsed, steps of 10 s, checkpoint steps of 30 s: 900 + 10 + 30 + 25 = 965 < 1000.
  EXPECT_FALSE(walltimeStopDue(900.0, 1000.0, 10.0, 30.0));
  // 940 s: 1005 > 1000: this step is the last, with a checkpoint.
  EXPECT_TRUE(walltimeStopDue(940.0, 1000.0, 10.0, 30.0));
  // No estimate yet (first step): only the reserve counts.
  EXPECT_FALSE(walltimeStopDue(0.5, 1000.0, 0.0, 0.0));
  EXPECT_TRUE(walltimeStopDue(0.5, 1.0, 0.0, 0.0));
}

TEST(Stopping, DivergenceHintNamesCourantAndSuggestsDt) {
  const std::string h = divergenceHint(42, 1e-3, 2.5);
  EXPECT_TRUE(contains(h, "diverged in step 42")) << h;
  EXPECT_TRUE(contains(h, "Courant number 2.5")) << h;
  EXPECT_TRUE(contains(h, "time.dt <= 0.0002 s")) << h; // 1e-3 * 0.5/2.5
  const std::string none = divergenceHint(1, 1e-3, -1.0);
  EXPECT_TRUE(contains(none, "no Courant number reported yet")) << none;
  EXPECT_TRUE(contains(none, "time.dt <= 0.0005 s")) << none;
}
