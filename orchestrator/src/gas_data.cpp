// Gas data of the ideal-gas model and the generated OpenFOAM dictionary (gas_data.h).
#include <cmath>
#include <fstream>
#include <iterator>
#include <regex>
#include <stdexcept>

#include <fmt/format.h>

#include <coredem/common/yaml_section.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/orchestrator/foam_field.h>
#include <coredem/orchestrator/gas_data.h>

namespace fs = std::filesystem;
namespace k = coredem::dem::kernels;

namespace coredem::orchestrator {
namespace {

/// Sutherland data as published: mu0 (Pa s) at T0 (K), Sutherland constant S (K).
struct SutherlandTriple {
  const char* name;
  double mu0, T0, S;
};

/// White, F. M., Viscous Fluid Flow, 3rd ed., McGraw-Hill 2006, Table 1-2 ("Sutherland-law
/// constants for gases"); stated accuracy about ±2 % over a wide range of temperatures. Checked
/// against independent data in the unit tests (Crane 1988 reference viscosities; IAPWS 2008 for
/// steam at 433 K and 1173 K).
constexpr SutherlandTriple kWhiteTable12[] = {
    {"CO", 1.657e-5, 273.0, 136.0}, {"CO2", 1.370e-5, 273.0, 222.0}, {"H2", 8.411e-6, 273.0, 97.0},
    {"N2", 1.663e-5, 273.0, 107.0}, {"H2O", 1.12e-5, 350.0, 1064.0}, // steam
};

/// The CFD gas species of the DEM's NASA-7 table (nasa7.h GasSpecies), by name.
struct Nasa7Gas {
  const char* name;
  k::GasSpecies species;
};
constexpr Nasa7Gas kNasa7Gases[] = {{"CO", k::GasSpecies::CO},
                                    {"CO2", k::GasSpecies::CO2},
                                    {"H2", k::GasSpecies::H2},
                                    {"H2O", k::GasSpecies::H2O},
                                    {"N2", k::GasSpecies::N2}};

// Air (the pseudo-species of a gas without species).
// NASA-7: Burcat's database, record "AIR L 9/95" (E. Goos, A. Burcat, B. Ruscic, Extended Third
// Millennium Ideal Gas and Condensed Phase Thermochemical Database; the copy Debian's openfoam
// package ships as etc/thermoData/therm.dat), 200-1000-6000 K.
// Molar mass: 28.96518 g/mol, Burcat's air (N2/O2/Ar/CO2 dry air), as NASA's pyCycle uses it.
// Sutherland: As = 1.458e-6 Pa s/K^0.5, Ts = 110.4 K (U.S. Standard Atmosphere 1976, Eq. 51).
constexpr double kAirMolarMass = 28.96518e-3;
constexpr double kAirTlow = 200.0, kAirTcommon = 1000.0, kAirThigh = 6000.0;
constexpr std::array<double, 7> kAirLow = {3.56839620,      -6.78729429e-04, 1.55371476e-06,
                                           -3.29937060e-12, -4.66395387e-13, -1.06234659e+03,
                                           3.71582965};
constexpr std::array<double, 7> kAirHigh = {3.08792717,     1.24597184e-03,  -4.23718945e-07,
                                            6.74774789e-11, -3.97076972e-15, -9.95262755e+02,
                                            5.95960930};
constexpr double kAirAs = 1.458e-6, kAirTs = 110.4;

constexpr const char* kNasa7Source =
    "the DEM's NASA-7 table (dem-gpu-server/include/coredem/dem/kernels/nasa7.h: Burcat via MFiX)";
constexpr const char* kWhiteSource = "White, Viscous Fluid Flow (2006), Table 1-2";

/// cp/R of NASA-7 coefficients at T.
double cpOverR(const std::array<double, 7>& a, double T) {
  return a[0] + T * (a[1] + T * (a[2] + T * (a[3] + T * a[4])));
}

/// The shortest text that reads back to the same double.
std::string num(double v) {
  return fmt::format("{}", v);
}

std::string coeffs(const std::array<double, 7>& a) {
  std::string s = "(";
  for (double v : a) {
    s += fmt::format(" {}", v);
  }
  s += " )";
  return s;
}

} // namespace

std::optional<GasSpeciesData> gasSpeciesData(const std::string& name) {
  GasSpeciesData d;
  d.name = name;
  if (name == kAirSpecies) {
    d.molarMass = kAirMolarMass;
    d.tLow = kAirTlow;
    d.tCommon = kAirTcommon;
    d.tHigh = kAirThigh;
    d.lowCoeffs = kAirLow;
    d.highCoeffs = kAirHigh;
    d.As = kAirAs;
    d.Ts = kAirTs;
    d.thermoSource = "Burcat's database, AIR L 9/95";
    d.transportSource = "U.S. Standard Atmosphere 1976";
    return d;
  }
  const Nasa7Gas* gas = nullptr;
  for (const auto& g : kNasa7Gases) {
    if (name == g.name) {
      gas = &g;
    }
  }
  const SutherlandTriple* s = nullptr;
  for (const auto& t : kWhiteTable12) {
    if (name == t.name) {
      s = &t;
    }
  }
  if (gas == nullptr || s == nullptr) {
    return std::nullopt;
  }
  const k::Nasa7Data n = k::nasa7Data(k::toSpecies(gas->species));
  // janaf has two intervals that meet at Tcommon.
  if (n.n != 2 || n.iv[0].tMax != n.iv[1].tMin) {
    return std::nullopt;
  }
  d.molarMass = k::molarMass(gas->species);
  d.tLow = n.iv[0].tMin;
  d.tCommon = n.iv[0].tMax;
  d.tHigh = n.iv[1].tMax;
  for (int i = 0; i < 7; ++i) {
    d.lowCoeffs[std::size_t(i)] = n.iv[0].a[i];
    d.highCoeffs[std::size_t(i)] = n.iv[1].a[i];
  }
  d.As = s->mu0 * (s->T0 + s->S) / std::pow(s->T0, 1.5);
  d.Ts = s->S;
  d.thermoSource = kNasa7Source;
  d.transportSource = kWhiteSource;
  return d;
}

std::vector<std::string> gasSpeciesWithData() {
  std::vector<std::string> names;
  for (const auto& g : kNasa7Gases) {
    if (gasSpeciesData(g.name)) {
      names.emplace_back(g.name);
    }
  }
  names.emplace_back(kAirSpecies);
  return names;
}

double sutherlandViscosity(const GasSpeciesData& d, double T) {
  return d.As * std::sqrt(T) / (1.0 + d.Ts / T);
}

GasState idealGasState(const std::vector<std::string>& species, const std::vector<double>& Y,
                       double T, double p) {
  if (species.size() != Y.size() || species.empty()) {
    throw std::invalid_argument("idealGasState: one mass fraction per species");
  }
  double invM = 0.0, cp = 0.0, As = 0.0, Ts = 0.0;
  for (std::size_t i = 0; i < species.size(); ++i) {
    const auto d = gasSpeciesData(species[i]);
    if (!d) {
      throw std::invalid_argument("idealGasState: no data for gas species " + species[i]);
    }
    const auto& a = T < d->tCommon ? d->lowCoeffs : d->highCoeffs;
    invM += Y[i] / d->molarMass;
    cp += Y[i] * cpOverR(a, T) * k::kGasConstant / d->molarMass;
    As += Y[i] * d->As;
    Ts += Y[i] * d->Ts;
  }
  GasState s;
  s.molarMass = 1.0 / invM;
  s.density = p * s.molarMass / (k::kGasConstant * T);
  s.cp = cp;
  s.viscosity = As * std::sqrt(T) / (1.0 + Ts / T);
  const double R = k::kGasConstant / s.molarMass; // J/kg/K
  const double cv = cp - R;
  s.conductivity = s.viscosity * cv * (1.32 + 1.77 * R / cv);
  return s;
}

std::vector<std::string> thermoSpecies(const CaseConfig& config) {
  std::vector<std::string> names;
  for (const auto& s : config.species) {
    names.push_back(s.name);
  }
  if (names.empty()) {
    names.emplace_back(kAirSpecies);
  }
  return names;
}

std::string thermophysicalPropertiesText(const CaseConfig& config) {
  const std::vector<std::string> species = thermoSpecies(config);
  std::string list;
  bool hasN2 = false;
  for (const auto& s : species) {
    list += fmt::format(" {}", s);
    hasN2 = hasN2 || s == "N2";
  }
  const auto& gp = config.gasProperties;
  std::string out = fmt::format(
      R"(/*--------------------------------*- C++ -*----------------------------------*\
  Generated by coredem from {} (gas_properties.model: ideal_gas).
  Do not edit: edit {} instead; coredem writes this file into every run.
\*---------------------------------------------------------------------------*/
FoamFile
{{
    version     2.0;
    format      ascii;
    class       dictionary;
    location    "constant";
    object      thermophysicalProperties;
}}
// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

thermoType
{{
    type            heRhoThermo;
    mixture         multiComponentMixture;
    transport       sutherland;
    thermo          janaf;
    energy          sensibleEnthalpy;
    equationOfState perfectGas;
    specie          specie;
}}

species ({} );
)",
      config.caseFile.filename().string(), config.caseFile.filename().string(), list);
  if (hasN2 || species.front() == kAirSpecies) {
    out += fmt::format("inertSpecie {};\n", hasN2 ? "N2" : kAirSpecies);
  }
  for (const auto& name : species) {
    const auto d = gasSpeciesData(name);
    if (!d) {
      throw CaseError(fmt::format("{}: species: gas species '{}' has no thermo or transport "
                                  "data for the ideal-gas model; species with data: {}",
                                  config.caseFile.string(), name,
                                  yaml::join(gasSpeciesWithData())));
    }
    out += fmt::format(R"(
// {}: NASA-7 from {}; Sutherland from {}
{}
{{
    specie
    {{
        molWeight       {};    // g/mol
    }}
    thermodynamics
    {{
        Tlow            {};
        Thigh           {};
        Tcommon         {};
        highCpCoeffs    {};
        lowCpCoeffs     {};
    }}
    transport
    {{
        As              {};    // Pa s/K^0.5: mu = As sqrt(T)/(1 + Ts/T)
        Ts              {};    // K
    }}
}}
)",
                       name, d->thermoSource, d->transportSource, name, num(d->molarMass * 1e3),
                       num(d->tLow), num(d->tHigh), num(d->tCommon), coeffs(d->highCoeffs),
                       coeffs(d->lowCoeffs), num(d->As), num(d->Ts));
  }
  out += fmt::format(R"(
coredem
{{
    pRef            {};    // Pa: thermodynamic pressure, rho = pRef M_mix/(R T)
    D               {};    // m2/s: species diffusivity
    alphacMin       {};    // smallest gas fraction the gas equations accept
}}

// ************************************************************************* //
)",
                     num(gp.pressure), num(gp.diffusivity), num(gp.alphacMin));
  return out;
}

std::string airFieldText(const CaseConfig& config) {
  return fmt::format(
      R"(/*--------------------------------*- C++ -*----------------------------------*\
  Generated by coredem from {} (gas_properties.model: ideal_gas, no species): the gas is air.
\*---------------------------------------------------------------------------*/
FoamFile
{{
    version     2.0;
    format      ascii;
    class       volScalarField;
    location    "0";
    object      air;
}}
// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

dimensions      [0 0 0 0 0 0 0];

internalField   uniform 1;

boundaryField
{{
    ".*"
    {{
        type            calculated;
        value           uniform 1;
    }}
    #includeEtc "caseDicts/setConstraintTypes"
}}

// ************************************************************************* //
)",
      config.caseFile.filename().string());
}

namespace {

void writeFile(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  const fs::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out) {
      throw UserError(fmt::format("cannot write {}", tmp.string()));
    }
  }
  fs::rename(tmp, file);
}

} // namespace

void writeGeneratedFoamDictionaries(const CaseConfig& config, const fs::path& workDir) {
  if (!config.gasProperties.idealGas()) {
    return;
  }
  writeFile(workDir / kThermophysicalProperties, thermophysicalPropertiesText(config));
  // A zero gauge kinematic p (pre-flight allows no other) is the same field in Pa.
  const fs::path pFile = workDir / "0" / "p";
  if (isZeroGaugeKinematicPressure(readFoamField(pFile))) {
    std::ifstream in(pFile, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::regex dims(R"(dimensions\s*\[\s*0\s+2\s+-2\s+0\s+0\s+0\s+0\s*\])");
    writeFile(pFile, std::regex_replace(
                         text, dims, std::string("dimensions      [") + kPressureDimensions + "]",
                         std::regex_constants::format_first_only));
  }
  // OpenFOAM's multiComponentMixture reads one field per species (or 0/Ydefault).
  const fs::path zero = workDir / "0";
  if (config.species.empty() && !fs::exists(zero / kAirSpecies) && !fs::exists(zero / "Ydefault")) {
    writeFile(zero / kAirSpecies, airFieldText(config));
  }
}

} // namespace coredem::orchestrator
