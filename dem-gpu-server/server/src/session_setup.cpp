#include "session_setup.h"

#include <cmath>
#include <filesystem>
#include <optional>

#include <malloc.h>

#include "configure_map.h"
#include "coredem/common/check.h"
#include "coredem/dem/time_handler.h"
#include "coredem/protocol/coupling_scheme.h"
#include "coredem/protocol/initial_state.h"
#include "coredem/protocol/protocol.h"

namespace coredem::server {

namespace proto = coredem::protocol;
namespace fs = std::filesystem;

namespace {

/// The coupling scheme is the server's own option (not a DEM model): an unknown value is
/// refused, never taken for the default.
std::optional<Refusal> readCouplingScheme(const v1::Configure& c, bool& staggered) {
  staggered = false;
  for (const auto& kv : c.options()) {
    if (kv.key() == proto::fields::kCouplingSchemeOption) {
      if (kv.value() == "staggered") {
        staggered = true;
      } else if (kv.value() != "sequential") {
        return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                       fmt::format("Configure option {} = '{}': this server runs 'sequential' or "
                                   "'staggered'",
                                   proto::fields::kCouplingSchemeOption, safe(kv.value(), 64))};
      }
    }
  }
  return std::nullopt;
}

/// How Configure.initial_state_file is read (protocol/initial_state.h): a new start from another
/// run's particles, or (absent, "resume") a checkpoint of this run. Another value is refused.
std::optional<Refusal> readInitialStateMode(const v1::Configure& c, bool& newStart) {
  newStart = false;
  for (const auto& kv : c.options()) {
    if (kv.key() == proto::fields::kInitialStateOption) {
      if (kv.value() == proto::fields::kInitialStateStart) {
        newStart = true;
      } else if (kv.value() != "resume") {
        return Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                       fmt::format("Configure option {} = '{}': this server reads 'start' or "
                                   "'resume'",
                                   proto::fields::kInitialStateOption, safe(kv.value(), 64))};
      }
    }
  }
  return std::nullopt;
}

/// The DEM system of `c` with its restart state (throws what the DEM core throws).
void build(const v1::Configure& c, const ServerOptions& options, std::atomic<bool>* stopFlag,
           SessionSetup& s) {
  const bool newStart = s.newStart;
  COREDEM_CHECK(c.coupling_mesh().has_cartesian(), "Configure has no Cartesian coupling grid");
  auto cfg = toDemConfig(c, &s.ignoredOptions);
  cfg.interrupt = stopFlag; // SIGINT/SIGTERM stop a long placement
  s.system =
      std::make_unique<dem::DemSystem>(cfg, dem::parseBackend(options.backend), options.threads);
  if (!c.initial_state_file().empty()) {
    COREDEM_CHECK(fs::exists(c.initial_state_file()), "initial state file '{}' does not exist",
                  c.initial_state_file());
    if (newStart) {
      // Another run's particles: time, ledgers and the staggered lag start afresh.
      s.system->startFromState(c.initial_state_file());
    } else {
      s.system->readState(c.initial_state_file());
      s.ledgers = readServerLedgers(c.initial_state_file(), c.species_size());
    }
    if (s.staggered && !newStart) {
      s.lag = readStaggeredState(c.initial_state_file(), proto::cellCount(c.coupling_mesh()),
                                 c.species_size());
    }
  }
  COREDEM_CHECK(std::isfinite(s.system->dtDemMax()) && s.system->dtDemMax() > 0.0,
                "no stable DEM time step can be derived (dt_dem_max = {}): give the particle "
                "sets (with an initial state file too, they define the sizes and materials)",
                s.system->dtDemMax());
  if (c.sub_cycling().dt_cfd() > 0.0) {
    s.nSub = static_cast<std::uint32_t>(
        dem::TimeHandler::subStepsFor(c.sub_cycling().dt_cfd(), s.system->dtDemMax()));
  }
}

} // namespace

std::variant<SessionSetup, SetupRefusal> setUpSession(const v1::Configure& c,
                                                      const ServerOptions& options,
                                                      const Limits& limits,
                                                      std::atomic<bool>* stopFlag) {
  if (const auto s = proto::validateConfigure(c); !s.ok()) {
    return SetupRefusal{Refusal{s.code, s.message}, std::string()};
  }
  // Admission control before anything is allocated: counts against the memory budget.
  if (const std::string why = admitConfigure(c, limits); !why.empty()) {
    return SetupRefusal{Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION, why}, std::string()};
  }
  SessionSetup s;
  if (auto no = readCouplingScheme(c, s.staggered)) {
    return SetupRefusal{std::move(*no), std::string()};
  }
  if (auto no = readInitialStateMode(c, s.newStart)) {
    return SetupRefusal{std::move(*no), std::string()};
  }
  s.lag.speciesComputed.assign(static_cast<std::size_t>(c.species_size()), 0.0);
  try {
    build(c, options, stopFlag, s);
  } catch (const dem::Interrupted& e) {
    s.system.reset();
    return SetupRefusal{Refusal{v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                                fmt::format("the server is stopping: Configure was {}", e.what())},
                        fmt::format("Configure stopped by a signal ({})", e.what())};
  } catch (const coredem::UserError& e) {
    s.system.reset();
    ::malloc_trim(0); // give a large failed build's memory back to the system
    return SetupRefusal{Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION, e.what()}, std::string()};
  } catch (const std::bad_alloc&) {
    s.system.reset();
    ::malloc_trim(0);
    return SetupRefusal{
        Refusal{v1::ERROR_CODE_INVALID_CONFIGURATION,
                fmt::format("Configure: out of memory while building the particles although the "
                            "estimate fits the {} budget; lower coredem-dem --max-memory so that "
                            "such a Configure is refused up front",
                            formatBytes(limits.memoryBytes))},
        std::string()};
  }
  return s;
}

} // namespace coredem::server
