#pragma once
/// @file
/// A coupled run (docs/session.md, docs/orchestrator.md): start or connect to the DEM server,
/// start the CFD participant, handshake, configure, then the step loop with the Δt policy,
/// sub-cycling plan, coordinated checkpoints, snapshots, timeseries and progress. Faults of a
/// participant (death, missed deadline, Error reply) are reported by name and reason.

#include <chrono>
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
  /// `--walltime SECONDS`: stop with a checkpoint before this much wall time has passed since
  /// `started` (docs/orchestrator.md "Stopping a run").
  std::optional<double> walltimeSeconds;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
};

/// Grace after SIGINT/SIGTERM: the run finishes the CFD step in flight and, when the estimate
/// fits, one more step with a checkpoint; past this (or at a second signal) it stops at once.
inline constexpr double kInterruptGraceSeconds = 10.0;

/// Wall time kept free before `--walltime`: shutdown of the participants and the last records.
inline double walltimeReserve(double walltime) {
  return 5.0 + 0.02 * walltime;
}

/// True when step `s`, about to be granted, must be the last one (with a checkpoint) so that
/// the run ends before `walltime`: `elapsed` since the start, `stepEst` and `checkpointStepEst`
/// the largest wall time of a step without and with a checkpoint so far. If s ran without a
/// checkpoint, the next possible stop would be after s+1 with one.
bool walltimeStopDue(double elapsed, double walltime, double stepEst, double checkpointStepEst);

/// The hint of a CFD participant killed by SIGFPE: the solution probably diverged at `step`
/// with `dt` and the last reported Courant number (< 0: none yet), and a Δt to try.
std::string divergenceHint(std::int64_t step, double dt, double courant);

/// Exit codes of `coredem`.
enum ExitCode : int {
  kExitOk = 0,
  kExitFault = 1,    ///< a participant failed, or another run-time error
  kExitBadInput = 2, ///< case file or command line invalid; nothing written
  kExitInterrupted = 130,
};

/// The folder of a new run: `out` (which must not hold a run yet: case.yaml, or staged.yaml of
/// a staged run), else `runs/<name>` or a timestamped sibling when that exists. Creates nothing.
std::filesystem::path chooseRunDir(const std::string& name,
                                   const std::optional<std::filesystem::path>& out);

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
