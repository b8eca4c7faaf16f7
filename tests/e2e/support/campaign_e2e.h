#pragma once
/// @file
/// What the campaign end-to-end tests (local and Slurm executors) read back from a campaign
/// folder: the member rows of campaign.db, read-only as a second process would, their events in
/// order, and the steps of a member's timeseries.csv; plus the check that every member ended
/// exactly once.

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sqlite3.h>

namespace coredem::e2e {

/// A member row of campaign.db with its events ("event: detail", in order).
struct MemberRow {
  std::string status, exitReason, lastCheckpoint, caseHash, softwareVersion, protocolVersion, jobId;
  int attempts = 0, failures = 0, doneCount = 0, doneEvents = 0;
  long pid = 0;
  std::vector<std::string> events;
};

/// Member id -> row; empty when the database cannot be opened (not yet written).
inline std::map<std::string, MemberRow> readCampaignDb(const std::filesystem::path& dir) {
  std::map<std::string, MemberRow> rows;
  sqlite3* db = nullptr;
  if (sqlite3_open_v2((dir / "campaign.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr) !=
      SQLITE_OK) {
    sqlite3_close(db);
    return rows;
  }
  sqlite3_busy_timeout(db, 5000);
  auto text = [](sqlite3_stmt* s, int c) {
    const auto* p = sqlite3_column_text(s, c);
    return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  };
  sqlite3_stmt* s = nullptr;
  const char* sql =
      "SELECT id, status, attempts, failures, done_count, pid, ifnull(exit_reason,''), "
      "ifnull(last_checkpoint,''), case_hash, ifnull(software_version,''), "
      "ifnull(protocol_version,''), ifnull(job_id,''), (SELECT count(*) FROM events e WHERE "
      "e.member = m.id AND e.event = 'done') FROM members m ORDER BY idx";
  if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) == SQLITE_OK) {
    while (sqlite3_step(s) == SQLITE_ROW) {
      MemberRow r;
      r.status = text(s, 1);
      r.attempts = sqlite3_column_int(s, 2);
      r.failures = sqlite3_column_int(s, 3);
      r.doneCount = sqlite3_column_int(s, 4);
      r.pid = static_cast<long>(sqlite3_column_int64(s, 5));
      r.exitReason = text(s, 6);
      r.lastCheckpoint = text(s, 7);
      r.caseHash = text(s, 8);
      r.softwareVersion = text(s, 9);
      r.protocolVersion = text(s, 10);
      r.jobId = text(s, 11);
      r.doneEvents = sqlite3_column_int(s, 12);
      rows[text(s, 0)] = r;
    }
  }
  sqlite3_finalize(s);
  if (sqlite3_prepare_v2(db, "SELECT member, event, ifnull(detail,'') FROM events ORDER BY seq", -1,
                         &s, nullptr) == SQLITE_OK) {
    while (sqlite3_step(s) == SQLITE_ROW) {
      const auto it = rows.find(text(s, 0));
      if (it != rows.end()) {
        it->second.events.push_back(text(s, 1) + ": " + text(s, 2));
      }
    }
  }
  sqlite3_finalize(s);
  sqlite3_close(db);
  return rows;
}

/// The events of a row, one per line, for failure messages.
inline std::string eventsOf(const MemberRow& r) {
  std::string s;
  for (const auto& e : r.events) {
    s += "\n  " + e;
  }
  return s;
}

/// How many events of kind `event` a row has.
inline int countEvents(const MemberRow& r, const std::string& event) {
  int n = 0;
  for (const auto& e : r.events) {
    n += e.rfind(event + ":", 0) == 0;
  }
  return n;
}

/// The `step` column of a member's timeseries.csv.
inline std::vector<long> stepsOf(const std::filesystem::path& runDir) {
  std::ifstream in(runDir / "timeseries.csv");
  std::string line;
  std::getline(in, line);
  std::vector<long> steps;
  while (std::getline(in, line)) {
    steps.push_back(std::stol(line.substr(0, line.find(','))));
  }
  return steps;
}

/// Every member done exactly once (status, done_count, one 'done' event, plus what `extra`
/// checks of the row) and its timeseries holds each step 1..N exactly once.
inline void
expectAllDoneOnce(const std::filesystem::path& dir, std::size_t members, long steps,
                  const std::function<void(const std::string&, const MemberRow&)>& extra = {}) {
  const auto rows = readCampaignDb(dir);
  ASSERT_EQ(rows.size(), members);
  for (const auto& [id, r] : rows) {
    EXPECT_EQ(r.status, "done") << id << ": " << r.exitReason << eventsOf(r);
    EXPECT_EQ(r.doneCount, 1) << id;
    EXPECT_EQ(r.doneEvents, 1) << id;
    if (extra) {
      extra(id, r);
    }
    const auto s = stepsOf(dir / "members" / id / "run");
    ASSERT_EQ(static_cast<long>(s.size()), steps) << id;
    for (long i = 0; i < steps; ++i) {
      EXPECT_EQ(s[static_cast<std::size_t>(i)], i + 1) << id;
    }
  }
}

} // namespace coredem::e2e
