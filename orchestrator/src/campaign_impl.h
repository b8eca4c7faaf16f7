#pragma once
// Internal to the campaign library: helpers shared by the local executor (campaign.cpp), the
// reports (campaign_report.cpp) and the Slurm executor (campaign_slurm.cpp).
#include <atomic>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <coredem/orchestrator/campaign_db.h>

namespace coredem::orchestrator::campaign_detail {

constexpr int kOk = 0, kFault = 1, kBadInput = 2, kInterrupted = 130;

/// The signal (SIGINT/SIGTERM) a campaign process received, 0 while none.
extern std::atomic<int> gSignal;
extern "C" void onCampaignSignal(int sig);

std::string readFile(const std::filesystem::path& p);
/// Folder of the running coredem executable.
std::filesystem::path selfDir();
/// Newest checkpoint folder with a manifest (no hash check; for the status display).
std::string newestCheckpointName(const std::filesystem::path& runDir);
/// The last "[error]" line of the member log after the latest attempt marker.
std::string lastErrorLine(const std::filesystem::path& log);

/// Holds an exclusive flock on DIR/campaign.lock for the life of the object.
class FolderLock {
public:
  explicit FolderLock(const std::filesystem::path& dir);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

private:
  int _fd = -1;
};

/// The command that continues member `m`: `coredem resume RUN --no-plots` when its run folder
/// has a complete checkpoint, else `coredem run CASE --out RUN --no-plots` (after removing a
/// run folder without one). `how` is set to "resume" or "run".
std::vector<std::string> memberCommand(const MemberRecord& m, std::string& how);

/// Records the end of a member attempt with waitpid() status `status` (-1: unknown) in the
/// database: done, or a failure (pending again while failures <= retries, else failed).
/// Returns the member's status after the transition.
std::string finishMember(CampaignDb& db, const std::string& id, const std::string& runDir,
                         int status, int retries);

// --- the reports (campaign_report.cpp)

/// `coredem campaign status DIR [--json]`: prints the members' state. Returns the exit code.
int status(const std::filesystem::path& dir, bool json);
/// `coredem campaign collect DIR [--no-plot]`: writes DIR/summary.csv (one row per member, the
/// sweep's values and collect.scalars) and plots it to DIR/plots/campaign.png.
/// `--from`/`--to` apply to every max/min/mean scalar that has no window of its own.
struct CollectWindow {
  double from = 0.0, to = 0.0;
  bool hasFrom = false, hasTo = false;
};
int collect(const std::filesystem::path& dir, bool noPlot, const CollectWindow& window = {});

// --- the Slurm executor (campaign_slurm.cpp)

/// Throws UserError naming the first of sbatch, squeue, scontrol, scancel missing on PATH.
void checkSlurmCommands();
/// Writes the sbatch script and submits every pending member without a live task; with
/// `wait`, follows the campaign until every member is done or failed (resubmitting members
/// whose tasks are gone). Returns the exit code.
int runSlurmCampaign(const std::filesystem::path& dir, CampaignDb& db, bool wait);
/// `coredem campaign member DIR --index I`: runs member I inside its Slurm task.
int slurmMemberMain(const std::filesystem::path& dir, int index);
/// Array task id ("1234_5") -> scheduler state ("RUNNING", "PENDING (BeginTime)") of the
/// tasks still known to squeue; empty when squeue is not available.
std::map<std::string, std::string> slurmQueue();

} // namespace coredem::orchestrator::campaign_detail
