// `coredem campaign status|collect` (campaign.h, docs/campaigns.md): the members' state as a
// table or JSON, and DIR/summary.csv with the plot of a campaign's scalars.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include <coredem/common/check.h>
#include <coredem/common/files.h>
#include <coredem/common/json.h>
#include <coredem/common/log.h>
#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/campaign_db.h>
#include <coredem/orchestrator/stats.h>

#include "campaign_impl.h"

namespace coredem::orchestrator::campaign_detail {

namespace fs = std::filesystem;

namespace {

std::string csvField(const std::string& v) {
  if (v.find_first_of(",\"\n") == std::string::npos) {
    return v;
  }
  std::string q = "\"";
  for (char c : v) {
    q += c == '"' ? std::string("\"\"") : std::string(1, c);
  }
  return q + "\"";
}

/// A JSON string literal with the common escaper (`status --json` is one line, written here).
std::string jsonString(const std::string& v) {
  std::string s = "\"";
  s += jsonEscape(v);
  s += '"';
  return s;
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  std::stringstream ss(line);
  while (std::getline(ss, cur, ',')) {
    out.push_back(cur);
  }
  if (!line.empty() && line.back() == ',') {
    out.emplace_back();
  }
  return out;
}

std::string valuesText(const MemberRecord& m) {
  std::string s;
  for (const auto& [path, value] : m.values) {
    s += (s.empty() ? "" : " ") + path + "=" + value;
  }
  return s;
}

/// One scalar of a member's timeseries.csv; "" when the run has no rows yet. max, min and mean
/// come from the same statistics as `coredem stats` (over the scalar's window; the mean
/// time-weighted).
std::string scalarOf(const fs::path& timeseries, const ScalarSpec& spec) {
  std::ifstream in(timeseries);
  std::string header;
  if (!in || !std::getline(in, header)) {
    return "";
  }
  const auto cols = splitCsvLine(header);
  const auto at = std::find(cols.begin(), cols.end(), spec.column);
  COREDEM_CHECK(at != cols.end(), "{}: no column '{}' (collect.scalars); columns: {}",
                timeseries.string(), spec.column, fmt::join(cols, ", "));
  const std::size_t c = static_cast<std::size_t>(at - cols.begin());
  std::string line, last;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    const auto f = splitCsvLine(line);
    if (f.size() <= c) {
      continue;
    }
    last = f[c];
    ++n;
  }
  if (n == 0) {
    return "";
  }
  if (spec.reduce == "final") {
    return last;
  }
  TimeseriesStats st;
  try {
    st = timeseriesStats(timeseries.parent_path(), {spec.from, spec.to});
  } catch (const UserError& e) {
    throw UserError(fmt::format("collect.scalars '{}': {}", spec.label(), e.what()));
  }
  for (const auto& cs : st.columns) {
    if (cs.name == spec.column) {
      const double v = spec.reduce == "max" ? cs.max : spec.reduce == "min" ? cs.min : cs.mean;
      return cs.rows == 0 ? "" : fmt::format("{:.17g}", v);
    }
  }
  return "";
}

/// First and last simulated time (column t) of a timeseries.csv; nullopt without rows.
std::optional<std::pair<double, double>> timeRange(const fs::path& timeseries) {
  std::ifstream in(timeseries);
  std::string header, line;
  if (!in || !std::getline(in, header)) {
    return std::nullopt;
  }
  const auto cols = splitCsvLine(header);
  const auto at = std::find(cols.begin(), cols.end(), "t");
  if (at == cols.end()) {
    return std::nullopt;
  }
  const std::size_t c = static_cast<std::size_t>(at - cols.begin());
  std::optional<std::pair<double, double>> out;
  while (std::getline(in, line)) {
    const auto f = splitCsvLine(line);
    if (f.size() <= c) {
      continue;
    }
    const double t = std::strtod(f[c].c_str(), nullptr);
    out = out ? std::pair{out->first, t} : std::pair{t, t};
  }
  return out;
}

/// What time the plotted value refers to, e.g. "final value at t = 0.05 s" or "mean over
/// t = 0.001–0.05 s" (a range of members' times when they differ).
std::string whenOf(const std::vector<MemberRecord>& members, const ScalarSpec& spec) {
  double lo0 = HUGE_VAL, hi0 = -HUGE_VAL, lo1 = HUGE_VAL, hi1 = -HUGE_VAL;
  for (const auto& m : members) {
    if (m.status != "done") {
      continue;
    }
    if (const auto r = timeRange(fs::path(m.runDir) / "timeseries.csv")) {
      lo0 = std::min(lo0, r->first);
      hi0 = std::max(hi0, r->first);
      lo1 = std::min(lo1, r->second);
      hi1 = std::max(hi1, r->second);
    }
  }
  if (lo1 > hi1) {
    return "";
  }
  auto span = [](double lo, double hi) {
    return lo == hi ? fmt::format("{:.6g}", lo) : fmt::format("{:.6g}..{:.6g}", lo, hi);
  };
  if (spec.reduce == "final") {
    return fmt::format("final value at t = {} s", span(lo1, hi1));
  }
  const std::string from = spec.from ? fmt::format("{:.6g}", *spec.from) : span(lo0, hi0);
  const std::string to = spec.to ? fmt::format("{:.6g}", std::min(*spec.to, hi1)) : span(lo1, hi1);
  return fmt::format("{} over t = {} to {} s{}", spec.reduce, from, to,
                     spec.from ? " (start-up excluded)" : "");
}

} // namespace

int status(const fs::path& dir, bool json) {
  CampaignDb db(dir / "campaign.db", false);
  const auto members = db.members();
  const bool slurm = db.setting("executor", "local") == "slurm";
  // the scheduler's view of every member's task (squeue; empty where it cannot be asked)
  const std::map<std::string, std::string> queue =
      slurm ? slurmQueue() : std::map<std::string, std::string>{};
  auto schedOf = [&](const MemberRecord& m) -> std::string {
    if (!slurm || m.jobId.empty()) {
      return "";
    }
    const auto it = queue.find(m.jobId);
    // a running member whose task squeue no longer lists is lost (resume resubmits it)
    return it != queue.end() ? it->second : (m.status == "running" ? "gone" : "-");
  };
  if (json) {
    std::ostringstream o;
    o << "{\"campaign\": " << jsonString(db.setting("name"))
      << ", \"executor\": " << jsonString(db.setting("executor", "local"))
      << ", \"dir\": " << jsonString(dir.string())
      << ", \"concurrency\": " << db.setting("concurrency")
      << ", \"retries\": " << db.setting("retries") << ", \"members\": [";
    for (std::size_t i = 0; i < members.size(); ++i) {
      const auto& m = members[i];
      o << (i ? ", " : "") << "{\"id\": " << jsonString(m.id)
        << ", \"status\": " << jsonString(m.status) << ", \"attempts\": " << m.attempts
        << ", \"failures\": " << m.failures << ", \"done_count\": " << m.doneCount
        << ", \"pid\": " << m.pid << ", \"job_id\": " << jsonString(m.jobId)
        << ", \"scheduler_state\": " << jsonString(schedOf(m))
        << ", \"started\": " << jsonString(m.started)
        << ", \"finished\": " << jsonString(m.finished)
        << ", \"last_checkpoint\": " << jsonString(m.lastCheckpoint)
        << ", \"exit_reason\": " << jsonString(m.exitReason)
        << ", \"case_hash\": " << jsonString(m.caseHash)
        << ", \"software_version\": " << jsonString(m.softwareVersion)
        << ", \"protocol_version\": " << jsonString(m.protocolVersion)
        << ", \"run_dir\": " << jsonString(m.runDir) << ", \"values\": {";
      for (std::size_t k = 0; k < m.values.size(); ++k) {
        o << (k ? ", " : "") << jsonString(m.values[k].first) << ": "
          << jsonString(m.values[k].second);
      }
      o << "}}";
    }
    o << "]}\n";
    std::cout << o.str();
    return kOk;
  }
  std::map<std::string, int> counts;
  std::printf("campaign %s (%s): concurrency %s, retries %s\n", db.setting("name").c_str(),
              dir.string().c_str(), db.setting("concurrency").c_str(),
              db.setting("retries").c_str());
  if (slurm) {
    std::printf("executor slurm: one array task per member (job id_index); scheduler state from "
                "squeue%s\n",
                queue.empty() ? " (no task of this user in the queue)" : "");
    std::printf("%-6s %-8s %8s %8s %-10s %-12s %-28s %-40s %s\n", "member", "status", "attempts",
                "failures", "checkpoint", "job", "scheduler", "values", "exit reason");
  } else {
    std::printf("%-6s %-8s %8s %8s %-10s %-40s %s\n", "member", "status", "attempts", "failures",
                "checkpoint", "values", "exit reason");
  }
  for (const auto& m : members) {
    ++counts[m.status];
    if (slurm) {
      std::printf("%-6s %-8s %8d %8d %-10s %-12s %-28s %-40s %s\n", m.id.c_str(), m.status.c_str(),
                  m.attempts, m.failures, m.lastCheckpoint.c_str(), m.jobId.c_str(),
                  schedOf(m).c_str(), valuesText(m).c_str(), m.exitReason.c_str());
      continue;
    }
    std::printf("%-6s %-8s %8d %8d %-10s %-40s %s\n", m.id.c_str(), m.status.c_str(), m.attempts,
                m.failures, m.lastCheckpoint.c_str(), valuesText(m).c_str(), m.exitReason.c_str());
  }
  std::printf("%zu members: %d done, %d running, %d pending, %d failed\n", members.size(),
              counts["done"], counts["running"], counts["pending"], counts["failed"]);
  return kOk;
}

int collect(const fs::path& dir, bool noPlot, const CollectWindow& window) {
  CampaignDb db(dir / "campaign.db", false);
  const auto members = db.members();
  if (window.hasFrom && window.hasTo && !(window.to > window.from)) {
    throw CaseError(fmt::format("--to {} s is not after --from {} s", window.to, window.from));
  }
  std::vector<ScalarSpec> scalars;
  std::string plotY = db.setting("plot_y");
  {
    std::stringstream ss(db.setting("scalars", "mean_T_p"));
    std::string t;
    while (std::getline(ss, t)) {
      ScalarSpec spec = parseScalarLabel(t);
      // --from/--to: for the reductions without a window of their own
      if (spec.reduce != "final" && !spec.from && !spec.to) {
        spec.from = window.hasFrom ? std::optional<double>(window.from) : std::nullopt;
        spec.to = window.hasTo ? std::optional<double>(window.to) : std::nullopt;
        if (t == plotY) {
          plotY = spec.label();
        }
      }
      scalars.push_back(spec);
    }
  }
  std::ostringstream csv;
  csv << "member,status";
  if (!members.empty()) {
    for (const auto& [path, value] : members.front().values) {
      csv << "," << csvField(path);
    }
  }
  for (const auto& s : scalars) {
    csv << "," << csvField(s.label());
  }
  csv << "\n";
  int done = 0;
  for (const auto& m : members) {
    csv << m.id << "," << m.status;
    for (const auto& [path, value] : m.values) {
      csv << "," << csvField(value);
    }
    for (const auto& s : scalars) {
      std::string v;
      if (m.status == "done") {
        try {
          v = scalarOf(fs::path(m.runDir) / "timeseries.csv", s);
        } catch (const UserError& e) {
          throw CaseError(fmt::format("member {}: {}", m.id, e.what())); // bad input: exit 2
        }
      }
      csv << "," << csvField(v);
    }
    csv << "\n";
    done += m.status == "done";
  }
  writeFileAtomic(dir / "summary.csv", csv.str());
  std::printf("summary: %s (%d of %zu members done)\n", (dir / "summary.csv").string().c_str(),
              done, members.size());
  if (noPlot) {
    return kOk;
  }
  const fs::path python = COREDEM_PYTHON;
  const fs::path script = COREDEM_CAMPAIGN_PLOT_SCRIPT;
  if (python.empty() || !fs::exists(python) || !fs::exists(script)) {
    logger("campaign")
        ->warn("no plot: python ('{}') or {} not found", python.string(), script.string());
    return kOk;
  }
  fs::create_directories(dir / "plots");
  const fs::path png = dir / "plots" / "campaign.png";
  std::string groups;
  if (!members.empty()) {
    for (const auto& [path, value] : members.front().values) {
      if (path != db.setting("plot_x")) {
        groups += fmt::format(" --group '{}'", path);
      }
    }
  }
  std::string when;
  for (const auto& sc : scalars) {
    if (sc.label() == plotY) {
      when = whenOf(members, sc);
    }
  }
  // collect.units: the axis unit of a key or column that units.py does not know (param.U_in)
  std::string units;
  {
    std::stringstream ss(db.setting("units"));
    for (std::string t; std::getline(ss, t);) {
      if (!t.empty()) {
        units += fmt::format(" --unit '{}'", t);
      }
    }
  }
  const std::string cmd = fmt::format(
      "'{}' '{}' '{}' --x '{}' --y '{}'{}{} --title '{}' --when '{}' --out '{}' > '{}' 2>&1",
      python.string(), script.string(), (dir / "summary.csv").string(), db.setting("plot_x"), plotY,
      groups, units, db.setting("name"), when, png.string(), (dir / "plots" / "plot.log").string());
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    logger("campaign")->warn("plot script failed (see {})", (dir / "plots" / "plot.log").string());
    return kOk;
  }
  std::printf("plot: %s\n", png.string().c_str());
  return kOk;
}

} // namespace coredem::orchestrator::campaign_detail
