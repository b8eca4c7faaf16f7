// Contact materials in the case file (docs/case-schema.md `materials[i]`, `material_pairs`, the
// walls' `material`; protocol 1.6): parsing and errors, Configure v1.6 to the DEM core, the
// pre-flight Δt_DEM equal to the DEM's, and the refusal of a DEM server older than 1.6.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include <coredem/dem/dem_system.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/protocol/validate.h>
#include <coredem/protocol/version.h>
#include <coredem/v1/configure.pb.h>

#include "case_text.h"
#include "configure.h"
#include "configure_map.h"
#include "dem_step.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::errorOf;
using coredem::orchestrator::test::replace;
namespace dem = coredem::dem;
namespace v1 = coredem::v1;

namespace {

/// A pseudo-2D bed: Hertz–Mindlin, glass beads between frictionless perspex front and back
/// planes, a steel floor (the box), glass–steel restitution 0.5.
const char* kCase = R"(name: contact
time: {end: 0.01, dt: 0.001}
grid:
  origin: [0, 0, 0]
  spacing: [0.01, 0.002, 0.01]
  cells: [4, 2, 4]
materials:
  - {name: glass, density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.25, e_n: 0.9, friction: 0.4}
  - {name: steel, density: 7800, youngs_modulus: 2.0e8, e_n: 0.8}
  - {name: perspex, density: 1200, youngs_modulus: 3.0e7, e_n: 0.9, friction: 0.0}
material_pairs:
  - {materials: [glass, steel], e_n: 0.5}
particles:
  - name: bed
    material: glass
    count: 20
    diameter: 0.001
    region: {min: [0.005, 0.001, 0.005], max: [0.035, 0.003, 0.03]}
walls:
  box: {min: [0, 0, 0], max: [0.04, 0.004, 0.04], material: steel}
  planes:
    - {point: [0, 0.0005, 0], normal: [0, 1, 0], material: perspex}
    - {point: [0, 0.0035, 0], normal: [0, -1, 0], material: perspex}
models:
  contact: hertz-mindlin
)";

CaseConfig parse(const std::string& text) {
  return parseCase(text, "cases/x/case.yaml", std::filesystem::temp_directory_path());
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

} // namespace

TEST(CaseContact, MaterialsPairsAndWallMaterialsReachTheDemCore) {
  const CaseConfig c = parse(kCase);
  ASSERT_EQ(c.materialPairs.size(), 1u);
  EXPECT_EQ(c.walls.boxMaterial, "steel");
  EXPECT_EQ(c.walls.planes[1].material, "perspex");
  SubcyclePlan plan;
  plan.nSub = 10;
  plan.dtDem = 1e-4;
  const v1::Configure sent = buildConfigure(c, std::filesystem::temp_directory_path(), 1e-3, plan);
  EXPECT_TRUE(coredem::protocol::validateConfigure(sent).ok());
  EXPECT_EQ(sent.materials(0).youngs_modulus(), 1.0e7);
  EXPECT_FALSE(sent.materials(1).has_poisson_ratio());
  EXPECT_FALSE(sent.materials(0).has_kt_factor());
  ASSERT_EQ(sent.material_pairs_size(), 1);
  EXPECT_FALSE(sent.material_pairs(0).has_friction());

  const dem::DemConfig d = coredem::server::toDemConfig(sent, nullptr);
  EXPECT_EQ(d.contact, dem::kernels::ContactLaw::HertzMindlin);
  EXPECT_EQ(d.materials[0].youngsModulus, 1.0e7);
  EXPECT_EQ(d.materials[0].poissonRatio, 0.25);
  EXPECT_EQ(d.materials[1].poissonRatio, 0.3); // the default
  ASSERT_EQ(d.materialPairs.size(), 1u);
  EXPECT_EQ(d.materialPairs[0].a, 0);
  EXPECT_EQ(d.materialPairs[0].b, 1);
  EXPECT_EQ(d.materialPairs[0].en, 0.5);
  EXPECT_TRUE(std::isnan(d.materialPairs[0].mu));
  ASSERT_EQ(d.walls.size(), 8u);
  for (int k = 0; k < 6; ++k)
    EXPECT_EQ(d.walls[k].material, 1) << k;
  EXPECT_EQ(d.walls[6].material, 2);
  EXPECT_EQ(d.walls[7].material, 2);
  // The DEM core runs it, and the pre-flight Δt_DEM,max is the DEM's (same formula, walls and
  // pairs included).
  dem::DemSystem sys(d, dem::BackendKind::Cpu, 1);
  EXPECT_EQ(estimateDtDemMax(c), sys.dtDemMax());
  sys.advance(1e-4, static_cast<int>(std::ceil(1e-4 / sys.dtDemMax())));

  // A case without contact materials sends none: a 1.5 server reads it as before.
  const CaseConfig lsd =
      parse(replace(replace(replace(replace(kCase, "models:\n  contact: hertz-mindlin\n", ""),
                                    "youngs_modulus: 1.0e7", "k_n: 100"),
                            "youngs_modulus: 2.0e8", "k_n: 1000"),
                    "youngs_modulus: 3.0e7", "k_n: 300"));
  EXPECT_NE(lsd.contactMaterialsUsed(), "");
  EXPECT_EQ(demVersionRefusal(lsd, 1, 6), "");
  const std::string old = demVersionRefusal(lsd, 1, 5);
  EXPECT_HAS(old, "1 material_pairs");
  EXPECT_HAS(old, "3 walls with a material");
  EXPECT_HAS(old, "protocol 1.6");
  EXPECT_HAS(demVersionRefusal(c, 1, 5), "models.contact: hertz-mindlin");
}

TEST(CaseContact, MissingPropertiesAndUnknownMaterialsAreRefused) {
  EXPECT_HAS(errorOf(replace(kCase, "youngs_modulus: 1.0e7, ", "")),
             "material 'glass' has no youngs_modulus");
  EXPECT_HAS(errorOf(replace(kCase, "youngs_modulus: 1.0e7, ", "")), "hertz-mindlin");
  EXPECT_HAS(errorOf(replace(kCase, "models:\n  contact: hertz-mindlin\n", "")),
             "material 'glass' has no k_n (N/m), which the contact law linear-spring-dashpot");
  EXPECT_HAS(errorOf(replace(kCase, "poisson_ratio: 0.25", "poisson_ratio: 0.5")),
             "materials[0].poisson_ratio");
  EXPECT_HAS(errorOf(replace(kCase, "poisson_ratio: 0.25", "poisson_ratio: -1")),
             "materials[0].poisson_ratio");
  EXPECT_HAS(errorOf(replace(kCase, "[glass, steel]", "[glass, iron]")), "unknown material 'iron'");
  EXPECT_HAS(errorOf(replace(kCase, "[glass, steel]", "[glass]")), "material_pairs[0].materials");
  EXPECT_HAS(errorOf(replace(kCase, "e_n: 0.5}",
                             "e_n: 0.5}\n  - {materials: [steel, glass], friction: 0}")),
             "given twice");
  EXPECT_HAS(errorOf(replace(kCase, ", e_n: 0.5}", "}")), "needs e_n or friction");
  EXPECT_HAS(errorOf(replace(kCase, "e_n: 0.5}", "e_n: 1.5}")), "material_pairs[0].e_n");
  EXPECT_HAS(errorOf(replace(kCase, "material: steel}", "material: iron}")),
             "walls.box.material: unknown material 'iron'");
  EXPECT_HAS(errorOf(replace(kCase, "normal: [0, 1, 0], material: perspex",
                             "normal: [0, 1, 0], material: pmma")),
             "walls.planes[0].material");
}
