#pragma once
/// @file
/// The `hopper` deck of bench/decks.md: a conical hopper (cylinder on a 30° cone) filled with a
/// settled bed that discharges through its outlet into a bin. `coredem-bench dem --case hopper`
/// runs it (bench/commands/hopper.cpp); bench/peers/liggghts/make_hopper.py writes the same deck
/// for LIGGGHTS from the files this code leaves in the deck directory (hopper.deck,
/// hopper.particles and the STL files), so that both codes read the same particles and meshes.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "coredem/dem/dem_system.h"
#include "coredem/dem/triangle_mesh.h"

namespace coredem::bench::hopper {

/// Material of the deck: the Patil glass of the other decks (k_n, e_n, k_t, η_t) with μ = 0.5
/// (particle–particle and particle–wall: Beverloo's law needs real friction).
inline constexpr double kDiameter = 1e-3;  ///< d_p (m)
inline constexpr double kDensity = 2500.0; ///< ρ_p (kg/m³)
inline constexpr double kKn = 1000.0;      ///< N/m
inline constexpr double kEn = 0.97;
inline constexpr double kMu = 0.5;
inline constexpr double kHalfAngleDeg = 30; ///< cone half-angle from the axis
inline constexpr int kSegments = 64;        ///< facets around the axis in the STL files
inline constexpr double kGravity = 9.81;

/// The hopper's geometry, axis z through x = y = 0, outlet plane z = 0 (all lengths in m).
struct Geometry {
  std::size_t n = 0;     ///< particles
  double outletD = 0;    ///< D_o
  double rOut = 0;       ///< D_o / 2, cone radius at z = 0
  double rCyl = 0;       ///< R_c, cylinder radius (cone radius at z = hCone)
  double hCone = 0;      ///< height of the cone: (R_c − R_o) / tan θ
  double hTop = 0;       ///< top of the hopper walls (the STL's upper end)
  double zFloor = 0;     ///< the bin's floor (a plane, normal +z)
  double zBinBottom = 0; ///< lower end of the bin's STL cylinder (below the floor)
  double spacing = 0;    ///< fill lattice spacing
  double jitter = 0;     ///< fill lattice jitter amplitude (m, per component)
  /// STL vertices lie at r / cos(π/segments): the facets touch the analytic surface along their
  /// mid-lines and lie outside it elsewhere (a bed settled against the analytic walls does not
  /// overlap them).
  double stlRadiusFactor = 0;
};

/// The geometry for n particles with an outlet of `outletOverD` particle diameters.
Geometry geometry(std::size_t n, double outletOverD);

/// The settled bed, read from / written to the deck directory.
struct Settled {
  std::vector<double> position, velocity, omega; ///< 3 per particle, in global-id order
  double time = 0;                               ///< settling time simulated (s)
  unsigned long long steps = 0;
  double vMax = 0;         ///< largest particle speed at the end of settling (m/s)
  double rhoBulk = 0;      ///< ρ_b measured in the settled bed, 2 d_p from the walls (kg/m³)
  double rhoAll = 0;       ///< the same with the wall layer (kg/m³)
  double bedTop = 0;       ///< highest particle centre (m)
  double rhoZ[2] = {0, 0}; ///< the slab [z0, z1] where ρ_b was measured (m)
};

/// Options of `coredem-bench dem --case hopper`.
struct Options {
  std::size_t n = 20000;
  std::string walls = "primitive"; ///< primitive | stl | none
  bool closed = false;             ///< keep the outlet plate (a bed at rest in the hopper)
  std::string deckDir;             ///< where the deck files live; empty: a temporary directory
  double outlet = 8.0;             ///< D_o / d_p
  int steps = 500, warmup = 20, threads = 2, sample = 500;
  std::string backend = "cpu";
  double skin = -1; ///< skin factor (< 0: the library's)
  bool json = false, heat = false, settleOnly = false, resettle = false;
  double until = 0;                ///< stop once this fraction has been discharged (0: never)
  double fitLo = 0.2, fitHi = 0.8; ///< discharged fractions bounding the rate fit
  std::string samplesOut;          ///< write "t count wall_contacts pair_contacts" per sample
};

/// Runs the deck (settling first if the deck directory holds no settled bed for it).
int run(const Options& options);

} // namespace coredem::bench::hopper
