// End-to-end tests of `coredem campaign` with `executor: slurm` (docs/campaigns.md "Campaigns
// on Slurm") against a real single-node Slurm started by each test (local-slurm.sh): a 4-member
// sweep completes as a job array; a member stopped by its 1-minute time limit writes a
// checkpoint, requeues its task and resumes to the end; `scancel` of a running member followed
// by `campaign resume` completes it. Every member ends exactly once (database and timeseries).
// Sweep-file errors of the slurm section and a missing sbatch are refused before anything is
// written (these need no Slurm).
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "campaign_e2e.h"
#include "coredem_e2e.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_SLURM_CASES;
const fs::path kLocalSlurm = COREDEM_LOCAL_SLURM;

using coredem::e2e::readAll;
using coredem::e2e::waitExit;

pid_t start(const std::vector<std::string>& args, const fs::path& log) {
  return coredem::e2e::startProgram(kBin / "coredem", args, log);
}

int runCoredem(const std::vector<std::string>& args, const fs::path& log,
               std::chrono::seconds timeout = 60s) {
  return waitExit(start(args, log), timeout);
}

using Row = coredem::e2e::MemberRow;
using coredem::e2e::countEvents;
using coredem::e2e::eventsOf;
using coredem::e2e::stepsOf;

std::map<std::string, Row> readDb(const fs::path& dir) {
  return coredem::e2e::readCampaignDb(dir);
}

/// Every member done exactly once with a Slurm task id (campaign_e2e.h).
void expectAllDoneOnce(const fs::path& dir, std::size_t members, long steps) {
  coredem::e2e::expectAllDoneOnce(dir, members, steps, [](const std::string& id, const Row& r) {
    EXPECT_NE(r.jobId.find('_'), std::string::npos) << id << ": job id '" << r.jobId << "'";
  });
}

/// Runs a command line through sh; returns its exit code and output.
std::pair<int, std::string> shell(const std::string& cmd, const fs::path& out) {
  const int rc = std::system((cmd + " >'" + out.string() + "' 2>&1").c_str());
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, readAll(out)};
}

/// A private single-node Slurm in the test's folder for the duration of one test; the tests
/// fail, saying why, where it cannot run (not root, packages missing: the slurm test group is
/// then opted out with -DCOREDEM_TEST_OPT_OUT=slurm) and with the daemons' logs where it should
/// run but does not come up.
class SlurmCampaignE2E : public coredem::e2e::RunFolderTest {
protected:
  SlurmCampaignE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredem-gas"}, "coredem-slurm") {}

  void SetUp() override {
    RunFolderTest::SetUp();
    if (HasFatalFailure()) {
      return;
    }
    // short: slurmstepd's socket paths under the spool folder must stay under 108 bytes
    char tmpl[] = "/tmp/coredem-slurm.XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    _slurmDir = tmpl;
    const auto [rc, out] = shell("'" + kLocalSlurm.string() + "' start '" + _slurmDir.string() +
                                     "' " + std::to_string(::getpid()),
                                 dir / "local-slurm.txt");
    ASSERT_NE(rc, 77) << "no Slurm here: " << out
                      << "(the slurm test group needs root, slurm-wlm and munge: run the tests as "
                         "root, or configure with -DCOREDEM_TEST_OPT_OUT=slurm)";
    _started = true;
    ASSERT_EQ(rc, 0) << "the test's Slurm did not start:\n" << out;
    ::setenv("SLURM_CONF", (_slurmDir / "slurm.conf").c_str(), 1);
    ::setenv("COREDEM_CAMPAIGN_POLL_S", "1", 1);
  }

  void TearDown() override {
    if (_started) {
      ::unsetenv("SLURM_CONF");
      shell("'" + kLocalSlurm.string() + "' stop '" + _slurmDir.string() + "'",
            dir / "local-slurm-stop.txt");
      if (HasFailure()) { // the daemons' logs, kept with the test folder
        std::error_code ec;
        fs::copy(_slurmDir, dir / "slurm", fs::copy_options::recursive, ec);
      }
    }
    if (!_slurmDir.empty()) {
      std::error_code ec;
      fs::remove_all(_slurmDir, ec);
    }
    RunFolderTest::TearDown();
  }

  /// Waits until member `id` runs (its coredem pid recorded) with a complete checkpoint.
  Row waitRunningWithCheckpoint(const fs::path& campaign, const std::string& id) {
    const auto deadline = std::chrono::steady_clock::now() + 60s;
    while (std::chrono::steady_clock::now() < deadline) {
      const auto rows = readDb(campaign);
      if (rows.count(id) && rows.at(id).status == "running" && rows.at(id).pid > 0) {
        std::error_code ec;
        for (const auto& e :
             fs::directory_iterator(campaign / "members" / id / "run" / "checkpoints", ec)) {
          if (fs::exists(e.path() / "manifest.json")) {
            return rows.at(id);
          }
        }
      }
      std::this_thread::sleep_for(50ms);
    }
    ADD_FAILURE() << id << " never ran with a checkpoint";
    return {};
  }

  fs::path _slurmDir;
  bool _started = false;
};

} // namespace

TEST_F(SlurmCampaignE2E, FourMemberSweepCompletesAsJobArray) {
  const fs::path c = dir / "c";
  ASSERT_EQ(runCoredem({"campaign", "run", (kCases / "grid4.yaml").string(), "--out", c.string()},
                       dir / "log.txt", 120s),
            0)
      << readAll(dir / "log.txt");
  expectAllDoneOnce(c, 4, 40);
  const auto rows = readDb(c);
  // one array: the task ids are the member indices of one job
  const std::string job = rows.at("m000").jobId.substr(0, rows.at("m000").jobId.find('_'));
  for (int i = 0; i < 4; ++i) {
    const std::string id = "m00" + std::to_string(i);
    EXPECT_EQ(rows.at(id).jobId, job + "_" + std::to_string(i));
    EXPECT_EQ(rows.at(id).attempts, 1) << id;
  }
  EXPECT_NE(readAll(dir / "log.txt").find("submitted Slurm job " + job + ": array tasks 0,1,2,3"),
            std::string::npos)
      << readAll(dir / "log.txt");
  // the sbatch script and the task logs
  EXPECT_NE(readAll(c / "slurm" / "member.sh").find("campaign member"), std::string::npos);
  EXPECT_NE(readAll(c / "slurm" / "logs" / (job + "_3.out")).find("member m003: done"),
            std::string::npos);
  // status shows the tasks; collect works as for the local executor
  ASSERT_EQ(runCoredem({"campaign", "status", c.string()}, dir / "status.txt"), 0);
  const std::string st = readAll(dir / "status.txt");
  EXPECT_NE(st.find("executor slurm"), std::string::npos) << st;
  EXPECT_NE(st.find(job + "_2"), std::string::npos) << st;
  EXPECT_NE(st.find("4 members: 4 done"), std::string::npos) << st;
  ASSERT_EQ(runCoredem({"campaign", "status", c.string(), "--json"}, dir / "status.json"), 0);
  EXPECT_NE(readAll(dir / "status.json").find("\"job_id\": \"" + job + "_1\""), std::string::npos)
      << readAll(dir / "status.json");
  ASSERT_EQ(runCoredem({"campaign", "collect", c.string(), "--no-plot"}, dir / "collect.txt"), 0);
  std::istringstream summary(readAll(c / "summary.csv"));
  std::string line;
  int lines = 0;
  while (std::getline(summary, line)) {
    ++lines;
    EXPECT_EQ(line.find(",,"), std::string::npos) << line; // every scalar present
  }
  EXPECT_EQ(lines, 5);
}

TEST_F(SlurmCampaignE2E, MemberStoppedByTimeLimitCheckpointsRequeuesAndResumes) {
  // One member under a 1-minute limit with stop_margin 40: it stops after 20 s of wall time or
  // on Slurm's SIGTERM (sbatch --signal=B:TERM@20), whichever comes first. Freezing its coredem
  // once it has a checkpoint makes sure it cannot finish first on a fast machine: then the
  // SIGTERM (forwarded with SIGCONT by campaign member) stops it.
  const fs::path c = dir / "c";
  const pid_t campaign =
      start({"campaign", "run", (kCases / "timelimit.yaml").string(), "--out", c.string()},
            dir / "log.txt");
  const Row first = waitRunningWithCheckpoint(c, "m000");
  ASSERT_GT(first.pid, 0) << readAll(dir / "log.txt");
  ::kill(static_cast<pid_t>(first.pid), SIGSTOP);
  ASSERT_EQ(waitExit(campaign, 200s), 0) << readAll(dir / "log.txt");
  expectAllDoneOnce(c, 1, 2000);
  const Row r = readDb(c).at("m000");
  EXPECT_GE(r.attempts, 2) << eventsOf(r);
  EXPECT_EQ(r.failures, 0) << eventsOf(r);
  EXPECT_GE(countEvents(r, "stopped"), 1) << eventsOf(r);
  EXPECT_GE(countEvents(r, "requeued"), 1) << eventsOf(r);
  // requeued, not resubmitted: the same array task throughout
  EXPECT_EQ(countEvents(r, "submitted"), 1) << eventsOf(r);
  // the second attempt continued from the checkpoint
  const std::string log = readAll(c / "members" / "m000" / "coredem.log");
  EXPECT_NE(log.find("=== campaign attempt 2"), std::string::npos) << log;
  EXPECT_NE(log.substr(log.find("=== campaign attempt 2")).find(": coredem resume"),
            std::string::npos)
      << log;
}

TEST_F(SlurmCampaignE2E, MemberStoppedByItsWalltimeBeforeTheLimitRequeuesAndResumes) {
  // The usual path: the member's own --walltime (time left - stop_margin, about 15 s here)
  // stops it with a checkpoint and exit code 0 before Slurm has to signal anything; campaign
  // member sees that the run did not reach its end, records it stopped (not done) and
  // requeues the task. The test freezes the member's coredem for 8 s (a longer silence ends
  // the participants' session) to pass the wall time on any machine.
  const fs::path c = dir / "c";
  const pid_t campaign =
      start({"campaign", "run", (kCases / "walltime.yaml").string(), "--out", c.string()},
            dir / "log.txt");
  const Row first = waitRunningWithCheckpoint(c, "m000");
  ASSERT_GT(first.pid, 0) << readAll(dir / "log.txt");
  ::kill(static_cast<pid_t>(first.pid), SIGSTOP);
  std::this_thread::sleep_for(8s);
  ::kill(static_cast<pid_t>(first.pid), SIGCONT);
  ASSERT_EQ(waitExit(campaign, 150s), 0) << readAll(dir / "log.txt");
  expectAllDoneOnce(c, 1, 2000);
  const Row r = readDb(c).at("m000");
  // each attempt runs about 10 s (the wall time less coredem's reserve), so a slow machine
  // may need more than two; every stop is requeued
  EXPECT_GE(r.attempts, 2) << eventsOf(r);
  EXPECT_EQ(r.failures, 0) << eventsOf(r);
  EXPECT_EQ(countEvents(r, "stopped"), r.attempts - 1) << eventsOf(r);
  EXPECT_EQ(countEvents(r, "requeued"), r.attempts - 1) << eventsOf(r);
  EXPECT_EQ(countEvents(r, "submitted"), 1) << eventsOf(r);
  bool walltimeStop = false;
  for (const auto& e : r.events) {
    walltimeStop = walltimeStop || e.find("stopped: stopped 105 s before its time limit") == 0;
  }
  EXPECT_TRUE(walltimeStop) << eventsOf(r);
  const std::string log = readAll(c / "members" / "m000" / "coredem.log");
  EXPECT_NE(log.find("before the wall-time limit"), std::string::npos) << log;
  EXPECT_NE(log.substr(log.find("=== campaign attempt 2")).find(": coredem resume"),
            std::string::npos)
      << log;
}

TEST_F(SlurmCampaignE2E, ScancelledMemberIsResubmittedByResumeAndCompletes) {
  const fs::path c = dir / "c";
  ASSERT_EQ(runCoredem({"campaign", "run", (kCases / "cancel.yaml").string(), "--out", c.string(),
                        "--no-wait"},
                       dir / "log.txt"),
            0)
      << readAll(dir / "log.txt");
  const Row running = waitRunningWithCheckpoint(c, "m000");
  ASSERT_FALSE(running.jobId.empty()) << readAll(dir / "log.txt");
  const auto [rc, out] = shell("scancel " + running.jobId, dir / "scancel.txt");
  ASSERT_EQ(rc, 0) << out;
  // wait until the task has left the queue
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline) {
    const auto [qrc, q] = shell("squeue -h -r -o %i", dir / "squeue.txt");
    if (qrc == 0 && q.find(running.jobId + "\n") == std::string::npos) {
      break;
    }
    std::this_thread::sleep_for(200ms);
  }
  const Row cancelled = readDb(c).at("m000");
  EXPECT_NE(cancelled.status, "done") << eventsOf(cancelled);
  EXPECT_EQ(cancelled.doneCount, 0);
  ASSERT_EQ(runCoredem({"campaign", "resume", c.string()}, dir / "resume.txt", 120s), 0)
      << readAll(dir / "resume.txt");
  expectAllDoneOnce(c, 2, 2000);
  const Row r = readDb(c).at("m000");
  EXPECT_EQ(r.attempts, 2) << eventsOf(r);
  EXPECT_EQ(r.failures, 0) << eventsOf(r);
  EXPECT_EQ(countEvents(r, "submitted"), 2) << eventsOf(r); // resubmitted by resume
  EXPECT_NE(r.jobId, running.jobId);
  EXPECT_EQ(countEvents(r, "stopped") + countEvents(r, "lost"), 1) << eventsOf(r);
  EXPECT_NE(readAll(dir / "resume.txt").find("submitted Slurm job"), std::string::npos);
  const std::string log = readAll(c / "members" / "m000" / "coredem.log");
  EXPECT_NE(log.substr(log.find("=== campaign attempt 2")).find(": coredem resume"),
            std::string::npos)
      << log;
}

TEST_F(SlurmCampaignE2E, MemberKilledWithItsTaskIsFoundLostAndResumed) {
  // As when a node dies: the task's `campaign member` process is killed (SIGKILL) before it
  // can record anything; Slurm then ends the task and its processes. The database still says
  // running; campaign resume sees the task gone, puts the member back to pending and
  // resubmits it, and it continues from its checkpoint.
  const fs::path c = dir / "c";
  ASSERT_EQ(runCoredem({"campaign", "run", (kCases / "cancel.yaml").string(), "--out", c.string(),
                        "--no-wait"},
                       dir / "log.txt"),
            0)
      << readAll(dir / "log.txt");
  const Row running = waitRunningWithCheckpoint(c, "m000");
  ASSERT_GT(running.pid, 0) << readAll(dir / "log.txt");
  // the member's coredem was started by `coredem campaign member` (its parent)
  const std::string stat = readAll("/proc/" + std::to_string(running.pid) + "/stat");
  std::istringstream rest(stat.substr(stat.rfind(')') + 2));
  char state = 0;
  pid_t member = 0;
  rest >> state >> member;
  ASSERT_GT(member, 1);
  ASSERT_NE(readAll("/proc/" + std::to_string(member) + "/cmdline").find("member"),
            std::string::npos);
  ::kill(member, SIGKILL);
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline) {
    const auto [qrc, q] = shell("squeue -h -r -o %i", dir / "squeue.txt");
    if (qrc == 0 && q.find(running.jobId + "\n") == std::string::npos) {
      break;
    }
    std::this_thread::sleep_for(200ms);
  }
  EXPECT_EQ(readDb(c).at("m000").status, "running"); // nobody could record the end
  ASSERT_EQ(runCoredem({"campaign", "resume", c.string()}, dir / "resume.txt", 120s), 0)
      << readAll(dir / "resume.txt");
  expectAllDoneOnce(c, 2, 2000);
  const Row r = readDb(c).at("m000");
  EXPECT_EQ(countEvents(r, "lost"), 1) << eventsOf(r);
  EXPECT_EQ(countEvents(r, "submitted"), 2) << eventsOf(r);
  EXPECT_EQ(r.failures, 0) << eventsOf(r);
  EXPECT_NE(r.exitReason, "");
}

// --- input errors (no Slurm needed)

TEST(SlurmCampaignInput, BadSlurmSectionsAreRefusedNamingTheKey) {
  const fs::path d = coredem::e2e::tempDir("coredem-slurm", "bad-sweeps");
  const std::string head =
      "name: bad\nbase_case: " + (kCases / "../../campaign/cases/tiny").string() + "\n";
  const std::string grid = "grid:\n  gas.T_g: [400.0]\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"executor: slurm\nslurm:\n  time: abc\n", "slurm.time"},
      {"executor: slurm\nslurm:\n  partiton: debug\n", "slurm.partiton"},
      {"executor: local\nslurm:\n  time: \"10\"\n", "needs 'executor: slurm'"},
      {"executor: slurm\nslurm:\n  time: \"1\"\n  stop_margin: 60\n", "slurm.stop_margin"},
      {"executor: slurm\nslurm:\n  cpus_per_task: 0\n", "slurm.cpus_per_task"},
      {"executor: slurm\nslurm:\n  extra: [--array=1-3]\n", "set by coredem campaign"},
      {"executor: slurm\nslurm:\n  extra: --qos=high\n", "slurm.extra"},
      {"executor: pbs\n", "allowed: local, slurm"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path sweep = d / ("bad" + std::to_string(i) + ".yaml");
    coredem::e2e::writeAll(sweep, head + cases[i].first + grid);
    const fs::path out = d / ("out" + std::to_string(i));
    EXPECT_EQ(runCoredem({"campaign", "run", sweep.string(), "--out", out.string()},
                         d / ("log" + std::to_string(i) + ".txt")),
              2)
        << cases[i].first;
    const std::string log = readAll(d / ("log" + std::to_string(i) + ".txt"));
    EXPECT_NE(log.find(cases[i].second), std::string::npos) << cases[i].first << log;
    EXPECT_NE(log.find(sweep.string() + ":"), std::string::npos) << log; // file:line:col
    EXPECT_FALSE(fs::exists(out)) << cases[i].first;
  }
  fs::remove_all(d);
}

TEST(SlurmCampaignInput, UnreachableSlurmIsNamedBeforeAnythingIsWritten) {
  // sbatch and squeue on PATH, but no cluster: squeue's own error is shown
  const fs::path d = coredem::e2e::tempDir("coredem-slurm", "no-cluster");
  fs::create_directories(d / "bin");
  for (const char* c : {"sbatch", "squeue", "scontrol", "scancel"}) {
    coredem::e2e::writeAll(d / "bin" / c, "#!/bin/sh\necho 'slurm_load_jobs error: Unable to "
                                          "contact slurm controller (connect failure)' >&2\n"
                                          "exit 1\n");
    fs::permissions(d / "bin" / c, fs::perms::owner_all);
  }
  coredem::SpawnOptions o;
  o.ownProcessGroup = false;
  o.env["PATH"] = (d / "bin").string();
  const int pid =
      coredem::spawnProcess("coredem",
                            {(kBin / "coredem").string(), "campaign", "run",
                             (kCases / "grid4.yaml").string(), "--out", (d / "c").string()},
                            d / "log.txt", o);
  EXPECT_EQ(waitExit(pid, 30s), 1);
  const std::string log = readAll(d / "log.txt");
  EXPECT_NE(log.find("Slurm does not answer here"), std::string::npos) << log;
  EXPECT_NE(log.find("Unable to contact slurm controller"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(d / "c"));
  fs::remove_all(d);
}

TEST(SlurmCampaignInput, MissingSbatchIsNamedBeforeAnythingIsWritten) {
  const fs::path d = coredem::e2e::tempDir("coredem-slurm", "no-sbatch");
  coredem::SpawnOptions o;
  o.ownProcessGroup = false;
  o.env["PATH"] = (d / "empty").string();
  const int pid =
      coredem::spawnProcess("coredem",
                            {(kBin / "coredem").string(), "campaign", "run",
                             (kCases / "grid4.yaml").string(), "--out", (d / "c").string()},
                            d / "log.txt", o);
  EXPECT_EQ(waitExit(pid, 30s), 1);
  const std::string log = readAll(d / "log.txt");
  EXPECT_NE(log.find("'sbatch' not found on PATH"), std::string::npos) << log;
  EXPECT_NE(log.find("slurm-client"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(d / "c"));
  fs::remove_all(d);
}
