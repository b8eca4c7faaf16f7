// Case schema validation: good cases parse; each kind of error names file, line, key and
// what is allowed.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include <coredem/dem/drag_calibration.h>
#include <coredem/orchestrator/case_config.h>

#include "case_text.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::errorOf;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;

namespace {

const char* kGood = R"(name: unit-case
time:
  end: 0.01
  dt: 1.0e-4
grid:
  origin: [0, 0, 0]
  spacing: [0.01, 0.01, 0.01]
  cells: [2, 2, 4]
materials:
  - name: glass
    density: 2500
    k_n: 1000
    e_n: 0.9
particles:
  - material: glass
    count: 10
    diameter: 2.0e-3
    region: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}
checkpoint: {every_steps: 10, keep: 2}
output: {every: 5}
)";

} // namespace

TEST(CaseConfig, GoodCaseParses) {
  const CaseConfig c = parseCase(kGood, "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(c.name, "unit-case");
  EXPECT_DOUBLE_EQ(c.endTime, 0.01);
  EXPECT_EQ(c.dt.kind, DtPolicyConfig::Kind::Fixed);
  EXPECT_EQ(c.grid.cells[2], 4u);
  ASSERT_EQ(c.particles.size(), 1u);
  EXPECT_EQ(c.particles[0].count, 10u);
  EXPECT_EQ(c.particles[0].packing, "lattice");
  EXPECT_EQ(c.checkpoint.everySteps, 10);
  EXPECT_EQ(c.checkpoint.keep, 2);
  EXPECT_EQ(c.output.snapshotEvery, 5);
  EXPECT_EQ(c.dem.backend, "cpu");
  EXPECT_EQ(c.cfd.participant, "coredem-gas");
  EXPECT_EQ(c.configHash.size(), 64u);
}

// Synchronized outputs every N steps and/or every S simulated seconds.
TEST(CaseConfig, OutputEverySeconds) {
  const CaseConfig c =
      parseCase(replace(kGood, "output: {every: 5}", "output: {every: 0, every_seconds: 0.002}"),
                "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(c.output.snapshotEvery, 0);
  EXPECT_DOUBLE_EQ(c.output.everySeconds, 0.002);
  EXPECT_TRUE(c.output.any());
  const CaseConfig none = parseCase(replace(kGood, "output: {every: 5}", "output: {every: 0}"),
                                    "case.yaml", fs::temp_directory_path());
  EXPECT_FALSE(none.output.any());
  const std::string e =
      errorOf(replace(kGood, "output: {every: 5}", "output: {every_seconds: -1}"));
  EXPECT_NE(e.find("output.every_seconds"), std::string::npos) << e;
}

TEST(CaseConfig, UnknownKeyNamesLineKeyAndAllowed) {
  const std::string e = errorOf(replace(kGood, "  dt: 1.0e-4", "  dtt: 1.0e-4"));
  EXPECT_NE(e.find("cases/x/case.yaml:4:3: time.dtt: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("allowed keys in 'time': end, dt, adaptive"), std::string::npos) << e;
}

TEST(CaseConfig, UnknownTopLevelKey) {
  const std::string e = errorOf(std::string(kGood) + "partciles: []\n");
  EXPECT_NE(e.find(":21:1: partciles: unknown key; allowed keys at the top level"),
            std::string::npos)
      << e;
}

TEST(CaseConfig, WrongTypeNamesExpectedType) {
  const std::string e = errorOf(replace(kGood, "end: 0.01", "end: soon"));
  EXPECT_NE(e.find("case.yaml:3:8: time.end: expected a number"), std::string::npos) << e;
  EXPECT_NE(e.find("got 'soon'"), std::string::npos) << e;
  const std::string v = errorOf(replace(kGood, "cells: [2, 2, 4]", "cells: 8"));
  EXPECT_NE(v.find("grid.cells: expected a list of 3 numbers"), std::string::npos) << v;
  const std::string m = errorOf(replace(kGood, "time:\n  end: 0.01\n  dt: 1.0e-4\n", "time: 3\n"));
  EXPECT_NE(m.find("time: expected a mapping"), std::string::npos) << m;
}

TEST(CaseConfig, OutOfRangeAndChoices) {
  const std::string e = errorOf(replace(kGood, "e_n: 0.9", "e_n: 1.5"));
  EXPECT_NE(e.find("materials[0].e_n: 1.5 is out of range; allowed: > 0 and <= 1"),
            std::string::npos)
      << e;
  const std::string p = errorOf(replace(kGood, "count: 10", "count: 10\n    packing: hexagonal"));
  EXPECT_NE(p.find("particles[0].packing: 'hexagonal' is not allowed; allowed: lattice, random"),
            std::string::npos)
      << p;
  const std::string m = errorOf(replace(kGood, "material: glass", "material: steel"));
  EXPECT_NE(m.find("unknown material 'steel'; allowed: glass"), std::string::npos) << m;
}

TEST(CaseConfig, MissingRequiredKey) {
  const std::string e = errorOf(replace(kGood, "  dt: 1.0e-4\n", ""));
  EXPECT_NE(e.find("time: missing required key 'dt'"), std::string::npos) << e;
}

TEST(CaseConfig, MissingFileNamesTheFile) {
  const std::string e = errorOf(std::string(kGood) + "initial_state: no-such-state.h5\n");
  EXPECT_NE(e.find("initial_state: file 'no-such-state.h5' not found"), std::string::npos) << e;
  EXPECT_NE(e.find(":21:16:"), std::string::npos) << e;
}

TEST(CaseConfig, MissingCaseFolder) {
  try {
    loadCase(fs::temp_directory_path() / "coredem-no-such-case");
    FAIL() << "no error";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("coredem-no-such-case: case file not found"),
              std::string::npos)
        << e.what();
  }
}

TEST(CaseConfig, InvalidYamlHasLine) {
  const std::string e = errorOf("name: a\ntime: [1, 2\n");
  EXPECT_NE(e.find("not valid YAML"), std::string::npos) << e;
}

TEST(CaseConfig, AdaptiveBounds) {
  const std::string good = replace(kGood, "  dt: 1.0e-4\n",
                                   "  dt: 1.0e-4\n  adaptive: {courant: 0.5, dt_min: 1.0e-5, "
                                   "dt_max: 1.0e-3}\n");
  const CaseConfig c = parseCase(good, "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(c.dt.kind, DtPolicyConfig::Kind::Courant);
  EXPECT_DOUBLE_EQ(c.dt.dtMax, 1e-3);
  const std::string e = errorOf(replace(good, "dt_min: 1.0e-5", "dt_min: 1.0e-2"));
  EXPECT_NE(e.find("need dt_min <= dt_max"), std::string::npos) << e;
}

// `models:` is checked with the DEM server's model registry (coredem/dem/models.h): a misspelled
// key or a bad value fails `coredem check` with file:line:col, the key and the allowed ones.
TEST(CaseConfig, ModelsMisspelledKeyNamesLineAndAllowedKeys) {
  const std::string text =
      std::string(kGood) + "models:\n  motion: frozen\n  convecton: li-mason\n";
  const std::string e = errorOf(text);
  EXPECT_NE(e.find("cases/x/case.yaml:23:3: models.convecton: unknown model key (did you mean "
                   "'convection'?); allowed keys: drag, "),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("lens_conduction"), std::string::npos) << e;
}

TEST(CaseConfig, ModelsBadValueNamesLineAndAllowedValues) {
  const std::string text = std::string(kGood) + "models: {convection: li-masn}\n";
  const std::string e = errorOf(text);
  EXPECT_NE(
      e.find(
          "cases/x/case.yaml:21:22: models.convection: 'li-masn' is not allowed (did "
          "you mean 'li-mason'?); allowed: li-mason, ranz-marshall, gunn, deen, tavassoli or off"),
      std::string::npos)
      << e;
  const std::string d = errorOf(std::string(kGood) + "models:\n  drag: stokes\n");
  EXPECT_NE(d.find("case.yaml:22:9: models.drag: 'stokes' is not allowed; allowed: gidaspow, "
                   "wen-yu, ergun, gidaspow-blend, di-felice, rong, syamlal-obrien, beetstra or "
                   "koch-hill"),
            std::string::npos)
      << d;
  EXPECT_EQ(errorOf(std::string(kGood) + "models:\n  drag: wen-yu\n"), "");
  const std::string n = errorOf(std::string(kGood) + "models:\n  flpc: 2\n");
  EXPECT_NE(n.find("models.flpc: '2' is not allowed; expected a number in [0, 1]"),
            std::string::npos)
      << n;
}

TEST(CaseConfig, ModelsValidPass) {
  const std::string text = std::string(kGood) +
                           "models: {motion: frozen, convection: \"off\", radiation: \"off\", "
                           "lens_conduction: \"off\", s_min: 1e-06, dem.history_slots: 16}\n";
  EXPECT_EQ(errorOf(text), "");
}

// The name becomes the run folder and log lines: a newline, NUL or 20 MB were accepted.
TEST(CaseConfig, CaseNamesAreOneShortPrintableLine) {
  EXPECT_EQ(errorOf(replace(kGood, "name: unit-case", "name: \"two words, ok\"")), "");
  for (const std::string bad : {std::string("name: \"a\\nb\""), std::string("name: \"a\\0b\""),
                                std::string("name: \"a\\tb\""), std::string("name: \"..\""),
                                "name: " + std::string(20u << 20, 'x')}) {
    const std::string e = errorOf(replace(kGood, "name: unit-case", bad));
    EXPECT_NE(e.find("cases/x/case.yaml:1:7: name: must be a non-empty name of at most 200 bytes"),
              std::string::npos)
        << e.substr(0, 300);
  }
  const std::string d =
      errorOf(replace(kGood, "name: unit-case", "name: d\ndescription: " + std::string(5000, 'y')));
  EXPECT_NE(d.find("description: 5000 bytes: at most 4096"), std::string::npos) << d.substr(0, 300);
}

// models: {drag.syamlal-obrien.u_mf, .eps_mf}: the reader calibrates c1 and d1 for the case's
// particles and gas (dem/drag_calibration.h) and sends them as the law's parameters; what it
// cannot calibrate is refused naming the key.
TEST(CaseConfig, SyamlalObrienCalibratedToTheMinimumFluidizationVelocity) {
  const std::string cal = std::string(kGood) +
                          "models:\n  drag: syamlal-obrien\n  drag.syamlal-obrien.u_mf: 0.8\n"
                          "  drag.syamlal-obrien.eps_mf: 0.42\n";
  const CaseConfig c = parseCase(cal, "case.yaml", fs::temp_directory_path());
  std::map<std::string, std::string> m(c.models.begin(), c.models.end());
  ASSERT_EQ(m.count("drag.syamlal-obrien.c1"), 1u);
  ASSERT_EQ(m.count("drag.syamlal-obrien.d1"), 1u);
  EXPECT_EQ(m.count("drag.syamlal-obrien.u_mf"), 0u);
  const double c1 = std::stod(m["drag.syamlal-obrien.c1"]);
  EXPECT_GT(c1, 0.0);
  EXPECT_LT(c1, 1.2);
  // 2 mm glass in the default gas (air at 20 °C) with gravity 9.81: the calibration's balance.
  EXPECT_NEAR(coredem::dem::syamlalBalance(c1, 0.8, 0.42, 2e-3, 2500.0, c.gasProperties.density,
                                           c.gasProperties.viscosity, 9.81),
              0.0, 1e-10);

  EXPECT_NE(errorOf(replace(cal, "  drag.syamlal-obrien.eps_mf: 0.42\n", ""))
                .find("needs both drag.syamlal-obrien.u_mf"),
            std::string::npos);
  EXPECT_NE(errorOf(replace(cal, "drag: syamlal-obrien", "drag: gidaspow"))
                .find("models.drag is 'gidaspow'"),
            std::string::npos);
  EXPECT_NE(errorOf(cal + "  drag.syamlal-obrien.c1: 0.5\n").find("not both"), std::string::npos);
  const std::string e = errorOf(replace(cal, "eps_mf: 0.42", "eps_mf: 0.9"));
  EXPECT_NE(e.find("models.drag.syamlal-obrien.eps_mf"), std::string::npos) << e;
  EXPECT_NE(e.find("(0, 0.85]"), std::string::npos) << e;
  EXPECT_NE(errorOf(replace(cal, "u_mf: 0.8", "u_mf: 900")).find("no c1 in"), std::string::npos);
}
