#pragma once
// Rows of the participant table (participants.cpp) kept beside what they point to.
#include <coredem/orchestrator/participants.h>

namespace coredem::orchestrator {

/// The OpenFOAM solver coredemFoam (participant_openfoam.cpp).
ParticipantDescriptor openFoamParticipant();

} // namespace coredem::orchestrator
