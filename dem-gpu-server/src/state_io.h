#pragma once
/// @file
/// HDF5 state files: /particles/<field> and /contacts/<field> for every checkpointed row of the
/// particle schema (coredem/dem/particle_schema.h), /meta attributes (with format_version),
/// /chemistry ledgers.

#include <cstdint>
#include <string>
#include <vector>

#include "engine.h"

namespace coredem::dem {

struct StateMeta {
  int formatVersion =
      schema::kFormatVersion; ///< read: the file's (1 when absent); written: always the current
  double time = 0;
  double timeCompensation = 0; ///< Kahan compensation term, for bitwise restarts
  std::uint64_t step = 0;
  std::string backend;
  std::string configHash;
  std::string softwareVersion;
  std::string protocolVersion; ///< coupling protocol of the writing server ("none" without one)
  HeatTotals heat;             ///< the heat ledger (kHeatLedger rows; 0 when a file lacks one)
  /// The materials' names in index order (/meta `material_names`, one per line; empty in files
  /// written before it: a new start then maps the particles' materials by index)
  std::vector<std::string> materialNames;
  bool hasChemistry = false; ///< write/read the chemistry ledgers (/chemistry)
  ChemistryTotals chemistry; ///< ledgers; read only when the file has /chemistry
};

/// Writes every checkpointed schema field and `meta`. Throws InternalError when a field of `s`
/// does not hold n · width values, UserError when the file cannot be written.
void writeStateFile(const std::string& path, const HostState& s, const StateMeta& meta);
/// Throws UserError when the file is missing, not HDF5, lacks a field its format version has,
/// holds a field with the wrong number of values, or has a newer format version than this build.
/// Fields the file's format version predates take their schema defaults.
void readStateFile(const std::string& path, HostState& s, StateMeta& meta);

} // namespace coredem::dem
