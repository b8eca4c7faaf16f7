// `coredem campaign run|resume|status|collect` (campaign.h, docs/campaigns.md): the local
// executor runs every member as a child `coredem run` / `coredem resume` process, at most
// `concurrency` at once, and records every transition in DIR/campaign.db.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/common/version.h>
#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/campaign_db.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/sha256.h>

#include "campaign_impl.h"

namespace coredem::orchestrator {

namespace campaign_detail {

namespace fs = std::filesystem;

std::atomic<int> gSignal{0};
extern "C" void onCampaignSignal(int sig) {
  gSignal = sig;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path selfDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path() : exe.parent_path();
}

// Held for the life of the process: two campaign processes never work on one folder. The
// kernel drops it when the process dies (kill -9).
FolderLock::FolderLock(const fs::path& dir) {
  _fd = ::open((dir / "campaign.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  COREDEM_CHECK(_fd >= 0, "cannot create {}/campaign.lock", dir.string());
  COREDEM_CHECK(::flock(_fd, LOCK_EX | LOCK_NB) == 0,
                "another coredem campaign process is working on {} (wait for it, or stop it "
                "and run coredem campaign resume {})",
                dir.string(), dir.string());
}
FolderLock::~FolderLock() {
  ::close(_fd);
}

std::string newestCheckpointName(const fs::path& runDir) {
  std::string best;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(runDir / "checkpoints", ec)) {
    if (fs::exists(e.path() / "manifest.json") && e.path().filename().string() > best) {
      best = e.path().filename().string();
    }
  }
  return best;
}

std::string lastErrorLine(const fs::path& log) {
  const std::string text = readFile(log);
  const auto start = text.rfind("=== campaign attempt");
  std::istringstream in(start == std::string::npos ? text : text.substr(start));
  std::string line, err;
  while (std::getline(in, line)) {
    if (line.find("[error]") != std::string::npos) {
      err = line;
    }
  }
  const auto tag = err.find("[error] ");
  return tag == std::string::npos ? err : err.substr(tag + 8);
}

std::vector<std::string> memberCommand(const MemberRecord& m, std::string& how) {
  const fs::path runDir = m.runDir;
  std::vector<std::string> args{(selfDir() / "coredem").string()};
  if (selectResumeCheckpoint(runDir).dir) {
    args.insert(args.end(), {"resume", runDir.string(), "--no-plots"});
    how = "resume";
  } else {
    std::error_code ec;
    fs::remove_all(runDir, ec);
    args.insert(args.end(), {"run", m.caseDir, "--out", runDir.string(), "--no-plots"});
    how = "run";
  }
  return args;
}

std::string finishMember(CampaignDb& db, const std::string& id, const std::string& runDir,
                         int status, int retries) {
  auto log = logger("campaign");
  const auto m = db.member(id);
  const bool ok = status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (ok) {
    const ResumeChoice c = selectResumeCheckpoint(runDir);
    std::string ckpt, sw, proto;
    if (c.dir && c.manifest) {
      ckpt = c.dir->filename().string();
      sw = c.manifest->softwareVersion;
      proto = c.manifest->protocolVersion;
      if (m && c.manifest->configHash != m->caseHash) {
        log->warn("member {}: config hash {} of the run differs from the campaign's {}", id,
                  c.manifest->configHash, m->caseHash);
      }
    }
    db.transaction([&] {
      if (db.markDone(id, ckpt, sw, proto)) {
        db.addEvent(id, "done", ckpt);
      }
    });
    log->info("member {}: done", id);
    return "done";
  }
  std::string reason = status < 0 ? "lost track of the process" : describeWaitStatus(status);
  const std::string err =
      lastErrorLine(fs::path(m ? m->caseDir : "").parent_path() / "coredem.log");
  if (!err.empty()) {
    reason += ": " + err;
  }
  bool final = false;
  db.transaction([&] {
    db.markFailed(id, reason, retries);
    const auto after = db.member(id);
    final = after && after->status == "failed";
    db.addEvent(id, final ? "failed" : "retry", reason);
  });
  if (final) {
    log->error("member {} failed for good ({} attempts): {}", id, m ? m->failures + 1 : 0, reason);
  } else {
    log->warn("member {} failed ({}); it will be retried", id, reason);
  }
  return final ? "failed" : "pending";
}

} // namespace campaign_detail

namespace {

using namespace campaign_detail;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

/// True when `pid` is a live (not zombie) process whose command line mentions `runDir`.
bool memberProcessAlive(std::int64_t pid, const std::string& runDir) {
  if (pid <= 0 || ::kill(static_cast<pid_t>(pid), 0) != 0) {
    return false;
  }
  const fs::path proc = fs::path("/proc") / std::to_string(pid);
  const std::string stat = readFile(proc / "stat");
  const auto close = stat.rfind(')');
  if (close == std::string::npos || close + 2 >= stat.size() || stat[close + 2] == 'Z') {
    return false;
  }
  std::string cmd = readFile(proc / "cmdline");
  for (auto& c : cmd) {
    c = c == '\0' ? ' ' : c;
  }
  return cmd.find(runDir) != std::string::npos;
}

/// A live `coredem` process working on `runDir` (found through /proc), or 0. Covers the
/// moment between a member's start and the record of its pid.
std::int64_t findMemberProcess(const std::string& runDir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    const std::int64_t pid = std::stoll(name);
    if (pid != ::getpid() && readFile(e.path() / "comm") == "coredem\n" &&
        memberProcessAlive(pid, runDir)) {
      return pid;
    }
  }
  return 0;
}

// ---------------------------------------------------------------------------------------
// the local executor

class Runner {
public:
  Runner(fs::path dir, CampaignDb& db)
      : _dir(std::move(dir))
      , _db(db)
      , _log(logger("campaign")) {
    _concurrency = std::stoi(_db.setting("concurrency", "1"));
    _retries = std::stoi(_db.setting("retries", "0"));
  }

  /// Runs until every member is done or failed (or a signal arrives). Returns the exit code.
  int run() {
    adoptOrRelease();
    auto lastScan = std::chrono::steady_clock::now();
    while (true) {
      if (gSignal != 0) {
        return interrupt();
      }
      reap();
      startPending();
      if (_running.empty()) {
        break;
      }
      if (std::chrono::steady_clock::now() - lastScan > 1s) {
        lastScan = std::chrono::steady_clock::now();
        for (auto& [id, r] : _running) {
          const std::string c = newestCheckpointName(r.runDir);
          if (c != r.lastCheckpoint) {
            r.lastCheckpoint = c;
            _db.setLastCheckpoint(id, c);
          }
        }
      }
      std::this_thread::sleep_for(50ms);
    }
    int done = 0, failed = 0, total = 0;
    for (const auto& m : _db.members()) {
      ++total;
      done += m.status == "done";
      failed += m.status == "failed";
    }
    std::printf("campaign %s: %d of %d members done, %d failed; results: coredem campaign "
                "collect %s\n",
                _dir.string().c_str(), done, total, failed, _dir.string().c_str());
    return failed == 0 && done == total ? kOk : kFault;
  }

private:
  struct Running {
    std::int64_t pid = 0;
    bool adopted = false; ///< started by a previous campaign process: not our child
    fs::path runDir;
    std::string lastCheckpoint;
  };

  /// Members left 'running' by a campaign process that died: a member process that still
  /// runs is adopted (watched until it ends), the others go back to pending.
  void adoptOrRelease() {
    for (const auto& m : _db.members()) {
      if (m.status != "running") {
        continue;
      }
      const std::int64_t pid =
          memberProcessAlive(m.pid, m.runDir) ? m.pid : findMemberProcess(m.runDir);
      if (pid > 0) {
        _log->info("member {}: process {} of a previous campaign process still runs; waiting "
                   "for it",
                   m.id, pid);
        _running[m.id] = {pid, true, m.runDir, m.lastCheckpoint};
        continue;
      }
      _db.transaction([&] {
        if (_db.markInterrupted(m.id, "the campaign process ended while it ran")) {
          _db.addEvent(m.id, "interrupted", fmt::format("process {} gone", m.pid));
        }
      });
      _log->info("member {}: its process is gone; it continues from its last complete "
                 "checkpoint",
                 m.id);
    }
  }

  void startPending() {
    if (gSignal != 0 || static_cast<int>(_running.size()) >= _concurrency) {
      return;
    }
    for (const auto& m : _db.members()) {
      if (static_cast<int>(_running.size()) >= _concurrency) {
        return;
      }
      if (m.status == "pending" && !_running.count(m.id)) {
        start(m);
      }
    }
  }

  void start(const MemberRecord& m) {
    const fs::path runDir = m.runDir;
    std::string how;
    const std::vector<std::string> args = memberCommand(m, how);
    bool claimed = false;
    _db.transaction([&] {
      claimed = _db.markRunning(m.id, "pending");
      if (claimed) {
        _db.addEvent(m.id, "start", fmt::format("attempt {}: coredem {}", m.attempts + 1, how));
      }
    });
    if (!claimed) {
      return;
    }
    const fs::path log = fs::path(m.caseDir).parent_path() / "coredem.log";
    {
      std::ofstream out(log, std::ios::app);
      out << "=== campaign attempt " << m.attempts + 1 << " " << utcNow() << ": coredem " << how
          << "\n";
    }
    int pid = -1;
    try {
      pid = spawnProcess("campaign member " + m.id, args, log); // own process group
    } catch (const UserError& e) {
      const std::string reason = e.what();
      _db.transaction([&] {
        _db.markFailed(m.id, reason, _retries);
        _db.addEvent(m.id, "failed", reason);
      });
      return;
    }
    _db.setPid(m.id, pid);
    _log->info("member {}: coredem {} (pid {}, attempt {})", m.id, how, pid, m.attempts + 1);
    _running[m.id] = {pid, false, runDir, m.lastCheckpoint};
  }

  void reap() {
    for (auto it = _running.begin(); it != _running.end();) {
      const std::string id = it->first;
      Running& r = it->second;
      if (r.adopted) {
        if (memberProcessAlive(r.pid, r.runDir.string())) {
          ++it;
          continue;
        }
        // Its exit code is lost with the old campaign process: `coredem resume` finds out
        // (a finished run resumes to its end at once).
        _db.transaction([&] {
          if (_db.markInterrupted(id, "adopted process ended")) {
            _db.addEvent(id, "interrupted", "adopted process ended; continues with resume");
          }
        });
        it = _running.erase(it);
        continue;
      }
      int status = 0;
      const pid_t w = ::waitpid(static_cast<pid_t>(r.pid), &status, WNOHANG);
      if (w == 0) {
        ++it;
        continue;
      }
      finish(id, r, w < 0 ? -1 : status);
      it = _running.erase(it);
    }
  }

  void finish(const std::string& id, const Running& r, int status) {
    finishMember(_db, id, r.runDir.string(), status, _retries);
  }

  /// SIGINT/SIGTERM: stop our members (they stop at a step and stay resumable), record them
  /// as pending, exit 130.
  int interrupt() {
    _log->warn("signal {}: stopping the running members", gSignal.load());
    for (auto& [id, r] : _running) {
      if (!r.adopted) {
        ::kill(-static_cast<pid_t>(r.pid), SIGTERM);
      }
    }
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    for (auto& [id, r] : _running) {
      if (r.adopted) {
        continue;
      }
      int status = 0;
      while (::waitpid(static_cast<pid_t>(r.pid), &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() > deadline) {
          ::kill(-static_cast<pid_t>(r.pid), SIGKILL);
          ::waitpid(static_cast<pid_t>(r.pid), &status, 0);
          break;
        }
        std::this_thread::sleep_for(50ms);
      }
      _db.transaction([&] {
        if (_db.markInterrupted(id, "campaign interrupted")) {
          _db.addEvent(id, "interrupted", "campaign interrupted");
        }
      });
    }
    std::printf("campaign interrupted; continue with: coredem campaign resume %s\n",
                _dir.string().c_str());
    return kInterrupted;
  }

  fs::path _dir;
  CampaignDb& _db;
  std::shared_ptr<spdlog::logger> _log;
  int _concurrency = 1;
  int _retries = 0;
  std::map<std::string, Running> _running;
};

// ---------------------------------------------------------------------------------------
// commands

/// Creates DIR with one case folder per member and DIR/campaign.db (built as a temp file and
/// renamed, so a crash during set-up leaves no half campaign).
void createCampaign(const Sweep& sw, const fs::path& dir) {
  COREDEM_CHECK(!fs::exists(dir / "campaign.db"),
                "{} already holds a campaign; continue it with coredem campaign resume {} or "
                "choose another --out",
                dir.string(), dir.string());
  fs::create_directories(dir / "members");
  writeFileAtomic(dir / "sweep.yaml", sw.text);
  const fs::path tmp = dir / "campaign.db.tmp";
  fs::remove(tmp);
  fs::remove(dir / "campaign.db.tmp-wal");
  fs::remove(dir / "campaign.db.tmp-shm");
  {
    CampaignDb db(tmp, true);
    db.createSchema();
    db.transaction([&] {
      db.setSetting("name", sw.name);
      db.setSetting("sweep_file", sw.file.string());
      db.setSetting("base_case", sw.baseCase.string());
      db.setSetting("executor", sw.executor);
      db.setSetting("concurrency", std::to_string(sw.concurrency));
      db.setSetting("retries", std::to_string(sw.retries));
      if (sw.executor == "slurm") {
        const SlurmOptions& o = sw.slurm;
        db.setSetting("slurm.partition", o.partition);
        db.setSetting("slurm.time", o.time);
        db.setSetting("slurm.time_seconds", std::to_string(o.timeSeconds));
        db.setSetting("slurm.cpus_per_task", std::to_string(o.cpusPerTask));
        db.setSetting("slurm.gres", o.gres);
        db.setSetting("slurm.mem", o.mem);
        db.setSetting("slurm.max_concurrent",
                      std::to_string(o.maxConcurrent > 0 ? o.maxConcurrent : sw.concurrency));
        db.setSetting("slurm.stop_margin", std::to_string(o.stopMargin));
        db.setSetting("slurm.extra", fmt::format("{}", fmt::join(o.extra, "\n")));
      }
      db.setSetting("software_version", kVersion);
      db.setSetting("created", utcNow());
      std::string scalars;
      for (const auto& s : sw.scalars) {
        scalars += (scalars.empty() ? "" : "\n") + s.label();
      }
      db.setSetting("scalars", scalars);
      db.setSetting("plot_x", sw.plotX);
      db.setSetting("plot_y", sw.plotY);
      std::string units;
      for (const auto& [key, unit] : sw.units) {
        units += (units.empty() ? "" : "\n") + key + "=" + unit;
      }
      db.setSetting("units", units);
      for (std::size_t i = 0; i < sw.members.size(); ++i) {
        const auto& mem = sw.members[i];
        const fs::path mdir = dir / "members" / mem.id;
        const fs::path caseDir = mdir / "case";
        fs::remove_all(mdir);
        fs::create_directories(caseDir);
        // the base case's other files (initial_state, cfd.case, ...) as links
        for (const auto& e : fs::directory_iterator(sw.baseCase)) {
          if (e.path().filename() != "case.yaml") {
            fs::create_symlink(e.path(), caseDir / e.path().filename());
          }
        }
        const std::string& text = sw.resolvedCases[i];
        writeFileAtomic(caseDir / "case.yaml", text);
        MemberRecord rec;
        rec.id = mem.id;
        rec.index = static_cast<int>(i);
        rec.caseDir = caseDir.string();
        rec.runDir = (mdir / "run").string();
        rec.caseHash = sha256Hex(text);
        rec.values = mem.values;
        db.addMember(rec);
        db.addEvent(mem.id, "created", "");
      }
    });
    db.transaction([&] { db.addEvent("", "campaign created", sw.file.string()); });
  }
  // fold the WAL into the file before the rename (a -wal file must follow its database)
  {
    CampaignDb db(tmp, false);
    db.setSetting("state", "ready");
  }
  fs::remove(dir / "campaign.db.tmp-wal");
  fs::remove(dir / "campaign.db.tmp-shm");
  fs::rename(tmp, dir / "campaign.db");
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

int runCampaign(const fs::path& dir, bool retryFailed, bool wait) {
  FolderLock lock(dir);
  CampaignDb db(dir / "campaign.db", false);
  if (retryFailed) {
    for (const auto& m : db.members()) {
      if (m.status == "failed") {
        db.transaction([&] {
          if (db.resetFailed(m.id)) {
            db.addEvent(m.id, "retry", "resume --retry-failed");
          }
        });
      }
    }
  }
  std::signal(SIGINT, onCampaignSignal);
  std::signal(SIGTERM, onCampaignSignal);
  if (db.setting("executor", "local") == "slurm") {
    checkSlurmCommands();
    return runSlurmCampaign(dir, db, wait);
  }
  Runner runner(dir, db);
  return runner.run();
}

} // namespace

int campaignMain(int argc, char** argv) {
  CLI::App app{"coredem campaign: parameter sweeps of coredem runs that survive crashes "
               "(docs/campaigns.md)"};
  app.require_subcommand(1);
  std::string sweep, out, dir;
  bool json = false, retryFailed = false, noPlot = false, noWait = false;
  int index = -1;
  auto* run = app.add_subcommand("run", "create a campaign from SWEEP.yaml in DIR and run it");
  run->add_option("SWEEP", sweep, "sweep file")->required();
  run->add_option("--out", out, "campaign folder (must not hold a campaign)")->required();
  run->add_flag("--no-wait", noWait,
                "executor slurm: submit and return (follow with status, continue with resume)");
  auto* resume = app.add_subcommand("resume", "continue a campaign after any crash");
  resume->add_option("DIR", dir, "campaign folder")->required();
  resume->add_flag("--retry-failed", retryFailed,
                   "give members that failed for good another round of attempts");
  resume->add_flag("--no-wait", noWait, "executor slurm: (re)submit and return");
  auto* st = app.add_subcommand("status", "print the members' state");
  st->add_option("DIR", dir, "campaign folder")->required();
  st->add_flag("--json", json, "as JSON");
  auto* col = app.add_subcommand("collect", "write DIR/summary.csv and DIR/plots/campaign.png");
  col->add_option("DIR", dir, "campaign folder")->required();
  col->add_flag("--no-plot", noPlot, "summary.csv only");
  CollectWindow window;
  auto* fromOpt = col->add_option("--from", window.from,
                                  "window start in s for every max/min/mean scalar without a "
                                  "window of its own (exclude the start-up transient)");
  auto* toOpt = col->add_option("--to", window.to, "window end in s (as --from)");
  auto* mem = app.add_subcommand(
      "member", "run one member inside its Slurm array task (called by DIR/slurm/member.sh)");
  mem->add_option("DIR", dir, "campaign folder")->required();
  mem->add_option("--index", index, "member index (the array task id)")
      ->required()
      ->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kOk : kBadInput;
  }
  auto log = logger("campaign");
  try {
    if (*run) {
      const Sweep sw = loadSweep(sweep); // throws CaseError: nothing written
      if (sw.executor == "slurm") {
        checkSlurmCommands(); // before anything is written
      }
      const fs::path d = fs::absolute(out);
      createCampaign(sw, d);
      log->info("campaign {}: {} members in {}", sw.name, sw.members.size(), d.string());
      return runCampaign(d, false, !noWait);
    }
    if (*resume) {
      return runCampaign(fs::absolute(dir), retryFailed, !noWait);
    }
    if (*mem) {
      return slurmMemberMain(fs::absolute(dir), index);
    }
    if (*st) {
      return status(fs::absolute(dir), json);
    }
    window.hasFrom = fromOpt->count() > 0;
    window.hasTo = toOpt->count() > 0;
    return collect(fs::absolute(dir), noPlot, window);
  } catch (const CaseError& e) {
    log->error("{}", e.what());
    return kBadInput;
  } catch (const UserError& e) {
    log->error("{}", e.what());
    return kFault;
  } catch (const std::exception& e) {
    log->error("internal error: {}", e.what());
    return kFault;
  }
}

} // namespace coredem::orchestrator
