#pragma once
// A Configure turned into what a session runs on, or refused before the session changes: the
// message's validation, admission control (admission.h), the coupling scheme (the server's own
// option), the DEM system built from it (configure_map.h), the restart state read back.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "admission.h"
#include "coredem/dem/dem_system.h"
#include "coredem/server/dem_server.h"
#include "reply_text.h"
#include "state_meta.h"

namespace coredem::server {

/// What a Configure set up, not yet the session's.
struct SessionSetup {
  std::unique_ptr<dem::DemSystem> system;
  std::uint32_t nSub = 0; ///< the sub-steps of Configure's dt_cfd (0: none given)
  bool staggered = false;
  bool newStart = false; ///< initial_state_file is another run's particles (initial_state.h)
  ServerLedgers ledgers;
  StaggeredState lag;
  std::vector<std::string> ignoredOptions; ///< Configure options that are not the DEM's
};

/// Why a Configure is refused; `warning` (when set) is logged first.
struct SetupRefusal {
  Refusal refusal;
  std::string warning;
};

/// Builds the session of Configure `c` (the DEM system on `options.backend`; `stopFlag` stops a
/// long placement), or says why not.
std::variant<SessionSetup, SetupRefusal> setUpSession(const v1::Configure& c,
                                                      const ServerOptions& options,
                                                      const Limits& limits,
                                                      std::atomic<bool>* stopFlag);

} // namespace coredem::server
