#pragma once
/// @file
/// `coredem-dem --timers`: where the DEM server's wall time goes in a session — the DEM
/// stages (coredem::dem::StageTimes) and the exchange with the CFD participant (waiting for
/// its GasFields, validating and unpacking them, building and sending Sources, ledgers,
/// checkpoints). Printed to the log every N steps and at the end of the session, and written
/// as JSON (docs/performance.md "Timers").

#include <cstdint>
#include <string>

#include "coredem/dem/dem_system.h"

namespace coredem::server {

/// Seconds spent by the server outside the DEM core during one session.
struct ExchangeTimes {
  double waitPeer =
      0; ///< from a step's StepDone to the next GasFields in hand (the CFD's step + transfer)
  double validate = 0;    ///< proto::validate of the GasFields (structure, NaN/Inf scan)
  double unpack = 0;      ///< array views + DemSystem::setGasFields (copy into the engine)
  double advance = 0;     ///< DemSystem::advance (split by StageTimes)
  double ledgers = 0;     ///< particle copy, ledgers, diagnostics
  double packSend = 0;    ///< Sources and StepDone built and handed to ZeroMQ
  double checkpoint = 0;  ///< state files written with the grant
  std::int64_t steps = 0; ///< CFD steps
  std::uint64_t particleSubSteps = 0; ///< Σ N · n_sub
};

/// The report: one line (`multiLine` false, for the every-N-steps log line) or a table.
std::string timersReport(const ExchangeTimes& x, const dem::StageTimes& st, double sessionSeconds,
                         bool multiLine);
/// The same figures as one JSON object.
std::string timersJson(const ExchangeTimes& x, const dem::StageTimes& st, double sessionSeconds,
                       const std::string& session, const std::string& backend, int threads);
/// Writes `text` to `path` atomically (coredem::writeFileAtomic), creating its folder.
/// Throws coredem::UserError on failure.
void writeTextFile(const std::string& path, const std::string& text);

} // namespace coredem::server
