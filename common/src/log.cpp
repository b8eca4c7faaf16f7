#include <cstdlib>
#include <mutex>

#include <coredem/common/log.h>

#if COREDEM_HAVE_FMT
#include <spdlog/sinks/stdout_color_sinks.h>
#else
#include <chrono>
#include <cstdio>
#include <ctime>
#include <map>
#endif

namespace coredem {

#if COREDEM_HAVE_FMT

std::shared_ptr<Logger> logger(const std::string& component) {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  if (auto existing = spdlog::get(component)) {
    return existing;
  }
  auto log = spdlog::stderr_color_mt(component);
  log->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  if (const char* level = std::getenv("COREDEM_LOG_LEVEL")) {
    log->set_level(spdlog::level::from_str(level));
  } else {
    log->set_level(spdlog::level::info);
  }
  return log;
}

#else

namespace {

/// COREDEM_LOG_LEVEL as spdlog reads it (an unknown name turns logging off, as there).
Logger::Level levelFromEnvironment() {
  const char* v = std::getenv("COREDEM_LOG_LEVEL");
  if (!v)
    return Logger::Level::Info;
  const std::string s(v);
  if (s == "trace")
    return Logger::Level::Trace;
  if (s == "debug")
    return Logger::Level::Debug;
  if (s == "info")
    return Logger::Level::Info;
  if (s == "warn" || s == "warning")
    return Logger::Level::Warn;
  if (s == "error" || s == "err" || s == "critical")
    return Logger::Level::Error;
  return Logger::Level::Off;
}

} // namespace

void Logger::write(Level l, const std::string& message) {
  static constexpr const char* names[] = {"trace", "debug", "info", "warning", "error", "off"};
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm local{};
  localtime_r(&t, &local);
  std::lock_guard lock(_mutex);
  std::fprintf(stderr, "[%02d:%02d:%02d.%03d] [%s] [%s] %s\n", local.tm_hour, local.tm_min,
               local.tm_sec, static_cast<int>(ms), _name.c_str(), names[static_cast<int>(l)],
               message.c_str());
}

std::shared_ptr<Logger> logger(const std::string& component) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<Logger>> loggers;
  std::lock_guard lock(mutex);
  auto& log = loggers[component];
  if (!log)
    log = std::make_shared<Logger>(component, levelFromEnvironment());
  return log;
}

#endif

} // namespace coredem
