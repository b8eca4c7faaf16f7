#pragma once
/// @file
/// One named logger per component: `auto log = coredem::logger("dem.server");`
/// Loggers print "[time] [name] [level] message" to stderr; the level comes from the
/// COREDEM_LOG_LEVEL environment variable (trace|debug|info|warn|error|off, default info).

#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace coredem {

/// The logger of a component, created on first use. Thread-safe.
std::shared_ptr<spdlog::logger> logger(const std::string& component);

} // namespace coredem
