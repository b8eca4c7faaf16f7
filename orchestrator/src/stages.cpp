// Staged cases: the `stages` list of a case file, each stage's case, and running them in order
// (coredem/orchestrator/stages.h, docs/case-schema.md "Stages").
#include "coredem/orchestrator/stages.h"

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/files.h>
#include <coredem/common/log.h>
#include <coredem/common/yaml_section.h>

#include "coredem/orchestrator/campaign.h"
#include "coredem/orchestrator/case_config.h"
#include "coredem/orchestrator/stats.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator {

namespace {

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw CaseError(fmt::format("{}: case file not found", file.string()));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string at(const fs::path& file, const YAML::Mark& m, const std::string& key,
               const std::string& what) {
  return fmt::format("{}:{}:{}: {}: {}", file.string(), m.line + 1, m.column + 1, key, what);
}

std::string flow(const YAML::Node& n) {
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

/// Whether a stage's value names the particles (only the first stage has its own).
bool namesParticles(const std::string& key) {
  return key.rfind("particles", 0) == 0 || key.rfind("initial_state", 0) == 0;
}

/// The last t of a run folder's timeseries.csv (-1: none yet).
double lastTime(const fs::path& runDir) {
  try {
    return timeseriesStats(runDir, {}).runEnd;
  } catch (const UserError&) {
    return -1; // no rows: the stage stopped before its first step
  }
}

/// The stage's case folder: its case.yaml and links to the case folder's other entries (the CFD
/// case, STL files, ...), as a campaign member's.
void writeStageCase(const fs::path& caseDir, const fs::path& stageCase, const std::string& text) {
  fs::create_directories(stageCase);
  for (const auto& e : fs::directory_iterator(caseDir)) {
    const fs::path link = stageCase / e.path().filename();
    if (e.path().filename() != "case.yaml" && !fs::exists(fs::symlink_status(link))) {
      fs::create_symlink(fs::absolute(e.path()), link);
    }
  }
  writeFileAtomic(stageCase / "case.yaml", text);
}

} // namespace

std::vector<Stage> readStages(const fs::path& file) {
  const std::string text = readText(file);
  const YAML::Node root = yaml::parse(text, file.string());
  const YAML::Node list = root.IsMap() ? root["stages"] : YAML::Node();
  std::vector<Stage> stages;
  if (!list) {
    return stages;
  }
  if (!list.IsSequence() || list.size() < 1) {
    throw CaseError(at(file, list.Mark(), "stages",
                       "expected a list of stages, each {name: ..., <dotted key>: value, ...}"));
  }
  // The case without `stages`: each stage's values are tried on it here, so that a key path
  // that does not fit the case is refused with its line.
  YAML::Node base = YAML::Clone(root);
  base.remove("stages");
  YAML::Emitter emitted;
  emitted << base;
  const std::string baseText = std::string(emitted.c_str()) + "\n";
  const std::regex nameRule("[A-Za-z0-9_-]{1,64}");
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node s = list[i];
    const std::string key = fmt::format("stages[{}]", i);
    if (!s.IsMap() || !s["name"] || !s["name"].IsScalar()) {
      throw CaseError(at(file, s.Mark(), key,
                         "expected a mapping with a name, e.g. {name: settle, time.end: 0.5}"));
    }
    Stage st;
    st.name = s["name"].as<std::string>();
    if (!std::regex_match(st.name, nameRule) || !names.insert(st.name).second) {
      throw CaseError(
          at(file, s["name"].Mark(), key + ".name",
             fmt::format("'{}': stage names are unique, 1-64 letters, digits, _ or -", st.name)));
    }
    for (const auto& kv : s) {
      if (!kv.first.IsScalar()) {
        throw CaseError(at(file, kv.first.Mark(), key,
                           "expected dotted keys (e.g. time.end: 0.5) besides name"));
      }
      const std::string k = kv.first.as<std::string>();
      if (k == "name") {
        continue;
      }
      if (k == "stages" || (i > 0 && namesParticles(k))) {
        throw CaseError(at(file, kv.first.Mark(), key + "." + k,
                           k == "stages" ? "stages do not nest"
                                         : "a later stage starts from the previous stage's "
                                           "particles; only the first stage may set them"));
      }
      st.values.emplace_back(k, flow(kv.second));
      try {
        setCaseKey(baseText, k, st.values.back().second);
      } catch (const CaseError& e) {
        throw CaseError(at(file, kv.first.Mark(), key + "." + k, e.what()));
      }
    }
    stages.push_back(std::move(st));
  }
  return stages;
}

std::string stageFolder(const std::vector<Stage>& stages, std::size_t i) {
  return fmt::format("{:02d}-{}", i + 1, stages[i].name);
}

std::string stageCaseText(const std::string& text, const fs::path& caseDir,
                          const std::vector<Stage>& stages, std::size_t i, bool fromPrevious) {
  YAML::Node root = YAML::Load(text);
  root.remove("stages");
  if (root["initial_state"] && !fromPrevious) {
    const fs::path given = root["initial_state"].as<std::string>();
    if (given.is_relative()) {
      root["initial_state"] = (fs::absolute(caseDir) / given).lexically_normal().string();
    }
  }
  if (fromPrevious) {
    root.remove("particles");
    root["initial_state"] = (fs::path("..") / ".." / stageFolder(stages, i - 1) / "run").string();
  }
  YAML::Emitter e;
  e << root;
  std::string out = std::string(e.c_str()) + "\n";
  for (const auto& [key, value] : stages[i].values) {
    out = setCaseKey(out, key, value);
  }
  return fmt::format("# stage {} of {} ('{}') of a staged case, written by coredem\n", i + 1,
                     stages.size(), stages[i].name) +
         out;
}

CaseConfig firstStageCase(const fs::path& file) {
  const fs::path caseDir = fs::absolute(file).parent_path();
  return parseCase(stageCaseText(readText(file), caseDir, readStages(file), 0, false), file,
                   caseDir);
}

void checkStages(const fs::path& file, const std::function<void(const CaseConfig&)>& check) {
  const std::vector<Stage> stages = readStages(file);
  const std::string text = readText(file);
  const fs::path caseDir = fs::absolute(file).parent_path();
  for (std::size_t i = 0; i < stages.size(); ++i) {
    const std::string stageText = stageCaseText(text, caseDir, stages, i, false);
    try {
      check(parseCase(stageText, file, caseDir));
    } catch (const CaseError& e) {
      throw CaseError(fmt::format("stage {} '{}': {}", i + 1, stages[i].name, e.what()));
    }
  }
}

int runStages(const fs::path& file, const fs::path& runDir, bool resume, RunOptions options,
              const std::function<void(const CaseConfig&)>& prepare,
              const std::function<void(const fs::path&, int)>& after) {
  auto log = logger("orchestrator");
  const fs::path staged = resume ? runDir / "staged.yaml" : file;
  const std::vector<Stage> stages = readStages(staged);
  const std::string text = readText(staged);
  fs::path caseDir = fs::absolute(file).parent_path();
  if (resume) {
    caseDir = readText(runDir / "stages" / "case_dir");
  } else {
    fs::create_directories(runDir / "stages");
    writeFileAtomic(runDir / "stages" / "case_dir", caseDir.string());
    writeFileAtomic(runDir / "staged.yaml", text); // last: marks the staged run folder
  }
  for (std::size_t i = 0; i < stages.size(); ++i) {
    const fs::path dir = runDir / "stages" / stageFolder(stages, i);
    if (fs::exists(dir / "done")) {
      log->info("stage {}/{} '{}' is done ({})", i + 1, stages.size(), stages[i].name,
                (dir / "run").string());
      continue;
    }
    RunOptions o = options;
    o.runDir = dir / "run";
    CaseConfig config;
    if (fs::exists(o.runDir / "case.yaml")) {
      log->info("stage {}/{} '{}': resuming {}", i + 1, stages.size(), stages[i].name,
                o.runDir.string());
      config = loadRunCase(o.runDir);
      o.resume = true;
    } else {
      log->info("stage {}/{} '{}'{}", i + 1, stages.size(), stages[i].name,
                i > 0 ? fmt::format(", from the end of '{}'", stages[i - 1].name) : "");
      writeStageCase(caseDir, dir / "case", stageCaseText(text, caseDir, stages, i, i > 0));
      config = loadCase(dir / "case");
      prepare(config);
      o.runDir = prepareRunDir(config, o.runDir);
      o.resume = false;
    }
    const int rc = runSession(config, o);
    after(o.runDir, rc);
    const double end = lastTime(o.runDir);
    if (rc != kExitOk || !(end >= config.endTime * (1.0 - 1e-12))) {
      if (rc == kExitOk) {
        log->info("stage {}/{} '{}' stopped at t = {:.6g} s before its end {:.6g} s; continue "
                  "the stages with 'coredem resume {}'",
                  i + 1, stages.size(), stages[i].name, end, config.endTime, runDir.string());
      }
      return rc;
    }
    writeFileAtomic(dir / "done", fmt::format("{}\n", end));
  }
  return kExitOk;
}

} // namespace coredem::orchestrator
