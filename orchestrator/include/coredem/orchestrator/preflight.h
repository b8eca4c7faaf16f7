#pragma once
/// @file
/// Pre-flight consistency of a case (`coredem check` and `coredem run`, docs/orchestrator.md
/// "Pre-flight checks"): what the schema alone cannot see. A failure throws CaseError (exit 2)
/// with file:line:col of case.yaml and both values; a warning is returned as a line of text.

#include <filesystem>
#include <string>
#include <vector>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/foam_field.h> // readFoamField, read by the pre-flight

namespace coredem::orchestrator {

/// Largest initial overlap of two particles given by `positions`, as a fraction of the smaller
/// diameter; more is refused.
inline constexpr double kMaxInitialOverlapFraction = 0.05;
/// Solid fraction above which particles cannot be placed without overlap (random close packing);
/// a random-packing region asked to hold more is refused.
inline constexpr double kMaxRandomSolidFraction = 0.64;
/// Solid fraction above which random placement may not find room (warning).
inline constexpr double kWarnRandomSolidFraction = 0.35;
/// Temperatures below this (K) are warned about: probably degrees Celsius.
inline constexpr double kImplausibleTemperatureK = 200.0;
/// Relative tolerance of the equality of case.yaml and OpenFOAM values (gravity, gas
/// properties): the OpenFOAM files are usually written with 4–5 significant digits.
inline constexpr double kFoamEqualityRelTol = 1e-3;

/// The case's geometry and temperatures: the coupling grid covers the particles' initial
/// region, walls.box, the cylinders and cones with side inside or both, and the mesh walls; the
/// particles lie inside walls.box, on the inner side of every plane, at least a radius inside
/// every side-inside cylinder and cone over the axial extent where it reaches them, and (their
/// centres) inside every closed mesh wall; lattice regions hold `count` sites, random regions a
/// solid fraction below kMaxRandomSolidFraction, explicit positions overlap by at most
/// kMaxInitialOverlapFraction; temperatures below kImplausibleTemperatureK are warned about.
/// Returns the warnings
/// ("file:line:col: key: what"); throws CaseError at the first failure.
std::vector<std::string> checkCaseConsistency(const CaseConfig& config);

/// Pre-flight of the OpenFOAM participant (its row in the participant table), each failure a
/// CaseError naming both values and both places (docs/orchestrator.md "One source of truth"):
/// - gravity of case.yaml equals `cfd.case`/constant/g;
/// - model constant: gas_properties (density, viscosity = nu·rho, cp, conductivity) equal
///   constant/transportProperties (rho, nu, cp, kappa) within kFoamEqualityRelTol, and there is
///   no constant/thermophysicalProperties (it would make the gas model ambiguous);
/// - model ideal_gas: no constant/thermophysicalProperties unless it is exactly the one coredem
///   writes (gas_data.h), and 0/T's uniform internalField equals gas_properties.temperature;
/// - the case's species are the mass-fraction fields of 0/ (each species has 0/<name>; no other
///   dimensionless volScalarField but alpha* and Ydefault);
/// - the gas state of 0/ (uniform internalField and fixedValue patch values): T > 0, every mass
///   fraction in [0, 1], and where all species are uniform they sum to 1 within
///   kMassFractionSumTol (non-uniform values are skipped with an info line).
void checkOpenFoamCase(const CaseConfig& config);

/// Mass fractions must sum to 1 within this.
inline constexpr double kMassFractionSumTol = 1e-9;

} // namespace coredem::orchestrator
