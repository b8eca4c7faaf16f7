#pragma once
/// @file
/// What the coredemFoam end-to-end tests share: the column template filled in, running `coredem` on
/// a case (with a deadline, no plots), the tail of coredemFoam's log for failure messages, a run
/// straight through against the same run stopped and resumed, and a case run on K decomposed CFD
/// ranks. Needs COREDEM_BIN_DIR (the build's bin folder).

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "coredem_e2e.h"

namespace coredem::e2e::foam {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

/// Copies the column template folder `from` to `to` with its inlet velocity (m/s) and
/// temperature (K) filled in (@U_IN@, @T_IN@).
inline void copyColumnTemplate(const fs::path& from, const fs::path& to, double uIn, double tIn) {
  fs::copy(from, to, fs::copy_options::recursive);
  for (const auto& e : fs::recursive_directory_iterator(to)) {
    if (e.is_regular_file()) {
      std::string s = readAll(e.path());
      s = replaceAll(s, "@U_IN@", std::to_string(uIn));
      s = replaceAll(s, "@T_IN@", std::to_string(tIn));
      writeAll(e.path(), s);
    }
  }
}

/// Runs `coredem args... --no-plots` with output into `log`, with a deadline; returns the exit
/// code.
inline int runCoredem(std::vector<std::string> args, const fs::path& log,
                      std::chrono::seconds timeout = 150s) {
  args.push_back("--no-plots");
  return waitExit(startProgram(fs::path(COREDEM_BIN_DIR) / "coredem", args, log), timeout);
}

/// The last 3000 characters of a run's coredemFoam log.
inline std::string logTail(const fs::path& runDir) {
  std::string s = readAll(runDir / "logs" / "cfd.log");
  return s.size() > 3000 ? s.substr(s.size() - 3000) : s;
}

/// Runs case `c` twice: straight through into dir/straight, and for `stopAfter` steps then
/// `coredem resume` into dir/resumed; both must exit 0 and the resume must restart coredemFoam
/// from the checkpoint. Returns {straight, resumed}.
inline std::pair<fs::path, fs::path> runStraightAndResumed(const fs::path& dir, const fs::path& c,
                                                           int stopAfter) {
  const fs::path a = dir / "straight", b = dir / "resumed";
  EXPECT_EQ(runCoredem({"run", c.string(), "--out", a.string()}, dir / "a.log"), 0)
      << readAll(dir / "a.log") << logTail(a);
  EXPECT_EQ(runCoredem(
                {"run", c.string(), "--out", b.string(), "--stop-after", std::to_string(stopAfter)},
                dir / "b.log"),
            0)
      << readAll(dir / "b.log") << logTail(b);
  EXPECT_EQ(runCoredem({"resume", b.string()}, dir / "b.log"), 0)
      << readAll(dir / "b.log") << logTail(b);
  EXPECT_NE(readAll(b / "logs" / "cfd.log").find("Restarting from"), std::string::npos)
      << "coredemFoam was not restarted from the checkpoint";
  return {a, b};
}

/// Runs case `c` (its case.yaml's cfd line ends in "case: openfoam, timeout_s: 120}") on `ranks`
/// CFD ranks into dir/run: for ranks > 1 the line gains "ranks: K" and the run must say that
/// the exchange is decomposed and leave processor folders. Returns the run's timeseries (empty
/// after a failed run, which fails the test).
inline std::map<std::string, std::vector<double>> runOnRanks(const fs::path& dir, const fs::path& c,
                                                             int ranks) {
  if (ranks > 1) {
    const fs::path y = c / "case.yaml";
    const std::string from = "case: openfoam, timeout_s: 120}";
    const std::string yaml = readAll(y);
    EXPECT_NE(yaml.find(from), std::string::npos) << y << " has no line to add ranks to";
    writeAll(y,
             replaceAll(yaml, from,
                        "case: openfoam, timeout_s: 120, ranks: " + std::to_string(ranks) + "}"));
  }
  const fs::path run = dir / "run";
  const int rc = runCoredem({"run", c.string(), "--out", run.string()}, dir / "coredem.log");
  EXPECT_EQ(rc, 0) << readAll(dir / "coredem.log") << logTail(run);
  if (rc != 0)
    return {};
  if (ranks > 1) {
    EXPECT_NE(readAll(run / "logs" / "cfd.log").find("Exchange: decomposed"), std::string::npos)
        << logTail(run);
    EXPECT_TRUE(fs::is_directory(run / "openfoam" / ("processor" + std::to_string(ranks - 1))));
    EXPECT_TRUE(fs::exists(run / "openfoam" / "system" / "decomposeParDict"));
  }
  return readTimeseries(run);
}

} // namespace coredem::e2e::foam
