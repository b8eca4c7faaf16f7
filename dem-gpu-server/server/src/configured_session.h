#pragma once
// What a Configure set up and the steps advance: the DEM system, the coupling grid, the server's
// ledgers and the staggered lag, the session's progress; with what a step reports from it (the
// Ledger of Sources and StepDone, StepDone's diagnostics) and the checkpoint it writes.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "coredem/common/log.h"
#include "coredem/dem/dem_system.h"
#include "coredem/protocol/protocol.h"
#include "replies.h"
#include "staggered_lag.h"
#include "state_meta.h"

namespace coredem::server {

struct ConfiguredSession {
  std::unique_ptr<dem::DemSystem> system;
  GridShape grid;
  std::vector<std::string> speciesNames;
  double cellVolume = 0.0;
  ServerLedgers ledgers;
  StaggeredLag lag;
  v1::Ledger lastLedger;      ///< the ledger of the last StepDone (sent with the lagged Sources)
  std::int64_t lastStep = 0;  ///< last completed step (kept after the session, for Heartbeat)
  std::int64_t stepsDone = 0; ///< in this session

  /// Takes a Configure's system, restored ledgers and lag, its coupling grid and start step.
  void start(std::unique_ptr<dem::DemSystem> built, ServerLedgers restored, bool staggered,
             StaggeredState restoredLag, const v1::Configure& c);
  /// The session ended: the system's memory goes back, ledgers, lag and progress are cleared
  /// (lastStep stays).
  void end();

  /// The ledger of the particles `p` (docs/heat-coupling.md, docs/thermochemistry.md,
  /// docs/coupling-schemes.md "Ledgers").
  v1::Ledger ledger(const dem::ParticleData& p) const;
  /// StepDone's diagnostics: particles, contacts, T_p mean/min/max, DEM time, bed height.
  void addDiagnostics(v1::StepDone& done, const dem::ParticleData& p) const;
  /// Writes DIR/dem.h5 (temp file + rename) and returns the file names relative to DIR.
  std::vector<std::string> writeCheckpoint(const std::string& dir, std::int64_t step,
                                           const std::string& session, spdlog::logger& log) const;
};

} // namespace coredem::server
