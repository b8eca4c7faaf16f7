#pragma once
/// @file
/// HDF5 state files (DESIGN §4): /particles/<field>, /contacts/<field>, /meta attributes.

#include "engine.h"

#include <cstdint>
#include <string>

namespace coredem::dem {

struct StateMeta {
  double time = 0;
  double timeCompensation = 0;  ///< Kahan compensation term, for bitwise restarts
  std::uint64_t step = 0;
  std::string backend;
  std::string configHash;
  std::string softwareVersion;
  std::string protocolVersion;
  double heatWall = 0;        ///< HeatTotals::wall (J); optional in the file
  double heatConvection = 0;  ///< HeatTotals (J); optional in the file (0 when absent)
  double heatRadiation = 0;
  bool hasChemistry = false;   ///< write/read the chemistry ledgers (/chemistry)
  ChemistryTotals chemistry;   ///< ledgers; read only when the file has /chemistry
};

void writeStateFile(const std::string& path, const HostState& s, const StateMeta& meta);
/// Throws UserError when the file is missing, not HDF5, or lacks a field.
void readStateFile(const std::string& path, HostState& s, StateMeta& meta);

} // namespace coredem::dem
