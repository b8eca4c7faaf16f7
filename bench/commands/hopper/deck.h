#pragma once
// Phase 1 of the `hopper` deck (deck.cpp): the settled bed and the deck directory's files, for
// the discharge run of hopper.cpp. Internal to coredem-bench.
#include <filesystem>
#include <string>

#include "../hopper.h"

namespace coredem::bench::hopper {

constexpr double kFillFraction = 0.6; ///< solid fraction assumed when sizing the hopper

/// Mass of one particle (kg).
double particleMass();
/// The deck's material (kKn, kEn, kMu).
dem::Material material();
/// The particle set of a settled bed (explicit positions, velocities, spins).
dem::ParticleSet explicitSet(const Settled& s);

/// Fills the hopper closed by the plate z = 0 and lets the bed settle until it is at rest (at
/// most 2 s simulated); dt is set to the settling system's time step.
Settled settle(const Geometry& g, const Options& o, double& dt);

/// v with 17 significant digits (the deck files' numbers).
std::string fmt17(double v);

/// Writes hopper.particles, the STL files and hopper.deck (the parameters, the settling and
/// the kinetic energy keInitial of the bed) to dir.
void writeDeck(const std::filesystem::path& dir, const Geometry& g, const Settled& s, double dt,
               double keInitial);
/// Reads the settled bed of `dir` if it was written for this geometry; false otherwise.
bool readDeck(const std::filesystem::path& dir, const Geometry& g, Settled& s);

} // namespace coredem::bench::hopper
