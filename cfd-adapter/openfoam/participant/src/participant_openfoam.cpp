// The OpenFOAM participant's row of the participant table (participants.h) and the hooks of
// the row that need no file of their own: the decomposition of its case for a run on K ranks,
// the walls from its mesh's patches and its initial gas composition. Its pre-flight is in
// preflight_foam.cpp, its generated dictionaries in foam_dictionaries.cpp.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/participant/foam_field.h>
#include <coredem/participant/foam_patches.h>
#include <coredem/participant/openfoam.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

/// Runs an OpenFOAM utility in `work` (log in logDir/<name>.log); throws naming the log on failure.
void runFoamUtility(const std::string& name, std::vector<std::string> args, const fs::path& work,
                    const fs::path& logDir) {
  const fs::path program = findProgram(name);
  COREDEM_CHECK(!program.empty(), "{} (OpenFOAM) not found on PATH: install Debian's openfoam",
                name);
  args.insert(args.begin(), program.string());
  args.insert(args.end(), {"-case", work.string()});
  const char* own = std::getenv("WM_PROJECT_DIR");
  fs::create_directories(logDir);
  ChildProcess p(name, args, {{"WM_PROJECT_DIR", own != nullptr ? own : "/usr/share/openfoam"}},
                 logDir / (name + ".log"));
  COREDEM_CHECK(p.waitFor(std::chrono::minutes(30)), "{} did not finish within 30 min", name);
  COREDEM_CHECK(p.exitCode() == 0, "{} -case {} failed ({}; see {}):\n{}", name, work.string(),
                p.exitReason().value_or("?"), p.logFile().string(), p.logTail());
}

} // namespace

void decomposeOpenFoamCase(const fs::path& work, int ranks, const fs::path& logDir) {
  auto log = coredem::logger("orchestrator");
  const fs::path dict = work / "system" / "decomposeParDict";
  if (!fs::exists(dict)) {
    std::ofstream out(dict);
    out << "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n"
        << "    object decomposeParDict;\n}\n\n// written by coredem for cfd.ranks: " << ranks
        << "\nnumberOfSubdomains " << ranks << ";\n\nmethod simple;\n\nsimpleCoeffs\n{\n    n ("
        << ranks << " 1 1);\n    delta 0.001;\n}\n";
    COREDEM_CHECK(out.good(), "cannot write {}", dict.string());
    log->info("wrote {} (method simple: {} slabs along x)", dict.string(), ranks);
  }
  if (fs::is_directory(work / ("processor" + std::to_string(ranks - 1))) &&
      !fs::exists(work / ("processor" + std::to_string(ranks)))) {
    return;
  }
  if (!fs::exists(work / "constant" / "polyMesh" / "faces") &&
      fs::exists(work / "system" / "blockMeshDict")) {
    runFoamUtility("blockMesh", {}, work, logDir);
  }
  for (const auto& e : fs::directory_iterator(work)) {
    if (e.path().filename().string().rfind("processor", 0) == 0) {
      fs::remove_all(e.path());
    }
  }
  runFoamUtility("decomposePar", {"-force"}, work, logDir);
  log->info("decomposed {} into {} processor folders (decomposePar)", work.string(), ranks);
}

CfdPatchSurface openFoamMeshPatches(const fs::path& caseFolder,
                                    const std::vector<std::string>& patches) {
  FoamPatchSurface s = readFoamPatches(caseFolder, patches);
  return {std::move(s.vertices), std::move(s.triangles), std::move(s.sourceFace),
          std::move(s.sourcePatch)};
}

std::optional<std::vector<double>> openFoamInitialMassFractions(
    const CaseConfig& config, const std::vector<std::string>& species) {
  std::vector<double> read;
  double sum = 0.0;
  for (const auto& n : species) {
    const FoamFieldValues f = readFoamField(config.caseDir / config.cfd.caseFolder / "0" / n);
    if (!f.found || f.values.empty() || f.values.front().patch != "internalField" ||
        !f.values.front().uniform || !(f.values.front().value >= 0.0)) {
      break;
    }
    read.push_back(f.values.front().value);
    sum += read.back();
  }
  if (read.size() == species.size() && std::abs(sum - 1.0) <= kMassFractionSumTol) {
    return read;
  }
  return std::nullopt;
}

ParticipantDescriptor openFoamParticipant() {
  // The OpenFOAM solver (docs/coredemFoam.md): runs in a copy of the OpenFOAM case inside the
  // run folder and learns its peers from the environment (docs/client.md). Its restart file
  // is coredemFoam.restart (the files of its time directory are listed as well).
  ParticipantDescriptor p;
  p.name = "coredemFoam";
  p.summary = "OpenFOAM solver (volume-averaged PIMPLE with the DEM sources)";
  // -epsMin: the clip of the gas fraction the DEM's drag uses too (models: {eps_min}).
  p.args = {"-case", "{work_dir}", "-epsMin", "{eps_min}"};
  p.restartArgs = {"-restart", "{restart_file}"};
  p.timersArgs = {"-timers"}; // writes RUN/timers-cfd.json
  p.env = {{"COREDEM_CONTROL_ENDPOINT", "{control_endpoint}"},
           {"COREDEM_DEM_ENDPOINT", "{dem_endpoint}"},
           {"COREDEM_SESSION", "{session}"},
           {"COREDEM_TIMEOUT_S", "{timeout_s}"},
           {"COREDEM_DEM_SERVER_KEY", "{dem_server_key}"},            // remote DEM behind CURVE
           {"COREDEM_DEM_CLIENT_KEY_FILE", "{dem_client_key_file}"}}; // a path, not the key
  // OpenFOAM reads its etc tree while its libraries load: Debian's unless set.
  p.envDefaults = {{"WM_PROJECT_DIR", "/usr/share/openfoam"}};
  p.restartFile = "coredemFoam.restart";
  p.caseFolder = "an OpenFOAM case folder";
  p.caseFolderMarker = "system/controlDict";
  p.caseFolderHint = "give the folder with system/, constant/ and 0/";
  p.takesBoundaries = true; // inlets, outlets: written into 0/U, 0/p, 0/T, 0/<species>
  p.solvesGas = true; // gas_properties.model ideal_gas: a variable-density gas
  p.workDir = "openfoam";
  p.meshPatches = &openFoamMeshPatches; // walls.meshes[].from_cfd reads its constant/polyMesh
  p.meshFolder = "constant/polyMesh";
  p.initialMassFractions = &openFoamInitialMassFractions; // ideal_gas: 0/<species>
  p.preflight = &checkOpenFoamCase; // gravity, gas model, species and gas state vs case.yaml
  p.generate = &writeGeneratedFoamDictionaries; // ideal_gas: constant/thermophysicalProperties
  p.parallelArgs = {"-parallel"}; // cfd.ranks > 1: mpirun -np K coredemFoam ... -parallel
  p.decompose = &decomposeOpenFoamCase;
  return p;
}

} // namespace coredem::orchestrator
