#pragma once
/// @file
/// CFD participants by contract (docs/architecture.md, "Participants"). The orchestrator knows a
/// CFD participant only through one row of the participant table: the value of `cfd.participant`
/// (which is also the program's name), its command template, the environment it reads, the
/// convention that finds its restart file among its checkpoint files, the input folder it takes
/// (`cfd.case`), its capabilities (stage timers, solves the gas, an OpenFOAM case) and its
/// pre-flight check. Nothing else in the orchestrator branches on a participant's name.
///
/// Adding a participant: a program that links `cfd-adapter/client` plus one row in
/// participants.cpp (and a line in docs/case-schema.md).
///
/// Command templates are lists of arguments in which `{name}` is replaced by a launch value:
///
/// | placeholder          | value                                                          |
/// |----------------------|----------------------------------------------------------------|
/// | `{run_case_file}`    | RUN/case.yaml (the run folder's copy of the case file)         |
/// | `{gas_key}`          | `cfd.gas_key` (key of the prescribed-gas section, default gas) |
/// | `{work_dir}`         | RUN/<work folder>: the run folder's copy of `cfd.case`         |
/// | `{control_endpoint}` | the orchestrator's control endpoint                            |
/// | `{dem_endpoint}`     | the DEM server's endpoint                                      |
/// | `{session}`          | the session id                                                 |
/// | `{timeout_s}`        | `cfd.timeout_s`                                                |
/// | `{dem_server_key}`   | the DEM server's CURVE public key (empty without CURVE)        |
/// | `{restart_file}`     | the restart file of the checkpoint resumed from                |

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// One row of the participant table.
struct ParticipantDescriptor {
  /// Value of `cfd.participant`; also the program looked for next to `coredem` or on PATH.
  std::string name;
  /// One line for messages and docs.
  std::string summary;

  /// Command template: the arguments after the program.
  std::vector<std::string> args;
  /// Appended when the run resumes from a checkpoint (uses `{restart_file}`).
  std::vector<std::string> restartArgs;
  /// Appended with stage timers (`coredem run --timers` or `cfd.timers: on`). Empty: the
  /// participant has no stage timers, and `cfd.timers` is refused by the case schema.
  std::vector<std::string> timersArgs;
  /// Environment (templates). A variable whose value expands to nothing is not set.
  std::vector<std::pair<std::string, std::string>> env;
  /// Environment defaults: set only when the orchestrator's own environment lacks them.
  std::vector<std::pair<std::string, std::string>> envDefaults;

  /// Restart-file convention: a shell pattern (fnmatch) for the file name of the participant's
  /// restart file among the files it lists in a checkpoint manifest (the first match is used).
  std::string restartFile;

  /// Input folder `cfd.case`: empty when the participant takes none (the key is then ignored),
  /// else what the folder is, with its article ("an OpenFOAM case folder"); the key is then
  /// required.
  std::string caseFolder;
  /// A file that must exist inside `cfd.case` (pre-flight), e.g. system/controlDict.
  std::string caseFolderMarker;
  /// What to give instead when the marker is missing (pre-flight message).
  std::string caseFolderHint;
  /// True when `cfd.case` is an OpenFOAM case: walls.meshes[].from_cfd may take the DEM walls
  /// from the patches of its constant/polyMesh.
  bool openFoamCase = false;
  /// True when the participant solves the gas equations (its gas properties can vary:
  /// gas_properties.model ideal_gas is allowed); false: it prescribes the gas with constant
  /// properties.
  bool solvesGas = false;
  /// Folder of the run folder into which `cfd.case` is copied once before the first start
  /// (a resumed run keeps it); `{work_dir}` names it.
  std::string workDir;

  /// Writes the input files case.yaml implies into the fresh copy of `cfd.case` (RUN/<workDir>),
  /// after the copy (coredemFoam: constant/thermophysicalProperties of the ideal-gas model);
  /// nullptr: none.
  void (*generate)(const CaseConfig& config, const std::filesystem::path& workDir) = nullptr;
  /// In-process check of the participant's input before anything is written (nullptr: none).
  /// Throws CaseError (exit 2) with file:line:col.
  void (*preflight)(const CaseConfig& config) = nullptr;
  /// Arguments of a decomposed run (cfd.ranks > 1, started as `mpirun -np K PROGRAM ARGS
  /// PARALLEL_ARGS`), e.g. {"-parallel"}; empty: the participant runs on one process only.
  std::vector<std::string> parallelArgs;
  /// Prepares the work folder for `ranks` processes before each start (coredemFoam: the mesh
  /// and decomposePar), logging into `logDir`; null: nothing to prepare.
  void (*decompose)(const std::filesystem::path& workDir, int ranks,
                    const std::filesystem::path& logDir) = nullptr;

  /// True when `cfd.timers` is allowed.
  bool hasTimers() const { return !timersArgs.empty(); }
};

/// The participant table, in the order of the docs (the first row is the default).
const std::vector<ParticipantDescriptor>& participantTable();

/// Names of all participants, in table order.
std::vector<std::string> participantNames();

/// The row of `name`. Throws CaseError naming the known participants when there is none.
const ParticipantDescriptor& participant(const std::string& name);

/// What the session knows when it starts the participant.
struct LaunchInputs {
  std::filesystem::path program; ///< the participant's executable (findProgram)
  std::filesystem::path runDir;  ///< absolute run folder
  std::string controlEndpoint, demEndpoint, session;
  std::string demServerKey;          ///< Z85 CURVE public key, empty without CURVE
  std::string demClientKeyFile;      ///< path of the client secret key, empty: none given
  std::filesystem::path restartFile; ///< empty: a fresh start
  bool timers = false;               ///< `coredem run --timers`
};

/// The command line and the extra environment of a participant start.
struct LaunchCommand {
  std::vector<std::string> argv; ///< argv[0] is the program
  std::map<std::string, std::string> env;
};

/// Expands the row's templates with the case and the launch values.
LaunchCommand launchCommand(const ParticipantDescriptor& p, const CaseConfig& config,
                            const LaunchInputs& in);

/// Replaces every `{name}` of `text` by `values.at(name)`; an unknown name is an internal error
/// (std::logic_error).
std::string expandTemplate(const std::string& text,
                           const std::map<std::string, std::string>& values);

/// Copies `cfd.case` into RUN/<workDir> unless a copy is there already (no-op for a participant
/// without a work folder), then writes the files case.yaml implies into the copy (the row's
/// `generate`). Throws UserError when `cfd.case` lacks the marker file.
void prepareWorkDir(const ParticipantDescriptor& p, const CaseConfig& config,
                    const std::filesystem::path& runDir);

/// True when `path` (a checkpoint file of the participant) is its restart file.
bool isRestartFile(const ParticipantDescriptor& p, const std::filesystem::path& path);

/// Pre-flight of `coredem run` / `coredem check`: coredem-dem (unless dem.endpoint names a
/// running server) and the participant's program exist (UserError, exit 1), `cfd.case` holds
/// the marker file and the participant's own pre-flight check passes (CaseError, exit 2).
void checkParticipantInput(const CaseConfig& config);

/// Pre-flight of the prescribed-gas participant: the gas section (`cfd.gas_key`) of the case
/// file, validated in-process by the gas model library. Throws CaseError with file:line:col.
void checkGasSection(const CaseConfig& config);

} // namespace coredem::orchestrator
