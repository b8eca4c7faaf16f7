// The Slurm executor of `coredem campaign` (docs/campaigns.md "Campaigns on Slurm"): one job
// array per submission round whose task ids are the member indices; every task runs
// `coredem campaign member DIR --index I`, which claims the member in DIR/campaign.db, runs
// `coredem run`/`coredem resume` with a wall-time limit just under the task's time limit,
// records the outcome and requeues its own task when the member stopped early (time limit,
// preemption) or failed within its retries. `campaign run`/`resume` reconcile the database with
// squeue: a member recorded running whose task is gone goes back to pending and is
// resubmitted; it continues from its last complete checkpoint.
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/campaign_db.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/time_handler.h>

#include "campaign_impl.h"

namespace coredem::orchestrator::campaign_detail {

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

struct Captured {
  int rc = -1; ///< exit code; -1 when it could not run or was killed
  std::string out, err;
};

/// Runs `argv` (argv[0] looked up on PATH) with stdin from /dev/null and returns its exit code,
/// stdout and stderr. The Slurm client commands answer within their MessageTimeout.
Captured capture(const std::vector<std::string>& argv) {
  Captured c;
  int outPipe[2], errPipe[2];
  if (::pipe2(outPipe, O_CLOEXEC) != 0) {
    c.err = std::strerror(errno);
    return c;
  }
  if (::pipe2(errPipe, O_CLOEXEC) != 0) {
    ::close(outPipe[0]);
    ::close(outPipe[1]);
    c.err = std::strerror(errno);
    return c;
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_RDONLY);
    ::dup2(devnull, 0);
    ::dup2(outPipe[1], 1);
    ::dup2(errPipe[1], 2);
    std::vector<char*> args;
    for (const auto& a : argv) {
      args.push_back(const_cast<char*>(a.c_str()));
    }
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    std::fprintf(stderr, "cannot run %s: %s\n", args[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  if (pid < 0) {
    ::close(outPipe[0]);
    ::close(errPipe[0]);
    c.err = std::strerror(errno);
    return c;
  }
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  int open = 2;
  char buf[4096];
  while (open > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) {
        continue;
      }
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd >= 0 && (fds[i].revents & (POLLIN | POLLHUP | POLLERR))) {
        const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
        if (n > 0) {
          (i == 0 ? c.out : c.err).append(buf, static_cast<std::size_t>(n));
        } else if (n == 0 || errno != EINTR) {
          ::close(fds[i].fd);
          fds[i].fd = -1;
          --open;
        }
      }
    }
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  c.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return c;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) {
    s.pop_back();
  }
  std::size_t b = 0;
  while (b < s.size() && std::isspace(static_cast<unsigned char>(s[b]))) {
    ++b;
  }
  return s.substr(b);
}

std::string firstLine(const std::string& s) {
  return trim(s.substr(0, s.find('\n')));
}

fs::path onPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  std::string d;
  while (std::getline(ss, d, ':')) {
    const fs::path p = fs::path(d.empty() ? "." : d) / name;
    if (::access(p.c_str(), X_OK) == 0) {
      return p;
    }
  }
  return {};
}

/// Single-quoted for sh.
std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return q + "'";
}

/// "1234_5" of this process's Slurm task ("" outside Slurm).
std::string ownTaskId() {
  const char* array = std::getenv("SLURM_ARRAY_JOB_ID");
  const char* task = std::getenv("SLURM_ARRAY_TASK_ID");
  if (array && task && *array && *task) {
    return std::string(array) + "_" + task;
  }
  const char* job = std::getenv("SLURM_JOB_ID");
  return job ? job : "";
}

/// Why a task that squeue no longer lists ended, from scontrol (Slurm keeps finished jobs for
/// MinJobAge) or sacct (where accounting is on); "" when neither knows.
std::string endedTaskState(const std::string& task) {
  const Captured s = capture({"scontrol", "-o", "show", "job", task});
  if (s.rc == 0) {
    const auto at = s.out.find("JobState=");
    if (at != std::string::npos) {
      return s.out.substr(at + 9, s.out.find(' ', at) - at - 9);
    }
  }
  const Captured a = capture({"sacct", "-n", "-X", "-P", "-o", "State", "-j", task});
  return a.rc == 0 ? firstLine(a.out) : "";
}

/// Slurm's remaining time of job `job` in seconds (squeue %L), or nullopt.
std::optional<long> timeLeft(const std::string& job) {
  const Captured c = capture({"squeue", "-h", "-j", job, "-o", "%L"});
  if (c.rc != 0) {
    return std::nullopt;
  }
  return parseSlurmTime(firstLine(c.out));
}

/// Starts the member's `coredem` in a process group of its own with stdout and stderr appended
/// to `log`. It dies with this process (PR_SET_PDEATHSIG): where the task's processes are
/// tracked by parent pid (proctrack/linuxproc), a killed `campaign member` must not leave a
/// `coredem` behind that works on the run folder while the member is resubmitted.
int spawnTied(const std::vector<std::string>& argv, const fs::path& log) {
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  COREDEM_CHECK(pid >= 0, "cannot start {}: {}", argv[0], std::strerror(errno));
  if (pid == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) {
      ::_exit(127);
    }
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (in < 0 || out < 0) {
      ::_exit(127);
    }
    ::dup2(in, 0);
    ::dup2(out, 1);
    ::dup2(out, 2);
    std::vector<char*> args;
    for (const auto& a : argv) {
      args.push_back(const_cast<char*>(a.c_str()));
    }
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    std::fprintf(stderr, "cannot run %s: %s\n", args[0], std::strerror(errno));
    ::_exit(127);
  }
  return pid;
}

/// True when the run folder's newest complete checkpoint is at the case's end time (a run
/// always writes one at its last step). `coredem run --walltime` exits 0 also when it stopped
/// early, so the exit code alone does not say that a member is done.
bool runReachedEnd(const fs::path& runDir, const fs::path& caseDir) {
  try {
    const ResumeChoice c = selectResumeCheckpoint(runDir);
    if (!c.dir || !c.manifest) {
      return false;
    }
    const double end = loadCase(caseDir).endTime; // the member case = the run's case
    return c.manifest->time >= end || timeEquals(c.manifest->time, end);
  } catch (const std::exception&) {
    return false;
  }
}

fs::path memberScript(const fs::path& dir) {
  return dir / "slurm" / "member.sh";
}

void writeMemberScript(const fs::path& dir) {
  fs::create_directories(dir / "slurm" / "logs");
  const std::string text =
      "#!/bin/sh\n"
      "# written by coredem campaign: one member of the campaign in " +
      dir.string() +
      " per array task (the task id is the member index).\n"
      "# Slurm sends SIGTERM to this process (sbatch --signal=B:TERM@<stop_margin>) before the\n"
      "# time limit; coredem campaign member then stops the member with a checkpoint and\n"
      "# requeues the task.\n"
      "exec " +
      shellQuote((selfDir() / "coredem").string()) + " campaign member " +
      shellQuote(dir.string()) + " --index \"$SLURM_ARRAY_TASK_ID\"\n";
  writeFileAtomic(memberScript(dir), text);
  ::chmod(memberScript(dir).c_str(), 0755);
}

/// Submits one job array over `members` (their indices are the task ids). Records the task of
/// every member that is still pending. Returns the job id.
std::string submit(const fs::path& dir, CampaignDb& db, const std::vector<MemberRecord>& members) {
  std::string indices;
  for (const auto& m : members) {
    indices += (indices.empty() ? "" : ",") + std::to_string(m.index);
  }
  const int maxConcurrent = std::stoi(db.setting("slurm.max_concurrent", "1"));
  std::vector<std::string> args{
      "sbatch", "--parsable", fmt::format("--array={}%{}", indices, maxConcurrent),
      "--job-name=coredem-" + db.setting("name"),
      "--output=" + (dir / "slurm" / "logs" / "%A_%a.out").string(), "--open-mode=append",
      "--chdir=" + dir.string(), "--requeue",
      // the last call: SIGTERM to member.sh's process half the stop margin before the limit,
      // for when the member's own wall-time stop did not come first (Slurm sends it up to a
      // minute early; its time limit may have been changed after the start)
      fmt::format("--signal=B:TERM@{}",
                  std::max(1, std::stoi(db.setting("slurm.stop_margin", "120")) / 2)),
      "--ntasks=1"};
  auto opt = [&](const std::string& key, const std::string& flag) {
    const std::string v = db.setting(key);
    if (!v.empty() && v != "0") {
      args.push_back(flag + "=" + v);
    }
  };
  opt("slurm.partition", "--partition");
  opt("slurm.time", "--time");
  opt("slurm.cpus_per_task", "--cpus-per-task");
  opt("slurm.gres", "--gres");
  opt("slurm.mem", "--mem");
  {
    std::stringstream ss(db.setting("slurm.extra"));
    std::string a;
    while (std::getline(ss, a)) {
      if (!a.empty()) {
        args.push_back(a);
      }
    }
  }
  args.push_back(memberScript(dir).string());
  const Captured c = capture(args);
  const std::string job = firstLine(c.out).substr(0, firstLine(c.out).find(';'));
  COREDEM_CHECK(c.rc == 0 && !job.empty() &&
                    job.find_first_not_of("0123456789") == std::string::npos,
                "sbatch failed (exit code {}): {}\n  command: {}", c.rc, trim(c.err + c.out),
                fmt::join(args, " "));
  db.transaction([&] {
    for (const auto& m : members) {
      const std::string task = job + "_" + std::to_string(m.index);
      db.setJob(m.id, task, "pending");
      db.addEvent(m.id, "submitted", "Slurm task " + task);
    }
  });
  std::string ids;
  for (const auto& m : members) {
    ids += (ids.empty() ? "" : " ") + m.id;
  }
  std::printf("submitted Slurm job %s: array tasks %s (at most %d at once) for members %s\n",
              job.c_str(), indices.c_str(), maxConcurrent, ids.c_str());
  std::fflush(stdout);
  return job;
}

/// Brings the database in line with the scheduler: a running member whose task is gone goes
/// back to pending. Returns the pending members without a live task (to submit).
std::vector<MemberRecord> reconcile(CampaignDb& db, const std::map<std::string, std::string>& q) {
  auto log = logger("campaign");
  std::vector<MemberRecord> toSubmit;
  for (const auto& m : db.members()) {
    const bool live = !m.jobId.empty() && q.count(m.jobId) > 0;
    if (live && m.schedState != q.at(m.jobId)) {
      db.setSchedState(m.id, q.at(m.jobId));
    }
    if (m.status == "running" && !live) {
      std::string state = m.jobId.empty() ? "" : endedTaskState(m.jobId);
      const std::string reason = fmt::format("its Slurm task {} ended{} while the member ran",
                                             m.jobId, state.empty() ? "" : " (" + state + ")");
      bool lost = false;
      db.transaction([&] {
        lost = db.markLost(m.id, m.jobId, reason);
        if (lost) {
          db.addEvent(m.id, "lost", reason);
          db.setSchedState(m.id, state.empty() ? "gone" : state);
        }
      });
      if (lost) {
        log->warn("member {}: {}; it continues from its last complete checkpoint", m.id, reason);
        auto again = db.member(m.id);
        if (again && again->status == "pending") {
          toSubmit.push_back(*again);
        }
      }
      continue;
    }
    if (m.status == "pending" && !live) {
      toSubmit.push_back(m);
    }
  }
  return toSubmit;
}

double pollSeconds() {
  const char* v = std::getenv("COREDEM_CAMPAIGN_POLL_S");
  const double s = v ? std::atof(v) : 0.0;
  return s > 0.0 ? s : 10.0;
}

} // namespace

void checkSlurmCommands() {
  for (const char* c : {"sbatch", "squeue", "scontrol", "scancel"}) {
    COREDEM_CHECK(!onPath(c).empty(),
                  "executor slurm: '{}' not found on PATH; the Slurm client commands (sbatch, "
                  "squeue, scontrol, scancel) must be installed and configured on this machine "
                  "(Debian: apt-get install slurm-client; on a cluster: module load slurm)",
                  c);
  }
  const Captured q = capture({"squeue", "-h", "--me", "-o", "%i"});
  COREDEM_CHECK(q.rc == 0,
                "executor slurm: Slurm does not answer here (squeue exit code {}: {}); run the "
                "campaign on a machine of the cluster (a login node), with SLURM_CONF set where "
                "slurm.conf is not in its default place",
                q.rc, trim(q.err + q.out));
}

std::map<std::string, std::string> slurmQueue() {
  std::map<std::string, std::string> q;
  if (onPath("squeue").empty()) {
    return q;
  }
  const Captured c = capture({"squeue", "-h", "-r", "--me", "-o", "%i|%T|%r"});
  COREDEM_CHECK(c.rc == 0, "squeue failed (exit code {}): {}", c.rc, trim(c.err + c.out));
  std::stringstream ss(c.out);
  std::string line;
  while (std::getline(ss, line)) {
    const auto a = line.find('|');
    const auto b = line.find('|', a == std::string::npos ? a : a + 1);
    if (a == std::string::npos || b == std::string::npos) {
      continue;
    }
    const std::string id = line.substr(0, a), state = line.substr(a + 1, b - a - 1);
    const std::string reason = trim(line.substr(b + 1));
    q[id] = reason.empty() || reason == "None" ? state : state + " (" + reason + ")";
  }
  return q;
}

int runSlurmCampaign(const fs::path& dir, CampaignDb& db, bool wait) {
  auto log = logger("campaign");
  writeMemberScript(dir);
  std::map<std::string, std::string> last;
  const double poll = pollSeconds();
  while (true) {
    if (gSignal != 0) {
      std::printf("stopped following campaign %s; its Slurm jobs keep running (scancel them to "
                  "stop); follow again with: coredem campaign resume %s\n",
                  dir.string().c_str(), dir.string().c_str());
      return kInterrupted;
    }
    const auto queue = slurmQueue();
    const auto toSubmit = reconcile(db, queue);
    if (!toSubmit.empty()) {
      submit(dir, db, toSubmit);
    }
    int done = 0, failed = 0, total = 0;
    for (const auto& m : db.members()) {
      ++total;
      done += m.status == "done";
      failed += m.status == "failed";
      const std::string now = m.status + (m.jobId.empty() ? "" : " (" + m.jobId + ")");
      if (last[m.id] != now) {
        if (m.status == "failed") {
          log->error("member {}: failed ({})", m.id, m.exitReason);
        } else {
          log->info("member {}: {}", m.id, now);
        }
        last[m.id] = now;
      }
    }
    if (!wait) {
      std::printf("campaign %s: %d of %d members done; follow with: coredem campaign status %s "
                  "(coredem campaign resume %s waits for the end and resubmits lost members)\n",
                  dir.string().c_str(), done, total, dir.string().c_str(), dir.string().c_str());
      return kOk;
    }
    if (done + failed == total) {
      std::printf("campaign %s: %d of %d members done, %d failed; results: coredem campaign "
                  "collect %s\n",
                  dir.string().c_str(), done, total, failed, dir.string().c_str());
      return failed == 0 ? kOk : kFault;
    }
    const auto until = std::chrono::steady_clock::now() +
                       std::chrono::milliseconds(static_cast<long>(poll * 1000));
    while (std::chrono::steady_clock::now() < until && gSignal == 0) {
      std::this_thread::sleep_for(50ms);
    }
  }
}

namespace {

/// Claims member m for Slurm task `task` on `host` (running, with the task's id): false, with
/// a note, when it is done, failed, running in a live task or changed meanwhile. Sets the
/// command that continues it (base) and how ("run" or "resume").
bool claimMember(CampaignDb& db, const std::optional<MemberRecord>& m, const std::string& task,
                 const char* host, std::vector<std::string>& base, std::string& how) {
  if (m->status == "done" || m->status == "failed") {
    std::printf("member %s is already %s; task %s has nothing to do\n", m->id.c_str(),
                m->status.c_str(), task.c_str());
    return false;
  }
  std::string from = m->status;
  if (m->status == "running" && m->jobId != task) {
    const auto q = slurmQueue();
    const auto it = q.find(m->jobId);
    if (it != q.end() && it->second.rfind("RUNNING", 0) == 0) {
      std::printf("member %s runs in Slurm task %s; task %s has nothing to do\n", m->id.c_str(),
                  m->jobId.c_str(), task.c_str());
      return false;
    }
  }
  base = memberCommand(*m, how);
  bool claimed = false;
  db.transaction([&] {
    const auto now = db.member(m->id);
    if (!now || now->status != from || (from == "running" && now->jobId != m->jobId)) {
      return; // changed meanwhile: let the next round decide
    }
    claimed = db.markRunning(m->id, from);
    if (claimed) {
      db.setJob(m->id, task, "running");
      db.setSchedState(m->id, "RUNNING");
      db.addEvent(m->id, "start",
                  fmt::format("attempt {}: coredem {} in Slurm task {} on {}", now->attempts + 1,
                              how, task, host));
    }
  });
  if (!claimed) {
    std::printf("member %s changed state while task %s started; nothing to do\n", m->id.c_str(),
                task.c_str());
  }
  return claimed;
}

/// Stop with a checkpoint `margin` seconds before the task's time limit: appends --walltime
/// to args and returns it (0: no limit known).
long addWalltime(CampaignDb& db, long margin, std::vector<std::string>& args) {
  const char* jobEnv = std::getenv("SLURM_JOB_ID");
  std::optional<long> left = jobEnv ? timeLeft(jobEnv) : std::nullopt;
  if (!left) {
    const long limit = std::stol(db.setting("slurm.time_seconds", "0"));
    left = limit > 0 ? std::optional<long>(limit) : std::nullopt;
  }
  long walltime = 0;
  if (left && *left > 0) {
    walltime = *left > margin + 5 ? *left - margin : std::max(1L, *left / 2);
    args.push_back("--walltime");
    args.push_back(std::to_string(walltime));
  }
  return walltime;
}

/// Waits for the member's coredem process `pid`, forwarding a signal to it (once: forwarded)
/// and recording its newest checkpoint. Returns its waitpid() status (-1: unknown).
int waitMember(CampaignDb& db, const MemberRecord& m, int pid, bool& forwarded,
               const std::shared_ptr<spdlog::logger>& log) {
  int status = 0;
  std::string lastCkpt = m.lastCheckpoint;
  auto lastScan = std::chrono::steady_clock::now();
  while (true) {
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid || (w < 0 && errno != EINTR)) {
      if (w < 0) {
        status = -1;
      }
      break;
    }
    if (gSignal != 0 && !forwarded) {
      log->warn("member {}: signal {} (time limit, preemption or scancel): stopping with a "
                "checkpoint",
                m.id, gSignal.load());
      ::kill(-pid, SIGTERM);
      ::kill(-pid, SIGCONT);
      forwarded = true;
    }
    if (std::chrono::steady_clock::now() - lastScan > 1s) {
      lastScan = std::chrono::steady_clock::now();
      const std::string c = newestCheckpointName(m.runDir);
      if (c != lastCkpt) {
        lastCkpt = c;
        db.setLastCheckpoint(m.id, c);
      }
    }
    std::this_thread::sleep_for(100ms);
  }
  return status;
}

/// After the member's process ended with `status`: done, failed, or stopped (pending, the
/// task requeued unless it is ending). Returns the exit code.
int memberEnded(const fs::path& dir, CampaignDb& db, const MemberRecord& m, const std::string& task,
                int status, bool forwarded, int retries, long margin,
                const std::shared_ptr<spdlog::logger>& log) {
  const bool exitedOk = status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  const bool ok = exitedOk && runReachedEnd(m.runDir, m.caseDir);
  std::string after;
  if (ok) {
    after = finishMember(db, m.id, m.runDir, status, retries);
    return after == "done" ? kOk : kFault;
  }
  // The scheduler's view of this task: still RUNNING after our own wall-time stop or the
  // time-limit warning (sbatch --signal=B:TERM): requeue it. Anything else (COMPLETING after
  // scancel, a hard time-limit kill or preemption) means the task is ending: the member stays
  // pending and the submitting side (campaign run/resume) resubmits it; Slurm requeues a
  // preempted task itself where PreemptMode=REQUEUE.
  const std::string jobState = endedTaskState(task);
  const bool ending = jobState.rfind("RUNNING", 0) != 0;
  // Stopped, not failed: exit 0 before the end (--walltime), 130 (the forwarded SIGTERM), a
  // signal to this process, or any end while the task is ending. scancel signals every process
  // of the task: a participant may stop first and coredem then exits 1 ("the other participant
  // was shut down") before this process forwards its own signal.
  const bool stopped = forwarded || gSignal != 0 || (ending && !jobState.empty()) || exitedOk ||
                       (status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == kInterrupted);
  if (stopped) {
    const std::string ckpt = newestCheckpointName(m.runDir);
    const std::string reason =
        ending ? fmt::format("its Slurm task ended ({}: scancel, time limit or preemption)",
                             jobState.empty() ? "state unknown" : jobState)
        : forwarded
            ? fmt::format("stopped by Slurm's time-limit warning (signal {})", gSignal.load())
            : fmt::format("stopped {} s before its time limit", margin);
    db.transaction([&] {
      if (db.markInterrupted(m.id, reason)) {
        db.setLastCheckpoint(m.id, ckpt);
        db.addEvent(m.id, "stopped",
                    reason + (ckpt.empty() ? "" : "; continues from checkpoint " + ckpt));
      }
    });
    log->warn("member {}: {}; continues from checkpoint {}", m.id, reason,
              ckpt.empty() ? "(none: from the start)" : ckpt);
    after = "pending";
  } else {
    after = finishMember(db, m.id, m.runDir, status, retries);
  }
  if (after != "pending") {
    return kFault;
  }
  if (ending) {
    log->info("member {}: coredem campaign resume {} resubmits it", m.id, dir.string());
    return kOk;
  }
  // Continue in a new run of this task (Slurm starts it again after its requeue delay). The
  // event comes first: the requeue ends this task, and Slurm may kill scontrol (and this
  // process) before scontrol can report its success.
  db.transaction([&] { db.addEvent(m.id, "requeued", "Slurm task " + task); });
  log->info("member {}: requeuing Slurm task {}", m.id, task);
  const Captured rq = capture({"scontrol", "requeue", task});
  if (rq.rc > 0) {
    db.transaction([&] { db.addEvent(m.id, "requeue failed", trim(rq.err + rq.out)); });
    log->warn("member {}: cannot requeue Slurm task {} ({}); coredem campaign resume {} "
              "resubmits the member",
              m.id, task, trim(rq.err + rq.out), dir.string());
  }
  return kOk;
}

} // namespace

int slurmMemberMain(const fs::path& dir, int index) {
  auto log = logger("campaign");
  const std::string task = ownTaskId();
  COREDEM_CHECK(!task.empty(),
                "coredem campaign member runs inside a Slurm task (DIR/slurm/member.sh); run "
                "members with coredem campaign run or resume");
  CampaignDb db(dir / "campaign.db", false);
  std::optional<MemberRecord> m;
  for (const auto& r : db.members()) {
    if (r.index == index) {
      m = r;
    }
  }
  COREDEM_CHECK(m.has_value(), "{}: no member with index {}", dir.string(), index);
  const int retries = std::stoi(db.setting("retries", "0"));
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);

  std::string how;
  std::vector<std::string> base;
  if (!claimMember(db, m, task, host, base, how)) {
    return kOk;
  }
  std::vector<std::string> args = base;
  const long margin = std::stol(db.setting("slurm.stop_margin", "120"));
  const long walltime = addWalltime(db, margin, args);
  const fs::path logFile = fs::path(m->caseDir).parent_path() / "coredem.log";
  const int attempt = m->attempts + 1;
  {
    std::ofstream out(logFile, std::ios::app);
    out << "=== campaign attempt " << attempt << " " << utcNow() << ": coredem " << how
        << " (Slurm task " << task << " on " << host << ")\n";
  }
  std::signal(SIGINT, onCampaignSignal);
  std::signal(SIGTERM, onCampaignSignal);
  int pid = -1;
  try {
    pid = spawnTied(args, logFile);
  } catch (const UserError& e) {
    const std::string reason = e.what();
    db.transaction([&] {
      db.markFailed(m->id, reason, retries);
      db.addEvent(m->id, "failed", reason);
    });
    log->error("member {}: {}", m->id, reason);
    return kFault;
  }
  db.setPid(m->id, pid);
  log->info("member {}: coredem {} (pid {} on {}, Slurm task {}, attempt {}{})", m->id, how, pid,
            host, task, attempt,
            walltime > 0 ? fmt::format(", stops at {} s wall time", walltime) : "");
  bool forwarded = false;
  const int status = waitMember(db, *m, pid, forwarded, log);
  return memberEnded(dir, db, *m, task, status, forwarded, retries, margin, log);
}

} // namespace coredem::orchestrator::campaign_detail
