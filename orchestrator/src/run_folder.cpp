// The run folder: creation for a new run, the case of an existing one, the checkpoint a resume
// starts from (with the participants' restart files), and the clean-up after a failure.
#include <ctime>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include <coredem/common/json.h>
#include <coredem/common/version.h>

#include "session_impl.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator {

fs::path chooseRunDir(const std::string& name, const std::optional<fs::path>& out) {
  fs::path dir;
  if (out) {
    dir = *out;
    if (fs::exists(dir / "case.yaml") || fs::exists(dir / "staged.yaml")) {
      throw CaseError(fmt::format("{} already holds a run; continue it with 'coredem resume {}' "
                                  "(from its latest complete checkpoint, or from step 0 when it "
                                  "has none) or choose another --out",
                                  dir.string(), dir.string()));
    }
  } else {
    dir = fs::path("runs") / name;
    if (fs::exists(dir)) {
      const std::time_t now = std::time(nullptr);
      std::tm tm{};
      ::localtime_r(&now, &tm);
      char buf[32];
      std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
      dir = fs::path("runs") / (name + "-" + buf);
      for (int i = 2; fs::exists(dir); ++i) {
        dir = fs::path("runs") / fmt::format("{}-{}-{}", name, buf, i);
      }
    }
  }
  return dir;
}

fs::path prepareRunDir(const CaseConfig& config, const std::optional<fs::path>& out) {
  const fs::path dir = chooseRunDir(config.name, out);
  fs::create_directories(dir / "logs");
  writeFileAtomic(dir / "case.yaml", config.text);
  JsonWriter run;
  run.beginObject()
      .field("case_dir", config.caseDir.string())
      .field("case_file", config.caseFile.filename().string())
      .field("created", utcNow())
      .field("software_version", kVersion)
      .endObject();
  writeFileAtomic(dir / "run.json", run.str());
  return fs::absolute(dir);
}

CaseConfig loadRunCase(const fs::path& runDir) {
  COREDEM_CHECK(fs::is_regular_file(runDir / "case.yaml") &&
                    fs::is_regular_file(runDir / "run.json"),
                "{} is not a run folder (no case.yaml/run.json); give the folder that "
                "'coredem run' created",
                runDir.string());
  std::ifstream in(runDir / "case.yaml", std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  fs::path caseDir = runDir;
  try {
    const YAML::Node run = YAML::LoadFile((runDir / "run.json").string());
    caseDir = run["case_dir"].as<std::string>();
  } catch (const std::exception& e) {
    COREDEM_CHECK(false, "{}: malformed run.json: {}", (runDir / "run.json").string(), e.what());
  }
  CaseConfig c = parseCase(text.str(), runDir / "case.yaml", caseDir);
  return c;
}

ResumePoint findResumePoint(const CaseConfig& config, const fs::path& runDir) {
  auto log = logger("orchestrator.session");
  const ResumeChoice choice = selectResumeCheckpoint(runDir);
  for (const auto& s : choice.skipped) {
    log->warn("skipping checkpoint {}: {}", s.dir.string(), s.reason);
  }
  COREDEM_CHECK(choice.dir.has_value(),
                "{}: no complete checkpoint to resume from; 'coredem resume {}' starts it again "
                "from step 0",
                runDir.string(), runDir.string());
  ResumePoint r;
  r.dir = *choice.dir;
  r.manifest = *choice.manifest;
  const Manifest& m = r.manifest;
  COREDEM_CHECK(m.configHash == config.configHash,
                "{}: case.yaml of the run folder changed since checkpoint {} (config hash {} vs "
                "{}); resume needs the case the run started with",
                runDir.string(), m.step, config.configHash.substr(0, 12),
                m.configHash.substr(0, 12));
  const ParticipantDescriptor& cfd = participant(config.cfd.participant);
  for (const auto& f : m.files) {
    if (f.participant == "dem" && r.demState.empty()) {
      r.demState = r.dir / f.path;
    }
    // The CFD participant's restart file, by its restart-file convention (it may list more
    // files, e.g. an OpenFOAM time directory).
    if (f.participant == "cfd" && r.cfdRestart.empty() && isRestartFile(cfd, f.path)) {
      r.cfdRestart = r.dir / f.path;
    }
  }
  COREDEM_CHECK(!r.demState.empty(), "checkpoint {} has no DEM state file", r.dir.string());
  return r;
}

void removeIncomplete(const fs::path& runDir) {
  for (const auto step : listCheckpointSteps(runDir)) {
    const fs::path d = checkpointDir(runDir, step);
    if (!fs::exists(d / "manifest.json")) {
      logger("orchestrator.session")->info("removing incomplete checkpoint {}", d.string());
      fs::remove_all(d);
    }
  }
  fs::remove_all(runDir / "snapshots" / ".incoming");
}

} // namespace coredem::orchestrator
