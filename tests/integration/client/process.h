#pragma once
// Child processes for the participant tests: start a program with extra environment
// variables, wait for it with a deadline, kill only our own child (by pid) if it overruns.
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/process.h>

namespace coredem::testing {

class Child {
public:
  Child(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env = {}) {
    coredem::SpawnOptions options;
    options.env = env;
    options.ownProcessGroup = false;
    options.stdinFromDevNull = false;
    _pid = coredem::spawnProcess("test peer", argv, {}, options); // output stays on the test's
  }
  ~Child() {
    if (_pid > 0 && !_done) {
      ::kill(_pid, SIGKILL);
      int st = 0;
      ::waitpid(_pid, &st, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Exit code, or -1 if it did not end within `timeout` (then it is killed), -2 on a signal.
  int wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      int st = 0;
      const pid_t r = ::waitpid(_pid, &st, WNOHANG);
      if (r == _pid) {
        _done = true;
        return WIFEXITED(st) ? WEXITSTATUS(st) : -2;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::kill(_pid, SIGKILL);
    int st = 0;
    ::waitpid(_pid, &st, 0);
    _done = true;
    return -1;
  }

private:
  pid_t _pid = -1;
  bool _done = false;
};

/// Waits until `file` exists with a complete line; returns its first line.
inline std::string waitForFile(const std::filesystem::path& file,
                               std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (std::filesystem::exists(file)) {
      std::ifstream in(file);
      std::string line;
      if (std::getline(in, line) && !line.empty()) {
        return line;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  throw std::runtime_error("timed out waiting for " + file.string());
}

/// A real coredem-dem process on an ephemeral loopback port, started like the orchestrator does.
class DemProcess {
public:
  explicit DemProcess(const std::filesystem::path& dir) {
    const auto file = dir / ("dem-endpoint-" + std::to_string(_counter++));
    std::filesystem::remove(file);
    _child = std::make_unique<Child>(std::vector<std::string>{
        COREDEM_DEM_BIN, "--bind", "tcp://127.0.0.1:*", "--backend", "cpu", "--threads", "1",
        "--exit-after-session", "--endpoint-file", file.string(), "--timeout-s", "60"});
    _endpoint = waitForFile(file, std::chrono::seconds(20));
  }
  const std::string& endpoint() const { return _endpoint; }
  int wait(std::chrono::milliseconds t) { return _child->wait(t); }

private:
  static inline int _counter = 0;
  std::unique_ptr<Child> _child;
  std::string _endpoint;
};

} // namespace coredem::testing
