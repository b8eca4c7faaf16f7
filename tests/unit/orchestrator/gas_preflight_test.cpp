// Pre-flight of the gas model against the OpenFOAM case (openfoam.h checkOpenFoamCase), on a copy
// of cases/clg: species fields of 0/ vs case.yaml species, the gas state of 0/ (T > 0, mass
// fractions in [0, 1] summing to 1), constant/thermophysicalProperties vs the model, and the
// ideal-gas initial temperature vs 0/T. Each refusal names both files and lines.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/gas_data.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/preflight.h>
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

void writeText(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

/// cases/clg (case.yaml and its OpenFOAM folder) copied to a temp folder, with the
/// constant-property gas of reduced-constant-gas.yaml (model: constant).
fs::path clgCopy(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("coredem-gas-preflight-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  const fs::path src = kSource / "cases" / "clg";
  fs::copy(src / "openfoam", d / "openfoam", fs::copy_options::recursive);
  writeText(d / "case.yaml",
            replace(readText(src / "case.yaml"),
                    "  model: ideal_gas\n  temperature: 1173.0\n  pressure: 101325.0\n"
                    "  diffusivity: 2.0e-4\n",
                    "  model: constant\n  density: 0.239\n  viscosity: 4.4e-5\n  conductivity: "
                    "0.085\n  cp: 1650.0\n  temperature: 1173.0\n  pressure: 101325.0\n"));
  return d;
}

/// The constant properties of the copy replaced by model ideal_gas (4 lines fewer).
void makeIdealGas(const fs::path& d) {
  writeText(d / "case.yaml",
            replace(readText(d / "case.yaml"),
                    "  model: constant\n  density: 0.239\n  viscosity: 4.4e-5\n  conductivity: "
                    "0.085\n  cp: 1650.0\n",
                    "  model: ideal_gas\n"));
}

/// The pre-flight of the case's participant ("" when it passes).
std::string failureOf(const fs::path& dir) {
  try {
    const CaseConfig c = loadCase(dir / "case.yaml");
    const ParticipantDescriptor& p = participant(c.cfd.participant);
    EXPECT_NE(p.preflight, nullptr);
    p.preflight(c);
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

void edit(const fs::path& file, const std::string& from, const std::string& to) {
  writeText(file, replace(readText(file), from, to));
}

} // namespace

TEST(GasPreflight, ClgPassesWithBothModels) {
  const fs::path d = clgCopy("both");
  EXPECT_EQ(failureOf(d), "");
  makeIdealGas(d);
  EXPECT_EQ(failureOf(d), "");
  // The ideal-gas initial state is the mixture of 0/ (H2O/N2 1:1 by moles at 1173 K).
  const CaseConfig c = loadCase(d / "case.yaml");
  const GasState s = idealGasState({"CO", "CO2", "H2", "H2O", "N2"},
                                   {0.0, 0.0, 0.0, 0.391384, 0.608616}, 1173.0, 101325.0);
  EXPECT_EQ(c.gasProperties.density, s.density);
  EXPECT_EQ(c.gasProperties.viscosity, s.viscosity);
  EXPECT_NEAR(c.gasProperties.density, 0.239, 0.001); // the constant case's estimate
  fs::remove_all(d);
}

TEST(GasPreflight, MissingSpeciesFieldNamesTheSpeciesAndTheFile) {
  const fs::path d = clgCopy("missing");
  fs::remove(d / "openfoam" / "0" / "CO2");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:28:12: species[1].name: gas species 'CO2', but the OpenFOAM "
                          "case has no field " +
                              (d / "openfoam" / "0" / "CO2").string()))
      << e;
  fs::remove_all(d);
}

TEST(GasPreflight, ExtraMassFractionFieldIsRefused) {
  const fs::path d = clgCopy("extra");
  fs::copy_file(d / "openfoam" / "0" / "CO", d / "openfoam" / "0" / "CH4");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:27:3: species: " + (d / "openfoam" / "0" / "CH4").string() +
                              ":15: CH4 is a dimensionless field (a mass fraction) of the "
                              "OpenFOAM case, but case.yaml has no gas species 'CH4' (species: "
                              "CO, CO2, H2, H2O, N2)"))
      << e;
  // alpha* fields and Ydefault are not species.
  fs::rename(d / "openfoam" / "0" / "CH4", d / "openfoam" / "0" / "alphac");
  EXPECT_EQ(failureOf(d), "");
  fs::rename(d / "openfoam" / "0" / "alphac", d / "openfoam" / "0" / "Ydefault");
  EXPECT_EQ(failureOf(d), "");
  fs::remove_all(d);
}

TEST(GasPreflight, MassFractionOutsideZeroOneIsRefused) {
  const fs::path d = clgCopy("range");
  edit(d / "openfoam" / "0" / "N2", "internalField   uniform 0.608616;",
       "internalField   uniform 1.2;");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "cfd.case: " + (d / "openfoam" / "0" / "N2").string() +
                              ":16: internalField mass fraction N2 = 1.2: must lie in [0, 1]"))
      << e;
  edit(d / "openfoam" / "0" / "N2", "internalField   uniform 1.2;",
       "internalField   uniform -0.1;");
  EXPECT_TRUE(contains(failureOf(d), "internalField mass fraction N2 = -0.1: must lie in [0, 1]"));
  fs::remove_all(d);
}

TEST(GasPreflight, MassFractionsNotSummingToOneAreRefused) {
  const fs::path d = clgCopy("sum");
  const fs::path n2 = d / "openfoam" / "0" / "N2";
  // The inlet only.
  edit(n2, "inlet   { type fixedValue; value uniform 0.608616; }",
       "inlet   { type fixedValue; value uniform 0.6; }");
  std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "species: the mass fractions of inlet in " +
                              (d / "openfoam" / "0").string() + " sum to 0.991384, not 1"))
      << e;
  EXPECT_TRUE(contains(e, "H2O 0.391384 (H2O:19) + N2 0.6 (N2:19)")) << e;
  // Within 1e-9 passes; 1e-8 off does not.
  edit(n2, "value uniform 0.6;", "value uniform 0.6086160000001;");
  EXPECT_EQ(failureOf(d), "");
  edit(n2, "internalField   uniform 0.608616;", "internalField   uniform 0.60861601;");
  e = failureOf(d);
  EXPECT_TRUE(contains(e, "the mass fractions of internalField")) << e;
  EXPECT_TRUE(contains(e, "sum to 1.00000001, not 1 (tolerance 1e-09)")) << e;
  fs::remove_all(d);
}

TEST(GasPreflight, NonUniformValuesAreSkipped) {
  const fs::path d = clgCopy("nonuniform");
  edit(d / "openfoam" / "0" / "N2", "internalField   uniform 0.608616;",
       "internalField   nonuniform List<scalar> 2(0.5 0.7);");
  EXPECT_EQ(failureOf(d), "");
  // A long list (a mapped field) is skipped as well, without reading it value by value.
  std::string values;
  for (int i = 0; i < 200000; ++i) {
    values += "0.608616\n";
  }
  edit(d / "openfoam" / "0" / "N2", "internalField   nonuniform List<scalar> 2(0.5 0.7);",
       "internalField   nonuniform List<scalar>\n200000\n(\n" + values + ");");
  EXPECT_EQ(failureOf(d), "");
  const FoamFieldValues v = readFoamField(d / "openfoam" / "0" / "N2");
  ASSERT_EQ(v.values.size(), 2u);
  EXPECT_FALSE(v.values[0].uniform);
  EXPECT_EQ(v.values[1].patch, "inlet");
  EXPECT_EQ(v.values[1].line, 200022);
  fs::remove_all(d);
}

TEST(GasPreflight, NonPositiveTemperatureIsRefused) {
  const fs::path d = clgCopy("temperature");
  const fs::path t = d / "openfoam" / "0" / "T";
  edit(t, "inlet   { type fixedValue; value uniform 1173.0; }",
       "inlet   { type fixedValue; value uniform 0; }");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "cfd.case: " + t.string() +
                              ":18: inlet T = 0 K: the gas temperature must be > 0 K"))
      << e;
  fs::remove_all(d);
}

TEST(GasPreflight, ThermophysicalPropertiesWithTheConstantModelIsAmbiguous) {
  const fs::path d = clgCopy("ambiguous");
  const fs::path file = d / "openfoam" / "constant" / "thermophysicalProperties";
  writeText(file, "thermoType { type heRhoThermo; }\n");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:40:10: gas_properties.model: constant (properties from "))
      << e;
  EXPECT_TRUE(contains(e, file.string() + ":1 exists and would select the ideal-gas solver: the "
                                          "gas model is ambiguous"))
      << e;
  fs::remove_all(d);
}

TEST(GasPreflight, UserThermophysicalPropertiesWithIdealGasMustBeTheGeneratedOne) {
  const fs::path d = clgCopy("user");
  makeIdealGas(d);
  const fs::path file = d / "openfoam" / "constant" / "thermophysicalProperties";
  // Exactly the generated one: accepted (it is rewritten identically).
  writeText(file, thermophysicalPropertiesText(loadCase(d / "case.yaml")));
  EXPECT_EQ(failureOf(d), "");
  // Anything else is refused naming the first differing line.
  edit(file, "pRef            101325;", "pRef            100000;");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:40:10: gas_properties.model: ideal_gas: coredem writes "
                          "constant/thermophysicalProperties from case.yaml"))
      << e;
  EXPECT_TRUE(contains(e, file.string() + ":")) << e;
  EXPECT_TRUE(contains(e, "reads '    pRef            100000;")) << e;
  EXPECT_TRUE(contains(e, "would write '    pRef            101325;")) << e;
  EXPECT_TRUE(contains(e, "remove it; case.yaml defines the gas")) << e;
  fs::remove_all(d);
}

TEST(GasPreflight, IdealGasTemperatureIsTheOneOfZeroT) {
  const fs::path d = clgCopy("t0");
  makeIdealGas(d);
  edit(d / "case.yaml", "  temperature: 1173.0\n  pressure: 101325.0",
       "  temperature: 1073.0\n  pressure: 101325.0");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "case.yaml:41:16: gas_properties.temperature: 1073 K (the initial gas "
                          "of the ideal-gas model), but " +
                              (d / "openfoam" / "0" / "T").string() +
                              ":15 gives internalField T = 1173 K"))
      << e;
  fs::remove_all(d);
}

TEST(GasPreflight, IdealGasDoesNotCompareTransportProperties) {
  const fs::path d = clgCopy("transport");
  makeIdealGas(d);
  // The constant-property values of transportProperties are not the ideal gas's: not compared.
  edit(d / "openfoam" / "constant" / "transportProperties", "rho             0.239;",
       "rho             0.5;");
  EXPECT_EQ(failureOf(d), "");
  fs::remove_all(d);
}

TEST(GasPreflight, ReadFoamFieldFindsInternalAndFixedValues) {
  const FoamFieldValues v = readFoamField(kSource / "cases" / "clg" / "openfoam" / "0" / "N2");
  ASSERT_TRUE(v.found);
  EXPECT_EQ(v.className, "volScalarField");
  EXPECT_EQ(v.dimensions, "0 0 0 0 0 0 0");
  ASSERT_EQ(v.values.size(), 2u); // internalField and the fixedValue inlet (not inletOutlet)
  EXPECT_EQ(v.values[0].patch, "internalField");
  EXPECT_EQ(v.values[0].value, 0.608616);
  EXPECT_EQ(v.values[0].line, 16);
  EXPECT_EQ(v.values[1].patch, "inlet");
  EXPECT_EQ(v.values[1].value, 0.608616);
  EXPECT_EQ(v.values[1].line, 19);
  EXPECT_FALSE(readFoamField(kSource / "cases" / "clg" / "openfoam" / "0" / "nope").found);
}

// ideal_gas solves p in Pa. The constant model's kinematic 0/p (m2/s2) of cases/clg is a zero gauge
// pressure, the same field in Pa: accepted, and the run's copy gets Pa dimensions (the case folder
// keeps its file). A non-zero kinematic value, or a patch type with a pressure of its own
// (totalPressure), is refused naming the file and the dimensions to give.
TEST(GasPreflight, KinematicPressureIsAcceptedOnlyAsAZeroGauge) {
  const fs::path d = clgCopy("kinematic-p");
  makeIdealGas(d);
  const fs::path p = d / "openfoam" / "0" / "p";
  ASSERT_TRUE(contains(readText(p), "dimensions      [0 2 -2 0 0 0 0];"));
  EXPECT_EQ(failureOf(d), "");
  const CaseConfig c = loadCase(d / "case.yaml");
  prepareWorkDir(participant("coredemFoam"), c, d / "run");
  const std::string copied = readText(d / "run" / "openfoam" / "0" / "p");
  EXPECT_TRUE(contains(copied, "dimensions      [1 -1 -2 0 0 0 0];")) << copied;
  EXPECT_EQ(readFoamField(d / "run" / "openfoam" / "0" / "p").dimensions, kPressureDimensions);
  EXPECT_TRUE(contains(readText(p), "dimensions      [0 2 -2 0 0 0 0];"));
  // With the constant model the copy keeps the kinematic p.
  const fs::path k = clgCopy("kinematic-p-constant");
  prepareWorkDir(participant("coredemFoam"), loadCase(k / "case.yaml"), k / "run");
  EXPECT_TRUE(contains(readText(k / "run" / "openfoam" / "0" / "p"), "[0 2 -2 0 0 0 0]"));

  edit(p, "outlet  { type fixedValue; value uniform 0; }",
       "outlet  { type fixedValue; value uniform 5; }");
  std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "gas_properties.model: ideal_gas solves p in Pa, but " + p.string() +
                              ":15 is the constant model's kinematic pressure"))
      << e;
  EXPECT_TRUE(contains(e, "give 0/p dimensions [1 -1 -2 0 0 0 0] and its values in Pa")) << e;
  edit(p, "outlet  { type fixedValue; value uniform 5; }",
       "outlet  { type totalPressure; p0 uniform 0; value uniform 0; }");
  e = failureOf(d);
  EXPECT_TRUE(contains(e, "kinematic pressure")) << e;
}

// A reacting ideal-gas case with one PIMPLE outer corrector conserves species mass only to O(Δt)
// of the density change (docs/coredemFoam.md): refused, naming fvSolution's line and the minimum;
// the constant model (density fixed) is not concerned, and an fvSolution without the entry is
// OpenFOAM's default, 1.
TEST(GasPreflight, ReactingIdealGasWithOneOuterCorrectorIsRefused) {
  const fs::path d = clgCopy("outer");
  const fs::path sol = d / "openfoam" / "system" / "fvSolution";
  edit(sol, "nOuterCorrectors 3;", "nOuterCorrectors 1;");
  EXPECT_EQ(failureOf(d), ""); // model constant
  makeIdealGas(d);
  std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "gas_properties.model: ideal_gas with reactions needs at least 3 PIMPLE "
                          "outer correctors, but " +
                              sol.string() + ":27 gives nOuterCorrectors 1:"))
      << e;
  edit(sol, "    nOuterCorrectors 1;\n", "");
  e = failureOf(d);
  EXPECT_TRUE(contains(e, "gives nOuterCorrectors 1 (no entry: OpenFOAM's default)")) << e;
  edit(sol, "PIMPLE\n{\n", "PIMPLE\n{\n    nOuterCorrectors 3;\n");
  EXPECT_EQ(failureOf(d), "");
  fs::remove_all(d);
}

// The gas model without gas_properties.model: ideal_gas where heat or reactions are exchanged and
// the participant solves the gas; constant properties then need model: constant (refused
// otherwise, naming the key); constant where nothing is exchanged (the isothermal
// fluidized-bed-small) or the participant prescribes the gas; an explicit constant gas 70 K from
// the particles is warned about.
TEST(GasPreflight, TheGasModelDefaultsToTheIdealGasWhereHeatOrReactionsAreExchanged) {
  const fs::path d = clgCopy("default");
  const fs::path yaml = d / "case.yaml";
  // No model, no constant values: the reacting CLG case is an ideal gas.
  edit(yaml,
       "  model: constant\n  density: 0.239\n  viscosity: 4.4e-5\n  conductivity: 0.085\n"
       "  cp: 1650.0\n",
       "");
  EXPECT_TRUE(loadCase(yaml).gasProperties.idealGas());
  EXPECT_EQ(failureOf(d), "");
  // Constant values without a model: refused, the model is ideal_gas by default.
  edit(yaml, "  temperature: 1173.0\n", "  density: 0.239\n  temperature: 1173.0\n");
  try {
    loadCase(yaml);
    ADD_FAILURE() << "constant values without a model were accepted";
  } catch (const CaseError& e) {
    EXPECT_TRUE(contains(e.what(), "gas_properties.density: the case has reactions with "
                                   "coredemFoam, so its gas model is ideal_gas (the default)"))
        << e.what();
    EXPECT_TRUE(contains(e.what(), "write gas_properties.model: constant")) << e.what();
  }
  fs::remove_all(d);

  // Nothing exchanged: an isothermal bed keeps the constant gas without a model key.
  const CaseConfig iso = loadCase(kSource / "cases" / "fluidized-bed-small" / "case.yaml");
  EXPECT_FALSE(iso.gasProperties.idealGas());
  EXPECT_EQ(largestGasTemperatureDifference(iso), 0.0);

  // A heated bed: ideal_gas by default; model: constant is kept and warned about (70 K).
  const fs::path h = fs::temp_directory_path() / "coredem-gas-default-heated";
  fs::remove_all(h);
  fs::create_directories(h);
  const fs::path src = kSource / "cases" / "fluidized-bed-cooling";
  fs::copy(src / "openfoam", h / "openfoam", fs::copy_options::recursive);
  std::string text = readText(src / "case.yaml");
  writeText(h / "case.yaml", replace(text, "  model: ideal_gas\n", ""));
  const CaseConfig heated = loadCase(h / "case.yaml");
  EXPECT_TRUE(heated.gasProperties.idealGas());
  EXPECT_NEAR(largestGasTemperatureDifference(heated), 363.0 - 293.15, 1e-9);
  EXPECT_TRUE(checkCaseConsistency(heated).empty());
  writeText(h / "case.yaml", replace(replace(text, "  diffusivity: 2.0e-5\n", ""),
                                     "  model: ideal_gas\n", "  model: constant\n"));
  const auto w = checkCaseConsistency(loadCase(h / "case.yaml"));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(contains(w[0], "gas_properties.model: constant gas properties with particles or "
                             "walls up to 69.85 K from the gas (more than 20 K)"))
      << w[0];
  // models.heat off: nothing is exchanged, the default is constant.
  writeText(h / "case.yaml",
            replace(replace(text, "  model: ideal_gas\n", ""), "  diffusivity: 2.0e-5\n", "") +
                "models: {heat: \"off\"}\n");
  EXPECT_FALSE(loadCase(h / "case.yaml").gasProperties.idealGas());
  fs::remove_all(h);
}

// One clip of the gas fraction (models: {eps_min}, coredemFoam -epsMin): an old alphacMin in
// transportProperties that differs is refused naming both; equal to models: {eps_min} it passes.
TEST(GasPreflight, TransportPropertiesAlphacMinMustBeTheCaseClip) {
  const fs::path d = clgCopy("alphacmin");
  const fs::path file = d / "openfoam" / "constant" / "transportProperties";
  writeText(file, readText(file) + "alphacMin 0.3;\n");
  const std::string e = failureOf(d);
  EXPECT_TRUE(contains(e, "models.eps_min: 0.35 (the clip of the gas fraction for the DEM's drag "
                          "and the gas), but " +
                              file.string()))
      << e;
  EXPECT_TRUE(contains(e, "gives alphacMin = 0.3: remove alphacMin there")) << e;
  edit(d / "case.yaml", "\nmodels:\n", "\nmodels:\n  eps_min: 0.3\n");
  EXPECT_EQ(failureOf(d), "");
  fs::remove_all(d);
}
