#pragma once
/// @file
/// One named logger per component: `auto log = coredem::logger("dem.server");`
/// Loggers print "[time] [name] [level] message" to stderr; the level comes from the
/// COREDEM_LOG_LEVEL environment variable (trace|debug|info|warn|error|off, default info).
///
/// Every build but the DEM core alone logs through spdlog (coredem::Logger is spdlog::logger).
/// The DEM core built alone (COREDEM_CORE_ONLY: no third-party library) has the small
/// coredem::Logger below with the same calls (trace/debug/info/warn/error with fmt-syntax
/// messages, coredem/common/format.h), the same line format and the same level variable.

#include <memory>
#include <string>

#if COREDEM_HAVE_FMT
#include <spdlog/spdlog.h>
#else
#include <mutex>
#include <string_view>

#include "coredem/common/format.h"
#endif

namespace coredem {

#if COREDEM_HAVE_FMT
using Logger = spdlog::logger;
#else
/// The DEM core's logger without spdlog: thread-safe, one line per message to stderr.
class Logger {
public:
  enum class Level { Trace, Debug, Info, Warn, Error, Off };

  Logger(std::string name, Level level)
      : _name(std::move(name))
      , _level(level) {}

  template <typename... A>
  void trace(std::string_view f, const A&... a) {
    log(Level::Trace, f, a...);
  }
  template <typename... A>
  void debug(std::string_view f, const A&... a) {
    log(Level::Debug, f, a...);
  }
  template <typename... A>
  void info(std::string_view f, const A&... a) {
    log(Level::Info, f, a...);
  }
  template <typename... A>
  void warn(std::string_view f, const A&... a) {
    log(Level::Warn, f, a...);
  }
  template <typename... A>
  void error(std::string_view f, const A&... a) {
    log(Level::Error, f, a...);
  }
  bool should_log(Level l) const { return l >= _level && _level != Level::Off; }
  const std::string& name() const { return _name; }

private:
  template <typename... A>
  void log(Level l, std::string_view f, const A&... a) {
    if (should_log(l))
      write(l, formatLite(f, a...));
  }
  void write(Level l, const std::string& message);

  std::string _name;
  Level _level;
  std::mutex _mutex;
};
#endif

/// The logger of a component, created on first use. Thread-safe.
std::shared_ptr<Logger> logger(const std::string& component);

} // namespace coredem
