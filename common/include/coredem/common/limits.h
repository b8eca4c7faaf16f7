#pragma once
/// @file
/// The limits every part applies to what a case asks for, in one table (docs/security.md
/// "Admission control" and docs/protocol.md §3 "Ranges"): the DEM server admits a Configure
/// against CountLimits (coredem-dem, with the memory-derived particle and cell counts on top),
/// refuses received gas fields outside GasRanges, and `coredem check` applies both to the case
/// before anything runs, so that what check accepts the run does not refuse.
#include <cstdint>

namespace coredem {

/// Counts of a Configure (the DEM server's admission control; coredem-dem's defaults).
struct CountLimits {
  std::uint64_t materials = 1024; ///< pair table <= 64 MiB
  std::uint64_t species = 256;    ///< gas species (columns of Y_g, R_species)
  std::uint64_t solidSpecies = 256;
  std::uint64_t particleSets = 4096;
  std::uint64_t reactions = 1024;
  std::uint64_t options = 256;        ///< Configure.options entries
  std::uint64_t revolvedWalls = 4096; ///< Configure.walls.revolved (cylinders, cones)
  std::uint64_t meshWalls = 256;      ///< Configure.walls.meshes
  /// Triangles and vertices over all mesh walls (a 10^6-triangle STL is 1-3·10^6 vertices).
  std::uint64_t meshTriangles = std::uint64_t{1} << 24;
  std::uint64_t meshVertices = std::uint64_t{3} << 24;
  std::uint64_t subSteps = 100000; ///< n_sub of a StepGrant (coredem-dem --max-sub-steps)
  std::uint64_t nameBytes = 256;   ///< any name or option key/value
};

/// Physically plausible ranges of the gas state the DEM receives (docs/protocol.md §3,
/// "Ranges"). Wide enough for any gas (and most liquids) a CFD-DEM run couples; a value outside
/// is a sender bug (wrong units, divergence, uninitialised memory), refused before it reaches
/// the DEM core, where it would turn every later Sources into NaN.
struct GasRanges {
  double temperatureMin = 100.0, temperatureMax = 6000.0; ///< T_g, K
  double densityMin = 1e-4, densityMax = 2e4;             ///< rho_g, kg/m3
  double viscosityMin = 1e-7, viscosityMax = 1.0;         ///< mu_g, Pa s
  double conductivityMin = 1e-4, conductivityMax = 1e3;   ///< kappa_g, W/m/K
  double heatCapacityMin = 100.0, heatCapacityMax = 1e5;  ///< cp_g, J/kg/K
  double speedMax = 1e4;                                  ///< |u_g|, m/s
  double pressureGradientMax = 1e12;                      ///< |grad_p|, Pa/m
  double massFractionTolerance = 1e-3;                    ///< Y_k in [-tol, 1 + tol]
  double massFractionSumTolerance = 0.05;                 ///< |sum_k Y_k - 1| (n_species >= 1)
};

} // namespace coredem
