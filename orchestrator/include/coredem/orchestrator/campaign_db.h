#pragma once
/// @file
/// The state of a campaign in SQLite (DIR/campaign.db, WAL journal): the campaign's settings,
/// one row per member with its status (pending, running, done, failed), attempts, failures,
/// pid, timestamps, last checkpoint, exit reason and provenance, the varied values and an
/// event log. Every status transition is one UPDATE ... WHERE status = <expected> inside a
/// BEGIN IMMEDIATE transaction together with its event row, so a crash of the campaign
/// process either records a transition completely or not at all: a member is never counted
/// done twice and never lost.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace coredem::orchestrator {

struct MemberRecord {
  std::string id;
  int index = 0;
  std::string caseDir, runDir, caseHash;
  std::string status; ///< pending, running, done, failed
  int attempts = 0;   ///< launches (first run, resumes, retries)
  int failures = 0;   ///< launches that ended with an error
  int doneCount = 0;  ///< times the member reached done (1 when done, never more)
  std::int64_t pid = 0;
  std::string jobId;      ///< Slurm array task ("1234_5") of the latest submission, "" locally
  std::string schedState; ///< last scheduler state seen by campaign resume (informational)
  std::string created, started, finished, lastCheckpoint, exitReason;
  std::string softwareVersion, protocolVersion;
  std::vector<std::pair<std::string, std::string>> values; ///< key path -> YAML value
};

class CampaignDb {
public:
  /// Opens an existing DIR/campaign.db (or `create`s a new file). Throws UserError.
  CampaignDb(const std::filesystem::path& file, bool create);
  ~CampaignDb();
  CampaignDb(const CampaignDb&) = delete;
  CampaignDb& operator=(const CampaignDb&) = delete;

  /// Creates the schema (new database only).
  void createSchema();
  void setSetting(const std::string& key, const std::string& value);
  std::string setting(const std::string& key, const std::string& fallback = "") const;
  /// Inserts a pending member with its values (inside the caller's transaction).
  void addMember(const MemberRecord& m);

  std::vector<MemberRecord> members() const;
  std::optional<MemberRecord> member(const std::string& id) const;
  /// Number of 'done' events of a member (the e2e tests check it is exactly 1).
  int doneEvents(const std::string& id) const;

  /// BEGIN IMMEDIATE ... COMMIT around `fn` (rolled back on an exception).
  template <class Fn>
  void transaction(Fn&& fn) {
    begin();
    try {
      fn();
    } catch (...) {
      rollback();
      throw;
    }
    commit();
  }

  // Transitions; each returns false when the member was not in the expected state.
  /// pending -> running (attempts + 1, started, pid 0), or running -> running when a
  /// crashed campaign's member is relaunched.
  bool markRunning(const std::string& id, const std::string& fromStatus);
  void setPid(const std::string& id, std::int64_t pid);
  /// The Slurm task that will run (pending) or runs (running) the member.
  void setJob(const std::string& id, const std::string& jobId, const std::string& fromStatus);
  void setSchedState(const std::string& id, const std::string& state);
  /// running -> pending when the member's Slurm task `jobId` is gone (no failure counted).
  bool markLost(const std::string& id, const std::string& jobId, const std::string& reason);
  bool markDone(const std::string& id, const std::string& lastCheckpoint,
                const std::string& softwareVersion, const std::string& protocolVersion);
  /// running -> pending (failures + 1) while failures <= retries, else running -> failed.
  bool markFailed(const std::string& id, const std::string& reason, int retries);
  /// running -> pending without counting a failure (the campaign itself was interrupted).
  bool markInterrupted(const std::string& id, const std::string& reason);
  /// failed -> pending with failures reset (resume --retry-failed).
  bool resetFailed(const std::string& id);
  void setLastCheckpoint(const std::string& id, const std::string& checkpoint);
  void addEvent(const std::string& id, const std::string& event, const std::string& detail);

private:
  void begin();
  void commit();
  void rollback();
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

} // namespace coredem::orchestrator
