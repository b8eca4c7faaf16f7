#pragma once
/// @file
/// An emulated remote node for the e2e tests: a network namespace joined to the host by a veth
/// pair with private addresses, processes started inside it (`ip netns exec`), and everything
/// removed by the destructor, also when the test fails. Names carry the test process's pid
/// (`coredem-e2e-<pid>`, veth `cdh<pid>` / `cdn<pid>`, 10.213.x.y/30), so that concurrent test
/// processes do not meet; names of processes that no longer run are removed first
/// (cleanStale). bench/remote/link.sh is the same set-up for the benchmarks.

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/process.h>

namespace coredem::e2e {

/// Runs `command` through the shell; returns its exit code and, in `output`, stdout + stderr.
inline int shell(const std::string& command, std::string* output = nullptr) {
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) {
    return -1;
  }
  std::string text;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) {
    text += buf;
  }
  const int status = ::pclose(p);
  if (output != nullptr) {
    *output = text;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class NetnsLink {
public:
  static constexpr const char* kNamespacePrefix = "coredem-e2e-";
  static constexpr const char* kVethPrefix = "cdh";

  /// Why this machine cannot build the link ("" when it can): not root, no `ip`, or the kernel
  /// refuses a namespace or a veth pair (a container without CAP_SYS_ADMIN / CAP_NET_ADMIN).
  /// Tries a throw-away namespace and veth pair, removed again.
  static std::string unavailableReason() {
    if (::geteuid() != 0) {
      return "network namespaces need root (ip netns add); run the e2e tests as root";
    }
    if (coredem::findProgram("ip").empty()) {
      return "the `ip` command (Debian package iproute2) is not installed";
    }
    const std::string probe = std::string(kNamespacePrefix) + std::to_string(::getpid()) + "p";
    std::string out;
    if (shell("ip netns add " + probe, &out) != 0) {
      return "cannot create a network namespace (ip netns add: " + trim(out) + ")";
    }
    const std::string veth = std::string(kVethPrefix) + std::to_string(::getpid()) + "p";
    const int rc = shell("ip link add " + veth + " type veth peer name cdp" +
                             std::to_string(::getpid()) + " netns " + probe,
                         &out);
    shell("ip link del " + veth);
    shell("ip netns del " + probe);
    if (rc != 0) {
      return "cannot create a veth pair (ip link add ... type veth: " + trim(out) + ")";
    }
    return "";
  }

  /// Removes namespaces and host-side veths of earlier test processes that no longer run
  /// (after a crash or a SIGKILL), with the processes still inside those namespaces.
  static void cleanStale() {
    std::string list;
    shell("ip netns list", &list);
    std::istringstream in(list);
    for (std::string line; std::getline(in, line);) {
      const std::string name = line.substr(0, line.find(' '));
      if (name.rfind(kNamespacePrefix, 0) == 0 && !ownerAlive(name, kNamespacePrefix)) {
        killInside(name);
        shell("ip netns del " + name);
      }
    }
    shell("ip -o link show", &list);
    std::istringstream links(list);
    for (std::string line; std::getline(links, line);) {
      // "12: cdh1234@if11: <...>"
      const auto a = line.find(": ");
      if (a == std::string::npos) {
        continue;
      }
      std::string name = line.substr(a + 2);
      name = name.substr(0, name.find_first_of("@:"));
      if (name.rfind(kVethPrefix, 0) == 0 && !ownerAlive(name, kVethPrefix)) {
        shell("ip link del " + name);
      }
    }
  }

  /// Creates the namespace and the veth pair, with the addresses up and loopback up inside.
  /// `ok()` says whether it worked; `error()` names the failed command.
  NetnsLink() {
    const std::string pid = std::to_string(::getpid());
    name = kNamespacePrefix + pid;
    _hostVeth = kVethPrefix + pid;
    _nsVeth = "cdn" + pid;
    const int index = static_cast<int>(::getpid() % 16000);
    const std::string net = "10.213." + std::to_string(index / 64) + ".";
    hostAddress = net + std::to_string((index % 64) * 4 + 1);
    nsAddress = net + std::to_string((index % 64) * 4 + 2);
    _created = true;
    for (const std::string& c :
         {"ip netns add " + name,
          "ip link add " + _hostVeth + " type veth peer name " + _nsVeth + " netns " + name,
          "ip addr add " + hostAddress + "/30 dev " + _hostVeth, "ip link set " + _hostVeth + " up",
          inside("ip addr add " + nsAddress + "/30 dev " + _nsVeth),
          inside("ip link set " + _nsVeth + " up"), inside("ip link set lo up")}) {
      std::string out;
      if (shell(c, &out) != 0) {
        _error = c + ": " + trim(out);
        return;
      }
    }
  }

  ~NetnsLink() {
    for (auto it = _pids.rbegin(); it != _pids.rend(); ++it) {
      stop(*it);
    }
    if (_created) {
      killInside(name);
      shell("ip link del " + _hostVeth);
      shell("ip netns del " + name);
    }
  }
  NetnsLink(const NetnsLink&) = delete;
  NetnsLink& operator=(const NetnsLink&) = delete;

  bool ok() const { return _error.empty(); }
  const std::string& error() const { return _error; }

  /// `command` run inside the namespace.
  std::string inside(const std::string& command) const {
    return "ip netns exec " + name + " " + command;
  }

  /// Whether the kernel has the netem qdisc (`tc qdisc add ... netem`); removed again.
  bool hasNetem() const {
    if (coredem::findProgram("tc").empty()) {
      return false;
    }
    const bool ok = shell("tc qdisc add dev " + _hostVeth + " root netem delay 0ms") == 0;
    if (ok) {
      shell("tc qdisc del dev " + _hostVeth + " root");
    }
    return ok;
  }

  /// `tc qdisc show` of both ends of the veth pair (host end first).
  std::string qdiscs() const {
    std::string host, ns;
    shell("tc qdisc show dev " + _hostVeth, &host);
    shell(inside("tc qdisc show dev " + _nsVeth), &ns);
    return host + ns;
  }

  /// netem on both ends: `oneWayMs` each way (round trip = 2 x oneWayMs); 0 removes it.
  bool setNetemDelay(double oneWayMs) const {
    bool ok = true;
    for (const std::string& c : {std::string("tc qdisc del dev ") + _hostVeth + " root",
                                 inside("tc qdisc del dev " + _nsVeth + " root")}) {
      shell(c); // no qdisc yet: fails, harmless
    }
    if (oneWayMs > 0.0) {
      const std::string d = " root netem delay " + std::to_string(oneWayMs) + "ms";
      ok = shell("tc qdisc add dev " + _hostVeth + d) == 0 &&
           shell(inside("tc qdisc add dev " + _nsVeth + d)) == 0;
    }
    return ok;
  }

  /// Starts `program args...` inside the namespace, stdout + stderr to `log`; stopped by the
  /// destructor (SIGTERM, then SIGKILL). `ip netns exec` execs the program: the pid is its.
  pid_t start(const std::filesystem::path& program, const std::vector<std::string>& args,
              const std::filesystem::path& log) {
    std::vector<std::string> argv = {coredem::findProgram("ip").string(), "netns", "exec", name,
                                     program.string()};
    argv.insert(argv.end(), args.begin(), args.end());
    coredem::SpawnOptions o;
    o.ownProcessGroup = false;
    const pid_t pid = coredem::spawnProcess(program.filename().string(), argv, log, o);
    _pids.push_back(pid);
    return pid;
  }

  /// SIGTERM, up to 10 s, then SIGKILL; returns the exit code (−signal when killed).
  static int stop(pid_t pid) {
    using namespace std::chrono_literals;
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) != 0) {
      return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
    }
    ::kill(pid, SIGTERM);
    const auto end = std::chrono::steady_clock::now() + 10s;
    while (::waitpid(pid, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > end) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(5ms);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }

  std::string name;        ///< the namespace
  std::string hostAddress; ///< the host's end of the veth pair
  std::string nsAddress;   ///< the namespace's end (the "remote node")

private:
  static std::string trim(std::string s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) {
      s.pop_back();
    }
    return s;
  }
  /// The pid in `<prefix><pid>[suffix]` runs.
  static bool ownerAlive(const std::string& name, const std::string& prefix) {
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
  }
  static void killInside(const std::string& ns) {
    std::string pids;
    shell("ip netns pids " + ns, &pids);
    std::istringstream in(pids);
    for (long pid = 0; in >> pid;) {
      ::kill(static_cast<pid_t>(pid), SIGKILL);
    }
  }

  std::string _hostVeth, _nsVeth, _error;
  bool _created = false;
  std::vector<pid_t> _pids;
};

} // namespace coredem::e2e
