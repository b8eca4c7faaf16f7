// Gas data of the ideal-gas model (gas_data.h).
#include <cmath>
#include <stdexcept>

#include <coredem/dem/kernels/nasa7.h>
#include <coredem/orchestrator/gas_data.h>

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

} // namespace coredem::orchestrator
