#pragma once
/// @file
/// Host-side gas data of the ideal-gas model (`gas_properties.model: ideal_gas`,
/// docs/case-schema.md): read by the case reader (the initial gas state) and by the OpenFOAM
/// participant's unit, which writes its constant/thermophysicalProperties from it
/// (coredem/participant/openfoam.h).
///
/// Per gas species: the molar mass and the NASA-7 (janaf) coefficients of the DEM's table
/// (coredem/dem/kernels/nasa7.h: read from there, never copied), and Sutherland viscosity
/// coefficients (this table). A case whose gas has no species is air: one pseudo-species `air`
/// whose data (NASA-7 from Burcat's database, Sutherland from the US Standard Atmosphere) live
/// only here, since the DEM never sees it.
///
///   Sutherland:  mu(T) = As sqrt(T) / (1 + Ts/T)   (Pa s),  As = mu0 (T0 + S) / T0^1.5, Ts = S

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// Name of the pseudo-species of a gas without species (the whole gas is air).
inline constexpr const char* kAirSpecies = "air";

/// Largest relative difference of a case.yaml species molar mass from the table's (ideal_gas).
inline constexpr double kIdealGasMolarMassRelTol = 1e-4;

/// Thermo and transport data of one gas species.
struct GasSpeciesData {
  std::string name;
  double molarMass = 0.0;                        ///< kg/mol
  double tLow = 0.0, tCommon = 0.0, tHigh = 0.0; ///< K: the two NASA-7 intervals
  std::array<double, 7> lowCoeffs{};             ///< NASA-7 a1..a7 on [tLow, tCommon]
  std::array<double, 7> highCoeffs{};            ///< NASA-7 a1..a7 on [tCommon, tHigh]
  double As = 0.0;                               ///< Sutherland coefficient, Pa s / K^0.5
  double Ts = 0.0;                               ///< Sutherland temperature, K
  std::string thermoSource, transportSource;     ///< where the numbers come from
};

/// The data of gas species `name`, or nullopt when it has none (no NASA-7 or no Sutherland data).
std::optional<GasSpeciesData> gasSpeciesData(const std::string& name);

/// Names of the gas species with data, in table order (for messages).
std::vector<std::string> gasSpeciesWithData();

/// Sutherland viscosity of `d` at T (K), Pa s.
double sutherlandViscosity(const GasSpeciesData& d, double T);

/// Ideal-gas state of a mixture, the way OpenFOAM's multiComponentMixture combines its species
/// (mass-fraction weighted janaf coefficients and Sutherland As, Ts; modified Eucken
/// conductivity kappa = mu cv (1.32 + 1.77 R/cv)).
struct GasState {
  double molarMass = 0.0;    ///< kg/mol
  double density = 0.0;      ///< kg/m3, p M/(R T)
  double viscosity = 0.0;    ///< Pa s
  double conductivity = 0.0; ///< W/m/K
  double cp = 0.0;           ///< J/kg/K
};

/// The state of the mixture of `species` (names with data) with mass fractions `Y` (same order,
/// summing to 1) at T (K) and p (Pa). Throws std::invalid_argument on unknown names.
GasState idealGasState(const std::vector<std::string>& species, const std::vector<double>& Y,
                       double T, double p);

/// The species of the ideal-gas dictionary: the case's gas species in case.yaml order, or
/// {"air"} when the case has none.
std::vector<std::string> thermoSpecies(const CaseConfig& config);

} // namespace coredem::orchestrator
