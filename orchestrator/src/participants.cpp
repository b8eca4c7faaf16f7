// The generic code that launches, prepares and checks a row of the participant table
// (participants.h; the table is participant_table.cpp).
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include <fnmatch.h>
#include <unistd.h>

#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/preflight.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {

std::string expandTemplate(const std::string& text,
                           const std::map<std::string, std::string>& values) {
  std::string out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t open = text.find('{', pos);
    if (open == std::string::npos) {
      out += text.substr(pos);
      return out;
    }
    const std::size_t close = text.find('}', open);
    if (close == std::string::npos) {
      throw std::logic_error("participant template '" + text + "': unclosed '{'");
    }
    const std::string name = text.substr(open + 1, close - open - 1);
    const auto it = values.find(name);
    if (it == values.end()) {
      throw std::logic_error("participant template '" + text + "': unknown placeholder {" + name +
                             "}");
    }
    out += text.substr(pos, open - pos) + it->second;
    pos = close + 1;
  }
}

LaunchCommand launchCommand(const ParticipantDescriptor& p, const CaseConfig& config,
                            const LaunchInputs& in) {
  const std::map<std::string, std::string> values = {
      {"run_case_file", (in.runDir / "case.yaml").string()},
      {"gas_key", config.cfd.gasKey},
      {"work_dir", p.workDir.empty() ? std::string() : (in.runDir / p.workDir).string()},
      {"control_endpoint", in.controlEndpoint},
      {"dem_endpoint", in.demEndpoint},
      {"session", in.session},
      {"timeout_s", fmt::format("{}", config.cfd.timeoutSeconds)},
      {"eps_min", fmt::format("{}", config.epsMin)}, // models: {eps_min}, shortest round trip
      {"dem_server_key", in.demServerKey},
      {"dem_client_key_file", in.demClientKeyFile},
      {"restart_file", in.restartFile.string()}};
  LaunchCommand cmd;
  const int ranks = config.cfd.ranks;
  if (ranks > 1) {
    // Debian's OpenMPI: oversubscription allowed (more ranks than cores), root allowed (CI
    // containers); the COREDEM_* environment is passed to every rank with -x.
    const fs::path mpirun = findProgram("mpirun");
    COREDEM_CHECK(!mpirun.empty(), "cfd.ranks: {} needs mpirun (Debian's openmpi-bin) on PATH",
                  ranks);
    cmd.argv = {mpirun.string(), "-np", std::to_string(ranks), "--oversubscribe"};
    if (::geteuid() == 0) {
      cmd.argv.push_back("--allow-run-as-root");
    }
  }
  cmd.argv.push_back(in.program.string());
  auto append = [&](const std::vector<std::string>& args) {
    for (const auto& a : args) {
      cmd.argv.push_back(expandTemplate(a, values));
    }
  };
  append(p.args);
  if (!in.restartFile.empty()) {
    append(p.restartArgs);
  }
  if (in.timers || config.cfd.timers) {
    append(p.timersArgs);
  }
  for (const auto& [key, text] : p.env) {
    std::string v = expandTemplate(text, values);
    if (!v.empty()) {
      cmd.env[key] = std::move(v);
    }
  }
  for (const auto& [key, value] : p.envDefaults) {
    const char* own = std::getenv(key.c_str());
    cmd.env[key] = own != nullptr ? own : value;
  }
  if (ranks > 1) {
    append(p.parallelArgs);
    // -x NAME for every variable of the participant's environment (mpirun starts the ranks).
    std::vector<std::string> exports;
    for (const auto& [key, value] : cmd.env) {
      exports.insert(exports.end(), {"-x", key});
    }
    cmd.argv.insert(cmd.argv.begin() + 4 + (::geteuid() == 0 ? 1 : 0), exports.begin(),
                    exports.end());
    cmd.env.insert_or_assign("OMPI_MCA_rmaps_base_oversubscribe", std::string("1"));
  }
  return cmd;
}

void prepareWorkDir(const ParticipantDescriptor& p, const CaseConfig& config,
                    const fs::path& runDir) {
  if (p.workDir.empty()) {
    return;
  }
  const fs::path work = runDir / p.workDir;
  const auto decompose = [&] {
    if (config.cfd.ranks > 1 && p.decompose != nullptr) {
      p.decompose(work, config.cfd.ranks, runDir / "logs");
    }
  };
  if (!p.caseFolderMarker.empty() && fs::exists(work / p.caseFolderMarker)) {
    decompose(); // made by the first start; a resumed run keeps it (and its decomposition)
    return;
  }
  const fs::path src = config.caseDir / config.cfd.caseFolder;
  COREDEM_CHECK(p.caseFolderMarker.empty() || fs::is_regular_file(src / p.caseFolderMarker),
                "cfd.case: {} is not {} (no {})", src.string(), p.caseFolder, p.caseFolderMarker);
  fs::create_directories(work);
  fs::copy(src, work, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  if (p.generate != nullptr) {
    p.generate(config, work); // e.g. constant/thermophysicalProperties (ideal_gas)
  }
  decompose();
}

bool isRestartFile(const ParticipantDescriptor& p, const fs::path& path) {
  return !p.restartFile.empty() &&
         ::fnmatch(p.restartFile.c_str(), path.filename().c_str(), 0) == 0;
}

void checkParticipantInput(const CaseConfig& config) {
  if (config.dem.endpoint.empty()) {
    COREDEM_CHECK(!findProgram("coredem-dem").empty(),
                  "coredem-dem not found next to coredem ({}) or on PATH; build it (cmake --build "
                  "build --target coredem-dem) or name a running server in dem.endpoint",
                  executableDir().string());
  }
  const ParticipantDescriptor& p = participant(config.cfd.participant);
  COREDEM_CHECK(!findProgram(p.name).empty(),
                "{} not found next to coredem ({}) or on PATH; build it (cmake --build "
                "build --target {})",
                p.name, executableDir().string(), p.name);
  if (!p.caseFolder.empty() && !p.caseFolderMarker.empty()) {
    const fs::path src = config.caseDir / config.cfd.caseFolder;
    if (!fs::is_regular_file(src / p.caseFolderMarker)) {
      throw CaseError(fmt::format("{}: cfd.case: {} is not {} (no {}); {}, relative to the "
                                  "case folder",
                                  config.caseFile.string(), src.string(), p.caseFolder,
                                  p.caseFolderMarker, p.caseFolderHint));
    }
  }
  if (p.preflight != nullptr) {
    p.preflight(config);
  }
  for (const auto& w : checkCaseConsistency(config)) {
    logger("orchestrator")->warn("{}", w);
  }
}

} // namespace coredem::orchestrator
