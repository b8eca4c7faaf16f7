#pragma once
/// @file
/// Host side of the chemistry (DemSystem): ChemistryOptions → ChemistrySetup, hash text,
/// per-particle references and the removal of particles below the size threshold.

#include <string>

#include "engine.h"

namespace coredem::dem {

/// Resolves species names to indices and checks the options (UserError: what to fix). Logs a
/// warning for a reaction whose Σ ν M is not zero.
ChemistrySetup makeChemistrySetup(const DemConfig& config);

/// Canonical text of the chemistry options for the config hash ("" when chemistry is off).
std::string chemistryHashText(const DemConfig& config);

/// Fills st.d0 (2 R) and st.chemRef (initial C mass, initial Fe2O3-equivalent mass) of every
/// particle.
void initChemistryReferences(const DemConfig& config, HostState& st);

/// Removes the particles with 2R < removalFraction · d0: compacts every per-particle array
/// (global ids stay with their particles), invalidates the neighbour lists, adds the removed
/// species masses to totals.removedSolid. Returns the number removed.
std::size_t removeSmallParticles(double removalFraction, HostState& st, ChemistryTotals& totals);

} // namespace coredem::dem
