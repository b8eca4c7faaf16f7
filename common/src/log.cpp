#include <cstdlib>
#include <mutex>

#include <spdlog/sinks/stdout_color_sinks.h>

#include <coredem/common/log.h>

namespace coredem {

std::shared_ptr<spdlog::logger> logger(const std::string& component) {
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

} // namespace coredem
