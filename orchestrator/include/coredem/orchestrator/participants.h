#pragma once
/// @file
/// CFD participants by contract (docs/architecture.md, "Participants"). The orchestrator knows a
/// CFD participant only through one row of the participant table: the value of `cfd.participant`
/// (which is also the program's name), its command template, the environment it reads, the
/// convention that finds its restart file among its checkpoint files, the input folder it takes
/// (`cfd.case`), its capabilities (stage timers, solves the gas, walls from its mesh) and its
/// hooks (pre-flight check, generated files, decomposition). The row type is in
/// participant_descriptor.h. Nothing else in the orchestrator branches on a participant's name.
///
/// Adding a participant: a program that links `cfd-adapter/client`, its unit
/// `cfd-adapter/<name>/participant` (the row and its hooks, declared in
/// `coredem/participant/<name>.h`) and one line in participant_table.cpp (and a line in
/// docs/case-schema.md).
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
#include <coredem/orchestrator/participant_descriptor.h>

namespace coredem::orchestrator {

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

} // namespace coredem::orchestrator
