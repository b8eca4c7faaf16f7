#pragma once
/// @file
/// A coupled run (docs/session.md, docs/orchestrator.md): start or connect to the DEM server,
/// start the CFD participant, handshake, configure, then the step loop with the Δt policy,
/// sub-cycling plan, coordinated checkpoints, snapshots, timeseries and progress. Faults of a
/// participant (death, missed deadline, Error reply) are reported by name and reason.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <coredem/common/check.h>
#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// A participant died, missed a deadline or refused a request. Exit code 1 (or an
/// automatic restart with --auto-restart).
class ParticipantFault : public UserError {
public:
  ParticipantFault(std::string participant, const std::string& reason)
      : UserError(participant + ": " + reason)
      , _participant(std::move(participant)) {}
  const std::string& participant() const { return _participant; }

private:
  std::string _participant;
};

struct RunOptions {
  std::filesystem::path runDir;              ///< created by prepareRunDir
  int autoRestart = 0;                       ///< relaunch + resume this many times after a fault
  std::optional<std::int64_t> stopAfterStep; ///< stop (with a checkpoint) after this step
  bool resume = false;                       ///< continue from the latest complete checkpoint
  bool tty = false;                          ///< progress as an updating line
  /// Per-stage timers in both participants (`coredem run --timers`; dem.timers in the case does
  /// it for the DEM server only): coredem-dem --timers writes RUN/timers-dem.json, coredemFoam
  /// -timers RUN/timers-cfd.json (docs/performance.md "Timers").
  bool timers = false;
};

/// Exit codes of `coredem`.
enum ExitCode : int {
  kExitOk = 0,
  kExitFault = 1,    ///< a participant failed, or another run-time error
  kExitBadInput = 2, ///< case file or command line invalid; nothing written
  kExitInterrupted = 130,
};

/// Creates the run folder for a new run (`runs/<name>` or a timestamped sibling when that
/// exists, or `out` which must not contain a run yet) and copies the case file into it.
std::filesystem::path prepareRunDir(const CaseConfig& config,
                                    const std::optional<std::filesystem::path>& out);

/// Loads the case of an existing run folder (its copy of case.yaml, relative paths resolved
/// against the original case folder).
CaseConfig loadRunCase(const std::filesystem::path& runDir);

/// Runs (or resumes) the case; returns the exit code. Logs the reason of any failure.
int runSession(const CaseConfig& config, const RunOptions& options);

} // namespace coredem::orchestrator
