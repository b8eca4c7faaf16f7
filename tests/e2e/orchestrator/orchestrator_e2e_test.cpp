// End-to-end tests of `coredem run/resume` with the real DEM server and coredem-gas:
// restart identity (200 straight == 100 + resume + 100, bitwise DEM state on the cpu
// backend), kill -9 of the DEM server (with and without --auto-restart), bad case files,
// SIGTERM with a checkpoint and resume, resume without a checkpoint, --walltime, a CFD
// participant dying of SIGFPE, pre-flight failures and warnings of `coredem check`.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>
#include <unistd.h>

#include "coredem_e2e.h"
#include "coredem_e2e_hdf5.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;

using coredem::e2e::readAll;

fs::path tempDir(const std::string& name) {
  return coredem::e2e::tempDir("coredem-e2e", name);
}

/// Starts coredem with `args`, output into `log`. Returns the pid.
pid_t startCoredem(const std::vector<std::string>& args, const fs::path& log) {
  return coredem::e2e::startProgram(kBin / "coredem", args, log);
}
using coredem::e2e::datasetsOf;
using coredem::e2e::waitExit;

int runCoredem(const std::vector<std::string>& args, const fs::path& log,
               std::chrono::seconds timeout = 50s) {
  return waitExit(startCoredem(args, log), timeout);
}

/// Direct children of `parent` whose command name is `comm`.
std::vector<pid_t> childrenNamed(pid_t parent, const std::string& comm) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    const std::string stat = readAll(e.path() / "stat");
    const auto open = stat.find('('), close = stat.rfind(')');
    if (open == std::string::npos || close == std::string::npos) {
      continue;
    }
    const std::string c = stat.substr(open + 1, close - open - 1);
    std::istringstream rest(stat.substr(close + 2));
    char state;
    pid_t ppid;
    rest >> state >> ppid;
    if (ppid == parent && c == comm.substr(0, 15)) {
      out.push_back(std::stoi(name));
    }
  }
  return out;
}

/// The DEM state file listed in a checkpoint manifest.
fs::path demStateOf(const fs::path& checkpoint) {
  const std::string m = readAll(checkpoint / "manifest.json");
  std::smatch match;
  const std::regex re("\\{\"path\": \"([^\"]+)\", \"participant\": \"dem\"");
  EXPECT_TRUE(std::regex_search(m, match, re)) << "no DEM file in " << checkpoint;
  return checkpoint / match[1].str();
}

/// Asserts that two DEM state files hold bitwise identical particle and contact datasets.
void expectSameDemState(const fs::path& a, const fs::path& b) {
  const auto da = datasetsOf(a), db = datasetsOf(b);
  ASSERT_FALSE(da.empty());
  ASSERT_TRUE(da.count("particles/position")) << "no particles/position in " << a;
  std::size_t compared = 0;
  for (const auto& [name, bytes] : da) {
    if (name.rfind("particles/", 0) != 0 && name.rfind("contacts/", 0) != 0) {
      continue;
    }
    ASSERT_TRUE(db.count(name)) << name << " missing in " << b;
    EXPECT_TRUE(bytes == db.at(name))
        << "dataset " << name << " differs between " << a << " and " << b;
    ++compared;
  }
  EXPECT_GE(compared, 5u);
}

std::vector<fs::path> leftovers(const fs::path& runDir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(runDir)) {
    if (e.path().filename().string().find(".tmp") != std::string::npos) {
      out.push_back(e.path());
    }
  }
  return out;
}

class CoredemE2E : public coredem::e2e::RunFolderTest {
protected:
  CoredemE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas"}, "coredem-e2e") {}
  const fs::path restartCase = kCases / "restart";
  const fs::path finalCheckpoint = "checkpoints/00000200";
};

} // namespace

// 200 steps straight vs 100 + resume + 100: bitwise identical DEM state (particles and
// contact history), identical gas ledgers and identical physical timeseries columns.
TEST_F(CoredemE2E, RestartIdentity) {
  const fs::path a = dir / "straight", b = dir / "split";
  ASSERT_EQ(runCoredem({"run", restartCase.string(), "--out", a.string()}, dir / "a.log"), 0)
      << readAll(dir / "a.log");
  ASSERT_EQ(runCoredem({"run", restartCase.string(), "--out", b.string(), "--stop-after", "100",
                        "--no-plots"},
                       dir / "b1.log"),
            0)
      << readAll(dir / "b1.log");
  ASSERT_TRUE(fs::exists(b / "checkpoints/00000100/manifest.json"));
  ASSERT_FALSE(fs::exists(b / finalCheckpoint));
  ASSERT_EQ(runCoredem({"resume", b.string(), "--no-plots"}, dir / "b2.log"), 0)
      << readAll(dir / "b2.log");
  EXPECT_NE(readAll(dir / "b2.log").find("resuming"), std::string::npos);
  expectSameDemState(demStateOf(a / finalCheckpoint), demStateOf(b / finalCheckpoint));
  // Same number of rows, and the simulated time column identical.
  const std::string ta = readAll(a / "timeseries.csv"), tb = readAll(b / "timeseries.csv");
  EXPECT_EQ(std::count(ta.begin(), ta.end(), '\n'), 201);
  EXPECT_EQ(std::count(tb.begin(), tb.end(), '\n'), 201);
  EXPECT_TRUE(leftovers(b).empty());
  // The straight run made its plots.
  EXPECT_TRUE(fs::exists(a / "plots" / "timeseries.png")) << readAll(a / "logs" / "plot.log");
  EXPECT_TRUE(fs::exists(a / "plots" / "particles.png"));
  // Snapshots: 0, 50, 100, 150, 200 in both, listed in particles.xdmf.
  for (const auto& run : {a, b}) {
    for (int s : {0, 50, 100, 150, 200}) {
      char name[64];
      std::snprintf(name, sizeof name, "snapshots/particles_%08d.h5", s);
      EXPECT_TRUE(fs::exists(run / name)) << run / name;
    }
    EXPECT_NE(readAll(run / "particles.xdmf").find("particles_00000200.h5:/particles/position"),
              std::string::npos);
  }
}

// The same with the CFL-adaptive Δt (Courant number from coredem-gas): the resumed run takes
// the same Δt sequence (dt policy state in the manifest) and ends in the same state.
TEST_F(CoredemE2E, AdaptiveRestartIdentity) {
  const fs::path c = kCases / "restart-adaptive";
  const fs::path a = dir / "straight", b = dir / "split";
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", a.string(), "--no-plots"}, dir / "a.log"), 0)
      << readAll(dir / "a.log");
  ASSERT_EQ(runCoredem({"run", c.string(), "--out", b.string(), "--stop-after", "30", "--no-plots"},
                       dir / "b1.log"),
            0)
      << readAll(dir / "b1.log");
  ASSERT_EQ(runCoredem({"resume", b.string(), "--no-plots"}, dir / "b2.log"), 0)
      << readAll(dir / "b2.log");
  auto lastCheckpoint = [](const fs::path& run) {
    fs::path last;
    for (const auto& e : fs::directory_iterator(run / "checkpoints")) {
      if (last.empty() || e.path().filename() > last.filename()) {
        last = e.path();
      }
    }
    return last;
  };
  const fs::path la = lastCheckpoint(a), lb = lastCheckpoint(b);
  ASSERT_EQ(la.filename(), lb.filename());
  // Δt really adapted: more than one distinct dt in the timeseries.
  const std::string ts = readAll(a / "timeseries.csv");
  EXPECT_NE(ts.find("\n2,0.0010999999999999998,0.00059999999999999995,"), std::string::npos)
      << ts.substr(0, 400);
  expectSameDemState(demStateOf(la), demStateOf(lb));
}

TEST(CoredemCli, DefaultCaseIsValid) {
  const fs::path d = tempDir("check-default");
  const fs::path defaultCase =
      kCases.parent_path().parent_path().parent_path().parent_path() / "cases" / "settling-heated";
  EXPECT_EQ(runCoredem({"check", defaultCase.string()}, d / "log", 30s), 0) << readAll(d / "log");
  fs::remove_all(d);
}

// kill -9 of the DEM server mid-run with --auto-restart 1: the run completes from the last
// checkpoint and ends in the same state as an uninterrupted run.
TEST_F(CoredemE2E, KillDemServerAutoRestart) {
  const fs::path a = dir / "straight", k = dir / "killed";
  ASSERT_EQ(
      runCoredem({"run", restartCase.string(), "--out", a.string(), "--no-plots"}, dir / "a.log"),
      0)
      << readAll(dir / "a.log");
  const pid_t o = startCoredem(
      {"run", restartCase.string(), "--out", k.string(), "--auto-restart", "1", "--no-plots"},
      dir / "k.log");
  // Kill D once the checkpoint of step 40 is complete (the run is then mid-way).
  const auto end = std::chrono::steady_clock::now() + 40s;
  pid_t killed = 0;
  while (std::chrono::steady_clock::now() < end && !killed) {
    if (fs::exists(k / "checkpoints/00000040/manifest.json")) {
      const auto dems = childrenNamed(o, "coredem-dem");
      ASSERT_EQ(dems.size(), 1u);
      ::kill(dems[0], SIGKILL);
      killed = dems[0];
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_NE(killed, 0) << "never saw checkpoint 40";
  ASSERT_EQ(waitExit(o, 50s), 0) << readAll(dir / "k.log");
  const std::string log = readAll(dir / "k.log");
  EXPECT_NE(
      log.find("DEM server coredem-dem: process " + std::to_string(killed) + " killed by signal 9"),
      std::string::npos)
      << log;
  EXPECT_NE(log.find("auto-restart"), std::string::npos) << log;
  expectSameDemState(demStateOf(a / finalCheckpoint), demStateOf(k / finalCheckpoint));
  EXPECT_TRUE(leftovers(k).empty());
}

// Without --auto-restart: the fault is named, the CFD participant is shut down, exit code 1,
// no temp files, and every checkpoint folder left is complete.
TEST_F(CoredemE2E, KillDemServerReportsAndStops) {
  const fs::path k = dir / "killed";
  const pid_t o = startCoredem({"run", restartCase.string(), "--out", k.string()}, dir / "k.log");
  const auto end = std::chrono::steady_clock::now() + 40s;
  pid_t gas = 0;
  bool killed = false;
  while (std::chrono::steady_clock::now() < end && !killed) {
    if (fs::exists(k / "checkpoints/00000020/manifest.json")) {
      const auto dems = childrenNamed(o, "coredem-dem");
      const auto gases = childrenNamed(o, "coredem-gas");
      ASSERT_EQ(dems.size(), 1u);
      ASSERT_EQ(gases.size(), 1u);
      gas = gases[0];
      ::kill(dems[0], SIGKILL);
      killed = true;
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(killed);
  EXPECT_EQ(waitExit(o, 50s), 1);
  const std::string log = readAll(dir / "k.log");
  EXPECT_NE(log.find("DEM server coredem-dem: process"), std::string::npos) << log;
  EXPECT_NE(log.find("killed by signal 9 (SIGKILL)"), std::string::npos) << log;
  EXPECT_NE(log.find("coredem resume"), std::string::npos) << log;
  EXPECT_NE(::kill(gas, 0), 0) << "coredem-gas (pid " << gas << ") still runs";
  EXPECT_TRUE(leftovers(k).empty());
  for (const auto& e : fs::directory_iterator(k / "checkpoints")) {
    EXPECT_TRUE(fs::exists(e.path() / "manifest.json"))
        << "incomplete checkpoint left: " << e.path();
  }
}

// A DEM server that stops answering (SIGSTOP) is reported after dem.timeout_s by name and
// reason; the CFD participant is shut down, exit code 1, only complete checkpoints remain.
TEST_F(CoredemE2E, HungDemServerMissesDeadline) {
  std::string text = readAll(restartCase / "case.yaml");
  text.replace(text.find("  timeout_s: 20\ncfd"), 15, "  timeout_s: 2");
  fs::create_directories(dir / "case");
  std::ofstream(dir / "case" / "case.yaml") << text;
  const fs::path k = dir / "hung";
  const pid_t o = startCoredem({"run", (dir / "case").string(), "--out", k.string(), "--no-plots"},
                               dir / "k.log");
  const auto end = std::chrono::steady_clock::now() + 40s;
  pid_t dem = 0, gas = 0;
  while (std::chrono::steady_clock::now() < end && !dem) {
    if (fs::exists(k / "checkpoints/00000020/manifest.json")) {
      const auto dems = childrenNamed(o, "coredem-dem");
      const auto gases = childrenNamed(o, "coredem-gas");
      ASSERT_EQ(dems.size(), 1u);
      ASSERT_EQ(gases.size(), 1u);
      gas = gases[0];
      dem = dems[0];
      ::kill(dem, SIGSTOP);
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_NE(dem, 0);
  EXPECT_EQ(waitExit(o, 50s), 1);
  const std::string log = readAll(dir / "k.log");
  EXPECT_NE(log.find("DEM server coredem-dem: stopped answering: no StepDone of step"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("within 2 s"), std::string::npos) << log;
  EXPECT_NE(::kill(gas, 0), 0) << "coredem-gas (pid " << gas << ") still runs";
  EXPECT_NE(::kill(dem, 0), 0) << "coredem-dem (pid " << dem << ") still runs";
  EXPECT_TRUE(leftovers(k).empty());
  for (const auto& e : fs::directory_iterator(k / "checkpoints")) {
    EXPECT_TRUE(fs::exists(e.path() / "manifest.json"))
        << "incomplete checkpoint left: " << e.path();
  }
}

// Bad case files: a clear message naming file, line and key; exit code 2; nothing written.
namespace {
struct BadCase {
  std::string name;
  std::string from, to; // textual edit of the restart case
  std::string expected; // message fragment
};

std::string editedCase(const std::string& from, const std::string& to) {
  std::string text = readAll(kCases / "restart" / "case.yaml");
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}
} // namespace

class BadCaseTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadCaseTest, ClearMessageExitTwoNothingWritten) {
  ASSERT_EQ(::access((kBin / "coredem").c_str(), X_OK), 0);
  const BadCase& bc = GetParam();
  const fs::path d = tempDir("bad-" + bc.name);
  fs::create_directories(d / "case");
  std::ofstream(d / "case" / "case.yaml") << editedCase(bc.from, bc.to);
  const fs::path out = d / "run";
  const int rc = runCoredem({"run", (d / "case").string(), "--out", out.string()}, d / "log", 30s);
  const std::string log = readAll(d / "log");
  EXPECT_EQ(rc, 2) << log;
  EXPECT_NE(log.find(bc.expected), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(out)) << "coredem wrote " << out << " for a bad case";
  fs::remove_all(d);
}

INSTANTIATE_TEST_SUITE_P(
    Orchestrator, BadCaseTest,
    ::testing::Values(BadCase{"UnknownKey", "  every_steps: 20", "  every_step: 20",
                              "case.yaml:40:3: checkpoint.every_step: unknown key; allowed keys in "
                              "'checkpoint': every_steps, every_seconds, keep"},
                      BadCase{"WrongType", "  dt: 5.0e-4", "  dt: fast",
                              "case.yaml:6:7: time.dt: expected a number"},
                      BadCase{"MissingFile",
                              "particles:", "initial_state: beads-at-rest.h5\nparticles:",
                              "initial_state: file 'beads-at-rest.h5' not found"},
                      BadCase{"GasSectionUnknownKey", "  T_g: 500.0", "  T_gas: 500.0", "T_gas"}),
    [](const auto& info) { return info.param.name; });

TEST(CoredemCli, MissingCaseFolderExitsTwo) {
  const fs::path d = tempDir("nocase");
  const int rc =
      runCoredem({"run", (d / "nope").string(), "--out", (d / "run").string()}, d / "log", 30s);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(readAll(d / "log").find("case file not found"), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "run"));
  fs::remove_all(d);
}

// A DEM server started elsewhere with CURVE keys: the orchestrator (and coredem-gas) connect
// with the server's public key; with another key the connection is refused (named, exit 1).
TEST_F(CoredemE2E, CurveRemoteServer) {
  ASSERT_EQ(std::system(((kBin / "coredem-dem").string() + " --generate-curve-keys " +
                         (dir / "keys").string() + " > /dev/null")
                            .c_str()),
            0);
  ASSERT_EQ(std::system(((kBin / "coredem-dem").string() + " --generate-curve-keys " +
                         (dir / "other").string() + " > /dev/null")
                            .c_str()),
            0);
  // Server: CURVE on an ephemeral loopback port, serving sessions one after the other.
  std::vector<std::string> argv = {(kBin / "coredem-dem").string(),
                                   "--bind",
                                   "tcp://127.0.0.1:*",
                                   "--curve-keys",
                                   (dir / "keys").string(),
                                   "--threads",
                                   "1",
                                   "--endpoint-file",
                                   (dir / "endpoint").string()};
  const pid_t server =
      coredem::e2e::startProgram(argv.front(), {argv.begin() + 1, argv.end()}, dir / "server.log");
  ASSERT_GT(server, 0);
  const auto end = std::chrono::steady_clock::now() + 20s;
  while (!fs::exists(dir / "endpoint") && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(10ms);
  }
  std::string endpoint = readAll(dir / "endpoint");
  while (!endpoint.empty() && std::isspace(static_cast<unsigned char>(endpoint.back()))) {
    endpoint.pop_back();
  }
  ASSERT_FALSE(endpoint.empty()) << readAll(dir / "server.log");

  auto writeCase = [&](const std::string& name, const fs::path& key) {
    std::string text = readAll(restartCase / "case.yaml");
    text.replace(text.find("  end: 0.1"), 10, "  end: 0.01"); // 20 steps
    text.replace(text.find("dem:\n"), 5,
                 "dem:\n  endpoint: " + endpoint + "\n  server_key: " + key.string() + "\n");
    text.replace(text.find("  timeout_s: 20"), 15, "  timeout_s: 5");
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "case.yaml") << text;
  };
  writeCase("good", dir / "keys" / "server.public");
  writeCase("bad", dir / "other" / "server.public");

  EXPECT_EQ(runCoredem({"run", (dir / "good").string(), "--out", (dir / "run-good").string(),
                        "--no-plots"},
                       dir / "good.log"),
            0)
      << readAll(dir / "good.log") << readAll(dir / "server.log");
  EXPECT_TRUE(fs::exists(dir / "run-good/checkpoints/00000020/manifest.json"));

  EXPECT_EQ(runCoredem({"run", (dir / "bad").string(), "--out", (dir / "run-bad").string()},
                       dir / "bad.log"),
            1);
  const std::string log = readAll(dir / "bad.log");
  EXPECT_NE(log.find("DEM server coredem-dem: no Welcome from " + endpoint), std::string::npos)
      << log;
  EXPECT_NE(log.find("CURVE"), std::string::npos) << log;
  ::kill(server, SIGTERM);
  int status = 0;
  ::waitpid(server, &status, 0);
}

// SIGTERM mid-run (as a batch scheduler sends it): coredem finishes the CFD step in flight,
// writes a checkpoint, stops both participants and exits 130; `coredem resume` continues and
// ends in the same state as an uninterrupted run (bitwise DEM datasets), with one timeseries
// row per step.
TEST_F(CoredemE2E, SigtermCheckpointsAndResumeMatches) {
  const fs::path a = dir / "straight", k = dir / "term";
  ASSERT_EQ(
      runCoredem({"run", restartCase.string(), "--out", a.string(), "--no-plots"}, dir / "a.log"),
      0)
      << readAll(dir / "a.log");
  const pid_t o =
      startCoredem({"run", restartCase.string(), "--out", k.string(), "--no-plots"}, dir / "k.log");
  const auto end = std::chrono::steady_clock::now() + 40s;
  std::vector<pid_t> children;
  while (std::chrono::steady_clock::now() < end && children.empty()) {
    if (fs::exists(k / "checkpoints/00000040/manifest.json")) {
      children = childrenNamed(o, "coredem-dem");
      const auto gases = childrenNamed(o, "coredem-gas");
      children.insert(children.end(), gases.begin(), gases.end());
      ASSERT_EQ(children.size(), 2u);
      ::kill(o, SIGTERM);
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_FALSE(children.empty()) << "never saw checkpoint 40";
  ASSERT_EQ(waitExit(o, 50s), 130) << readAll(dir / "k.log");
  const std::string log = readAll(dir / "k.log");
  std::smatch m;
  const std::regex re("stopped after step ([0-9]+) with checkpoint");
  ASSERT_TRUE(std::regex_search(log, m, re)) << log;
  const int stopped = std::stoi(m[1].str());
  // The signal comes right after checkpoint 40: when coredem sees it before granting step 41
  // it stops at 40 (already checkpointed), else after the step in flight with a new checkpoint.
  EXPECT_GE(stopped, 40);
  EXPECT_LT(stopped, 200);
  char ck[64];
  std::snprintf(ck, sizeof ck, "checkpoints/%08d/manifest.json", stopped);
  EXPECT_TRUE(fs::exists(k / ck)) << log;
  EXPECT_NE(log.find("coredem resume " + k.string()), std::string::npos) << log;
  for (const pid_t c : children) {
    EXPECT_NE(::kill(c, 0), 0) << "participant " << c << " still runs";
  }
  EXPECT_TRUE(leftovers(k).empty());

  ASSERT_EQ(runCoredem({"resume", k.string(), "--no-plots"}, dir / "r.log"), 0)
      << readAll(dir / "r.log");
  expectSameDemState(demStateOf(a / finalCheckpoint), demStateOf(k / finalCheckpoint));
  const std::string ts = readAll(k / "timeseries.csv");
  EXPECT_EQ(std::count(ts.begin(), ts.end(), '\n'), 201);
}

// A run folder without a complete checkpoint (interrupted before the first one) is no dead
// end: `coredem run --out` on it points to `coredem resume`, which starts it again from step 0
// and ends in the same state as an uninterrupted run.
TEST_F(CoredemE2E, ResumeWithoutCheckpointStartsFromStepZero) {
  const fs::path a = dir / "straight", k = dir / "nock";
  ASSERT_EQ(
      runCoredem({"run", restartCase.string(), "--out", a.string(), "--no-plots"}, dir / "a.log"),
      0)
      << readAll(dir / "a.log");
  ASSERT_EQ(runCoredem({"run", restartCase.string(), "--out", k.string(), "--stop-after", "10",
                        "--no-plots"},
                       dir / "k1.log"),
            0)
      << readAll(dir / "k1.log");
  fs::remove_all(k / "checkpoints"); // as after an interrupt before the first checkpoint
  // `run` into the same folder: exit 2, naming resume and what it does without a checkpoint.
  EXPECT_EQ(
      runCoredem({"run", restartCase.string(), "--out", k.string(), "--no-plots"}, dir / "k2.log"),
      2);
  const std::string runLog = readAll(dir / "k2.log");
  EXPECT_NE(runLog.find("coredem resume " + k.string()), std::string::npos) << runLog;
  EXPECT_NE(runLog.find("from step 0 when it has none"), std::string::npos) << runLog;
  ASSERT_EQ(runCoredem({"resume", k.string(), "--no-plots"}, dir / "k3.log"), 0)
      << readAll(dir / "k3.log");
  const std::string resumeLog = readAll(dir / "k3.log");
  EXPECT_NE(resumeLog.find("no complete checkpoint; starting the run again from step 0"),
            std::string::npos)
      << resumeLog;
  expectSameDemState(demStateOf(a / finalCheckpoint), demStateOf(k / finalCheckpoint));
  const std::string ts = readAll(k / "timeseries.csv");
  EXPECT_EQ(std::count(ts.begin(), ts.end(), '\n'), 201);
  EXPECT_TRUE(fs::exists(k / "snapshots/particles_00000000.h5"));
}

// --walltime: a limit shorter than the reserve stops after the first step with a checkpoint
// (exit 0, the reason logged); resume finishes and matches an uninterrupted run. A generous
// limit does not stop the run.
TEST_F(CoredemE2E, WalltimeStopsWithCheckpoint) {
  const fs::path a = dir / "straight", w = dir / "wall";
  ASSERT_EQ(runCoredem({"run", restartCase.string(), "--out", a.string(), "--no-plots",
                        "--walltime", "100000"},
                       dir / "a.log"),
            0)
      << readAll(dir / "a.log");
  EXPECT_EQ(readAll(dir / "a.log").find("wall-time limit"), std::string::npos);
  EXPECT_TRUE(fs::exists(a / finalCheckpoint));
  ASSERT_EQ(runCoredem(
                {"run", restartCase.string(), "--out", w.string(), "--no-plots", "--walltime", "1"},
                dir / "w1.log"),
            0)
      << readAll(dir / "w1.log");
  const std::string log = readAll(dir / "w1.log");
  EXPECT_NE(log.find("stopped after step 1 "), std::string::npos) << log;
  EXPECT_NE(log.find("before the wall-time limit (--walltime 1 s)"), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(w / "checkpoints/00000001/manifest.json"));
  EXPECT_FALSE(fs::exists(w / finalCheckpoint));
  ASSERT_EQ(runCoredem({"resume", w.string(), "--no-plots"}, dir / "w2.log"), 0)
      << readAll(dir / "w2.log");
  expectSameDemState(demStateOf(a / finalCheckpoint), demStateOf(w / finalCheckpoint));
}

// A CFD participant killed by SIGFPE (a diverged solution) is reported with the step, its
// Δt_CFD, the last Courant number coredem-gas reported (0.2 m/s · 0.5 ms / 5 mm = 0.02) and a
// Δt to try; exit 1, the DEM server is stopped.
TEST_F(CoredemE2E, CfdSigfpeReportsCourantAndSuggestsDt) {
  const fs::path k = dir / "fpe";
  const pid_t o =
      startCoredem({"run", restartCase.string(), "--out", k.string(), "--no-plots"}, dir / "k.log");
  const auto end = std::chrono::steady_clock::now() + 40s;
  pid_t dem = 0;
  while (std::chrono::steady_clock::now() < end && !dem) {
    if (fs::exists(k / "checkpoints/00000020/manifest.json")) {
      const auto dems = childrenNamed(o, "coredem-dem");
      const auto gases = childrenNamed(o, "coredem-gas");
      ASSERT_EQ(dems.size(), 1u);
      ASSERT_EQ(gases.size(), 1u);
      dem = dems[0];
      ::kill(gases[0], SIGFPE);
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_NE(dem, 0) << "never saw checkpoint 20";
  EXPECT_EQ(waitExit(o, 50s), 1);
  const std::string log = readAll(dir / "k.log");
  EXPECT_NE(log.find("killed by signal 8 (SIGFPE); floating-point exception: the CFD solution "
                     "probably diverged in step"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("(dt_CFD = 0.0005 s; last reported Courant number 0.02). Try time.dt <= "
                     "0.00025 s"),
            std::string::npos)
      << log;
  EXPECT_NE(::kill(dem, 0), 0) << "coredem-dem (pid " << dem << ") still runs";
}

// `coredem check` on the command line: a pre-flight failure exits 2 with file:line:col and
// both values; a temperature in °C is a warning (exit 0).
TEST(CoredemCli, CheckPreflightFailsAndWarns) {
  const fs::path d = tempDir("check-preflight");
  const std::string text = readAll(kCases / "restart" / "case.yaml");
  auto write = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto pos = t.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    t.replace(pos, from.size(), to);
    fs::create_directories(d / "case");
    std::ofstream(d / "case" / "case.yaml") << t;
  };
  write("max: [0.0095, 0.0095, 0.014]", "max: [0.0095, 0.0095, 0.025]");
  EXPECT_EQ(runCoredem({"check", (d / "case").string()}, d / "log1", 30s), 2);
  const std::string l1 = readAll(d / "log1");
  EXPECT_NE(l1.find("case.yaml:24:13: particles[0].region: particles[0] (beads): the particle "
                    "region is"),
            std::string::npos)
      << l1;
  EXPECT_NE(l1.find("(z = 0.025 m > 0.02 m)"), std::string::npos) << l1;
  write("temperature: 300.0", "temperature: 27.0");
  EXPECT_EQ(runCoredem({"check", (d / "case").string()}, d / "log2", 30s), 0);
  const std::string l2 = readAll(d / "log2");
  EXPECT_NE(l2.find("particles[0].temperature: 27 K is below 200 K: °C given?"), std::string::npos)
      << l2;
  fs::remove_all(d);
}
