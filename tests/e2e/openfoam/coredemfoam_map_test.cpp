// coredemFoam's map between an OpenFOAM mesh and the Cartesian coupling grid
// (cfd-adapter/openfoam/coredemFoam/couplingGrid.H), checked by coredemMapCheck with synthetic
// fields on meshes made by Debian's blockMesh and polyDualMesh from the column of the e2e tests
// (1 x 4 x 1 cm; coupling grid 5 x 20 x 5 cells of 2 mm):
//   * a mesh graded towards the walls (cells down to 0.37 mm, smaller than the 1 mm particles),
//   * a polyhedral mesh (polyDualMesh of a block mesh),
//   * a smaller box (9 x 39 x 6.5 mm): coupling cells partly filled and without fluid,
// each conserve the sources (sum over mesh cells of s V = sum over coupling cells of s times the
// fluid volume) and the solid volume to 1e-12 relative, give the gas fraction of the fluid
// volume in partly filled cells (1 - phi everywhere for a solid volume phi V_f in every cell) and
// keep it in (0, 1]; a mesh the grid does not cover is refused naming the cell (exit 2); the
// uniform block equal to the grid keeps the exact map; decomposed meshes (2 and 4 processors)
// give contributions that add up to the serial map.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem_e2e.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kFoamBin = COREDEM_OPENFOAM_BIN_DIR;
const fs::path kTemplate = COREDEM_FOAM_E2E_TEMPLATE;

using coredem::e2e::readAll;
using coredem::e2e::writeAll;

using coredem::e2e::replaceAll;

class CoredemFoamMap : public coredem::e2e::RunFolderTest {
protected:
  CoredemFoamMap()
      : RunFolderTest(kBin, {"coredemMapCheck"}, "coredemfoam-map") {}

  void SetUp() override {
    RunFolderTest::SetUp();
    // OpenFOAM's utilities need the etc tree (no bashrc).
    ::setenv("WM_PROJECT_DIR", COREDEM_OPENFOAM_PROJECT_DIR, 1);
  }

  /// The column template with `blocks` (and `vertices` when given) as the blockMeshDict.
  fs::path makeMesh(const std::string& blocks, const std::string& vertices = "") {
    const fs::path c = dir / "case";
    fs::copy(kTemplate, c, fs::copy_options::recursive);
    for (const auto& e : fs::recursive_directory_iterator(c / "0")) {
      writeAll(e.path(),
               replaceAll(replaceAll(readAll(e.path()), "@U_IN@", "0.3"), "@T_IN@", "293.15"));
    }
    const fs::path dict = c / "system" / "blockMeshDict";
    std::string s = readAll(dict);
    const std::string uniform = "(5 20 5) simpleGrading (1 1 1)";
    EXPECT_NE(s.find(uniform), std::string::npos);
    s = replaceAll(s, uniform, blocks);
    if (!vertices.empty()) {
      const auto a = s.find("vertices"), b = s.find(");", a);
      s = s.substr(0, a) + "vertices\n(\n" + vertices + "\n" + s.substr(b);
    }
    writeAll(dict, s);
    run(kFoamBin / "blockMesh", {"-case", c.string()}, "blockMesh", 0);
    return c;
  }

  /// Runs `program args` into dir/<name>.log; expects exit code `rc`; returns the log.
  std::string run(const fs::path& program, std::vector<std::string> args, const std::string& name,
                  int rc) {
    const fs::path log = dir / (name + ".log");
    fs::remove(log);
    EXPECT_EQ(coredem::e2e::waitExit(coredem::e2e::startProgram(program, args, log), 60s), rc)
        << readAll(log);
    return readAll(log);
  }

  /// coredemMapCheck on case `c` against the tests' coupling grid (counts `counts`).
  std::string check(const fs::path& c, int rc = 0, const std::string& counts = "(5 20 5)") {
    return run(kBin / "coredemMapCheck",
               {"-case", c.string(), "-origin", "(0 0 0)", "-spacing", "(0.002 0.002 0.002)",
                "-counts", counts},
               "mapcheck", rc);
  }

  /// "check NAME: VALUE" lines of coredemMapCheck.
  static std::map<std::string, double> checks(const std::string& log) {
    std::map<std::string, double> out;
    const std::regex re("check ([a-z_]+): ([-0-9.eE+]+)");
    for (std::sregex_iterator it(log.begin(), log.end(), re), end; it != end; ++it) {
      out[(*it)[1].str()] = std::strtod((*it)[2].str().c_str(), nullptr);
    }
    return out;
  }

  /// Every check within 1e-12 relative (the conservation and gas-fraction checks included).
  static void expectConservative(const std::string& log) {
    const auto c = checks(log);
    for (const char* name : {"volume", "sources", "fraction_solid_volume", "fraction_range",
                             "fraction_uniform", "gather_constant", "gather_conservative"}) {
      ASSERT_TRUE(c.count(name)) << name << " missing:\n" << log;
      EXPECT_LE(c.at(name), 1e-12) << name << "\n" << log;
    }
    EXPECT_NE(log.find("map checks passed"), std::string::npos) << log;
  }

  /// A number after `key` in the log ("map: ... 12 partial").
  static long count(const std::string& log, const std::string& what) {
    std::smatch m;
    EXPECT_TRUE(std::regex_search(log, m, std::regex("([0-9]+) " + what))) << what << "\n" << log;
    return m.size() > 1 ? std::stol(m[1].str()) : -1;
  }
};

// Graded towards every wall: 12 x 30 x 12 cells, the ones at the walls 0.37 mm wide (smaller
// than a 1 mm particle), none aligned with the coupling grid.
TEST_F(CoredemFoamMap, GradedMeshIsConservative) {
  const fs::path c = makeMesh("(12 30 12) simpleGrading (((0.5 0.5 4) (0.5 0.5 0.25)) 1 "
                              "((0.5 0.5 4) (0.5 0.5 0.25)))");
  const std::string log = check(c);
  EXPECT_NE(log.find("overlap,"), std::string::npos) << log;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("smallest cell width ([-0-9.eE+]+)")));
  EXPECT_LT(std::strtod(m[1].str().c_str(), nullptr), 0.5e-3);
  EXPECT_EQ(count(log, "partial"), 0);
  EXPECT_EQ(count(log, "empty"), 0);
  expectConservative(log);
}

// polyDualMesh of a 7 x 23 x 6 block: polyhedra along the walls, cells across the grid planes.
TEST_F(CoredemFoamMap, PolyhedralMeshIsConservative) {
  const fs::path c = makeMesh("(7 23 6) simpleGrading (1 1 1)");
  run(kFoamBin / "polyDualMesh", {"-case", c.string(), "60", "-overwrite"}, "polyDualMesh", 0);
  const std::string log = check(c);
  EXPECT_GT(count(log, "cells not hexahedra"), 100);
  EXPECT_NE(log.find("overlap,"), std::string::npos) << log;
  expectConservative(log);
}

// A 9 x 39 x 6.5 mm box in the 10 x 40 x 10 mm grid: the coupling cells along x = 8-10 mm,
// y = 38-40 mm and z = 6-8 mm are partly filled, those beyond z = 8 mm have no fluid. The gas
// fraction of a partly filled cell is that of its fluid volume.
TEST_F(CoredemFoamMap, PartlyFilledCouplingCellsUseTheirFluidVolume) {
  const fs::path c = makeMesh("(9 26 7) simpleGrading (1 1 1)",
                              "(0 0 0) (0.009 0 0) (0.009 0.039 0) (0 0.039 0)\n"
                              "(0 0 0.0065) (0.009 0 0.0065) (0.009 0.039 0.0065) "
                              "(0 0.039 0.0065)");
  const std::string log = check(c);
  // Partly filled: i = 4 or j = 19 or k = 3 (of k < 4): 5*20*4 - 4*19*3 = 172; empty: k = 4.
  EXPECT_EQ(count(log, "partial"), 172);
  EXPECT_EQ(count(log, "empty"), 100);
  expectConservative(log);
}

// An inclined wall (x from 9.3 mm at z = 0 to 4.7 mm at z = 10 mm) cuts the coupling cells
// into slivers of every size. A packed bed that puts more solid into a sliver than its fluid
// volume's share (1 - eps_min) V_f: the gas sees every m3 of solid the DEM deposited (1e-12
// relative: the excess goes to the neighbouring cells' free room, sum and order of the
// additions only) and nothing is clipped; a domain overfilled everywhere (0.7 V_f in every
// cell, eps_min 0.35) books exactly the 0.05 sum V_f it cannot place as clipped.
TEST_F(CoredemFoamMap, WallCutCouplingCellsKeepTheirSolid) {
  const fs::path c = makeMesh("(9 20 10) simpleGrading (1 1 1)",
                              "(0 0 0) (0.0093 0 0) (0.0093 0.04 0) (0 0.04 0)\n"
                              "(0 0 0.01) (0.0047 0 0.01) (0.0047 0.04 0.01) (0 0.04 0.01)");
  const std::string log = run(kBin / "coredemMapCheck",
                              {"-case", c.string(), "-origin", "(0 0 0)", "-spacing",
                               "(0.002 0.002 0.002)", "-counts", "(5 20 5)", "-epsMin", "0.35"},
                              "mapcheck", 0);
  EXPECT_GT(count(log, "partial"), 100);
  expectConservative(log);
  const auto v = checks(log);
  for (const char* name :
       {"packed_solid_volume", "packed_clipped", "overfilled_solid_volume", "overfilled_clipped"}) {
    ASSERT_TRUE(v.count(name)) << name << " missing:\n" << log;
    EXPECT_LE(v.at(name), 1e-12) << name << "\n" << log;
  }
}

// A coupling grid 2 mm short of the mesh (19 cells high for a 40 mm column) is refused naming
// the first mesh cell it does not cover (exit 2).
TEST_F(CoredemFoamMap, MeshNotCoveredByTheGridIsRefused) {
  const fs::path c = makeMesh("(12 30 12) simpleGrading (1 1 1)");
  const std::string log = check(c, 2, "(5 19 5)");
  EXPECT_TRUE(
      std::regex_search(log, std::regex("mesh cell [0-9]+ \\(centre .*outside the coupling grid")))
      << log;
  EXPECT_NE(log.find("must cover the fluid domain"), std::string::npos) << log;
}

// The uniform block equal to the grid keeps the exact map (coredemFoam's in-place exchange).
TEST_F(CoredemFoamMap, MeshEqualToTheGridIsTheExactMap) {
  const fs::path c = makeMesh("(5 20 5) simpleGrading (1 1 1)");
  const std::string log = check(c);
  EXPECT_NE(log.find("exact,"), std::string::npos) << log;
  expectConservative(log);
}

// Decomposed (decomposePar, then mpirun -np K coredemMapCheck -parallel): each processor maps
// its own cells and touches only part of the grid; the checks hold over all processors, and the
// processors' contributions added up give the serial run's totals to 1e-12 relative (fluid
// volume, sum of the gathered field times the fluid volume, its largest value). The graded mesh
// on 2 processors, the polyhedral one on 4 (oversubscribed).
TEST_F(CoredemFoamMap, DecomposedMapsAddUpToTheSerialMap) {
  // Debian's openfoam depends on mpi-default-bin (Open MPI's mpirun).
  ASSERT_FALSE(std::string(COREDEM_MPIRUN).empty())
      << "no mpirun although Debian's openfoam is installed (apt-get install mpi-default-bin)";
  // Open MPI refuses root unless told (containers, CI).
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  auto figures = [](const std::string& log) {
    std::map<std::string, double> out;
    const std::regex re("figure ([a-z_]+): ([-0-9.eE+]+)");
    for (std::sregex_iterator it(log.begin(), log.end(), re), end; it != end; ++it) {
      out[(*it)[1].str()] = std::strtod((*it)[2].str().c_str(), nullptr);
    }
    return out;
  };
  for (const auto& [kind, ranks] : {std::pair<std::string, int>{"graded", 2}, {"polyhedral", 4}}) {
    SCOPED_TRACE(kind);
    fs::remove_all(dir / "case");
    const fs::path c = kind == "graded"
                           ? makeMesh("(12 30 12) simpleGrading (((0.5 0.5 4) (0.5 0.5 0.25)) 1 "
                                      "((0.5 0.5 4) (0.5 0.5 0.25)))")
                           : makeMesh("(7 23 6) simpleGrading (1 1 1)");
    if (kind == "polyhedral") {
      run(kFoamBin / "polyDualMesh", {"-case", c.string(), "60", "-overwrite"}, "polyDualMesh", 0);
    }
    const std::string serial = check(c);
    expectConservative(serial);
    writeAll(c / "system" / "decomposeParDict",
             "FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }\n"
             "numberOfSubdomains " +
                 std::to_string(ranks) + ";\nmethod simple;\nsimpleCoeffs { n (" +
                 std::to_string(ranks / 2) + " 2 1); delta 0.001; }\n");
    run(kFoamBin / "decomposePar", {"-case", c.string(), "-force"}, "decomposePar", 0);
    const std::string par =
        run(COREDEM_MPIRUN,
            {"--oversubscribe", "-np", std::to_string(ranks), (kBin / "coredemMapCheck").string(),
             "-parallel", "-case", c.string(), "-origin", "(0 0 0)", "-spacing",
             "(0.002 0.002 0.002)", "-counts", "(5 20 5)"},
            "mapcheck-parallel", 0);
    EXPECT_NE(par.find("nProcs : " + std::to_string(ranks)), std::string::npos) << par;
    expectConservative(par);
    // Every processor touches part of the grid only.
    const std::regex touched("\\[([0-9]+)\\] touched: ([0-9]+) of 500 grid cells");
    int processors = 0;
    for (std::sregex_iterator it(par.begin(), par.end(), touched), end; it != end; ++it) {
      ++processors;
      EXPECT_LT(std::stol((*it)[2].str()), 500) << (*it)[0].str();
      EXPECT_GT(std::stol((*it)[2].str()), 0) << (*it)[0].str();
    }
    EXPECT_EQ(processors, ranks) << par;
    const auto a = figures(serial), b = figures(par);
    for (const char* name : {"fluid_volume", "gathered_total", "gathered_max"}) {
      ASSERT_TRUE(a.count(name) && b.count(name)) << name << "\n" << par;
      EXPECT_NEAR(b.at(name), a.at(name), 1e-12 * std::abs(a.at(name))) << name;
    }
  }
}

// Pre-flight of the DEM's revolved walls against the CFD mesh (issue 41 item 4): the cylindrical
// bed's O-grid has 32 flat wall faces around; its DEM cylinder and cone at the inscribed radii
// R cos(π/32) pass `coredem check`; the full radius R (0.072 mm outside the flat faces at their
// middles) is refused naming the wall and the boundary's distance from the axis.
TEST_F(CoredemFoamMap, DemCylinderOutsideAFacetedCfdWallIsRefused) {
  const fs::path c = dir / "bed";
  fs::copy(fs::path(COREDEM_SOURCE_DIR) / "cases" / "cylindrical-bed", c,
           fs::copy_options::recursive);
  run(kFoamBin / "blockMesh", {"-case", (c / "openfoam").string()}, "blockMesh", 0);
  run(kBin / "coredem", {"check", c.string()}, "check-inscribed", 0);
  std::string yaml = readAll(c / "case.yaml");
  yaml = replaceAll(yaml, "radius: 0.0149277709, from: 0.015", "radius: 0.015, from: 0.015");
  writeAll(c / "case.yaml", yaml);
  const std::string log = run(kBin / "coredem", {"check", c.string()}, "check-outside", 2);
  EXPECT_NE(log.find("walls.cylinders[0]: radius 0.015 m"), std::string::npos) << log;
  const std::smatch m = [&] {
    std::smatch r;
    std::regex_search(log, r, std::regex("is ([0-9.e-]+) m from the axis"));
    return r;
  }();
  ASSERT_EQ(m.size(), 2u) << log;
  // The nearest boundary along the sampled rays: the inscribed radius 14.928 mm, or a little
  // more between the face centres (1/cos of at most π/64).
  const double inscribed = 0.015 * std::cos(M_PI / 32.0);
  EXPECT_GE(std::stod(m[1].str()), inscribed * (1 - 1e-6)) << log;
  EXPECT_LE(std::stod(m[1].str()), inscribed / std::cos(M_PI / 64.0)) << log;
}

} // namespace

namespace {

/// `text` without its top-level sections `keys` (each key line and the indented or comment lines
/// under it).
std::string withoutSections(const std::string& text, const std::vector<std::string>& keys) {
  std::istringstream in(text);
  std::string out, line;
  bool skipping = false;
  while (std::getline(in, line)) {
    bool starts = false;
    for (const auto& k : keys) {
      starts = starts || line.rfind(k + ":", 0) == 0;
    }
    if (starts || (skipping && (line.empty() || line[0] == ' ' || line[0] == '#'))) {
      skipping = true;
      continue;
    }
    skipping = false;
    out += line + "\n";
  }
  return out;
}

} // namespace

// Vessels from one description (issue 41 item 4): `coredem mesh` turns the cylindrical bed's
// vessel (R 15 mm, 120 mm, a cone 15 mm high from r 5 mm, 32 around) into a blockMeshDict that
// Debian's blockMesh meshes and checkMesh passes (7680 hexahedra, as the hand-written O-grid had),
// and a case.yaml part (grid, inscribed DEM walls, inlet, outlet) with which `coredem check`
// passes the case, the DEM walls inside the faceted CFD walls included. The same for a box.
TEST_F(CoredemFoamMap, VesselFromOneDescriptionMeshesAndPassesCheck) {
  const fs::path c = dir / "bed";
  fs::copy(fs::path(COREDEM_SOURCE_DIR) / "cases" / "cylindrical-bed", c,
           fs::copy_options::recursive);
  fs::remove(c / "openfoam" / "system" / "blockMeshDict");
  writeAll(dir / "vessel.yaml", "shape: cylinder\naxis: z\nradius: 0.015\nheight: 0.12\n"
                                "cone: {height: 0.015, radius: 0.005}\ncell_size: 0.0025\n"
                                "around: 32\n");
  const std::string mesh = run(
      kBin / "coredem", {"mesh", (dir / "vessel.yaml").string(), "--out", c.string()}, "mesh", 0);
  EXPECT_NE(mesh.find("10 blocks, 7680 cells"), std::string::npos) << mesh;
  run(kFoamBin / "blockMesh", {"-case", (c / "openfoam").string()}, "blockMesh", 0);
  const std::string checkMesh =
      run(kFoamBin / "checkMesh", {"-case", (c / "openfoam").string()}, "checkMesh", 0);
  EXPECT_NE(checkMesh.find("Mesh OK."), std::string::npos) << checkMesh;
  EXPECT_NE(checkMesh.find("cells:            7680"), std::string::npos) << checkMesh;
  // Run again: the same files are not an error; a changed description needs --force.
  run(kBin / "coredem", {"mesh", (dir / "vessel.yaml").string(), "--out", c.string()}, "mesh2", 0);
  writeAll(dir / "vessel.yaml", readAll(dir / "vessel.yaml") + "origin: [0, 0, 0.001]\n");
  EXPECT_NE(run(kBin / "coredem", {"mesh", (dir / "vessel.yaml").string(), "--out", c.string()},
                "mesh3", 1)
                .find("exists and differs; give --force"),
            std::string::npos);

  const std::string part =
      replaceAll(readAll(c / "vessel.case.yaml"), "superficial_velocity: [0, 0, 0]",
                 "superficial_velocity: [0, 0, 10.8]");
  writeAll(c / "case.yaml",
           withoutSections(readAll(c / "case.yaml"), {"grid", "walls", "gravity"}) + part);
  const std::string check = run(kBin / "coredem", {"check", c.string()}, "check", 0);
  EXPECT_NE(check.find("case.yaml: valid"), std::string::npos) << check;

  // The box: one block, the coupling grid is the mesh.
  const fs::path b = dir / "box";
  fs::copy(fs::path(COREDEM_SOURCE_DIR) / "cases" / "fluidized-bed-cooling", b,
           fs::copy_options::recursive);
  fs::remove(b / "openfoam" / "system" / "blockMeshDict");
  writeAll(dir / "box.yaml", "shape: box\naxis: y\nsize: [0.02, 0.06, 0.004]\ncell_size: 0.002\n");
  run(kBin / "coredem", {"mesh", (dir / "box.yaml").string(), "--out", b.string()}, "mesh-box", 0);
  run(kFoamBin / "blockMesh", {"-case", (b / "openfoam").string()}, "blockMesh-box", 0);
  EXPECT_NE(run(kFoamBin / "checkMesh", {"-case", (b / "openfoam").string()}, "checkMesh-box", 0)
                .find("Mesh OK."),
            std::string::npos);
  writeAll(
      b / "case.yaml",
      withoutSections(readAll(b / "case.yaml"), {"grid", "walls", "gravity", "inlets", "outlets"}) +
          replaceAll(readAll(b / "vessel.case.yaml"), "superficial_velocity: [0, 0, 0]",
                     "superficial_velocity: [0, 1.5, 0]"));
  const std::string boxCheck = run(kBin / "coredem", {"check", b.string()}, "check-box", 0);
  EXPECT_NE(boxCheck.find("case.yaml: valid"), std::string::npos) << boxCheck;
}
