// Cylinder, cone and STL mesh walls in the case file (docs/case-schema.md "walls"): a good
// section, each bad input with its error, the pre-flight geometry (walls in the grid, particles
// inside the walls), the point-in-closed-surface test, the way through Configure v1.4 to the DEM
// core, and the refusal of a DEM server older than protocol 1.4.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <coredem/dem/dem_system.h>
#include <coredem/dem/triangle_mesh.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/preflight.h>
#include <coredem/orchestrator/wall_geometry.h>
#include <coredem/protocol/validate.h>
#include <coredem/protocol/version.h>
#include <coredem/v1/configure.pb.h>

#include "admission.h"
#include "case_text.h"
#include "configure.h"
#include "configure_map.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;
namespace dem = coredem::dem;
namespace v1 = coredem::v1;

namespace {

/// A 12 x 12 x 32 cm grid around a column: a capped cylinder (r = 5 cm, 0-30 cm), a hopper cone
/// at its foot (touched from both sides) and a closed STL cylinder (r = 5.5 cm, 0-31 cm).
const char* kCase = R"(name: walls
time: {end: 0.01, dt: 0.001}
grid:
  origin: [-0.06, -0.06, 0]
  spacing: [0.01, 0.01, 0.01]
  cells: [12, 12, 32]
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - name: bed
    material: glass
    count: 10
    diameter: 0.004
    region: {min: [-0.02, -0.02, 0.1], max: [0.02, 0.02, 0.2]}
walls:
  cylinders:
    - point: [0, 0, 0]
      axis: [0, 0, 2]
      radius: 0.05
      from: 0.0
      to: 0.3
      side: inside
      caps: [start]
  cones:
    - {point: [0, 0, 0], axis: [0, 0, 1], from: 0.0, to: 0.05, radius_from: 0.005, radius_to: 0.05, side: both, caps: []}
  meshes:
    - file: column.stl
      closed: true
)";

/// A folder of its own with the STL files of the tests: column.stl (closed, m), column-mm.stl (the
/// same in mm), tube.stl (open: no caps).
class CaseWalls : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir() = fs::temp_directory_path() / ("coredem-case-walls-" + std::to_string(::getpid()));
    fs::create_directories(dir());
    const auto column =
        dem::meshRevolved({0, 0, 0}, {0, 0, 1}, {{0.0, 0.055}, {0.31, 0.055}}, 32, true, true);
    dem::writeStl(column, dir() / "column.stl", true);
    dem::TriangleMesh mm = column;
    for (double& v : mm.vertices) {
      v *= 1000.0;
    }
    dem::writeStl(mm, dir() / "column-mm.stl", false);
    dem::writeStl(
        dem::meshRevolved({0, 0, 0}, {0, 0, 1}, {{0.0, 0.055}, {0.31, 0.055}}, 32, false, false),
        dir() / "tube.stl", true);
    // Floors of 10 cm × 10 cm at z = 1 cm: squares of 5 mm and of 0.5 mm (triangles of 12.5 and
    // 0.125 mm² under particles of 4 mm: about 0.5 and 44 within a particle's heat reach).
    for (const auto& [name, quads] : {std::pair{"floor-coarse.stl", 20}, {"floor-fine.stl", 200}})
      dem::writeStl(
          dem::meshRectangle({-0.05, -0.05, 0.01}, {0.1, 0, 0}, {0, 0.1, 0}, quads, quads),
          dir() / name, true);
  }
  static void TearDownTestSuite() { fs::remove_all(dir()); }
  static fs::path& dir() {
    static fs::path d;
    return d;
  }

  static CaseConfig parse(const std::string& text) {
    return parseCase(text, dir() / "case.yaml", dir());
  }
  static std::string errorOf(const std::string& text) {
    try {
      const CaseConfig c = parse(text);
      (void)checkCaseConsistency(c);
    } catch (const CaseError& e) {
      return e.what();
    }
    return "";
  }
};

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

} // namespace

TEST_F(CaseWalls, AGoodSectionIsParsedAndPassesPreflight) {
  const CaseConfig c = parse(kCase);
  EXPECT_TRUE(c.usesWallShapes());
  ASSERT_EQ(c.walls.revolved.size(), 2u);
  const RevolvedWallConfig& cyl = c.walls.revolved[0];
  EXPECT_FALSE(cyl.cone);
  EXPECT_EQ(cyl.key(), "walls.cylinders[0]");
  EXPECT_EQ(cyl.axis, (Vec3{0, 0, 1})); // normalised
  EXPECT_EQ(cyl.radiusFrom, 0.05);
  EXPECT_EQ(cyl.radiusTo, 0.05);
  EXPECT_TRUE(cyl.finite);
  EXPECT_EQ(cyl.to, 0.3);
  EXPECT_EQ(cyl.side, "inside");
  EXPECT_TRUE(cyl.capStart);
  EXPECT_FALSE(cyl.capEnd);
  const RevolvedWallConfig& cone = c.walls.revolved[1];
  EXPECT_TRUE(cone.cone);
  EXPECT_EQ(cone.key(), "walls.cones[0]");
  EXPECT_EQ(cone.radiusFrom, 0.005);
  EXPECT_EQ(cone.radiusTo, 0.05);
  EXPECT_EQ(cone.side, "both");
  ASSERT_EQ(c.walls.meshes.size(), 1u);
  const MeshWallConfig& m = c.walls.meshes[0];
  EXPECT_EQ(m.file, "column.stl");
  EXPECT_EQ(m.path, dir() / "column.stl"); // relative to the case folder
  EXPECT_TRUE(m.closed);
  EXPECT_EQ(m.scale, 1.0);
  EXPECT_EQ(m.triangles.size(), 3u * 4 * 32); // 32 side quads and two 32-triangle fans
  EXPECT_TRUE(checkCaseConsistency(c).empty());
  // An infinite cylinder, outside: no extent, no caps.
  const CaseConfig inf = parse(replace(
      replace(replace(kCase, "      from: 0.0\n      to: 0.3\n", ""), "caps: [start]", "caps: []"),
      "side: inside", "side: outside"));
  EXPECT_FALSE(inf.walls.revolved[0].finite);
  EXPECT_EQ(inf.walls.revolved[0].side, "outside");
  // Without the new keys a case needs no v1.4 server.
  const std::string plain =
      "name: plain" + std::string(kCase).substr(11, std::string(kCase).find("walls:") - 11);
  EXPECT_FALSE(parse(plain).usesWallShapes());
}

TEST_F(CaseWalls, BadInputsAreRefusedNamingTheKey) {
  EXPECT_HAS(errorOf(replace(kCase, "side: inside", "side: within")),
             "walls.cylinders[0].side: 'within' is not allowed; allowed: inside, outside, both");
  EXPECT_HAS(errorOf(replace(kCase, "side: inside", "side: within")), "case.yaml:");
  // caps without from/to (an infinite cylinder)
  const std::string noExtent = replace(kCase, "      from: 0.0\n      to: 0.3\n", "");
  EXPECT_HAS(errorOf(noExtent), "walls.cylinders[0].caps: an infinite cylinder has no ends to cap");
  EXPECT_HAS(errorOf(replace(kCase, "      to: 0.3\n", "")),
             "walls.cylinders[0].from: give both 'from' and 'to'");
  EXPECT_HAS(errorOf(replace(kCase, "caps: [start]", "caps: [start, top]")),
             "walls.cylinders[0].caps[1]: 'top' is not an end; allowed: start, end");
  EXPECT_HAS(errorOf(replace(kCase, "caps: [start]", "caps: [end, end]")), "listed twice");
  EXPECT_HAS(errorOf(replace(kCase, "radius: 0.05", "radius: 0")), "walls.cylinders[0].radius");
  EXPECT_HAS(errorOf(replace(kCase, "radius: 0.05", "radius: -0.05")), "m, > 0");
  EXPECT_HAS(errorOf(replace(kCase, "to: 0.3", "to: -0.1")), "walls.cylinders[0].to");
  EXPECT_HAS(errorOf(replace(kCase, "axis: [0, 0, 2]", "axis: [0, 0, 0]")),
             "walls.cylinders[0].axis: must be a nonzero direction");
  EXPECT_HAS(errorOf(replace(kCase, "from: 0.0, to: 0.05, radius_from", "radius_from")),
             "walls.cones[0]: missing required key 'from'");
  EXPECT_HAS(errorOf(replace(kCase, "radius_from: 0.005, radius_to: 0.05",
                             "radius_from: 0, radius_to: 0")),
             "walls.cones[0].radius_to: a cone needs a radius > 0");
  EXPECT_HAS(errorOf(replace(kCase, "side: both", "side: sideways")), "walls.cones[0].side");
  EXPECT_HAS(errorOf(replace(kCase, "      caps: [start]\n", "      cap: [start]\n")),
             "unknown key");
  // a missing STL file
  const std::string missing = errorOf(replace(kCase, "file: column.stl", "file: hopper.stl"));
  EXPECT_HAS(missing, "walls.meshes[0].file: file 'hopper.stl' not found");
  EXPECT_HAS(missing, (dir() / "hopper.stl").string());
  // not a regular file (issue 39 item 5: reported as "not found" before, and a FIFO would block)
  fs::create_directories(dir() / "adir.stl");
  EXPECT_HAS(errorOf(replace(kCase, "file: column.stl", "file: adir.stl")),
             "is a directory, not a regular file");
  ASSERT_EQ(::mkfifo((dir() / "pipe.stl").c_str(), 0600), 0);
  EXPECT_HAS(errorOf(replace(kCase, "file: column.stl", "file: pipe.stl")),
             "is a FIFO, not a regular file");
  fs::create_symlink("/dev/zero", dir() / "zero.stl");
  EXPECT_HAS(errorOf(replace(kCase, "file: column.stl", "file: zero.stl")),
             "is a device, not a regular file");
  // a scale that is no length unit
  EXPECT_HAS(errorOf(replace(kCase, "file: column.stl", "file: column.stl\n      scale: 1.0e-30")),
             "walls.meshes[0].scale: 1e-30 is not a length unit");
  // an STL in mm without scale, and with it
  const std::string mm = errorOf(replace(kCase, "file: column.stl", "file: column-mm.stl"));
  EXPECT_HAS(mm, "walls.meshes[0].file: column-mm.stl: the STL is probably in millimetres");
  EXPECT_HAS(mm, "scale: 0.001");
  EXPECT_EQ(errorOf(replace(kCase, "file: column.stl", "file: column-mm.stl\n      scale: 0.001")),
            "");
  EXPECT_HAS(errorOf(replace(kCase, "file: column.stl", "file: column.stl\n      scale: 0")),
             "walls.meshes[0].scale");
  // an open mesh required to be closed; allowed when not
  const std::string open = errorOf(replace(kCase, "file: column.stl", "file: tube.stl"));
  EXPECT_HAS(open, "walls.meshes[0].file: tube.stl: the surface is not closed");
  EXPECT_HAS(open, "walls.meshes[0].closed: false");
  EXPECT_EQ(errorOf(replace(replace(kCase, "file: column.stl", "file: tube.stl"), "closed: true",
                            "closed: false")),
            "");
}

TEST_F(CaseWalls, PreflightKeepsTheParticlesInsideTheWalls) {
  // Particles beyond the cylinder's radius (the region reaches x = 6 cm > 5 cm - r).
  const std::string out =
      errorOf(replace(kCase, "max: [0.02, 0.02, 0.2]", "max: [0.055, 0.02, 0.2]"));
  EXPECT_HAS(out, "particles[0].region: particles[0] (bed): a particle centre at");
  EXPECT_HAS(out, "the cylinder walls.cylinders[0]");
  EXPECT_HAS(out, "move the region towards the axis");
  // Beyond its axial extent the cylinder does not hold them: only the part within is checked
  // (without the mesh, which would refuse the region above it).
  const std::string noMesh = std::string(kCase).substr(0, std::string(kCase).find("  meshes:"));
  const std::string above = replace(replace(noMesh, "min: [-0.02, -0.02, 0.1]",
                                            "min: [-0.055, "
                                            "-0.02, 0.305]"),
                                    "max: [0.02, 0.02, 0.2]", "max: [0.02, 0.02, 0.315]");
  EXPECT_EQ(errorOf(above), "");
  // ... but a region that crosses its end is checked where it overlaps: a cylinder over
  // 0.1-0.25 m and a region of centres over 0.052-0.313 m have no corner within the extent, only
  // the points where the region's edges cross the planes t = from and t = to, too far out.
  const std::string across =
      replace(replace(above, "min: [-0.055, -0.02, 0.305]", "min: [-0.055, -0.02, 0.05]"),
              "      from: 0.0\n      to: 0.3\n", "      from: 0.1\n      to: 0.25\n");
  EXPECT_HAS(errorOf(across), "a particle centre at [-0.053, -0.018, 0.1] (axial coordinate "
                              "0.1 m) is -0.00597321 m inside the cylinder walls.cylinders[0]");
  EXPECT_EQ(errorOf(replace(across, "min: [-0.055,", "min: [-0.02,")), "");
  // Explicit positions: one outside the cone (side inside).
  const std::string cone = replace(replace(noMesh, "side: both", "side: inside"),
                                   "    count: 10\n    diameter: 0.004\n    region: {min: [-0.02, "
                                   "-0.02, 0.1], max: [0.02, 0.02, 0.2]}\n",
                                   "    diameter: 0.004\n    positions: [[0, 0, 0.04], [0.03, 0, "
                                   "0.02]]\n");
  const std::string coneError = errorOf(cone);
  EXPECT_HAS(coneError, "particles[0].positions: particles[0] (bed): a particle centre at [0.03, "
                        "0, 0.02]");
  EXPECT_HAS(coneError, "the cone walls.cones[0]");
  EXPECT_EQ(errorOf(replace(cone, "[0.03, 0, 0.02]", "[0.01, 0, 0.03]")), "");
  // Outside a closed mesh (the cylinder wall out of the way: infinite and outside).
  const std::string meshOnly =
      replace(replace(replace(replace(replace(kCase, "      from: 0.0\n      to: 0.3\n", ""),
                                      "caps: [start]", "caps: []"),
                              "side: inside", "side: outside"),
                      "radius: 0.05", "radius: 0.001"),
              "- point: [0, 0, 0]", "- point: [0.045, 0.045, 0]");
  EXPECT_EQ(errorOf(meshOnly), "");
  const std::string meshOut =
      errorOf(replace(meshOnly, "max: [0.02, 0.02, 0.2]", "max: [0.02, 0.02, 0.318]"));
  EXPECT_HAS(meshOut, "lies outside the closed mesh wall walls.meshes[0] ('column.stl'");
  // Walls beyond the coupling grid.
  EXPECT_HAS(errorOf(replace(kCase, "radius: 0.05", "radius: 0.07")),
             "walls.cylinders[0]: the cylinder spans");
  EXPECT_HAS(errorOf(replace(kCase, "cells: [12, 12, 32]", "cells: [12, 12, 29]")),
             "walls.cylinders[0]: the cylinder spans");
  // The cylinder fits (to 0.3 m), the mesh (to 0.31 m) does not.
  EXPECT_HAS(errorOf(replace(kCase, "cells: [12, 12, 32]", "cells: [12, 12, 30]")),
             "walls.meshes[0].file: the mesh 'column.stl' spans");
}

TEST_F(CaseWalls, ClosedSurfaceContainsExactlyItsInside) {
  // A unit cube of 2 x 2 quads per face: lattice points on the mesh's own edge lines send rays
  // through edges and vertices, which must count once.
  dem::TriangleMesh cube;
  const auto face = [&](std::array<double, 3> o, std::array<double, 3> u, std::array<double, 3> v) {
    const dem::TriangleMesh f = dem::meshRectangle(o, u, v, 2, 2);
    const auto base = std::int32_t(cube.vertices.size() / 3);
    cube.vertices.insert(cube.vertices.end(), f.vertices.begin(), f.vertices.end());
    for (const auto t : f.triangles) {
      cube.triangles.push_back(base + t);
    }
  };
  face({0, 0, 0}, {0, 1, 0}, {1, 0, 0}); // z = 0, normal -z
  face({0, 0, 1}, {1, 0, 0}, {0, 1, 0}); // z = 1, +z
  face({0, 0, 0}, {1, 0, 0}, {0, 0, 1}); // y = 0, -y
  face({0, 1, 0}, {0, 0, 1}, {1, 0, 0}); // y = 1, +y
  face({0, 0, 0}, {0, 0, 1}, {0, 1, 0}); // x = 0, -x
  face({1, 0, 0}, {0, 1, 0}, {0, 0, 1}); // x = 1, +x
  const ClosedSurface s(cube.vertices, cube.triangles);
  int checked = 0;
  for (double x : {-0.5, 0.25, 0.5, 0.75, 1.5}) {
    for (double y : {-0.25, 0.0, 0.25, 0.5, 0.75, 1.0, 1.25}) {
      for (double z : {-0.25, 0.0, 0.25, 0.5, 0.75, 1.0, 1.25}) {
        const bool inside = x > 0 && x < 1 && y > 0 && y < 1 && z > 0 && z < 1;
        const bool onBoundary = (y == 0.0 || y == 1.0 || z == 0.0 || z == 1.0) && x > 0 && x < 1;
        if (!onBoundary) {
          EXPECT_EQ(s.contains({x, y, z}), inside) << x << " " << y << " " << z;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 150);
  // A revolved closed surface (the case's column): the axis and near the wall.
  const auto column =
      dem::meshRevolved({0, 0, 0}, {0, 0, 1}, {{0.0, 0.055}, {0.31, 0.055}}, 32, true, true);
  const ClosedSurface c(column.vertices, column.triangles);
  EXPECT_TRUE(c.contains({0, 0, 0.1}));
  EXPECT_TRUE(c.contains({0.054, 0, 0.3}));
  EXPECT_FALSE(c.contains({0.056, 0, 0.1}));
  EXPECT_FALSE(c.contains({0, 0, 0.32}));
  EXPECT_FALSE(c.contains({0, 0, -0.01}));
}

TEST_F(CaseWalls, ConfigureCarriesTheWallsToTheDemCore) {
  const CaseConfig c = parse(kCase);
  SubcyclePlan plan;
  plan.nSub = 10;
  plan.dtDem = 1e-4;
  v1::Configure sent = buildConfigure(c, dir(), 1e-3, plan);
  v1::Configure cfg;
  ASSERT_TRUE(cfg.ParseFromString(sent.SerializeAsString()));
  EXPECT_TRUE(coredem::protocol::validateConfigure(cfg).ok())
      << coredem::protocol::validateConfigure(cfg).toString();
  EXPECT_EQ(coredem::server::admitConfigure(cfg, coredem::server::limitsFor(1ull << 30, 1000)), "");
  ASSERT_EQ(cfg.walls().revolved_size(), 2);
  EXPECT_EQ(cfg.walls().revolved(0).side(), v1::WALL_SIDE_INSIDE);
  EXPECT_FALSE(cfg.walls().revolved(0).infinite());
  EXPECT_EQ(cfg.walls().revolved(1).side(), v1::WALL_SIDE_BOTH);
  ASSERT_EQ(cfg.walls().meshes_size(), 1);
  EXPECT_EQ(cfg.walls().meshes(0).name(), "column.stl");

  const dem::DemConfig d = coredem::server::toDemConfig(cfg, nullptr);
  ASSERT_EQ(d.walls.size(), 2u);
  const dem::Wall& cyl = d.walls[0];
  EXPECT_EQ(cyl.shape, dem::WallShape::Cylinder);
  EXPECT_EQ(cyl.normal, (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(cyl.radius, 0.05);
  EXPECT_EQ(cyl.start, 0.0);
  EXPECT_EQ(cyl.end, 0.3);
  EXPECT_EQ(cyl.side, dem::WallSide::Inside);
  EXPECT_TRUE(cyl.capStart);
  EXPECT_FALSE(cyl.capEnd);
  const dem::Wall& cone = d.walls[1];
  EXPECT_EQ(cone.shape, dem::WallShape::Cone);
  EXPECT_EQ(cone.radius, 0.005);
  EXPECT_EQ(cone.radiusEnd, 0.05);
  EXPECT_EQ(cone.end, 0.05);
  EXPECT_EQ(cone.side, dem::WallSide::Both);
  ASSERT_EQ(d.meshes.size(), 1u);
  EXPECT_EQ(d.meshes[0].name, "column.stl");
  EXPECT_EQ(d.meshes[0].vertices, c.walls.meshes[0].vertices);
  EXPECT_EQ(d.meshes[0].triangles, c.walls.meshes[0].triangles);
  // The DEM core accepts them and keeps the particles in.
  dem::DemSystem sys(d, dem::BackendKind::Cpu, 1);
  sys.advance(0.01, 1000); // Δt_DEM = 1e-5 s < t_col/50
  for (std::size_t i = 0; i < sys.particles().radius.size(); ++i) {
    const double x = sys.particles().position[3 * i], y = sys.particles().position[3 * i + 1];
    EXPECT_LT(std::hypot(x, y), 0.05);
  }

  // An infinite cylinder travels as infinite and arrives with ±inf extent.
  const CaseConfig inf = parse(
      replace(replace(kCase, "      from: 0.0\n      to: 0.3\n", ""), "caps: [start]", "caps: []"));
  const dem::DemConfig di =
      coredem::server::toDemConfig(buildConfigure(inf, dir(), 1e-3, plan), nullptr);
  EXPECT_TRUE(std::isinf(di.walls[0].start) && di.walls[0].start < 0);
  EXPECT_TRUE(std::isinf(di.walls[0].end) && di.walls[0].end > 0);
}

TEST_F(CaseWalls, LimitsAreCheckedBeforeAnythingIsBuilt) {
  const CaseConfig c = parse(kCase);
  SubcyclePlan plan;
  plan.nSub = 10;
  plan.dtDem = 1e-4;
  const v1::Configure cfg = buildConfigure(c, dir(), 1e-3, plan);
  // The server's count limits (admission) name the field, the value and the limit.
  coredem::server::Limits l = coredem::server::limitsFor(1ull << 30, 1000);
  l.meshTriangles = 100;
  EXPECT_HAS(coredem::server::admitConfigure(cfg, l),
             "walls.meshes[].triangles (total, triangles) = 128 exceeds the limit 100");
  l = coredem::server::limitsFor(1ull << 30, 1000);
  l.revolvedWalls = 1;
  EXPECT_HAS(coredem::server::admitConfigure(cfg, l), "walls.revolved (count) = 2");
  // The message limit: the orchestrator refuses before sending.
  EXPECT_EQ(configureSizeRefusal(cfg, coredem::protocol::kDefaultMaxMessageBytes), "");
  const std::string big = configureSizeRefusal(cfg, 1000);
  EXPECT_HAS(big, "128 triangles in walls.meshes");
  EXPECT_HAS(big, "--max-message-mb");
  // About 24 bytes per triangle of a welded mesh: 10^6 triangles fit the 256 MiB default.
  const double perTriangle =
      double(cfg.walls().meshes(0).ByteSizeLong()) / double(c.walls.meshes[0].triangles.size() / 3);
  EXPECT_LT(perTriangle * 1e6, double(coredem::protocol::kDefaultMaxMessageBytes) / 4);
}

TEST_F(CaseWalls, AServerOlderThanOneDotFourIsRefused) {
  const CaseConfig c = parse(kCase);
  const std::string why = demVersionRefusal(c, 1, 3);
  EXPECT_HAS(why, "speaks protocol 1.3");
  EXPECT_HAS(why, "1 in walls.cylinders, 1 in walls.cones, 1 in walls.meshes");
  EXPECT_HAS(why, "need protocol 1.4");
  EXPECT_HAS(why, "Use a coredem-dem built from this release");
  EXPECT_EQ(demVersionRefusal(c, 1, coredem::protocol::kMinorWallShapes), "");
  EXPECT_EQ(demVersionRefusal(c, 1, 5), "");
  // A case without them still runs with a 1.0 server.
  const std::string plain = std::string(kCase).substr(0, std::string(kCase).find("walls:"));
  EXPECT_EQ(demVersionRefusal(parse(plain), 1, 0), "");
}

// A mesh wall much finer than the smallest particle is accepted with a warning naming the mesh,
// the triangles' mean area, the particle diameter and how many triangles a particle reaches; a
// coarser one gets none.
TEST_F(CaseWalls, AMeshMuchFinerThanTheParticlesIsWarnedAbout) {
  const std::string column = "    - file: column.stl\n      closed: true\n";
  const auto warnings = [&](const char* floor) {
    return checkCaseConsistency(
        parse(replace(kCase, column, column + "    - file: " + floor + "\n")));
  };
  EXPECT_TRUE(warnings("floor-coarse.stl").empty());
  const std::vector<std::string> fine = warnings("floor-fine.stl");
  ASSERT_EQ(fine.size(), 1u);
  EXPECT_HAS(fine[0], "walls.meshes[1].file: the mesh 'floor-fine.stl' has triangles of 0.125 mm²");
  EXPECT_HAS(fine[0], "smallest particle (d = 4 mm): about 44 lie within");
  EXPECT_HAS(fine[0], "the nearest 16 are considered");
}
