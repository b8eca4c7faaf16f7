#pragma once
/// @file
/// OpenFOAM field files read simply (ASCII, comments ignored, macros and #include not expanded):
/// what the OpenFOAM participant's pre-flight, its generated 0/p and its initial gas composition
/// (the case reader's ideal-gas check) read from 0/<name> of `cfd.case`.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace coredem::orchestrator {

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
