#pragma once
/// @file
/// Pre-flight consistency of a case (`coredem check` and `coredem run`, docs/orchestrator.md
/// "Pre-flight checks"): what the schema alone cannot see. A failure throws CaseError (exit 2)
/// with file:line:col of case.yaml and both values; a warning is returned as a line of text.

#include <filesystem>
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
/// Intersecting placed sets listed one warning each, up to this many pairs (then one line).
inline constexpr std::size_t kMaxIntersectionWarnings = 10;
/// Temperatures below this (K) are warned about: probably degrees Celsius.
inline constexpr double kImplausibleTemperatureK = 200.0;
/// A constant-property gas solved by the CFD (gas_properties.model: constant) further than this
/// (K) from a particle set or fixed-temperature walls is warned about: its density and viscosity
/// would change by more than ~7 % (ideal gas at 300 K).
inline constexpr double kConstantGasWarnDeltaT = 20.0;

/// The case's geometry and temperatures: the coupling grid covers the particles' initial
/// region, walls.box, the cylinders and cones with side inside or both, and the mesh walls; the
/// particles lie inside walls.box, on the inner side of every plane, at least a radius inside
/// every side-inside cylinder and cone over the axial extent where it reaches them, and (their
/// centres) inside every closed mesh wall; lattice regions hold `count` sites, random regions a
/// solid fraction below kMaxRandomSolidFraction, explicit positions overlap by at most
/// kMaxInitialOverlapFraction; temperatures below kImplausibleTemperatureK are warned about, and
/// a constant-property gas the CFD solves more than kConstantGasWarnDeltaT from the particles or
/// walls.
/// Returns the warnings
/// ("file:line:col: key: what"); throws CaseError at the first failure.
std::vector<std::string> checkCaseConsistency(const CaseConfig& config);

} // namespace coredem::orchestrator
