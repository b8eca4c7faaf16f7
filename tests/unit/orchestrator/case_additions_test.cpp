// Case-file additions of the verification cases (docs/case-schema.md): explicit particle
// positions, the forced DEM step time.dt_dem, and the DEM option motion: frozen (held particles).
#include <cmath>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>

#include <coredem/dem/dem_system.h>
#include <coredem/orchestrator/case_config.h>

#include "case_text.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::errorOf;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;

namespace {

const char* kCase = R"(name: additions
time:
  end: 1.0
  dt: 0.1
  dt_dem: 1.0e-3
grid:
  spacing: [0.01, 0.01, 0.01]
  cells: [1, 1, 1]
materials:
  - {name: a, density: 420, k_n: 1.6e4, e_n: 0.9}
particles:
  - name: pair
    material: a
    diameter: 3.0e-3
    positions: [[0.005, 0.002, 0.005], [0.005, 0.0049, 0.005]]
models: {motion: frozen}
)";

} // namespace

TEST(CaseAdditions, PositionsGiveCountAndExplicitPacking) {
  const CaseConfig c = parseCase(kCase, "case.yaml", fs::temp_directory_path());
  ASSERT_EQ(c.particles.size(), 1u);
  const auto& p = c.particles[0];
  EXPECT_EQ(p.count, 2u);
  EXPECT_EQ(p.packing, "explicit");
  ASSERT_EQ(p.positions.size(), 2u);
  EXPECT_DOUBLE_EQ(p.positions[1][1], 0.0049);
  EXPECT_DOUBLE_EQ(c.dtDem, 1.0e-3);
  ASSERT_EQ(c.models.size(), 1u);
  EXPECT_EQ(c.models[0].first, "motion");
  EXPECT_EQ(c.models[0].second, "frozen");
}

TEST(CaseAdditions, CountMatchingPositionsIsAccepted) {
  const std::string text =
      replace(kCase, "    diameter: 3.0e-3\n", "    diameter: 3.0e-3\n    count: 2\n");
  EXPECT_EQ(errorOf(text), "");
}

TEST(CaseAdditions, BadPositionsAreRefused) {
  // count disagreeing with the positions
  std::string e =
      errorOf(replace(kCase, "    diameter: 3.0e-3\n", "    diameter: 3.0e-3\n    count: 3\n"));
  EXPECT_NE(e.find("particles[0].count"), std::string::npos) << e;
  EXPECT_NE(e.find("3 particles but 2 positions"), std::string::npos) << e;
  // a centre with two numbers
  e = errorOf(replace(kCase, "[0.005, 0.0049, 0.005]", "[0.005, 0.0049]"));
  EXPECT_NE(e.find("particles[0].positions[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a centre [x, y, z]"), std::string::npos) << e;
  // not a number
  e = errorOf(replace(kCase, "[0.005, 0.0049, 0.005]", "[0.005, far, 0.005]"));
  EXPECT_NE(e.find("particles[0].positions[1][1]"), std::string::npos) << e;
  // an empty list
  e = errorOf(replace(kCase, "[[0.005, 0.002, 0.005], [0.005, 0.0049, 0.005]]", "[]"));
  EXPECT_NE(e.find("non-empty list of particle centres"), std::string::npos) << e;
  // positions and a region together
  e = errorOf(replace(kCase, "    diameter: 3.0e-3\n",
                      "    diameter: 3.0e-3\n    region: {min: [0, 0, 0], max: [1, 1, 1]}\n"));
  EXPECT_NE(e.find("particles[0].region"), std::string::npos) << e;
  EXPECT_NE(e.find("not used with 'positions'"), std::string::npos) << e;
  // packing other than explicit with positions
  e = errorOf(
      replace(kCase, "    diameter: 3.0e-3\n", "    diameter: 3.0e-3\n    packing: random\n"));
  EXPECT_NE(e.find("particles[0].packing"), std::string::npos) << e;
  // no positions and no region
  e = errorOf(replace(kCase, "    positions: [[0.005, 0.002, 0.005], [0.005, 0.0049, 0.005]]\n",
                      "    count: 2\n"));
  EXPECT_NE(e.find("missing required key 'region'"), std::string::npos) << e;
}

TEST(CaseAdditions, DtDemMustDivideDt) {
  EXPECT_EQ(errorOf(replace(kCase, "dt_dem: 1.0e-3", "dt_dem: 0.1")), ""); // n_sub = 1
  EXPECT_EQ(errorOf(replace(kCase, "dt_dem: 1.0e-3", "dt_dem: 3.3333333333333335e-2")), "");
  std::string e = errorOf(replace(kCase, "dt_dem: 1.0e-3", "dt_dem: 3.0e-2"));
  EXPECT_NE(e.find("time.dt_dem"), std::string::npos) << e;
  EXPECT_NE(e.find("is not an integer >= 1"), std::string::npos) << e;
  e = errorOf(replace(kCase, "dt_dem: 1.0e-3", "dt_dem: 0.2")); // larger than dt
  EXPECT_NE(e.find("is not an integer >= 1"), std::string::npos) << e;
  e = errorOf(replace(kCase, "dt_dem: 1.0e-3", "dt_dem: 0"));
  EXPECT_NE(e.find("time.dt_dem"), std::string::npos) << e;
  e = errorOf(replace(kCase, "dt_dem: 1.0e-3", "dt_dem: often"));
  EXPECT_NE(e.find("expected a number"), std::string::npos) << e;
  e = errorOf(replace(kCase, "  dt_dem: 1.0e-3\n",
                      "  dt_dem: 1.0e-3\n  adaptive: {courant: 0.5, dt_min: 0.01, dt_max: 0.2}\n"));
  EXPECT_NE(e.find("needs a fixed time.dt"), std::string::npos) << e;
  // absent: 0, the plan comes from the DEM's stable step
  const CaseConfig c =
      parseCase(replace(kCase, "  dt_dem: 1.0e-3\n", ""), "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(c.dtDem, 0.0);
}

namespace {

/// The pair of kCase in the DEM core: overlapping by 0.1 mm, gravity on, soft springs.
coredem::dem::DemConfig pairConfig(bool frozen) {
  coredem::dem::DemConfig cfg;
  cfg.materials[0].kn = 1.6e4;
  cfg.materials[0].en = 0.9;
  cfg.gravity = {0.0, 0.0, -9.81};
  cfg.frozenMotion = frozen;
  coredem::dem::ParticleSet s;
  s.packing = coredem::dem::Packing::Explicit;
  s.diameter = 3.0e-3;
  s.density = 420.0;
  s.positions = {0.005, 0.002, 0.005, 0.005, 0.0049, 0.005};
  s.velocities = {0.0, 0.1, 0.0, 0.0, 0.0, 0.0};
  s.count = 2;
  cfg.particleSets.push_back(s);
  return cfg;
}

} // namespace

TEST(CaseAdditions, FrozenMotionHoldsParticles) {
  coredem::dem::DemSystem frozen(pairConfig(true));
  EXPECT_EQ(frozen.dtDemMax(), std::numeric_limits<double>::max()); // no collision limit
  const auto before = frozen.particles();
  frozen.advance(0.01, 10);
  const auto after = frozen.particles();
  ASSERT_EQ(after.count, 2u);
  for (std::size_t i = 0; i < after.count; ++i) {
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(after.velocity[3 * i + d], 0.0);
      EXPECT_EQ(after.angularVelocity[3 * i + d], 0.0);
    }
  }
  for (std::size_t i = 0; i < after.count; ++i) {
    for (std::size_t j = 0; j < before.count; ++j) {
      if (before.globalId[j] == after.globalId[i]) {
        for (int d = 0; d < 3; ++d) {
          EXPECT_EQ(after.position[3 * i + d], before.position[3 * j + d]) << "particle " << i;
        }
      }
    }
  }
  // The same pair without the option moves (contact, gravity, initial velocity), and its
  // stable step is t_col/50.
  coredem::dem::DemSystem free(pairConfig(false));
  EXPECT_LT(free.dtDemMax(), 1e-4);
  const int nSub = int(std::ceil(0.01 / free.dtDemMax()));
  free.advance(0.01, nSub);
  const auto moved = free.particles();
  double shift = 0.0;
  for (std::size_t i = 0; i < moved.count; ++i) {
    for (std::size_t j = 0; j < before.count; ++j) {
      if (before.globalId[j] == moved.globalId[i]) {
        shift = std::max(shift, std::abs(moved.position[3 * i + 2] - before.position[3 * j + 2]));
      }
    }
  }
  EXPECT_GT(shift, 1e-4); // fell ~0.5 mm under gravity in 10 ms
}

TEST(CaseAdditions, FrozenIsPartOfTheConfigHash) {
  coredem::dem::DemSystem frozen(pairConfig(true));
  coredem::dem::DemSystem free(pairConfig(false));
  EXPECT_NE(frozen.configHash(), free.configHash());
}
