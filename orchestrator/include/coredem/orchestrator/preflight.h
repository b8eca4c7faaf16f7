#pragma once
/// @file
/// Pre-flight consistency of a case (`coredem check` and `coredem run`, docs/orchestrator.md
/// "Pre-flight checks"): what the schema alone cannot see. A failure throws CaseError (exit 2)
/// with file:line:col of case.yaml and both values; a warning is returned as a line of text.

#include <string>
#include <vector>

#include <coredem/orchestrator/case_config.h>

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
/// region and walls.box; the particles lie inside walls.box and on the inner side of every
/// plane; lattice regions hold `count` sites, random regions a solid fraction below
/// kMaxRandomSolidFraction, explicit positions overlap by at most kMaxInitialOverlapFraction;
/// temperatures below kImplausibleTemperatureK are warned about. Returns the warnings
/// ("file:line:col: key: what"); throws CaseError at the first failure.
std::vector<std::string> checkCaseConsistency(const CaseConfig& config);

/// Pre-flight of the OpenFOAM participant (its row in the participant table): gravity of
/// case.yaml equals `cfd.case`/constant/g, and gas_properties (density, viscosity = nu·rho, cp,
/// conductivity) equal constant/transportProperties (rho, nu, cp, kappa) within
/// kFoamEqualityRelTol. Throws CaseError naming both values and both places.
void checkOpenFoamCase(const CaseConfig& config);

} // namespace coredem::orchestrator
