// A coupled run (session.h): Session::run (resume point, start, step loop, shutdown), liveness
// of the participants, their shutdown, and runSession with signals and automatic restarts. The
// other members of Session are in session_start.cpp, step_loop.cpp and records.cpp.
#include <algorithm>
#include <atomic>
#include <csignal>

#include "session_impl.h"

namespace fs = std::filesystem;
namespace v1 = coredem::v1;
using namespace std::chrono_literals;

namespace coredem::orchestrator {
namespace {

std::atomic<int> gSignals{0};
std::atomic<std::int64_t> gFirstSignalNs{0};
extern "C" void onSignal(int) {
  // clock_gettime (steady_clock) is async-signal-safe.
  if (gSignals.fetch_add(1) == 0) {
    gFirstSignalNs =
        std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now().time_since_epoch())
            .count();
  }
}

} // namespace

bool interruptRequested() {
  return gSignals > 0;
}

int interruptCount() {
  return gSignals;
}

double secondsSinceInterrupt() {
  // The handler may run on another thread (ZeroMQ's): the time may not be stored yet.
  if (gSignals == 0 || gFirstSignalNs == 0) {
    return 0.0;
  }
  const std::int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now().time_since_epoch())
          .count();
  return double(now - gFirstSignalNs) * 1e-9;
}

void Session::checkInterrupt() const {
  if (interruptRequested() &&
      (!_inStepLoop || interruptCount() >= 2 || secondsSinceInterrupt() > kInterruptGraceSeconds)) {
    throw Interrupted();
  }
}

using protocol::Message;

void Session::checkAlive() {
  checkInterrupt();
  if (_demProc) {
    if (auto why = _demProc->exitReason()) {
      throw ParticipantFault(kDemName,
                             fmt::format("process {} {} (log {}):\n{}", _demProc->pid(), *why,
                                         _demProc->logFile().string(), _demProc->logTail()));
    }
  }
  if (_cfdProc) {
    if (auto why = _cfdProc->exitReason()) {
      // SIGFPE: a diverged CFD solution, reported with the Courant number and a Δt to try.
      const std::string hint = why->find("SIGFPE") != std::string::npos
                                   ? "; " + divergenceHint(_step + 1, _dtInFlight, _lastCourant)
                                   : std::string();
      throw ParticipantFault(cfdName(),
                             fmt::format("process {} {}{} (log {}):\n{}", _cfdProc->pid(), *why,
                                         hint, _cfdProc->logFile().string(), _cfdProc->logTail()));
    }
  }
}

void Session::shutdownAll(bool clean) {
  // C: answer its pending request with Shutdown (or wait briefly for one), else stop it.
  if (_ctrl && _cfdProc && !_cfdProc->exitReason()) {
    if (!_pendingCfd) {
      try {
        auto r = _ctrl->receive(clean ? 2000ms : 300ms);
        if (r && r->status.ok()) {
          _pendingCfd = std::move(r);
        }
      } catch (const std::exception&) {
      }
    }
    if (_pendingCfd) {
      Message s = protocol::makeShutdown(clean ? "run finished" : "run aborted");
      s.setSequence(_pendingCfd->message.envelope().sequence()).setSessionId(_session);
      _ctrl->reply(_pendingCfd->peer, std::move(s));
      _pendingCfd.reset();
    }
    if (!_cfdProc->waitFor(clean ? 10000ms : 2000ms)) {
      _log->warn("stopping {} (pid {})", _cfd.name, _cfdProc->pid());
      _cfdProc->stop();
    }
  }
  // D: Shutdown request when it is alive (ends the session; a server we started exits).
  if (_demUnresponsive && _demProc) {
    _log->warn("stopping the unresponsive DEM server (pid {})", _demProc->pid());
    _demProc->stop(1000ms);
  }
  if (_dem && !_demUnresponsive && (!_demProc || !_demProc->exitReason())) {
    try {
      Message s = protocol::makeShutdown(clean ? "run finished" : "run aborted");
      s.setSessionId(_session);
      _dem->send(std::move(s));
      _dem->receive(3000ms);
    } catch (const std::exception& e) {
      _log->debug("DEM shutdown: {}", e.what());
    }
    if (_demProc && !_demProc->waitFor(5000ms)) {
      _log->warn("stopping the DEM server (pid {})", _demProc->pid());
      _demProc->stop();
    }
  }
  if (_cfdProc) {
    _cfdProc->stop();
  }
  if (_demProc) {
    _demProc->stop();
  }
}

int Session::run() {
  fs::create_directories(_o.runDir / "logs");
  fs::create_directories(_o.runDir / "snapshots");
  fs::path initialState, cfdRestart;
  std::int64_t startStep = 0;
  // A run folder without a complete checkpoint (interrupted before the first one) resumes from
  // step 0: the same folder, its case.yaml, the earlier attempt's records replaced.
  bool fromCheckpoint = _o.resume;
  if (_o.resume && !selectResumeCheckpoint(_o.runDir).dir) {
    for (const auto& s : selectResumeCheckpoint(_o.runDir).skipped) {
      _log->warn("skipping checkpoint {}: {}", s.dir.string(), s.reason);
    }
    _log->warn("{}: no complete checkpoint; starting the run again from step 0 in this folder",
               _o.runDir.string());
    fromCheckpoint = false;
    fs::remove_all(_o.runDir / "snapshots");
    fs::create_directories(_o.runDir / "snapshots");
    fs::remove(_o.runDir / "particles.xdmf");
    fs::remove(_o.runDir / "outputs.csv");
    if (!_cfd.workDir.empty()) {
      fs::remove_all(_o.runDir / _cfd.workDir); // a fresh copy of cfd.case (prepareWorkDir)
    }
  }
  if (fromCheckpoint) {
    const ResumePoint r = findResumePoint(_c, _o.runDir);
    const Manifest& m = r.manifest;
    initialState = r.demState;
    cfdRestart = r.cfdRestart;
    startStep = m.step;
    _lastCheckpointStep = m.step; // an interrupt right away needs no new one
    _time = TimeHandler(m.time, m.timeCompensation);
    _policy = DtPolicy(_c.dt, m.lastDt);
    _lastCourant = m.lastCourant;
    _snapshots.clear();
    for (const auto& s : readSnapshotIndex(_o.runDir)) {
      if (s.step <= m.step) {
        _snapshots.push_back(s);
      } else {
        fs::remove(_o.runDir / s.file);
      }
    }
    writeSnapshotIndex(_o.runDir, _snapshots);
    _timeseries = std::make_unique<TimeseriesWriter>(_o.runDir / "timeseries.csv", m.step);
    _log->info("resuming {} from checkpoint {} (step {}, t = {:.6g} s)", _o.runDir.string(),
               r.dir.string(), m.step, m.time);
  } else {
    _time = TimeHandler();
    _policy = DtPolicy(_c.dt);
    _timeseries = std::make_unique<TimeseriesWriter>(_o.runDir / "timeseries.csv");
  }

  bool clean = false;
  try {
    startDem();
    configureDem(startStep, _time.time(), initialState);
    startCfd(cfdRestart);
    handshakeCfd();
    if (!fromCheckpoint && _c.output.any()) {
      takeSnapshot(0, 0.0, _c.dt.dt);
    }
    stepLoop(startStep);
    clean = true;
  } catch (...) {
    shutdownAll(false);
    throw;
  }
  shutdownAll(clean);
  _overhead.report(*_log, _o.runDir);
  if (_time.reached(_c.endTime)) {
    _earlyStop = EarlyStop::None; // the step that ended early was the last one anyway
  }
  const std::string ck =
      _lastCheckpointStep == _step
          ? fmt::format("with checkpoint {}", checkpointDir(_o.runDir, _step).string())
          : "without a new checkpoint (the step estimate did not fit the grace)";
  if (_earlyStop == EarlyStop::Interrupt) {
    _log->error("interrupted (SIGINT/SIGTERM): stopped after step {} {}; participants stopped. "
                "Continue with: coredem resume {}",
                _step, ck, _o.runDir.string());
    return kExitInterrupted;
  }
  if (_earlyStop == EarlyStop::Walltime) {
    _log->warn("stopped after step {} (t = {:.6g} s of {:.6g} s) {} before the wall-time limit "
               "(--walltime {} s). Continue with: coredem resume {}",
               _step, _time.time(), _c.endTime, ck, *_o.walltimeSeconds, _o.runDir.string());
  }
  return kExitOk;
}

int runSession(const CaseConfig& config, const RunOptions& options) {
  auto log = logger("orchestrator.session");
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGPIPE, SIG_IGN);
  RunOptions opts = options;
  int restartsLeft = options.autoRestart;
  while (true) {
    try {
      Session session(config, opts);
      return session.run();
    } catch (const Interrupted& e) {
      removeIncomplete(opts.runDir);
      log->error("{}; participants stopped, no checkpoint written for the step in flight. "
                 "Continue with: coredem resume {} (from its latest complete checkpoint, or "
                 "from step 0 when it has none)",
                 e.what(), opts.runDir.string());
      return kExitInterrupted;
    } catch (const ParticipantFault& e) {
      log->error("{}", e.what());
      removeIncomplete(opts.runDir);
      const bool canResume = selectResumeCheckpoint(opts.runDir).dir.has_value();
      if (restartsLeft > 0 && canResume) {
        --restartsLeft;
        log->warn("auto-restart ({} left): relaunching the participants from the last complete "
                  "checkpoint",
                  restartsLeft);
        opts.resume = true;
        continue;
      }
      if (restartsLeft > 0) {
        log->error("no complete checkpoint to restart from");
      }
      log->error("the run stopped; the other participant was shut down. Continue with: coredem "
                 "resume {}",
                 opts.runDir.string());
      return kExitFault;
    }
  }
}

} // namespace coredem::orchestrator
