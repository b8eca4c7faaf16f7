// SQLite state of a campaign (campaign_db.h).
#include <map>

#include <sqlite3.h>

#include <coredem/common/check.h>
#include <coredem/orchestrator/campaign_db.h>
#include <coredem/orchestrator/checkpoint.h> // utcNow

namespace coredem::orchestrator {

namespace {

/// A prepared statement; text columns come back as "" for NULL.
class Stmt {
public:
  Stmt(sqlite3* db, const char* sql)
      : _db(db) {
    COREDEM_CHECK(sqlite3_prepare_v2(db, sql, -1, &_s, nullptr) == SQLITE_OK,
                  "campaign database: cannot prepare '{}': {}", sql, sqlite3_errmsg(db));
  }
  ~Stmt() { sqlite3_finalize(_s); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  Stmt& bind(int i, const std::string& v) {
    sqlite3_bind_text(_s, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Stmt& bind(int i, std::int64_t v) {
    sqlite3_bind_int64(_s, i, v);
    return *this;
  }
  Stmt& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  /// true while a row is available.
  bool step() {
    const int rc = sqlite3_step(_s);
    if (rc == SQLITE_ROW) {
      return true;
    }
    COREDEM_CHECK(rc == SQLITE_DONE,
                  "campaign database: {} (is the disk full or the file "
                  "locked by another process?)",
                  sqlite3_errmsg(_db));
    return false;
  }
  std::string text(int c) const {
    const auto* p = sqlite3_column_text(_s, c);
    return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  }
  std::int64_t integer(int c) const { return sqlite3_column_int64(_s, c); }
  int changes() const { return sqlite3_changes(_db); }

private:
  sqlite3* _db;
  sqlite3_stmt* _s = nullptr;
};

constexpr const char* kMemberColumns =
    "id, idx, case_dir, run_dir, case_hash, status, attempts, failures, done_count, pid, "
    "created, started, finished, last_checkpoint, exit_reason, software_version, "
    "protocol_version, job_id, sched_state";

} // namespace

struct CampaignDb::Impl {
  sqlite3* db = nullptr;
  std::filesystem::path file;

  void exec(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string msg = err ? err : "unknown error";
      sqlite3_free(err);
      throw UserError(fmt::format("campaign database {}: {} (in '{}')", file.string(), msg, sql));
    }
  }
  bool update(const char* sql, const std::vector<std::string>& args) {
    Stmt s(db, sql);
    for (std::size_t i = 0; i < args.size(); ++i) {
      s.bind(static_cast<int>(i + 1), args[i]);
    }
    s.step();
    return s.changes() > 0;
  }
};

CampaignDb::CampaignDb(const std::filesystem::path& file, bool create)
    : _impl(std::make_unique<Impl>()) {
  _impl->file = file;
  COREDEM_CHECK(create || std::filesystem::exists(file),
                "{} not found: not a campaign folder (start one with coredem campaign run "
                "SWEEP.yaml --out DIR)",
                file.string());
  const int flags = SQLITE_OPEN_READWRITE | (create ? SQLITE_OPEN_CREATE : 0);
  if (sqlite3_open_v2(file.c_str(), &_impl->db, flags, nullptr) != SQLITE_OK) {
    const std::string msg = _impl->db ? sqlite3_errmsg(_impl->db) : "out of memory";
    sqlite3_close(_impl->db);
    _impl->db = nullptr;
    throw UserError(fmt::format("cannot open campaign database {}: {}", file.string(), msg));
  }
  sqlite3_busy_timeout(_impl->db, 10000);
  // WAL needs shared memory between all its users, i.e. one machine: the local executor's
  // campaigns use it; a Slurm campaign, written by tasks on many nodes over a shared file
  // system, uses the rollback journal, which needs only working POSIX locks.
  std::string journal = "WAL";
  {
    sqlite3_stmt* q = nullptr;
    if (sqlite3_prepare_v2(_impl->db, "SELECT value FROM settings WHERE key = 'executor'", -1, &q,
                           nullptr) == SQLITE_OK &&
        sqlite3_step(q) == SQLITE_ROW) {
      const auto* v = sqlite3_column_text(q, 0);
      if (v && std::string(reinterpret_cast<const char*>(v)) == "slurm") {
        journal = "DELETE";
      }
    }
    sqlite3_finalize(q);
  }
  _impl->exec(("PRAGMA journal_mode=" + journal).c_str());
  _impl->exec("PRAGMA synchronous=FULL");
  _impl->exec("PRAGMA foreign_keys=ON");
  // databases of earlier versions lack the Slurm columns
  sqlite3_stmt* probe = nullptr;
  const bool hasMembers = sqlite3_prepare_v2(_impl->db, "SELECT idx FROM members LIMIT 0", -1,
                                             &probe, nullptr) == SQLITE_OK;
  sqlite3_finalize(probe);
  probe = nullptr;
  if (hasMembers && sqlite3_prepare_v2(_impl->db, "SELECT job_id FROM members LIMIT 0", -1, &probe,
                                       nullptr) != SQLITE_OK) {
    _impl->exec("ALTER TABLE members ADD COLUMN job_id TEXT");
    _impl->exec("ALTER TABLE members ADD COLUMN sched_state TEXT");
  }
  sqlite3_finalize(probe);
}

CampaignDb::~CampaignDb() {
  if (_impl && _impl->db) {
    sqlite3_close(_impl->db);
  }
}

void CampaignDb::createSchema() {
  _impl->exec(R"sql(
CREATE TABLE IF NOT EXISTS settings(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS members(
  id TEXT PRIMARY KEY, idx INTEGER NOT NULL UNIQUE,
  case_dir TEXT NOT NULL, run_dir TEXT NOT NULL, case_hash TEXT NOT NULL,
  status TEXT NOT NULL CHECK(status IN ('pending','running','done','failed')),
  attempts INTEGER NOT NULL DEFAULT 0, failures INTEGER NOT NULL DEFAULT 0,
  done_count INTEGER NOT NULL DEFAULT 0 CHECK(done_count <= 1),
  pid INTEGER NOT NULL DEFAULT 0,
  created TEXT NOT NULL, started TEXT, finished TEXT, last_checkpoint TEXT, exit_reason TEXT,
  software_version TEXT, protocol_version TEXT, job_id TEXT, sched_state TEXT);
CREATE TABLE IF NOT EXISTS member_values(
  member TEXT NOT NULL REFERENCES members(id), pos INTEGER NOT NULL, path TEXT NOT NULL,
  value TEXT NOT NULL, PRIMARY KEY(member, pos));
CREATE TABLE IF NOT EXISTS events(
  seq INTEGER PRIMARY KEY AUTOINCREMENT, member TEXT, time TEXT NOT NULL, event TEXT NOT NULL,
  detail TEXT);
)sql");
}

void CampaignDb::setSetting(const std::string& key, const std::string& value) {
  _impl->update("INSERT OR REPLACE INTO settings(key, value) VALUES(?1, ?2)", {key, value});
}

std::string CampaignDb::setting(const std::string& key, const std::string& fallback) const {
  Stmt s(_impl->db, "SELECT value FROM settings WHERE key = ?1");
  s.bind(1, key);
  return s.step() ? s.text(0) : fallback;
}

void CampaignDb::addMember(const MemberRecord& m) {
  Stmt s(_impl->db, "INSERT INTO members(id, idx, case_dir, run_dir, case_hash, status, created) "
                    "VALUES(?1, ?2, ?3, ?4, ?5, 'pending', ?6)");
  s.bind(1, m.id).bind(2, m.index).bind(3, m.caseDir).bind(4, m.runDir).bind(5, m.caseHash);
  s.bind(6, utcNow());
  s.step();
  int pos = 0;
  for (const auto& [path, value] : m.values) {
    Stmt v(_impl->db, "INSERT INTO member_values(member, pos, path, value) VALUES(?1,?2,?3,?4)");
    v.bind(1, m.id).bind(2, pos++).bind(3, path).bind(4, value);
    v.step();
  }
}

std::vector<MemberRecord> CampaignDb::members() const {
  std::vector<MemberRecord> out;
  Stmt s(_impl->db, fmt::format("SELECT {} FROM members ORDER BY idx", kMemberColumns).c_str());
  while (s.step()) {
    MemberRecord m;
    m.id = s.text(0);
    m.index = static_cast<int>(s.integer(1));
    m.caseDir = s.text(2);
    m.runDir = s.text(3);
    m.caseHash = s.text(4);
    m.status = s.text(5);
    m.attempts = static_cast<int>(s.integer(6));
    m.failures = static_cast<int>(s.integer(7));
    m.doneCount = static_cast<int>(s.integer(8));
    m.pid = s.integer(9);
    m.created = s.text(10);
    m.started = s.text(11);
    m.finished = s.text(12);
    m.lastCheckpoint = s.text(13);
    m.exitReason = s.text(14);
    m.softwareVersion = s.text(15);
    m.protocolVersion = s.text(16);
    m.jobId = s.text(17);
    m.schedState = s.text(18);
    out.push_back(std::move(m));
  }
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < out.size(); ++i) {
    index[out[i].id] = i;
  }
  Stmt v(_impl->db, "SELECT member, path, value FROM member_values ORDER BY member, pos");
  while (v.step()) {
    const auto it = index.find(v.text(0));
    if (it != index.end()) {
      out[it->second].values.emplace_back(v.text(1), v.text(2));
    }
  }
  return out;
}

std::optional<MemberRecord> CampaignDb::member(const std::string& id) const {
  for (auto& m : members()) {
    if (m.id == id) {
      return m;
    }
  }
  return std::nullopt;
}

int CampaignDb::doneEvents(const std::string& id) const {
  Stmt s(_impl->db, "SELECT count(*) FROM events WHERE member = ?1 AND event = 'done'");
  s.bind(1, id);
  s.step();
  return static_cast<int>(s.integer(0));
}

void CampaignDb::begin() {
  _impl->exec("BEGIN IMMEDIATE");
}
void CampaignDb::commit() {
  _impl->exec("COMMIT");
}
void CampaignDb::rollback() {
  sqlite3_exec(_impl->db, "ROLLBACK", nullptr, nullptr, nullptr);
}

bool CampaignDb::markRunning(const std::string& id, const std::string& fromStatus) {
  return _impl->update("UPDATE members SET status = 'running', attempts = attempts + 1, "
                       "pid = 0, started = ?3, finished = NULL WHERE id = ?1 AND status = ?2",
                       {id, fromStatus, utcNow()});
}

void CampaignDb::setPid(const std::string& id, std::int64_t pid) {
  _impl->update("UPDATE members SET pid = ?2 WHERE id = ?1 AND status = 'running'",
                {id, std::to_string(pid)});
}

void CampaignDb::setJob(const std::string& id, const std::string& jobId,
                        const std::string& fromStatus) {
  _impl->update("UPDATE members SET job_id = ?2 WHERE id = ?1 AND status = ?3",
                {id, jobId, fromStatus});
}

void CampaignDb::setSchedState(const std::string& id, const std::string& state) {
  _impl->update("UPDATE members SET sched_state = ?2 WHERE id = ?1", {id, state});
}

bool CampaignDb::markLost(const std::string& id, const std::string& jobId,
                          const std::string& reason) {
  return _impl->update("UPDATE members SET status = 'pending', pid = 0, finished = ?3, "
                       "exit_reason = ?4 WHERE id = ?1 AND status = 'running' AND job_id = ?2",
                       {id, jobId, utcNow(), reason});
}

bool CampaignDb::markDone(const std::string& id, const std::string& lastCheckpoint,
                          const std::string& softwareVersion, const std::string& protocolVersion) {
  return _impl->update(
      "UPDATE members SET status = 'done', done_count = done_count + 1, pid = 0, "
      "finished = ?2, last_checkpoint = ?3, software_version = ?4, protocol_version = ?5, "
      "exit_reason = 'finished' WHERE id = ?1 AND status = 'running'",
      {id, utcNow(), lastCheckpoint, softwareVersion, protocolVersion});
}

bool CampaignDb::markFailed(const std::string& id, const std::string& reason, int retries) {
  return _impl->update(
      "UPDATE members SET failures = failures + 1, pid = 0, finished = ?2, exit_reason = ?3, "
      "status = CASE WHEN failures + 1 > CAST(?4 AS INTEGER) THEN 'failed' ELSE 'pending' END "
      "WHERE id = ?1 AND status = 'running'",
      {id, utcNow(), reason, std::to_string(retries)});
}

bool CampaignDb::markInterrupted(const std::string& id, const std::string& reason) {
  return _impl->update("UPDATE members SET status = 'pending', pid = 0, finished = ?2, "
                       "exit_reason = ?3 WHERE id = ?1 AND status = 'running'",
                       {id, utcNow(), reason});
}

bool CampaignDb::resetFailed(const std::string& id) {
  return _impl->update(
      "UPDATE members SET status = 'pending', failures = 0 WHERE id = ?1 AND status = 'failed'",
      {id});
}

void CampaignDb::setLastCheckpoint(const std::string& id, const std::string& checkpoint) {
  _impl->update("UPDATE members SET last_checkpoint = ?2 WHERE id = ?1", {id, checkpoint});
}

void CampaignDb::addEvent(const std::string& id, const std::string& event,
                          const std::string& detail) {
  _impl->update("INSERT INTO events(member, time, event, detail) VALUES(?1, ?2, ?3, ?4)",
                {id, utcNow(), event, detail});
}

} // namespace coredem::orchestrator
