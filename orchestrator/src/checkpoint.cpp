#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/check.h>
#include <coredem/common/json.h>
#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/sha256.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

std::string formatDouble(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

} // namespace

bool checkpointDue(std::int64_t step, bool lastStep, std::int64_t everySteps, double everySeconds,
                   double wallSecondsSinceLast) {
  return lastStep || (everySteps > 0 && step % everySteps == 0) ||
         (everySeconds > 0.0 && wallSecondsSinceLast >= everySeconds);
}

fs::path checkpointDir(const fs::path& runDir, std::int64_t step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%08lld", static_cast<long long>(step));
  return runDir / "checkpoints" / buf;
}

std::string doubleToHex(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

double doubleFromHex(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  COREDEM_CHECK(end && *end == '\0' && !text.empty(), "'{}' is not a number", text);
  return v;
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void writeManifest(const fs::path& dir, Manifest manifest,
                   const std::vector<std::pair<std::string, std::string>>& filesAndParticipants) {
  manifest.files.clear();
  for (const auto& [rel, who] : filesAndParticipants) {
    const fs::path file = dir / rel;
    COREDEM_CHECK(fs::is_regular_file(file),
                  "checkpoint file '{}' reported by the {} participant does not exist",
                  file.string(), who);
    manifest.files.push_back({rel, who, fs::file_size(file), sha256File(file)});
    fsyncPath(file, false);
  }
  if (manifest.created.empty()) {
    manifest.created = utcNow();
  }
  // One member a line, one file a line (docs/orchestrator.md "Checkpoints"); time also as a
  // hex float, which resume reads, so that the orchestrator's state comes back bit for bit.
  JsonWriter js;
  js.beginObject()
      .field("format", "coredem-checkpoint-1")
      .field("step", manifest.step)
      .key("time")
      .raw(formatDouble(manifest.time))
      .field("time_hex", doubleToHex(manifest.time))
      .field("time_compensation_hex", doubleToHex(manifest.timeCompensation))
      .field("last_dt_hex", doubleToHex(manifest.lastDt))
      .field("last_courant_hex", doubleToHex(manifest.lastCourant))
      .field("software_version", manifest.softwareVersion)
      .field("protocol_version", manifest.protocolVersion)
      .field("config_hash", manifest.configHash)
      .field("created", manifest.created)
      .key("files")
      .beginArray();
  for (const auto& f : manifest.files) {
    js.raw(fmt::format("{{\"path\": \"{}\", \"participant\": \"{}\", \"bytes\": {}, "
                       "\"sha256\": \"{}\"}}",
                       jsonEscape(f.path), jsonEscape(f.participant), f.bytes,
                       jsonEscape(f.sha256)));
  }
  js.endArray().endObject();
  writeFileAtomic(dir / "manifest.json", js.str());
}

Manifest readManifest(const fs::path& dir) {
  const fs::path file = dir / "manifest.json";
  COREDEM_CHECK(fs::is_regular_file(file), "{}: no manifest (the checkpoint is incomplete)",
                file.string());
  Manifest m;
  try {
    const YAML::Node root = YAML::LoadFile(file.string()); // JSON is YAML flow style
    COREDEM_CHECK(root["format"] && root["format"].as<std::string>() == "coredem-checkpoint-1",
                  "{}: not a coredem checkpoint manifest (format)", file.string());
    m.step = root["step"].as<std::int64_t>();
    m.time = doubleFromHex(root["time_hex"].as<std::string>());
    m.timeCompensation = doubleFromHex(root["time_compensation_hex"].as<std::string>());
    m.lastDt = doubleFromHex(root["last_dt_hex"].as<std::string>());
    m.lastCourant = doubleFromHex(root["last_courant_hex"].as<std::string>());
    m.softwareVersion = root["software_version"].as<std::string>();
    m.protocolVersion = root["protocol_version"].as<std::string>();
    m.configHash = root["config_hash"].as<std::string>();
    m.created = root["created"].as<std::string>();
    for (const auto& f : root["files"]) {
      m.files.push_back({f["path"].as<std::string>(), f["participant"].as<std::string>(),
                         f["bytes"].as<std::uint64_t>(), f["sha256"].as<std::string>()});
    }
  } catch (const YAML::Exception& e) {
    COREDEM_CHECK(false, "{}: malformed manifest: {}", file.string(), e.what());
  }
  return m;
}

std::string verifyCheckpoint(const fs::path& dir) {
  Manifest m;
  try {
    m = readManifest(dir);
  } catch (const UserError& e) {
    return e.what();
  }
  for (const auto& f : m.files) {
    const fs::path file = dir / f.path;
    if (!fs::is_regular_file(file)) {
      return fmt::format("{}: file listed in the manifest is missing", file.string());
    }
    if (fs::file_size(file) != f.bytes) {
      return fmt::format("{}: size {} bytes, manifest says {} (truncated or modified)",
                         file.string(), fs::file_size(file), f.bytes);
    }
    if (sha256File(file) != f.sha256) {
      return fmt::format("{}: SHA-256 does not match the manifest (corrupted)", file.string());
    }
  }
  return "";
}

std::vector<std::int64_t> listCheckpointSteps(const fs::path& runDir) {
  std::vector<std::int64_t> steps;
  const fs::path root = runDir / "checkpoints";
  if (!fs::is_directory(root)) {
    return steps;
  }
  for (const auto& entry : fs::directory_iterator(root)) {
    if (!entry.is_directory()) {
      continue;
    }
    const std::string name = entry.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) {
      continue;
    }
    steps.push_back(std::stoll(name));
  }
  std::sort(steps.begin(), steps.end());
  return steps;
}

ResumeChoice selectResumeCheckpoint(const fs::path& runDir) {
  ResumeChoice choice;
  auto steps = listCheckpointSteps(runDir);
  for (auto it = steps.rbegin(); it != steps.rend(); ++it) {
    const fs::path dir = checkpointDir(runDir, *it);
    const std::string problem = verifyCheckpoint(dir);
    if (problem.empty()) {
      choice.dir = dir;
      choice.manifest = readManifest(dir);
      break;
    }
    choice.skipped.push_back({dir, problem});
  }
  return choice;
}

std::vector<fs::path> pruneCheckpoints(const fs::path& runDir, int keep) {
  std::vector<fs::path> removed;
  const auto steps = listCheckpointSteps(runDir);
  int complete = 0;
  bool newestCompleteSeen = false;
  for (auto it = steps.rbegin(); it != steps.rend(); ++it) {
    const fs::path dir = checkpointDir(runDir, *it);
    const bool hasManifest = fs::is_regular_file(dir / "manifest.json");
    if (!newestCompleteSeen) {
      if (!hasManifest) {
        continue; // newer than any complete checkpoint: maybe being written; leave it
      }
      newestCompleteSeen = true;
    }
    if (hasManifest && complete < keep) {
      ++complete;
      continue;
    }
    fs::remove_all(dir);
    removed.push_back(dir);
  }
  return removed;
}

} // namespace coredem::orchestrator
