#pragma once
// The coupled run behind runSession (session.h), internal to the orchestrator. Its members are
// defined by topic:
//   session.cpp        run(), liveness, shutdown, runSession (auto-restart)
//   session_start.cpp  DEM server start/handshake/Configure, CFD participant start/handshake,
//                      the receive loops with deadlines
//   step_loop.cpp      the step loop (grants, StepDone of both participants)
//   records.cpp        timeseries rows, checkpoint manifests, snapshots, overhead record
//   run_folder.cpp     run folder creation, resume point, clean-up after a failure
//   configure.cpp      the Configure message
//   participants.cpp   the participant table (launch, restart file, pre-flight)

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/common/version.h>
#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/outputs.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/session.h>
#include <coredem/orchestrator/time_handler.h>
#include <coredem/protocol/protocol.h>

namespace coredem::orchestrator {

using SteadyClock = std::chrono::steady_clock;

/// SIGINT/SIGTERM arrived: the participants are stopped; exit 130, the run can be resumed.
class Interrupted : public UserError {
public:
  Interrupted()
      : UserError("interrupted (SIGINT/SIGTERM)") {}
};

/// True after SIGINT/SIGTERM (set by runSession's handler).
bool interruptRequested();
/// Number of SIGINT/SIGTERM received, and seconds since the first one (0 when none).
int interruptCount();
double secondsSinceInterrupt();

inline const std::string kDemName = "DEM server coredem-dem";

// ------------------------------------------------------------------------- run folder

/// Where a resumed run starts: the checkpoint, its DEM state file and the CFD participant's
/// restart file (by the participant's restart-file convention; empty when it listed none).
struct ResumePoint {
  std::filesystem::path dir;
  Manifest manifest;
  std::filesystem::path demState;
  std::filesystem::path cfdRestart;
};

/// The latest complete checkpoint of `runDir` for `config` (warns about skipped newer ones).
/// Throws UserError when there is none, or when the case changed since.
ResumePoint findResumePoint(const CaseConfig& config, const std::filesystem::path& runDir);

/// Nothing half-written after a failure: checkpoint folders without a manifest and a snapshot
/// being received are removed.
void removeIncomplete(const std::filesystem::path& runDir);

// ------------------------------------------------------------------------- records

struct SnapshotEntry {
  std::int64_t step;
  double time;
  std::string file; ///< relative to the run folder
  std::string gas;  ///< the CFD participant's output folder of the same time ("" if none)
};

/// RUN/snapshots/index.csv (exact hex times), RUN/outputs.csv (the index of synchronized
/// outputs: step, decimal time, particle snapshot, gas time folder) and RUN/particles.xdmf.
std::vector<SnapshotEntry> readSnapshotIndex(const std::filesystem::path& runDir);
void writeSnapshotIndex(const std::filesystem::path& runDir,
                        const std::vector<SnapshotEntry>& snaps);

/// The first multiple of `every` (s) after `time` (s), a multiple within 1e-9·every counting as
/// reached.
double nextOutputTime(double time, double every);

/// The CFD participant's output folder of time `time` (s) under RUN/<workDir>: the numeric
/// time folder nearest to it within half a step `dt` (relative to the run folder; "" if none).
std::string gasOutputFolder(const std::filesystem::path& runDir, const std::string& workDir,
                            double time, double dt);

/// Ledger entries and diagnostics of a StepDone as (name, value) pairs, appended to `row`.
void collect(const v1::StepDone& done, std::vector<std::pair<std::string, double>>& row);

/// Wall-time accounting of the step loop, reported at the end (log + RUN/logs/overhead.json).
struct OverheadTotals {
  double overhead = 0.0, stepWall = 0.0, demWall = 0.0, checkpoints = 0.0, snapshots = 0.0;
  std::int64_t measured = 0;

  void report(spdlog::logger& log, const std::filesystem::path& runDir) const;
};

// ------------------------------------------------------------------------- the session

class Session {
public:
  Session(const CaseConfig& config, const RunOptions& options)
      : _c(config)
      , _o(options)
      , _cfd(participant(config.cfd.participant))
      , _log(logger("orchestrator.session")) {}

  int run();

private:
  // session.cpp
  void checkAlive();
  /// Throws Interrupted when a signal must stop the run at once: before the step loop, at a
  /// second signal, or when the grace (kInterruptGraceSeconds) has passed.
  void checkInterrupt() const;
  void shutdownAll(bool clean);
  std::string cfdName() const { return "CFD participant " + _cfd.name; }
  // session_start.cpp
  void startDem();
  void configureDem(std::int64_t startStep, double startTime,
                    const std::filesystem::path& initialState);
  void startCfd(const std::filesystem::path& cfdRestart);
  void handshakeCfd();
  protocol::Request receiveFromCfd(std::chrono::milliseconds timeout, const std::string& awaited);
  protocol::Message receiveFromDem(std::chrono::milliseconds timeout, const std::string& awaited);
  // step_loop.cpp
  void stepLoop(std::int64_t startStep);
  /// Sends the StepGrant of `step` to both participants (the CFD participant's answers its
  /// pending request): with the checkpoint directory when ckDir is not empty, and to the CFD
  /// participant the output tag when `output`.
  void sendStepGrants(std::int64_t step, double tStart, double dt, const SubcyclePlan& plan,
                      const std::filesystem::path& ckDir, bool output);
  /// The DEM server's and the CFD participant's StepDone of `step` (other CFD requests are
  /// answered with an error meanwhile).
  std::pair<protocol::Message, protocol::Request>
  awaitStepDone(std::int64_t step, std::chrono::milliseconds demTimeout,
                std::chrono::milliseconds cfdTimeout);
  // records.cpp
  void writeTimeseriesRow(std::int64_t step, double dt, const SubcyclePlan& plan, double wallStep,
                          const v1::StepDone& dem, const v1::StepDone& cfd);
  void writeCheckpoint(std::int64_t step, const std::filesystem::path& dir, const v1::StepDone& dem,
                       const v1::StepDone& cfd);
  void takeSnapshot(std::int64_t step, double time, double dt);

  const CaseConfig& _c;
  RunOptions _o;
  const ParticipantDescriptor& _cfd;
  std::shared_ptr<spdlog::logger> _log;

  std::unique_ptr<ChildProcess> _demProc, _cfdProc;
  std::unique_ptr<protocol::Client> _dem;
  std::unique_ptr<protocol::Server> _ctrl;
  std::string _demEndpoint, _ctrlEndpoint, _session, _serverKey;
  v1::Configure _configure;
  double _dtDemMax = 0.0;
  std::uint64_t _cells = 0;
  std::uint32_t _species = 0;
  protocol::PeerId _cfdPeer;
  std::optional<protocol::Request> _pendingCfd; ///< C's request awaiting O's reply
  bool _demUnresponsive = false;                ///< D missed a deadline: do not wait on it
  bool _inStepLoop = false;                     ///< a signal lets the step in flight finish
  double _dtInFlight = 0.0;                     ///< Δt_CFD of the step granted last

  /// Why the step loop ended before time.end (none: it reached it, or --stop-after).
  enum class EarlyStop { None, Interrupt, Walltime };
  EarlyStop _earlyStop = EarlyStop::None;
  std::int64_t _lastCheckpointStep = -1; ///< newest checkpoint written in this session

  TimeHandler _time;
  DtPolicy _policy{DtPolicyConfig{}};
  double _lastCourant = -1.0;
  std::int64_t _step = 0;
  std::vector<SnapshotEntry> _snapshots;
  std::unique_ptr<TimeseriesWriter> _timeseries;

  OverheadTotals _overhead; ///< overhead measurement
};

} // namespace coredem::orchestrator
