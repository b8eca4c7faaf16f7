// Vessels from one description (foam_vessel.h, `coredem mesh`): the description's refusals, the
// O-grid's vertices and blocks against the geometry (every arc corner on its circle, the square
// at half the radius, the cell count of 5 blocks per section), the inscribed DEM walls and the
// coupling grid of the case.yaml part, the box. blockMesh and checkMesh run on the result in the
// e2e test CoredemFoamMap.VesselFromOneDescriptionMeshesAndPassesCheck.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <coredem/participant/foam_vessel.h>

using namespace coredem::orchestrator;
namespace fs = std::filesystem;

namespace {

fs::path writeVessel(const std::string& name, const std::string& text) {
  const fs::path f = fs::temp_directory_path() / ("coredem-vessel-" + name + ".yaml");
  std::ofstream(f) << text;
  return f;
}

std::string errorOf(const std::string& text) {
  try {
    vesselFiles(readVesselSpec(writeVessel("bad", text)), "v.yaml");
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// The vertices of a blockMeshDict's `vertices ( ... );` list.
std::vector<Vec3> vertices(const std::string& dict) {
  const auto a = dict.find("\nvertices"), b = dict.find(");", a);
  const std::string list = dict.substr(a, b - a);
  std::vector<Vec3> out;
  const std::regex re(R"(\(([-0-9.e]+) ([-0-9.e]+) ([-0-9.e]+)\))");
  for (std::sregex_iterator it(list.begin(), list.end(), re), end; it != end; ++it) {
    out.push_back({std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3])});
  }
  return out;
}

} // namespace

TEST(Vessel, BadDescriptionsAreRefusedNamingTheKey) {
  const std::string cyl = "shape: cylinder\nradius: 0.015\nheight: 0.12\ncell_size: 0.002\n";
  EXPECT_EQ(errorOf(cyl), "");
  EXPECT_TRUE(contains(errorOf(cyl + "cone: {height: 0.12, radius: 0.005}\n"),
                       "cone.height: 0.12 m leaves no cylinder above it"));
  EXPECT_TRUE(contains(errorOf(cyl + "cone: {height: 0.01, radius: 0.02}\n"), "cone.radius"));
  EXPECT_TRUE(contains(errorOf(cyl + "around: 30\n"), "around: 30 is not a multiple of 4"));
  EXPECT_TRUE(contains(errorOf(cyl + "size: [1, 1, 1]\n"), "size: a cylinder has radius"));
  EXPECT_TRUE(contains(errorOf(cyl + "radiuss: 1\n"), "radiuss"));
  EXPECT_TRUE(contains(errorOf("shape: box\nsize: [0.1, 0.1, 0.1]\nradius: 1\ncell_size: 0.01\n"),
                       "radius: a box has 'size'"));
  EXPECT_TRUE(contains(errorOf("shape: sphere\ncell_size: 0.01\n"), "shape"));
  EXPECT_TRUE(contains(errorOf("shape: box\nsize: [1, 1, 1]\ncell_size: 1.0e-4\n"),
                       "the mesh would have 1000000000000 cells"));
  EXPECT_TRUE(contains(errorOf(cyl + "cell_size: 0.001\n"), "cell_size"));
}

// The cylindrical bed's vessel (cases/cylindrical-bed): R 15 mm, 120 mm, a cone 15 mm high from
// r 5 mm, 32 around, 2.5 mm cells: its hand-written O-grid had 7680 cells in 10 blocks.
TEST(Vessel, CylinderOGridFollowsTheGeometry) {
  const VesselSpec s = readVesselSpec(
      writeVessel("bed", "shape: cylinder\naxis: z\norigin: [0.001, -0.002, 0.003]\nradius: 0.015\n"
                         "height: 0.12\ncone: {height: 0.015, radius: 0.005}\ncell_size: 0.0025\n"
                         "around: 32\n"));
  const VesselFiles f = vesselFiles(s, "bed.yaml");
  EXPECT_EQ(f.cells, 7680);
  const std::regex hex(R"(hex \(([0-9 ]+)\) \((\d+) (\d+) (\d+)\))");
  long long cells = 0;
  int blocks = 0;
  for (std::sregex_iterator it(f.blockMeshDict.begin(), f.blockMeshDict.end(), hex), end; it != end;
       ++it, ++blocks) {
    cells += std::stoll((*it)[2]) * std::stoll((*it)[3]) * std::stoll((*it)[4]);
  }
  EXPECT_EQ(blocks, 10);
  EXPECT_EQ(cells, f.cells);
  const auto v = vertices(f.blockMeshDict);
  ASSERT_EQ(v.size(), 24u);
  const double z[3] = {0.0, 0.015, 0.12}, r[3] = {0.005, 0.015, 0.015};
  for (int level = 0; level < 3; ++level) {
    for (int k = 0; k < 8; ++k) {
      const Vec3& p = v[std::size_t(8 * level + k)];
      const double dx = p[0] - 0.001, dy = p[1] + 0.002, rad = std::hypot(dx, dy);
      EXPECT_NEAR(p[2] - 0.003, z[level], 1e-12);
      // square corners at (±r/2, ±r/2), arc corners on the circle at 225, 315, 45, 135 degrees
      EXPECT_NEAR(rad, k < 4 ? r[level] / std::numbers::sqrt2 : r[level], 1e-10)
          << "level " << level << " vertex " << k;
    }
  }
  // The arcs pass through the circle at 0, 90, 180, 270 degrees.
  EXPECT_TRUE(contains(f.blockMeshDict, "arc 12 13 (0.001 -0.017 0.018)"));
  // The case.yaml part: inscribed walls r cos(pi/32), the coupling grid around the vessel.
  const YAML::Node y = YAML::Load(f.caseYaml);
  const double c = std::cos(std::numbers::pi / 32.0);
  EXPECT_NEAR(y["walls"]["cylinders"][0]["radius"].as<double>(), 0.015 * c, 1e-12);
  EXPECT_NEAR(y["walls"]["cones"][0]["radius_from"].as<double>(), 0.005 * c, 1e-12);
  EXPECT_NEAR(y["walls"]["cones"][0]["radius_to"].as<double>(), 0.015 * c, 1e-12);
  EXPECT_EQ(y["grid"]["cells"][0].as<int>(), 12);
  EXPECT_EQ(y["grid"]["cells"][2].as<int>(), 48);
  EXPECT_NEAR(y["grid"]["origin"][0].as<double>(), 0.001 - 0.015, 1e-12);
  EXPECT_NEAR(y["gravity"][2].as<double>(), -9.81, 0.0);
  EXPECT_EQ(y["inlets"][0]["patch"].as<std::string>(), "inlet");
  EXPECT_EQ(y["outlets"][0]["patch"].as<std::string>(), "outlet");
}

// Other axes are cyclic permutations of (x, y, z): a vessel along y has its levels along y.
TEST(Vessel, AxisYPutsTheLevelsAlongY) {
  const VesselFiles f = vesselFiles(
      readVesselSpec(writeVessel("y", "shape: cylinder\naxis: y\nradius: 0.01\nheight: 0.05\n"
                                      "cell_size: 0.002\n")),
      "y.yaml");
  const auto v = vertices(f.blockMeshDict);
  ASSERT_EQ(v.size(), 16u);
  for (std::size_t k = 0; k < v.size(); ++k) {
    EXPECT_NEAR(v[k][1], k < 8 ? 0.0 : 0.05, 1e-12);
  }
  EXPECT_EQ(f.cells, 25 * (5 * 5 + 4 * 5 * 3)); // 20 around, 3 radially, 25 layers
  EXPECT_TRUE(contains(f.caseYaml, "gravity: [0, -9.81, 0]"));
}

TEST(Vessel, BoxIsOneBlockAndItsGridIsTheMesh) {
  const VesselFiles f = vesselFiles(
      readVesselSpec(writeVessel("box", "shape: box\naxis: y\nsize: [0.02, 0.06, 0.004]\n"
                                        "cell_size: 0.002\n")),
      "box.yaml");
  EXPECT_EQ(f.cells, 600);
  EXPECT_TRUE(contains(f.blockMeshDict, "hex (0 1 2 3 4 5 6 7) (10 30 2)"));
  EXPECT_TRUE(contains(f.blockMeshDict, "inlet  { type patch; faces ((0 1 5 4)); }"));
  EXPECT_TRUE(contains(f.blockMeshDict, "outlet { type patch; faces ((3 7 6 2)); }"));
  const YAML::Node y = YAML::Load(f.caseYaml);
  EXPECT_EQ(y["grid"]["cells"][1].as<int>(), 30);
  EXPECT_NEAR(y["grid"]["spacing"][1].as<double>(), 0.002, 1e-15);
  EXPECT_NEAR(y["walls"]["box"]["max"][1].as<double>(), 0.06, 1e-15);
}
