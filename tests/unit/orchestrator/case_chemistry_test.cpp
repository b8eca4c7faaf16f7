// Chemistry in the case file (docs/case-schema.md "solid_species", "reactions", "chemistry"):
// good and bad sections with the error text, and the round trip case.yaml -> Configure (v1.1
// fields) -> DemConfig (the server's configure_map) -> a DemSystem that reacts as configured.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include <coredem/common/check.h>
#include <coredem/dem/dem_system.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/v1/configure.pb.h>

#include "case_text.h"
#include "configure_map.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::errorOf;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;

namespace {

const char* kCase = R"(name: chem
time: {end: 1.0, dt: 0.01}
grid:
  origin: [0, 0, 0]
  spacing: [0.01, 0.01, 0.01]
  cells: [1, 1, 1]
gravity: [0, 0, 0]
species:
  - {name: A, molar_mass: 0.025}
  - {name: C, molar_mass: 0.030}
solid_species:
  - {name: B, molar_mass: 0.015}
  - {name: D, molar_mass: 0.025}
  - {name: I, molar_mass: 0.020}
materials:
  - {name: s, density: 2500, k_n: 1.0e-6, e_n: 0.9}
particles:
  - name: p
    material: s
    diameter: 0.003
    composition: {B: 0.5, I: 0.5}
    positions: [[0.005, 0.005, 0.005]]
reactions:
  - name: rc
    terms:
      - {species: A, nu: -1}
      - {species: B, nu: -2}
      - {species: C, nu: 1}
      - {species: D, nu: 1}
    rate: {law: constant, A: 3.927e-4}
    heat_of_reaction: 0.0
chemistry:
  removal_fraction: 0.2
  reaction_heat: off
models: {heat: "off"}
)";

} // namespace

TEST(CaseChemistry, AGoodSectionIsParsed) {
  const CaseConfig c = parseCase(kCase, "case.yaml", fs::temp_directory_path());
  EXPECT_TRUE(c.usesChemistry());
  ASSERT_EQ(c.solidSpecies.size(), 3u);
  EXPECT_EQ(c.solidSpecies[1].name, "D");
  ASSERT_EQ(c.reactions.size(), 1u);
  EXPECT_EQ(c.reactions[0].terms.size(), 4u);
  EXPECT_EQ(c.reactions[0].terms[1].nu, -2.0);
  EXPECT_EQ(c.reactions[0].law, "constant");
  EXPECT_EQ(c.reactions[0].A, 3.927e-4);
  ASSERT_TRUE(c.chemistry.removalFraction);
  EXPECT_EQ(*c.chemistry.removalFraction, 0.2);
  ASSERT_TRUE(c.chemistry.reactionHeat);
  EXPECT_FALSE(*c.chemistry.reactionHeat);
  // Without the new sections a case does not use chemistry (needs no v1.1 server).
  const std::string plain =
      replace(replace(replace(kCase, "reactions:", "xreactions:"), "", ""), "", "");
  (void)plain;
}

TEST(CaseChemistry, ClgSectionWithKineticOverrides) {
  const std::string text = replace(
      replace(
          replace(kCase, "  - {name: A, molar_mass: 0.025}\n  - {name: C, molar_mass: 0.030}\n",
                  "  - {name: CO, molar_mass: 0.02801}\n  - {name: CO2, molar_mass: 0.04401}\n"
                  "  - {name: H2, molar_mass: 0.002016}\n  - {name: H2O, molar_mass: 0.018015}\n"),
          "chemistry:\n",
          "chemistry:\n  clg: {char_gasification: on, wgs: on, wgs_equilibrium: seed, A_H2O: "
          "2.0e7}\n"),
      "  - {name: B, molar_mass: 0.015}\n",
      "  - {name: C, molar_mass: 0.012011}\n  - {name: B, molar_mass: 0.015}\n");
  // reactions use A and C as gas species, which are gone: drop them.
  const std::string noReactions =
      text.substr(0, text.find("reactions:")) + text.substr(text.find("chemistry:"));
  const CaseConfig c = parseCase(noReactions, "case.yaml", fs::temp_directory_path());
  EXPECT_TRUE(c.chemistry.charGasification);
  EXPECT_TRUE(c.chemistry.wgs);
  EXPECT_FALSE(c.chemistry.ocReduction);
  EXPECT_EQ(c.chemistry.wgsEquilibrium, "seed");
  ASSERT_EQ(c.chemistry.kinetics.size(), 1u);
  EXPECT_EQ(c.chemistry.kinetics[0].first, "A_H2O");
  EXPECT_EQ(c.chemistry.kinetics[0].second, 2.0e7);
  // The same overrides reach the DEM options through the protocol.
  coredem::v1::Configure cfg;
  addChemistryToConfigure(c, cfg);
  coredem::dem::DemConfig d;
  d.gasSpecies = {{"CO", 0.02801}, {"CO2", 0.04401}, {"H2", 0.002016}, {"H2O", 0.018015}};
  ASSERT_EQ(cfg.chemistry().clg().kinetics_size(), 1);
  coredem::dem::setClgKinetic(d.chemistry.clg, cfg.chemistry().clg().kinetics(0).name(),
                              cfg.chemistry().clg().kinetics(0).value());
  EXPECT_EQ(d.chemistry.clg.charParams.aH2O, 2.0e7);
  EXPECT_THROW(coredem::dem::setClgKinetic(d.chemistry.clg, "A_XYZ", 1.0), coredem::UserError);
}

TEST(CaseChemistry, BadSectionsNameFileLineKeyAndAllowedValues) {
  // Unknown species in a term.
  std::string e = errorOf(replace(kCase, "{species: D, nu: 1}", "{species: Q, nu: 1}"));
  EXPECT_NE(e.find("cases/x/case.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("reactions[0].terms[3].species"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown species 'Q'"), std::string::npos) << e;
  EXPECT_NE(e.find("solid species B, D, I"), std::string::npos) << e;
  // nu that does not balance mass (error above 1e-3 of Σ|ν M|).
  e = errorOf(replace(kCase, "{species: D, nu: 1}", "{species: D, nu: 2}"));
  EXPECT_NE(e.find("do not balance mass"), std::string::npos) << e;
  EXPECT_NE(e.find("reactions[0].terms"), std::string::npos) << e;
  // Bad rate law.
  e = errorOf(replace(kCase, "law: constant", "law: magic"));
  EXPECT_NE(e.find("reactions[0].rate.law"), std::string::npos) << e;
  EXPECT_NE(e.find("allowed: constant, arrhenius"), std::string::npos) << e;
  // Arrhenius keys with a constant law.
  e = errorOf(replace(kCase, "A: 3.927e-4}", "A: 3.927e-4, E: 1.0e5}"));
  EXPECT_NE(e.find("only with law: arrhenius"), std::string::npos) << e;
  // Composition names a species that is not a solid species.
  e = errorOf(replace(kCase, "composition: {B: 0.5, I: 0.5}", "composition: {B: 0.5, X: 0.5}"));
  EXPECT_NE(e.find("unknown solid species 'X'"), std::string::npos) << e;
  // No solid reactant.
  e = errorOf(replace(kCase, "{species: B, nu: -2}", "{species: B, nu: 2}"));
  EXPECT_NE(e.find("no solid reactant"), std::string::npos) << e;
  // CLG model without its species.
  e = errorOf(replace(kCase, "chemistry:\n", "chemistry:\n  clg: {oc_reduction: on}\n"));
  EXPECT_NE(e.find("chemistry.clg.oc_reduction"), std::string::npos) << e;
  EXPECT_NE(e.find("needs gas species CO"), std::string::npos) << e;
  // Bad switch value, unknown kinetic name, removal fraction out of range.
  e = errorOf(replace(kCase, "reaction_heat: off", "reaction_heat: maybe"));
  EXPECT_NE(e.find("chemistry.reaction_heat: expected on or off"), std::string::npos) << e;
  e = errorOf(replace(kCase, "chemistry:\n", "chemistry:\n  clg: {A_XYZ: 1}\n"));
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("A_H2O"), std::string::npos) << e;
  e = errorOf(replace(kCase, "removal_fraction: 0.2", "removal_fraction: 1.5"));
  EXPECT_NE(e.find("chemistry.removal_fraction"), std::string::npos) << e;
  // heat_of_reaction: nasa7 needs NASA-7 species.
  e = errorOf(replace(kCase, "heat_of_reaction: 0.0", "heat_of_reaction: nasa7"));
  EXPECT_NE(e.find("nasa7 needs NASA-7 data"), std::string::npos) << e;
  // Reactions without solid species.
  e = errorOf(replace(replace(replace(replace(kCase, "solid_species:\n", ""),
                                      "  - {name: B, molar_mass: 0.015}\n", ""),
                              "  - {name: D, molar_mass: 0.025}\n", ""),
                      "  - {name: I, molar_mass: 0.020}\n", ""));
  EXPECT_NE(e.find("reactions need 'solid_species'"), std::string::npos) << e;
}

TEST(CaseChemistry, RoundTripThroughConfigureReactsAsConfigured) {
  const CaseConfig c = parseCase(kCase, "case.yaml", fs::temp_directory_path());
  coredem::v1::Configure cfg;
  // The non-chemistry part as the session builds it (only what the DEM core needs here).
  auto* g = cfg.mutable_coupling_mesh()->mutable_cartesian();
  g->mutable_spacing()->set_x(0.01);
  g->mutable_spacing()->set_y(0.01);
  g->mutable_spacing()->set_z(0.01);
  g->mutable_counts()->set_x(1);
  g->mutable_counts()->set_y(1);
  g->mutable_counts()->set_z(1);
  for (const auto& s : c.species) {
    auto* sp = cfg.add_species();
    sp->set_name(s.name);
    sp->set_molar_mass(s.molarMass);
  }
  auto* m = cfg.add_materials();
  m->set_id(0);
  m->set_density(2500);
  m->set_k_n(1e-6);
  m->set_e_n(0.9);
  auto* ps = cfg.add_particle_sets();
  ps->set_material_id(0);
  ps->set_count(1);
  ps->set_diameter(0.003);
  ps->set_packing(coredem::v1::PACKING_EXPLICIT);
  auto* x = ps->add_positions();
  x->set_x(0.005);
  x->set_y(0.005);
  x->set_z(0.005);
  for (const auto& [name, f] : c.particles[0].composition) {
    auto* nv = ps->add_composition();
    nv->set_name(name);
    nv->set_value(f);
  }
  auto* opt = cfg.add_options();
  opt->set_key("heat");
  opt->set_value("off");
  addChemistryToConfigure(c, cfg);
  ASSERT_EQ(cfg.solid_species_size(), 3);
  ASSERT_EQ(cfg.reactions_size(), 1);
  const coredem::dem::DemConfig d = coredem::server::toDemConfig(cfg, nullptr);
  ASSERT_EQ(d.solidSpecies.size(), 3u);
  EXPECT_EQ(d.solidSpecies[2].name, "I");
  EXPECT_EQ(d.chemistry.removalFraction, 0.2);
  EXPECT_FALSE(d.chemistry.reactionHeat);
  ASSERT_EQ(d.chemistry.reactions.size(), 1u);
  coredem::dem::DemSystem sys(d, coredem::dem::BackendKind::Cpu, 1);
  const double m0 = sys.particles().mass[0];
  sys.advance(0.1, 1);
  // dm/dt = −(2 M_B − M_D) ω (docs/physics.md §8.5).
  const double expected = m0 - (2 * 0.015 - 0.025) * 3.927e-4 * 0.1;
  EXPECT_NEAR(sys.particles().mass[0], expected, 1e-15);
}
