#pragma once
/// @file
/// The prescribed-gas participant coredem-gas as the orchestrator knows it: its row of the
/// participant table (participants.h) and its pre-flight.

#include <coredem/orchestrator/participant_descriptor.h>

namespace coredem::orchestrator {

/// The row of coredem-gas: prescribed gas fields from the case file's gas section
/// (docs/client.md "coredem-gas"), everything on its command line, restart file gas.h5.
ParticipantDescriptor gasParticipant();

/// Pre-flight of the prescribed-gas participant: the gas section (`cfd.gas_key`) of the case
/// file, validated in-process by the gas model library. Throws CaseError with file:line:col.
void checkGasSection(const CaseConfig& config);

} // namespace coredem::orchestrator
