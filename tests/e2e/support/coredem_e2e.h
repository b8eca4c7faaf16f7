#pragma once
/// @file
/// Helpers shared by the end-to-end tests: temporary folders, whole-file I/O, and running
/// `coredem` as a child process with a deadline (a test never waits forever on it).

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/process.h>

namespace coredem::e2e {

namespace fs = std::filesystem;

/// A fresh, empty folder `<tmp>/<prefix>-<pid>-<name>` (removed first if it exists).
inline fs::path tempDir(const std::string& prefix, const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / (prefix + "-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// timeseries.csv of a run: column name -> values (one per row; an empty cell is NaN).
inline std::map<std::string, std::vector<double>> readTimeseries(const fs::path& runDir) {
  std::ifstream in(runDir / "timeseries.csv");
  std::map<std::string, std::vector<double>> out;
  std::string line;
  std::vector<std::string> names;
  if (!std::getline(in, line)) {
    ADD_FAILURE() << "no timeseries.csv in " << runDir;
    return out;
  }
  std::stringstream h(line);
  for (std::string n; std::getline(h, n, ',');)
    names.push_back(n);
  while (std::getline(in, line)) {
    std::stringstream r(line);
    std::size_t i = 0;
    for (std::string v; std::getline(r, v, ',') && i < names.size(); ++i) {
      out[names[i]].push_back(v.empty() ? std::nan("") : std::strtod(v.c_str(), nullptr));
    }
  }
  return out;
}

/// The file of the last line of a run's snapshots/index.csv (the run's end).
inline fs::path lastSnapshot(const fs::path& runDir) {
  const std::string index = readAll(runDir / "snapshots" / "index.csv");
  const auto end = index.find_last_not_of('\n');
  const auto start = index.rfind('\n', end);
  const std::string line = index.substr(start + 1, end - start);
  return runDir / line.substr(line.rfind(',') + 1);
}

inline void writeAll(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

/// `s` with every occurrence of `from` replaced by `to` (case-text edits of the e2e tests).
inline std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t i = s.find(from); i != std::string::npos; i = s.find(from, i + to.size())) {
    s.replace(i, from.size(), to);
  }
  return s;
}

/// Starts `program args...` with stdout and stderr appended to `log`; returns the pid (-1 and
/// a test failure when it cannot be started).
inline pid_t startProgram(const fs::path& program, const std::vector<std::string>& args,
                          const fs::path& log) {
  std::vector<std::string> argv = {program.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  coredem::SpawnOptions options;
  options.ownProcessGroup = false;
  options.stdinFromDevNull = false;
  try {
    return coredem::spawnProcess(program.filename().string(), argv, log, options);
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what();
    return -1;
  }
}

/// Waits for `pid` until `timeout`; past it the process gets SIGTERM, then SIGKILL two seconds
/// later, and the test fails. Returns the exit code, or −signal when it was killed.
inline int waitExit(pid_t pid, std::chrono::seconds timeout) {
  using namespace std::chrono_literals;
  if (pid <= 0) {
    return -1;
  }
  const auto end = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > end) {
      ::kill(pid, SIGTERM);
      std::this_thread::sleep_for(2s);
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      ADD_FAILURE() << "process " << pid << " did not finish within " << timeout.count() << " s";
      return -1000;
    }
    std::this_thread::sleep_for(5ms);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

/// A test with a fresh temporary folder `dir` (named after the test), kept for inspection when
/// the test fails. Set-up fails when one of `programs` is not built in `bin`.
class RunFolderTest : public ::testing::Test {
protected:
  RunFolderTest(fs::path bin, std::vector<std::string> programs, std::string prefix)
      : _bin(std::move(bin))
      , _programs(std::move(programs))
      , _prefix(std::move(prefix)) {}

  void SetUp() override {
    for (const auto& exe : _programs) {
      ASSERT_EQ(::access((_bin / exe).c_str(), X_OK), 0)
          << (_bin / exe) << " is not built: build all targets first";
    }
    dir = tempDir(_prefix, ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override {
    if (!HasFailure()) {
      fs::remove_all(dir);
    } else {
      std::cerr << "kept " << dir << " for inspection\n";
    }
  }

  fs::path dir;

private:
  fs::path _bin;
  std::vector<std::string> _programs;
  std::string _prefix;
};

} // namespace coredem::e2e
