// The step loop of a run (docs/orchestrator.md "A run, step by step", 5): Δt from the dt policy,
// the sub-cycling plan, the checkpoint decision, the same StepGrant to both participants, their
// StepDone, then the records of the step (records.cpp).
#include <algorithm>
#include <cmath>

#include <coredem/orchestrator/progress.h>

#include "configure.h"
#include "session_impl.h"

namespace fs = std::filesystem;
namespace v1 = coredem::v1;

namespace coredem::orchestrator {

using protocol::Message;

void Session::stepLoop(std::int64_t startStep) {
  _step = startStep;
  const auto demTimeout = std::chrono::milliseconds(int(_c.dem.timeoutSeconds * 1000));
  const auto cfdTimeout = std::chrono::milliseconds(int(_c.cfd.timeoutSeconds * 1000));
  Progress progress(_time.time(), _c.endTime, _step, _o.tty);
  auto lastCheckpointWall = SteadyClock::now();
  auto afterPrevious = SteadyClock::now();
  // Wall-time estimates for an early stop (SIGINT/SIGTERM, --walltime): the largest wall time
  // of a step (grant to records) without and with a checkpoint so far.
  double stepEst = 0.0, checkpointStepEst = 0.0;
  bool lastGranted = false; ///< the step just done was granted as the last one (early stop)
  _inStepLoop = true;

  while (true) {
    const bool stopHere = _o.stopAfterStep && _step >= *_o.stopAfterStep;
    if (_time.reached(_c.endTime) || stopHere || lastGranted) {
      break;
    }
    bool earlyLast = false;
    if (interruptRequested()) {
      // The step in flight is done. One more step with a checkpoint when the last one had none
      // and the estimate fits the grace; else stop here.
      _earlyStop = EarlyStop::Interrupt;
      if (_lastCheckpointStep == _step ||
          secondsSinceInterrupt() + std::max(stepEst, checkpointStepEst) > kInterruptGraceSeconds) {
        break;
      }
      _log->warn("SIGINT/SIGTERM: finishing with a checkpoint after step {}", _step + 1);
      earlyLast = true;
    } else if (_o.walltimeSeconds &&
               walltimeStopDue(
                   std::chrono::duration<double>(SteadyClock::now() - _o.started).count(),
                   *_o.walltimeSeconds, stepEst, checkpointStepEst)) {
      _earlyStop = EarlyStop::Walltime;
      earlyLast = true;
    }
    const auto t0 = SteadyClock::now();
    const std::int64_t step = _step + 1;
    const double tStart = _time.time();
    // Synchronized outputs every output.every_seconds land exactly on their multiples: the step
    // is shortened to reach the next one as it is to reach time.end.
    double toEnd = _time.remaining(_c.endTime);
    double tOutput = 0.0;
    if (_c.output.everySeconds > 0.0) {
      tOutput = nextOutputTime(tStart, _c.output.everySeconds);
      while (_time.reached(tOutput)) { // within the time tolerance of a multiple already
        tOutput += _c.output.everySeconds;
      }
      toEnd = std::min(toEnd, _time.remaining(tOutput));
    }
    const double dt = _policy.next(_lastCourant, toEnd);
    _dtInFlight = dt;
    const SubcyclePlan plan = planFor(_c, dt, _dtDemMax);
    TimeHandler probe = _time;
    probe.advance(dt);
    const bool last =
        probe.reached(_c.endTime) || (_o.stopAfterStep && step >= *_o.stopAfterStep) || earlyLast;
    lastGranted = earlyLast;
    const bool output =
        _c.output.any() &&
        (last || (_c.output.snapshotEvery > 0 && step % _c.output.snapshotEvery == 0) ||
         (_c.output.everySeconds > 0.0 && probe.reached(tOutput)));
    const bool checkpoint = checkpointDue(
        step, last, _c.checkpoint.everySteps, _c.checkpoint.everySeconds,
        std::chrono::duration<double>(SteadyClock::now() - lastCheckpointWall).count());
    fs::path ckDir;
    if (checkpoint) {
      ckDir = fs::absolute(checkpointDir(_o.runDir, step));
      fs::remove_all(ckDir); // a stale, incomplete one from an earlier attempt
      fs::create_directories(ckDir);
    }
    sendStepGrants(step, tStart, dt, plan, ckDir, output);
    _overhead.overhead += std::chrono::duration<double>(SteadyClock::now() - afterPrevious).count();

    auto [demDone, cfdDone] = awaitStepDone(step, demTimeout, cfdTimeout);
    const auto tDone = SteadyClock::now();
    _time.advance(dt);
    _step = step;
    const auto& dd = demDone.envelope().step_done();
    const auto& cd = cfdDone.message.envelope().step_done();
    _lastCourant = cd.cfl();

    // The timeseries row of a step is written before its checkpoint manifest: a resume from
    // that checkpoint must find the row (a crash between the two would otherwise lose it).
    if (step % _c.output.timeseriesEvery == 0 || last) {
      writeTimeseriesRow(step, dt, plan, std::chrono::duration<double>(tDone - t0).count(), dd, cd);
    }
    const auto tIo0 = SteadyClock::now();
    if (checkpoint) {
      writeCheckpoint(step, ckDir, dd, cd);
      lastCheckpointWall = SteadyClock::now();
      _lastCheckpointStep = step;
    }
    const auto tIo1 = SteadyClock::now();
    if (output) {
      takeSnapshot(step, _time.time(), dt);
    }
    const auto tIo2 = SteadyClock::now();
    _overhead.checkpoints += std::chrono::duration<double>(tIo1 - tIo0).count();
    _overhead.snapshots += std::chrono::duration<double>(tIo2 - tIo1).count();
    _overhead.stepWall += std::chrono::duration<double>(tDone - t0).count();
    _overhead.demWall += dd.wall_seconds();
    ++_overhead.measured;
    progress.update(_step, _time.time());
    _pendingCfd = std::move(cfdDone);
    afterPrevious = SteadyClock::now();
    const double wall = std::chrono::duration<double>(afterPrevious - t0).count();
    double& estimate = checkpoint ? checkpointStepEst : stepEst;
    estimate = std::max(estimate, wall);
    _overhead.overhead += std::chrono::duration<double>(afterPrevious - tDone).count() -
                          std::chrono::duration<double>(tIo2 - tIo0).count();
  }
  _inStepLoop = false;
  progress.finish(_step, _time.time());
}

void Session::sendStepGrants(std::int64_t step, double tStart, double dt, const SubcyclePlan& plan,
                             const fs::path& ckDir, bool output) {
  const bool checkpoint = !ckDir.empty();
  auto makeGrant = [&](bool cfd) {
    Message g = protocol::makeStepGrant(step, tStart, dt, std::uint32_t(plan.nSub), plan.dtDem);
    g.setSessionId(_session);
    if (checkpoint) {
      g.envelope().mutable_step_grant()->mutable_checkpoint()->set_directory(ckDir.string());
    }
    if (cfd && output) { // the DEM server's part of an output is the snapshot request below
      g.envelope().mutable_step_grant()->mutable_checkpoint()->set_tag(protocol::kOutputTag);
    }
    return g;
  };
  _dem->send(makeGrant(false));
  {
    Message g = makeGrant(true);
    g.setSequence(_pendingCfd->message.envelope().sequence());
    _ctrl->reply(_pendingCfd->peer, std::move(g));
    _pendingCfd.reset();
  }
}

std::pair<Message, protocol::Request> Session::awaitStepDone(std::int64_t step,
                                                             std::chrono::milliseconds demTimeout,
                                                             std::chrono::milliseconds cfdTimeout) {
  Message demDone = receiveFromDem(demTimeout, fmt::format("StepDone of step {}", step));
  if (demDone.type() != v1::MESSAGE_TYPE_STEP_DONE || demDone.envelope().step() != step) {
    throw ParticipantFault(kDemName, fmt::format("answered the grant of step {} with {} of step {}",
                                                 step, protocol::messageTypeName(demDone.type()),
                                                 demDone.envelope().step()));
  }
  // The scheme the DEM server runs is the one asked for: a server that ignored the Configure
  // option (an older coredem-dem logs unknown options and runs sequential) reports no lag.
  if (const std::string why = couplingSchemeMismatch(_c, demDone.envelope().step_done(), step);
      !why.empty()) {
    throw ParticipantFault(kDemName, why);
  }
  protocol::Request cfdDone;
  while (true) {
    cfdDone = receiveFromCfd(cfdTimeout, fmt::format("StepDone of step {}", step));
    if (cfdDone.message.type() == v1::MESSAGE_TYPE_STEP_DONE &&
        cfdDone.message.envelope().step() == step) {
      break;
    }
    Message err =
        protocol::makeError(v1::ERROR_CODE_OUT_OF_ORDER,
                            fmt::format("expected StepDone of step {}, got {} of step {}", step,
                                        protocol::messageTypeName(cfdDone.message.type()),
                                        cfdDone.message.envelope().step()),
                            cfdDone.message.envelope().sequence(), cfdDone.message.type());
    _ctrl->reply(cfdDone.peer, std::move(err));
  }
  return {std::move(demDone), std::move(cfdDone)};
}

} // namespace coredem::orchestrator
