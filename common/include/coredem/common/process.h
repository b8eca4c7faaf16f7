#pragma once
/// @file
/// Child processes (the orchestrator's participants, campaign members, test peers): spawn with
/// output redirected to a log file, liveness checks that name the exit reason, and a clean stop
/// (SIGTERM, grace period, SIGKILL).

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace coredem {

/// How spawnProcess() starts a program.
struct SpawnOptions {
  std::map<std::string, std::string> env; ///< set (or override) these environment variables
  bool ownProcessGroup = true;  ///< own process group: a terminal Ctrl-C reaches only the parent
  bool stdinFromDevNull = true; ///< stdin from /dev/null (else inherited)
};

/// Starts `argv[0]` (a path) with stdout and stderr appended to `logFile` (inherited when
/// `logFile` is empty). Returns the pid.
/// Throws UserError naming `what` and the program if it cannot be started.
int spawnProcess(const std::string& what, const std::vector<std::string>& argv,
                 const std::filesystem::path& logFile, const SpawnOptions& options = {});

/// "exited with code 1", "killed by signal 9 (SIGKILL)" for a waitpid() status.
std::string describeWaitStatus(int status);

class ChildProcess {
public:
  /// Starts `argv[0]` with the arguments, extra environment variables, stdout+stderr
  /// appended to `logFile`. Throws UserError if the program cannot be started.
  ChildProcess(std::string name, std::vector<std::string> argv,
               const std::map<std::string, std::string>& env, const std::filesystem::path& logFile);
  ~ChildProcess(); ///< stops the process if it still runs
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  const std::string& name() const { return _name; }
  int pid() const { return _pid; }
  /// nullopt while running; else why it ended ("exited with code 1", "killed by signal 9
  /// (SIGKILL)").
  std::optional<std::string> exitReason();
  /// Exit code when it exited normally (after exitReason() reported an end), else -1.
  int exitCode() const { return _exitCode; }
  /// Waits up to `timeout` for the process to end on its own; true if it ended.
  bool waitFor(std::chrono::milliseconds timeout);
  /// SIGTERM, wait `grace`, then SIGKILL. No-op when already ended.
  void stop(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));
  /// The last `lines` lines of its log file (for error reports).
  std::string logTail(int lines = 15) const;
  const std::filesystem::path& logFile() const { return _log; }

private:
  std::string _name;
  std::filesystem::path _log;
  int _pid = -1;
  bool _ended = false;
  int _exitCode = -1;
  std::string _reason;
};

/// Folder of the running executable (coredem-dem and coredem-gas are looked up there first).
std::filesystem::path executableDir();

/// Finds a program: next to the coredem executable, else on PATH. Empty if not found.
std::filesystem::path findProgram(const std::string& name);

} // namespace coredem
