#include <cerrno>
#include <csignal>
#include <cstring>
#include <deque>
#include <fstream>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/log.h>
#include <coredem/common/process.h>

extern char** environ;

namespace fs = std::filesystem;

namespace coredem {

int spawnProcess(const std::string& what, const std::vector<std::string>& argv,
                 const fs::path& logFile, const SpawnOptions& options) {
  COREDEM_CHECK(!argv.empty(), "no program given for {}", what);
  std::vector<std::string> envStrings;
  for (char** e = environ; *e; ++e) {
    const std::string kv = *e;
    const std::string key = kv.substr(0, kv.find('='));
    if (!options.env.count(key)) {
      envStrings.push_back(kv);
    }
  }
  for (const auto& [k, v] : options.env) {
    envStrings.push_back(k + "=" + v);
  }
  std::vector<std::string> args = argv;
  std::vector<char*> cargv, cenv;
  for (auto& a : args) {
    cargv.push_back(a.data());
  }
  cargv.push_back(nullptr);
  for (auto& e : envStrings) {
    cenv.push_back(e.data());
  }
  cenv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (!logFile.empty()) {
    posix_spawn_file_actions_addopen(&actions, 1, logFile.c_str(), O_WRONLY | O_CREAT | O_APPEND,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
  }
  if (options.stdinFromDevNull) {
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  }
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  if (options.ownProcessGroup) {
    // Own process group: a Ctrl-C on the terminal reaches the parent, which stops the children.
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
  }
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, cargv[0], &actions, &attr, cargv.data(), cenv.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  COREDEM_CHECK(rc == 0, "cannot start the {} ('{}'): {}", what, argv[0], std::strerror(rc));
  return pid;
}

std::string describeWaitStatus(int status) {
  if (WIFEXITED(status)) {
    return fmt::format("exited with code {}", WEXITSTATUS(status));
  }
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* sname = sigabbrev_np(sig);
    return fmt::format("killed by signal {} (SIG{})", sig, sname ? sname : "?");
  }
  return "ended";
}

ChildProcess::ChildProcess(std::string name, std::vector<std::string> argv,
                           const std::map<std::string, std::string>& env, const fs::path& logFile)
    : _name(std::move(name))
    , _log(logFile) {
  SpawnOptions options;
  options.env = env;
  _pid = spawnProcess(_name, argv, logFile, options);
  logger("process")->debug("started {} (pid {}): log {}", _name, _pid, _log.string());
}

ChildProcess::~ChildProcess() {
  try {
    stop(std::chrono::milliseconds(2000));
  } catch (...) {
  }
}

std::optional<std::string> ChildProcess::exitReason() {
  if (_ended) {
    return _reason;
  }
  int status = 0;
  const pid_t r = ::waitpid(_pid, &status, WNOHANG);
  if (r == 0) {
    return std::nullopt;
  }
  _ended = true;
  if (r < 0) {
    _reason = "vanished (waitpid failed)";
  } else {
    _exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    _reason = describeWaitStatus(status);
  }
  return _reason;
}

bool ChildProcess::waitFor(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!exitReason()) {
    if (std::chrono::steady_clock::now() >= end) {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

void ChildProcess::stop(std::chrono::milliseconds grace) {
  if (_pid <= 0 || exitReason()) {
    return;
  }
  ::kill(_pid, SIGTERM);
  ::kill(_pid, SIGCONT); // a stopped (hung) process must run to act on SIGTERM
  if (!waitFor(grace)) {
    ::kill(_pid, SIGKILL);
    waitFor(std::chrono::milliseconds(5000));
  }
}

std::string ChildProcess::logTail(int lines) const {
  std::ifstream in(_log);
  std::deque<std::string> tail;
  std::string line;
  while (std::getline(in, line)) {
    tail.push_back(line);
    if (int(tail.size()) > lines) {
      tail.pop_front();
    }
  }
  std::string out;
  for (const auto& l : tail) {
    out += "    | " + l + "\n";
  }
  return out;
}

fs::path executableDir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path() : self.parent_path();
}

fs::path findProgram(const std::string& name) {
  const fs::path local = executableDir() / name;
  if (::access(local.c_str(), X_OK) == 0) {
    return local;
  }
  if (const char* path = std::getenv("PATH")) {
    std::string p = path;
    std::size_t start = 0;
    while (start <= p.size()) {
      const std::size_t end = p.find(':', start);
      const fs::path cand = fs::path(p.substr(start, end - start)) / name;
      if (::access(cand.c_str(), X_OK) == 0) {
        return cand;
      }
      if (end == std::string::npos) {
        break;
      }
      start = end + 1;
    }
  }
  return {};
}

} // namespace coredem
