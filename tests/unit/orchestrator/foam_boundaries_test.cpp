// case.yaml's inlets and outlets (docs/case-schema.md "Inlets and outlets"): the reader's values
// and refusals, the OpenFOAM participant's pre-flight of them against the mesh's patches and the
// fields of 0/, and the patch entries it writes into the run's copy of 0/ (read back as
// OpenFOAM's field syntax: readFoamField and the text).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/participant/foam_field.h>
#include <coredem/participant/openfoam.h>

#include "case_text.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = COREDEM_SOURCE_DIR;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// cases/<name>/case.yaml without its own inlets and outlets (the default case declares them).
std::string caseText(const std::string& name) {
  std::string s = readText(kSource / "cases" / name / "case.yaml");
  const auto a = s.find("\ninlets:");
  if (a != std::string::npos) {
    s.erase(a, s.find("\ndem:", a) - a);
  }
  return s;
}

/// cases/<name> copied to a temp folder, `extra` appended to its case.yaml (without its own
/// inlets and outlets).
fs::path caseCopy(const std::string& name, const std::string& tag, const std::string& extra) {
  const fs::path d = fs::temp_directory_path() / ("coredem-boundaries-" + tag);
  fs::remove_all(d);
  fs::copy(kSource / "cases" / name, d, fs::copy_options::recursive);
  std::ofstream(d / "case.yaml", std::ios::trunc) << caseText(name) << "\n" << extra;
  return d;
}

/// The CaseError of loading and pre-flighting the case's participant ("" when both pass).
std::string failureOf(const fs::path& dir) {
  try {
    const CaseConfig c = loadCase(dir / "case.yaml");
    participant(c.cfd.participant).preflight(c);
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

const std::string kInlet =
    "inlets:\n  - {patch: inlet, superficial_velocity: [0.0, 1.25, 0.0], temperature: 300.0}\n"
    "outlets:\n  - {patch: outlet}\n";

} // namespace

TEST(Boundaries, InletsAndOutletsAreReadWithTheirValues) {
  const fs::path d = caseCopy("fluidized-bed-cooling", "read", kInlet);
  const CaseConfig c = loadCase(d);
  ASSERT_EQ(c.inlets.size(), 1u);
  EXPECT_EQ(c.inlets[0].patch, "inlet");
  EXPECT_EQ(c.inlets[0].velocity, (Vec3{0.0, 1.25, 0.0}));
  EXPECT_TRUE(c.inlets[0].velocityTable.empty());
  EXPECT_EQ(c.inlets[0].temperature.value_or(0.0), 300.0);
  ASSERT_EQ(c.outlets.size(), 1u);
  EXPECT_EQ(c.outlets[0].patch, "outlet");
  EXPECT_EQ(failureOf(d), "");

  const fs::path t = caseCopy("fluidized-bed-cooling", "table",
                              "inlets:\n  - patch: inlet\n    superficial_velocity_table: [[0, 0, "
                              "0, 0], [0.1, 0, 1.5, 0]]\n");
  const CaseConfig ct = loadCase(t);
  ASSERT_EQ(ct.inlets[0].velocityTable.size(), 2u);
  EXPECT_EQ(ct.inlets[0].velocityTable[1], (std::array<double, 4>{0.1, 0.0, 1.5, 0.0}));
}

TEST(Boundaries, BadInletsAreRefusedNamingTheKey) {
  const std::string base = caseText("fluidized-bed-cooling");
  const auto error = [&](const std::string& extra) {
    return coredem::orchestrator::test::errorOf(base + "\n" + extra);
  };
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet}\n"), "give one of superficial_velocity"));
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet, superficial_velocity: 1.5}\n"),
                       "inlets[0].superficial_velocity: expected the superficial gas velocity "
                       "[ux, uy, uz]"));
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet, superficial_velocity_table: [[0, 0, 0, "
                             "0], [0, 0, 1, 0]]}\n"),
                       "times must increase"));
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet, superficial_velocity: [0, 1, 0], "
                             "temperature: 20}\n"),
                       "inlets[0].temperature"));
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet, superficial_velocity: [0, 1, 0], "
                             "mass_fractions: {N2: 1}}\n"),
                       "the case has no gas species"));
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet, superficial_velocity: [0, 1, 0]}\n"
                             "outlets:\n  - {patch: inlet}\n"),
                       "patch 'inlet' is given twice"));
  EXPECT_TRUE(contains(error("inlets:\n  - {patch: inlet, superficial_velocity: [0, nan, 0]}\n"),
                       "inlets[0].superficial_velocity[1]"));
  // Species: every one, known, summing to 1 (cases/clg has CO, CO2, H2, H2O, N2).
  const std::string clg = readText(kSource / "cases" / "clg" / "case.yaml");
  const auto clgError = [&](const std::string& y) {
    return coredem::orchestrator::test::errorOf(
        clg +
        "\ninlets:\n  - {patch: inlet, superficial_velocity: [0, 0.24, 0], "
        "mass_fractions: " +
        y + "}\n");
  };
  EXPECT_EQ(clgError("{CO: 0, CO2: 0, H2: 0, H2O: 0.5, N2: 0.5}"), "");
  EXPECT_TRUE(contains(clgError("{H2O: 0.5, N2: 0.5}"), "'CO' is missing"));
  EXPECT_TRUE(contains(clgError("{CO: 0, CO2: 0, H2: 0, H2O: 0.5, N2: 0.5, O2: 0}"),
                       "inlets[0].mass_fractions.O2: unknown species"));
  EXPECT_TRUE(contains(clgError("{CO: 0, CO2: 0, H2: 0, H2O: 0.5, N2: 0.6}"), "sum to 1.1"));
  // The prescribed gas takes its inlet from its own section.
  const std::string gas = readText(kSource / "cases" / "settling-heated" / "case.yaml");
  EXPECT_TRUE(contains(coredem::orchestrator::test::errorOf(gas + "\n" + kInlet),
                       "coredem-gas takes no boundary conditions from case.yaml"));
}

TEST(Boundaries, PreflightRefusesAPatchTheMeshLacksAWallAndAFixedOtherVariable) {
  auto fails = [&](const std::string& tag, const std::string& extra) {
    return failureOf(caseCopy("fluidized-bed-cooling", tag, extra));
  };
  const std::string missing =
      fails("missing", "inlets:\n  - {patch: bottom, superficial_velocity: [0, 1, 0]}\n");
  EXPECT_TRUE(contains(missing, "inlets[0].patch: no patch 'bottom' in"));
  EXPECT_TRUE(contains(missing, "blockMeshDict; its patches: inlet (patch), outlet (patch), "
                                "walls (wall)"));
  EXPECT_TRUE(
      contains(fails("wall", "outlets:\n  - {patch: walls}\n"), "patch 'walls' is of type 'wall'"));
  // The case fixes U at its inlet: an outlet there contradicts it.
  EXPECT_TRUE(contains(fails("outlet-at-inlet", "outlets:\n  - {patch: inlet}\n"),
                       "fixes the velocity at 'inlet' (type fixedValue), but an outlet fixes the "
                       "pressure there"));
  // ... and p at its outlet: an inlet there too.
  EXPECT_TRUE(contains(
      fails("inlet-at-outlet", "inlets:\n  - {patch: outlet, superficial_velocity: [0, -1, 0]}\n"),
      "fixes the pressure at 'outlet' (type fixedValue), but an inlet fixes"));
  // Species fields: cases/clg has them all.
  EXPECT_EQ(failureOf(caseCopy("clg", "clg",
                               "inlets:\n  - {patch: inlet, superficial_velocity: [0, 0.3, 0], "
                               "temperature: 1173.0, mass_fractions: {CO: 0, CO2: 0, H2: 0, H2O: "
                               "0.6, N2: 0.4}}\n")),
            "");
}

TEST(Boundaries, PatchEntryIsReplacedOrInsertedBeforePatterns) {
  const std::string text = "FoamFile { class volScalarField; }\n"
                           "dimensions [0 0 0 1 0 0 0];\ninternalField uniform 300;\n"
                           "boundaryField\n{\n"
                           "    // inlet { type zeroGradient; } (a comment)\n"
                           "    #includeEtc \"caseDicts/setConstraintTypes\"\n"
                           "    \"(walls|side)\" { type zeroGradient; }\n"
                           "    inlet\n    {\n        type fixedValue;\n        value uniform "
                           "{ 1 };\n    }\n"
                           "    outlet { type zeroGradient; }\n}\n";
  const std::string lines = "        type fixedValue;\n        value uniform 350;\n";
  const std::string replaced = replaceFoamPatchEntry(text, "inlet", lines, "0/T");
  EXPECT_TRUE(contains(replaced, "    inlet\n    {\n        type fixedValue;\n        value "
                                 "uniform 350;\n    }\n    outlet { type zeroGradient; }"));
  EXPECT_FALSE(contains(replaced, "uniform { 1 }"));
  EXPECT_TRUE(contains(replaced, "// inlet { type zeroGradient; } (a comment)"));
  // A patch only a pattern names gets its own entry first.
  const std::string inserted = replaceFoamPatchEntry(text, "side", lines, "0/T");
  EXPECT_TRUE(contains(inserted, "boundaryField\n{\n    side\n    {\n        type fixedValue;"));
  EXPECT_TRUE(contains(inserted, "\"(walls|side)\" { type zeroGradient; }"));
  try {
    replaceFoamPatchEntry("internalField uniform 1;\n", "inlet", lines, "0/T");
    ADD_FAILURE() << "a file without boundaryField was accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_TRUE(contains(e.what(), "0/T: no boundaryField"));
  }
}

TEST(Boundaries, TheRunsCopyOfTheCaseGetsTheInletAndOutlet) {
  const fs::path d = caseCopy("clg", "write",
                              "inlets:\n  - {patch: inlet, superficial_velocity: [0, 0.3, 0], "
                              "temperature: 1000.0, mass_fractions: {CO: 0, CO2: 0.25, H2: 0, "
                              "H2O: 0.5, N2: 0.25}}\noutlets:\n  - {patch: outlet}\n");
  const CaseConfig c = loadCase(d);
  const fs::path work = d / "openfoam";
  writeFoamBoundaries(c, work);
  const FoamFieldValues t = readFoamField(work / "0" / "T");
  bool inletT = false;
  for (const auto& v : t.values) {
    inletT = inletT || (v.patch == "inlet" && v.value == 1000.0);
  }
  EXPECT_TRUE(inletT) << readText(work / "0" / "T");
  const FoamFieldValues co2 = readFoamField(work / "0" / "CO2");
  bool inletY = false;
  for (const auto& v : co2.values) {
    inletY = inletY || (v.patch == "inlet" && v.value == 0.25);
  }
  EXPECT_TRUE(inletY) << readText(work / "0" / "CO2");
  const std::string u = readText(work / "0" / "U");
  EXPECT_TRUE(contains(u, "type            interstitialInletVelocity;\n        inletVelocity   "
                          "uniform (0 0.3 0);\n        alpha           alphac;"))
      << u;
  EXPECT_TRUE(contains(u, "outlet\n    {\n        // coredem: outlets[0] of case.yaml\n        "
                          "type            pressureInletOutletVelocity;"));
  EXPECT_TRUE(contains(u, "walls   { type slip; }"));
  const FoamFieldValues p = readFoamField(work / "0" / "p");
  for (const auto& [name, type] : p.patchTypes) {
    if (name == "outlet") {
      EXPECT_EQ(type, "fixedValue");
    }
  }
  // A table: uniformFixedValue with OpenFOAM's inline table (clamped beyond its ends).
  const fs::path dt = caseCopy("fluidized-bed-cooling", "write-table",
                               "inlets:\n  - patch: inlet\n    superficial_velocity_table: [[0, "
                               "0, 0, 0], [0.25, 0, 1.5, 0]]\n");
  writeFoamBoundaries(loadCase(dt), dt / "openfoam");
  EXPECT_TRUE(contains(readText(dt / "openfoam" / "0" / "U"),
                       "type            uniformFixedValue;\n        uniformValue    table ( (0 (0 "
                       "0 0)) (0.25 (0 1.5 0)) );"));
}
