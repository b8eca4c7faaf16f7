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

/// One uniform or non-uniform value of an OpenFOAM field file.
struct FoamFieldValue {
  std::string patch;   ///< "internalField", or the patch name of a fixedValue patch
  bool uniform = true; ///< false: nonuniform (value is 0, not read)
  double value = 0.0;  ///< the scalar of "uniform X"
  int line = 0;        ///< 1-based line of the entry
};

/// What readFoamField found in a field file (0/<name>).
struct FoamFieldValues {
  bool found = false;     ///< the file exists and could be read
  std::string className;  ///< FoamFile class, e.g. volScalarField
  std::string dimensions; ///< the text inside [ ], e.g. "0 0 0 1 0 0 0"
  int dimensionsLine = 0;
  /// internalField first (when it is a scalar), then each fixedValue patch with a scalar value,
  /// in file order. Vector values are left out.
  std::vector<FoamFieldValue> values;
  /// (patch, type) of every patch entry of boundaryField, in file order.
  std::vector<std::pair<std::string, std::string>> patchTypes;
};

/// The dimensions of the constant model's kinematic pressure p/rho (m2/s2) and of a pressure (Pa)
/// as readFoamField gives them.
inline constexpr const char* kKinematicPressureDimensions = "0 2 -2 0 0 0 0";
inline constexpr const char* kPressureDimensions = "1 -1 -2 0 0 0 0";

/// True when 0/p (read by readFoamField) is a kinematic pressure that is the same field in Pa: a
/// zero gauge pressure (internalField and every fixedValue patch uniform 0; the other patches of
/// types that carry no pressure value of their own: fixedFluxPressure, zeroGradient, calculated
/// and the constraint types).
bool isZeroGaugeKinematicPressure(const FoamFieldValues& p);

/// Reads the class, dimensions, internalField and fixedValue patch values of an ASCII OpenFOAM
/// field file (comments ignored; macros and #include not expanded).
FoamFieldValues readFoamField(const std::filesystem::path& file);

} // namespace coredem::orchestrator
