// The gas model of case.yaml (gas_properties.model constant | ideal_gas, docs/case-schema.md):
// each parse rule and refusal (file:line:col and the message), the gas data table (NASA-7 read
// from the DEM's nasa7.h, Sutherland coefficients checked against independent data), the
// mixture state, and the generated constant/thermophysicalProperties read back number by number.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <coredem/dem/dem_config.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/models.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/gas_data.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/participant/openfoam.h>

#include "case_text.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::errorOf;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;
namespace k = coredem::dem::kernels;

namespace {

// Line numbers matter: the tests check file:line:col.
const char* kIdealGas = R"(name: gasmodel
time: {end: 0.01, dt: 1.0e-4}
grid: {spacing: [0.01, 0.01, 0.01], cells: [2, 2, 4]}
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - {material: glass, count: 1, diameter: 2.0e-3, region: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}}
cfd: {participant: coredemFoam, case: openfoam}
gas_properties:
  model: ideal_gas
  temperature: 1173.0
  pressure: 101325.0
)";

const char* kSpecies = R"(species:
  - {name: CO, molar_mass: 0.028010}
  - {name: CO2, molar_mass: 0.044009}
  - {name: H2, molar_mass: 0.002016}
  - {name: H2O, molar_mass: 0.018015}
  - {name: N2, molar_mass: 0.028014}
)";

CaseConfig parse(const std::string& text) {
  return parseCase(text, "cases/x/case.yaml", fs::temp_directory_path());
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// Burcat's AIR record (L 9/95), as printed in therm.dat: a1..a7 of 1000-6000 K and 200-1000 K.
const std::array<double, 7> kBurcatAirHigh = {3.08792717E+00, 1.24597184E-03,  -4.23718945E-07,
                                              6.74774789E-11, -3.97076972E-15, -9.95262755E+02,
                                              5.95960930E+00};
const std::array<double, 7> kBurcatAirLow = {3.56839620E+00,  -6.78729429E-04, 1.55371476E-06,
                                             -3.29937060E-12, -4.66395387E-13, -1.06234659E+03,
                                             3.71582965E+00};

// ------------------------------------------------------------ reading the dictionary back

/// One species block of a generated thermophysicalProperties.
struct FoamSpecies {
  double molWeight = 0, Tlow = 0, Thigh = 0, Tcommon = 0, As = 0, Ts = 0;
  std::vector<double> high, low;
};

struct FoamThermo {
  std::vector<std::string> species;
  std::string inertSpecie;
  std::map<std::string, FoamSpecies> data;
  std::map<std::string, double> coredem;
  std::map<std::string, std::string> thermoType;
};

std::string stripComments(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  std::string line;
  bool block = false;
  while (std::getline(in, line)) {
    if (block) {
      if (line.find("*/") != std::string::npos) {
        block = false;
      }
      continue;
    }
    if (line.rfind("/*", 0) == 0) {
      block = line.find("*/") == std::string::npos;
      continue;
    }
    const auto c = line.find("//");
    out += (c == std::string::npos ? line : line.substr(0, c)) + "\n";
  }
  return out;
}

/// The body of sub-dictionary `name` ("name { ... }", braces balanced) inside `text`.
std::string block(const std::string& text, const std::string& name) {
  const std::regex head("(^|\\s)" + name + "\\s*\\{");
  std::smatch m;
  if (!std::regex_search(text, m, head)) {
    return "";
  }
  std::size_t i = std::size_t(m.position(0) + m.length(0));
  int depth = 1;
  const std::size_t start = i;
  for (; i < text.size() && depth > 0; ++i) {
    depth += text[i] == '{' ? 1 : text[i] == '}' ? -1 : 0;
  }
  return text.substr(start, i - 1 - start);
}

double entry(const std::string& text, const std::string& key) {
  std::smatch m;
  EXPECT_TRUE(std::regex_search(text, m, std::regex("(^|\\s)" + key + "\\s+([^;\\s]+)\\s*;")))
      << key;
  return std::strtod(m[2].str().c_str(), nullptr);
}

std::vector<double> list(const std::string& text, const std::string& key) {
  std::smatch m;
  EXPECT_TRUE(std::regex_search(text, m, std::regex(key + "\\s*\\(([^)]*)\\)\\s*;"))) << key;
  std::istringstream in(m[1].str());
  std::vector<double> v;
  std::string w;
  while (in >> w) {
    v.push_back(std::strtod(w.c_str(), nullptr)); // strtod: exact round trip of the text
  }
  return v;
}

FoamThermo readBack(const std::string& raw) {
  const std::string text = stripComments(raw);
  FoamThermo t;
  std::smatch m;
  EXPECT_TRUE(std::regex_search(text, m, std::regex("\\nspecies\\s*\\(([^)]*)\\)\\s*;")));
  std::istringstream in(m[1].str());
  std::string w;
  while (in >> w) {
    t.species.push_back(w);
  }
  if (std::regex_search(text, m, std::regex("\\ninertSpecie\\s+(\\w+)\\s*;"))) {
    t.inertSpecie = m[1].str();
  }
  const std::string type = block(text, "thermoType");
  for (const char* key :
       {"type", "mixture", "transport", "thermo", "energy", "equationOfState", "specie"}) {
    std::smatch e;
    EXPECT_TRUE(std::regex_search(type, e, std::regex(std::string(key) + "\\s+(\\w+)\\s*;")))
        << key;
    t.thermoType[key] = e[1].str();
  }
  for (const auto& s : t.species) {
    const std::string b = block(text, s);
    FoamSpecies f;
    f.molWeight = entry(block(b, "specie"), "molWeight");
    const std::string th = block(b, "thermodynamics");
    f.Tlow = entry(th, "Tlow");
    f.Thigh = entry(th, "Thigh");
    f.Tcommon = entry(th, "Tcommon");
    f.high = list(th, "highCpCoeffs");
    f.low = list(th, "lowCpCoeffs");
    const std::string tr = block(b, "transport");
    f.As = entry(tr, "As");
    f.Ts = entry(tr, "Ts");
    t.data[s] = f;
  }
  const std::string c = block(text, "coredem");
  for (const char* key : {"pRef", "D", "alphacMin"}) {
    t.coredem[key] = entry(c, key);
  }
  return t;
}

} // namespace

// ------------------------------------------------------------------------ parse rules

TEST(GasModelParse, DefaultIsConstantAndUnchanged) {
  const char* constant = R"(name: c
time: {end: 0.01, dt: 1.0e-4}
grid: {spacing: [0.01, 0.01, 0.01], cells: [2, 2, 4]}
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - {material: glass, count: 1, diameter: 2.0e-3, region: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}}
gas_properties: {density: 1.1, viscosity: 2e-5, conductivity: 0.03, cp: 1000, temperature: 300}
)";
  const CaseConfig c = parse(constant);
  EXPECT_EQ(c.gasProperties.model, "constant");
  EXPECT_FALSE(c.gasProperties.idealGas());
  EXPECT_EQ(c.gasProperties.density, 1.1);
  EXPECT_EQ(c.gasProperties.viscosity, 2e-5);
  EXPECT_EQ(c.gasProperties.conductivity, 0.03);
  EXPECT_EQ(c.gasProperties.cp, 1000.0);
  EXPECT_EQ(c.gasProperties.temperature, 300.0);
  EXPECT_EQ(c.gasProperties.pressure, 101325.0);
  // Explicit model constant: the same.
  const CaseConfig e = parse(replace(constant, "{density: 1.1", "{model: constant, density: 1.1"));
  EXPECT_EQ(e.gasProperties.model, "constant");
  EXPECT_EQ(e.gasProperties.density, 1.1);
  // No gas_properties at all: constant with the defaults.
  const CaseConfig d = parse(replace(constant,
                                     "gas_properties: {density: 1.1, viscosity: 2e-5, "
                                     "conductivity: 0.03, cp: 1000, temperature: 300}\n",
                                     ""));
  EXPECT_EQ(d.gasProperties.model, "constant");
  EXPECT_EQ(d.gasProperties.density, 1.204);
}

TEST(GasModelParse, UnknownModelNamesTheChoices) {
  const std::string e = errorOf(replace(kIdealGas, "model: ideal_gas", "model: perfect"));
  EXPECT_TRUE(contains(e, "cases/x/case.yaml:10:10: gas_properties.model")) << e;
  EXPECT_TRUE(contains(e, "constant, ideal_gas")) << e;
}

TEST(GasModelParse, IdealGasKeysAndDefaults) {
  const CaseConfig c = parse(kIdealGas);
  EXPECT_TRUE(c.gasProperties.idealGas());
  EXPECT_EQ(c.gasProperties.temperature, 1173.0);
  EXPECT_EQ(c.gasProperties.pressure, 101325.0);
  EXPECT_EQ(c.gasProperties.diffusivity, 2e-5);
  const CaseConfig g = parse(std::string(kIdealGas) + "  diffusivity: 2.0e-4\n");
  EXPECT_EQ(g.gasProperties.diffusivity, 2e-4);
  std::string e = errorOf(std::string(kIdealGas) + "  diffusivity: 0\n");
  EXPECT_TRUE(contains(e, "case.yaml:13:16: gas_properties.diffusivity")) << e;
  EXPECT_TRUE(contains(e, "m2/s, > 0")) << e;
  e = errorOf(std::string(kIdealGas) + "models: {eps_min: 1.5}\n");
  EXPECT_TRUE(contains(e, "case.yaml:13:19: models.eps_min")) << e;
  EXPECT_TRUE(contains(e, "in (0, 1)")) << e;
}

TEST(GasModelParse, IdealGasRefusesTheComputedProperties) {
  for (const std::string key : {"density", "viscosity", "conductivity", "cp"}) {
    const std::string e = errorOf(std::string(kIdealGas) + "  " + key + ": 1.0\n");
    EXPECT_TRUE(contains(e, "cases/x/case.yaml:13:" + std::to_string(key.size() + 5) +
                                ": gas_properties." + key + ": not with model: ideal_gas"))
        << e;
    EXPECT_TRUE(contains(e, "computes the")) << e;
    EXPECT_TRUE(contains(e, "remove the key, or use model: constant")) << e;
  }
}

TEST(GasModelParse, ConstantRefusesTheIdealGasKeys) {
  const std::string constant = replace(kIdealGas, "model: ideal_gas", "model: constant");
  const std::string e = errorOf(constant + "  diffusivity: 0.2\n");
  EXPECT_TRUE(
      contains(e, "case.yaml:13:16: gas_properties.diffusivity: only with model: ideal_gas"))
      << e;
  EXPECT_TRUE(contains(e, "constant/transportProperties gives D")) << e;
}

TEST(GasModelParse, TemperatureAndPressureMustBePositive) {
  std::string e = errorOf(replace(kIdealGas, "pressure: 101325.0", "pressure: 0"));
  EXPECT_TRUE(contains(e, "case.yaml:12:13: gas_properties.pressure")) << e;
  EXPECT_TRUE(contains(e, "Pa, > 0")) << e;
  e = errorOf(replace(kIdealGas, "temperature: 1173.0", "temperature: -5"));
  EXPECT_TRUE(contains(e, "case.yaml:11:16: gas_properties.temperature")) << e;
  EXPECT_TRUE(contains(e, "K, > 0")) << e;
}

TEST(GasModelParse, PrescribedGasParticipantHasNoIdealGas) {
  const std::string e =
      errorOf(replace(kIdealGas, "cfd: {participant: coredemFoam, case: openfoam}",
                      "cfd: {participant: coredem-gas}"));
  EXPECT_TRUE(contains(e, "case.yaml:10:10: gas_properties.model: ideal_gas needs a CFD "
                          "participant that solves the gas (cfd.participant: coredemFoam)"))
      << e;
  EXPECT_TRUE(contains(e, "coredem-gas prescribes the gas")) << e;
  // Without a cfd section the participant is coredem-gas: refused the same way.
  EXPECT_TRUE(
      contains(errorOf(replace(kIdealGas, "cfd: {participant: coredemFoam, case: openfoam}\n", "")),
               "ideal_gas needs a CFD participant"));
}

// The variable-density gas books the heat split for the sequential scheme only.
TEST(GasModelParse, StaggeredSchemeIsRefusedWithTheIdealGas) {
  const std::string e = errorOf(std::string(kIdealGas) + "coupling: {scheme: staggered}\n");
  EXPECT_TRUE(contains(e, "coupling.scheme: staggered is not available with "
                          "gas_properties.model: ideal_gas yet"))
      << e;
  EXPECT_TRUE(contains(e, "use scheme: sequential")) << e;
  EXPECT_NO_THROW(parse(std::string(kIdealGas) + "coupling: {scheme: sequential}\n"));
}

TEST(GasModelParse, SpeciesWithoutDataAreRefusedNamingTheSupportedOnes) {
  const std::string e =
      errorOf(std::string(kIdealGas) + kSpecies + "  - {name: O2, molar_mass: 0.031998}\n");
  EXPECT_TRUE(contains(e, "case.yaml:19:12: species[5].name: gas species 'O2' has no thermo "
                          "(NASA-7) or transport (Sutherland) data"))
      << e;
  EXPECT_TRUE(contains(e, "species with data: CO, CO2, H2, H2O, N2")) << e;
  // The constant model needs no data: any name.
  EXPECT_EQ(
      errorOf(replace(std::string(kIdealGas) + kSpecies + "  - {name: O2, molar_mass: 0.031998}\n",
                      "model: ideal_gas\n  temperature: 1173.0\n  pressure: 101325.0\n",
                      "model: constant\n")),
      "");
}

TEST(GasModelParse, SpeciesMolarMassMustBeTheTablesOne) {
  const std::string e = errorOf(std::string(kIdealGas) +
                                replace(kSpecies, "molar_mass: 0.028010", "molar_mass: 0.0281"));
  EXPECT_TRUE(contains(e, "case.yaml:14:28: species[0].molar_mass: 0.0281 kg/mol, but the "
                          "ideal-gas data (the DEM's NASA-7 table) give 0.02801 kg/mol for CO"))
      << e;
}

TEST(GasModelParse, AirIsNotASpeciesName) {
  const std::string e =
      errorOf(std::string(kIdealGas) + "species:\n  - {name: air, molar_mass: 0.02897}\n");
  EXPECT_TRUE(contains(e, "case.yaml:14:12: species[0].name: 'air' is the gas of a case without "
                          "species"))
      << e;
}

TEST(GasModelParse, IdealGasInitialStateIsTheMixtures) {
  // Air (no species) at 1173 K: the state of the air data.
  const CaseConfig air = parse(kIdealGas);
  const GasState s = idealGasState({"air"}, {1.0}, 1173.0, 101325.0);
  EXPECT_EQ(air.gasProperties.density, s.density);
  EXPECT_EQ(air.gasProperties.viscosity, s.viscosity);
  EXPECT_EQ(air.gasProperties.cp, s.cp);
  EXPECT_EQ(air.gasProperties.conductivity, s.conductivity);
  // p M/(R T) written out.
  EXPECT_NEAR(s.density, 101325.0 * 0.02896518 / (8.314462618 * 1173.0), 1e-12);
}

// ------------------------------------------------------------------------ the data

TEST(GasData, Nasa7IsTheDemsTable) {
  for (const auto& [name, g] :
       std::vector<std::pair<std::string, k::GasSpecies>>{{"CO", k::GasSpecies::CO},
                                                          {"CO2", k::GasSpecies::CO2},
                                                          {"H2", k::GasSpecies::H2},
                                                          {"H2O", k::GasSpecies::H2O},
                                                          {"N2", k::GasSpecies::N2}}) {
    const auto d = gasSpeciesData(name);
    ASSERT_TRUE(d) << name;
    const k::Nasa7Data n = k::nasa7Data(k::toSpecies(g));
    EXPECT_EQ(d->molarMass, k::molarMass(g)) << name;
    EXPECT_EQ(d->tLow, n.iv[0].tMin);
    EXPECT_EQ(d->tCommon, n.iv[0].tMax);
    EXPECT_EQ(d->tHigh, n.iv[1].tMax);
    for (int i = 0; i < 7; ++i) {
      EXPECT_EQ(d->lowCoeffs[std::size_t(i)], n.iv[0].a[i]) << name << " a" << i + 1;
      EXPECT_EQ(d->highCoeffs[std::size_t(i)], n.iv[1].a[i]) << name << " a" << i + 1;
    }
  }
  EXPECT_FALSE(gasSpeciesData("O2"));
  EXPECT_FALSE(gasSpeciesData("C")); // a solid species of the table
  EXPECT_EQ(gasSpeciesWithData(),
            (std::vector<std::string>{"CO", "CO2", "H2", "H2O", "N2", "air"}));
}

TEST(GasData, AirIsBurcatsRecord) {
  const auto d = gasSpeciesData("air");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->lowCoeffs, kBurcatAirLow);
  EXPECT_EQ(d->highCoeffs, kBurcatAirHigh);
  EXPECT_EQ(d->molarMass, 28.96518e-3);
  EXPECT_EQ(d->As, 1.458e-6);
  EXPECT_EQ(d->Ts, 110.4);
  // cp of air at 300 K: 1005 J/kg/K within 0.5 % (tables: 1005-1007).
  const GasState s = idealGasState({"air"}, {1.0}, 300.0, 101325.0);
  EXPECT_NEAR(s.cp, 1006.0, 5.0);
  // Both intervals meet at 1000 K (cp continuous within 0.1 %).
  const GasState lo = idealGasState({"air"}, {1.0}, 999.999999, 101325.0);
  const GasState hi = idealGasState({"air"}, {1.0}, 1000.0, 101325.0);
  EXPECT_NEAR(lo.cp, hi.cp, 1e-3 * hi.cp);
}

// Sutherland coefficients against independent data: Crane Co. (1988) reference viscosities
// (mu0 at T0) and IAPWS 2008 for steam (low-density limit at 1 kg/m3); each within 2 %
// (White's stated accuracy of the Sutherland law).
TEST(GasData, SutherlandMatchesIndependentViscosities) {
  struct Ref {
    const char* name;
    double T, mu;
  };
  for (const Ref& r :
       {Ref{"CO", 288.15, 17.2e-6}, Ref{"CO2", 293.15, 14.8e-6}, Ref{"H2", 293.85, 8.76e-6},
        Ref{"N2", 300.55, 17.81e-6}, Ref{"H2O", 433.15, 14.538e-6}, Ref{"H2O", 1173.15, 44.217e-6},
        Ref{"air", 293.15, 18.13e-6}}) {
    const auto d = gasSpeciesData(r.name);
    ASSERT_TRUE(d) << r.name;
    EXPECT_NEAR(sutherlandViscosity(*d, r.T), r.mu, 0.02 * r.mu) << r.name << " at " << r.T;
  }
  // As from (mu0, T0, S): CO of White's table, 1.657e-5 Pa s at 273 K, S = 136 K.
  EXPECT_NEAR(gasSpeciesData("CO")->As, 1.657e-5 * (273.0 + 136.0) / std::pow(273.0, 1.5), 1e-20);
  EXPECT_EQ(gasSpeciesData("CO")->Ts, 136.0);
}

TEST(GasData, MixtureStateCombinesLikeOpenFoam) {
  const double T = 1173.0, p = 101325.0;
  const std::vector<std::string> sp = {"H2O", "N2"};
  const std::vector<double> Y = {0.391384, 0.608616};
  const GasState s = idealGasState(sp, Y, T, p);
  const double M =
      1.0 / (Y[0] / k::molarMass(k::GasSpecies::H2O) + Y[1] / k::molarMass(k::GasSpecies::N2));
  EXPECT_NEAR(s.molarMass, M, 1e-15);
  EXPECT_NEAR(s.density, p * M / (k::kGasConstant * T), 1e-12);
  EXPECT_NEAR(s.cp,
              Y[0] * k::nasa7CpMass(k::Species::H2O, T) + Y[1] * k::nasa7CpMass(k::Species::N2, T),
              1e-9);
  // H2O/N2 1:1 by moles: M = 23.0 g/mol (the CLG case's estimate).
  EXPECT_NEAR(s.molarMass, 0.02302, 1e-5);
  const auto h2o = *gasSpeciesData("H2O");
  const auto n2 = *gasSpeciesData("N2");
  const double As = Y[0] * h2o.As + Y[1] * n2.As, Ts = Y[0] * h2o.Ts + Y[1] * n2.Ts;
  EXPECT_NEAR(s.viscosity, As * std::sqrt(T) / (1.0 + Ts / T), 1e-18);
  const double R = k::kGasConstant / M, cv = s.cp - R;
  EXPECT_NEAR(s.conductivity, s.viscosity * cv * (1.32 + 1.77 * R / cv), 1e-15);
  EXPECT_THROW(idealGasState({"O2"}, {1.0}, T, p), std::invalid_argument);
}

// Reference: Debian's OpenFOAM v1912 rhoReactingFoam (heRhoThermo, multiComponentMixture,
// sutherland, janaf) on a one-cell case with the dictionary coredem generates for the five CLG
// species, H2O/N2 mass fractions 0.391384/0.608616, 1173 K, 101325 Pa (and for air); fields
// written by
// `rhoReactingFoam -postProcess -func 'writeObjects(rho, thermo:mu, thermo:alpha)'` (8 digits).
// rho differs by OpenFOAM's gas constant (8314.47 J/kmol/K vs CODATA 8314.462618: 9e-7).
TEST(GasData, MixtureStateIsOpenFoamsThermo) {
  const GasState s = idealGasState({"CO", "CO2", "H2", "H2O", "N2"},
                                   {0.0, 0.0, 0.0, 0.391384, 0.608616}, 1173.0, 101325.0);
  EXPECT_NEAR(s.density, 0.23910327, 2e-6 * 0.23910327);
  EXPECT_NEAR(s.viscosity, 4.3687841e-05, 1e-7 * 4.3687841e-05);
  EXPECT_NEAR(s.conductivity / s.cp, 6.1906876e-05, 1e-6 * 6.1906876e-05); // alpha = kappa/cp
  // The air case (generated 0/air, 2-D mesh with empty patches) at 293.15 K.
  const GasState air = idealGasState({"air"}, {1.0}, 293.15, 101325.0);
  EXPECT_NEAR(air.density, 1.2041161, 2e-6 * 1.2041161);
  EXPECT_NEAR(air.viscosity, 1.8134059e-05, 1e-7 * 1.8134059e-05);
}

// ------------------------------------------------------------------------ the dictionary

TEST(GasModelDictionary, FiveSpeciesReadBackExactly) {
  const CaseConfig c = parse(std::string(kIdealGas) + kSpecies + "  \n");
  const std::string text = thermophysicalPropertiesText(c);
  EXPECT_TRUE(contains(text, "Generated by coredem from case.yaml")) << text;
  EXPECT_TRUE(contains(text, "edit case.yaml instead")) << text;
  const FoamThermo t = readBack(text);
  EXPECT_EQ(t.species, (std::vector<std::string>{"CO", "CO2", "H2", "H2O", "N2"}));
  EXPECT_EQ(t.inertSpecie, "N2");
  EXPECT_EQ(t.thermoType.at("type"), "heRhoThermo");
  EXPECT_EQ(t.thermoType.at("mixture"), "multiComponentMixture");
  EXPECT_EQ(t.thermoType.at("transport"), "sutherland");
  EXPECT_EQ(t.thermoType.at("thermo"), "janaf");
  EXPECT_EQ(t.thermoType.at("energy"), "sensibleEnthalpy");
  EXPECT_EQ(t.thermoType.at("equationOfState"), "perfectGas");
  EXPECT_EQ(t.thermoType.at("specie"), "specie");
  const std::vector<k::GasSpecies> gas = {k::GasSpecies::CO, k::GasSpecies::CO2, k::GasSpecies::H2,
                                          k::GasSpecies::H2O, k::GasSpecies::N2};
  for (std::size_t i = 0; i < gas.size(); ++i) {
    const FoamSpecies& f = t.data.at(t.species[i]);
    const k::Nasa7Data n = k::nasa7Data(k::toSpecies(gas[i]));
    SCOPED_TRACE(t.species[i]);
    EXPECT_EQ(f.molWeight, k::molarMass(gas[i]) * 1e3); // g/mol, exact round trip
    EXPECT_EQ(f.Tlow, n.iv[0].tMin);
    EXPECT_EQ(f.Tcommon, n.iv[0].tMax);
    EXPECT_EQ(f.Thigh, n.iv[1].tMax);
    ASSERT_EQ(f.low.size(), 7u);
    ASSERT_EQ(f.high.size(), 7u);
    for (int j = 0; j < 7; ++j) {
      EXPECT_EQ(f.low[std::size_t(j)], n.iv[0].a[j]) << "low a" << j + 1;
      EXPECT_EQ(f.high[std::size_t(j)], n.iv[1].a[j]) << "high a" << j + 1;
    }
    const auto d = gasSpeciesData(t.species[i]);
    EXPECT_EQ(f.As, d->As);
    EXPECT_EQ(f.Ts, d->Ts);
  }
  EXPECT_EQ(t.coredem.at("pRef"), 101325.0);
  EXPECT_EQ(t.coredem.at("D"), 2e-5);
  EXPECT_EQ(t.coredem.at("alphacMin"), 0.35); // models: {eps_min}, default
}

// One clip ε_min of the gas fraction for both sides (docs/physics.md §1.1): the DEM's drag and
// convection clip (its DemConfig after the case's models:, as the server applies them) and the
// gas's alphacMin (the generated dictionary) are the same number, exactly, by default and for
// every spelling of the key; two spellings at once and the old gas_properties.alphac_min are
// refused naming models: {eps_min}.
TEST(GasModelDictionary, OneGasFractionClipForTheGasAndTheDrag) {
  auto clips = [](const CaseConfig& c) {
    coredem::dem::DemConfig d;
    for (const auto& [key, value] : c.models) {
      coredem::dem::applyModelOption(d, key, value);
    }
    return std::make_pair(d.epsMinDrag,
                          readBack(thermophysicalPropertiesText(c)).coredem.at("alphacMin"));
  };
  const auto byDefault = clips(parse(kIdealGas));
  EXPECT_EQ(byDefault.first, 0.35);
  EXPECT_EQ(byDefault.second, byDefault.first) << "the gas clips at another eps_min than the drag";
  for (const char* key : {"eps_min", "dem.eps_min_drag", "eps_min_drag"}) {
    SCOPED_TRACE(key);
    const auto given = clips(parse(std::string(kIdealGas) + "models: {" + key + ": 0.3125}\n"));
    EXPECT_EQ(given.first, 0.3125);
    EXPECT_EQ(given.second, 0.3125);
  }
  std::string e =
      errorOf(std::string(kIdealGas) + "models: {eps_min: 0.3, dem.eps_min_drag: 0.3}\n");
  EXPECT_TRUE(contains(e, "models.dem.eps_min_drag: the clip of the gas fraction is given twice"))
      << e;
  e = errorOf(std::string(kIdealGas) + "  alphac_min: 0.3\n");
  EXPECT_TRUE(contains(e, "case.yaml:13:15: gas_properties.alphac_min: replaced by models: "
                          "{eps_min: ...}"))
      << e;
}

TEST(GasModelDictionary, AirCaseHasOneSpecies) {
  const CaseConfig air =
      parse(replace(kIdealGas, "pressure: 101325.0", "pressure: 2.0e5\n  diffusivity: 3.0e-5"));
  const FoamThermo t = readBack(thermophysicalPropertiesText(air));
  EXPECT_EQ(t.species, (std::vector<std::string>{"air"}));
  EXPECT_EQ(t.inertSpecie, "air");
  const FoamSpecies& f = t.data.at("air");
  EXPECT_EQ(f.molWeight, 28.96518);
  EXPECT_EQ(f.Tlow, 200.0);
  EXPECT_EQ(f.Tcommon, 1000.0);
  EXPECT_EQ(f.Thigh, 6000.0);
  EXPECT_EQ(f.high, std::vector<double>(kBurcatAirHigh.begin(), kBurcatAirHigh.end()));
  EXPECT_EQ(f.low, std::vector<double>(kBurcatAirLow.begin(), kBurcatAirLow.end()));
  EXPECT_EQ(f.As, 1.458e-6);
  EXPECT_EQ(f.Ts, 110.4);
  EXPECT_EQ(t.coredem.at("pRef"), 2.0e5);
  EXPECT_EQ(t.coredem.at("D"), 3.0e-5);
}

TEST(GasModelDictionary, WrittenIntoTheRunCopyOnlyWithIdealGas) {
  const fs::path d = fs::temp_directory_path() / "coredem-gas-model-copy";
  fs::remove_all(d);
  fs::create_directories(d / "case" / "openfoam" / "system");
  fs::create_directories(d / "case" / "openfoam" / "constant");
  std::ofstream(d / "case" / "openfoam" / "system" / "controlDict") << "application coredemFoam;\n";
  const CaseConfig c = parseCase(kIdealGas, d / "case" / "case.yaml", d / "case");
  prepareWorkDir(participant("coredemFoam"), c, d / "run");
  const fs::path file = d / "run" / "openfoam" / "constant" / "thermophysicalProperties";
  ASSERT_TRUE(fs::is_regular_file(file));
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(text, thermophysicalPropertiesText(c));
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
  // An air case gets its one species field, 0/air (mass fraction 1).
  ASSERT_TRUE(fs::is_regular_file(d / "run" / "openfoam" / "0" / "air"));
  std::ifstream airIn(d / "run" / "openfoam" / "0" / "air");
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(airIn)), {}), airFieldText(c));
  EXPECT_TRUE(contains(airFieldText(c), "internalField   uniform 1;"));
  EXPECT_TRUE(contains(airFieldText(c), "#includeEtc \"caseDicts/setConstraintTypes\""));
  // The case folder itself is not touched.
  EXPECT_FALSE(fs::exists(d / "case" / "openfoam" / "constant" / "thermophysicalProperties"));
  EXPECT_FALSE(fs::exists(d / "case" / "openfoam" / "0" / "air"));
  // A user's 0/Ydefault (or 0/air) is kept: no 0/air written.
  fs::create_directories(d / "case" / "openfoam" / "0");
  std::ofstream(d / "case" / "openfoam" / "0" / "Ydefault") << "user";
  prepareWorkDir(participant("coredemFoam"), c, d / "run3");
  EXPECT_TRUE(
      fs::is_regular_file(d / "run3" / "openfoam" / "constant" / "thermophysicalProperties"));
  EXPECT_FALSE(fs::exists(d / "run3" / "openfoam" / "0" / "air"));
  fs::remove(d / "case" / "openfoam" / "0" / "Ydefault");
  // A case with species: their fields come with cfd.case; no 0/air.
  const CaseConfig withSpecies =
      parseCase(std::string(kIdealGas) + kSpecies, d / "case" / "case.yaml", d / "case");
  prepareWorkDir(participant("coredemFoam"), withSpecies, d / "run4");
  EXPECT_TRUE(
      fs::is_regular_file(d / "run4" / "openfoam" / "constant" / "thermophysicalProperties"));
  EXPECT_FALSE(fs::exists(d / "run4" / "openfoam" / "0" / "air"));
  // Constant model: nothing generated.
  const CaseConfig k2 = parseCase(replace(kIdealGas, "model: ideal_gas", "model: constant"),
                                  d / "case" / "case.yaml", d / "case");
  prepareWorkDir(participant("coredemFoam"), k2, d / "run2");
  EXPECT_TRUE(fs::is_regular_file(d / "run2" / "openfoam" / "system" / "controlDict"));
  EXPECT_FALSE(fs::exists(d / "run2" / "openfoam" / "constant" / "thermophysicalProperties"));
  fs::remove_all(d);
}
