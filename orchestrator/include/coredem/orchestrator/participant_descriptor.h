#pragma once
/// @file
/// One row of the participant table (participants.h): what the orchestrator knows of a CFD
/// participant. A participant's unit (cfd-adapter/<name>/participant) builds its row, and the
/// hooks the row points to, from these types alone.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// The surface of some patches of a participant's mesh (walls.meshes[].from_cfd): triangles in
/// the winding of the mesh's faces, in the order of the patches asked for.
struct CfdPatchSurface {
  std::vector<double> vertices;         ///< x0,y0,z0,x1,... (m)
  std::vector<std::int32_t> triangles;  ///< 3 vertex indices per triangle
  std::vector<std::int64_t> sourceFace; ///< per triangle: its mesh face (0-based)
  std::vector<std::size_t> sourcePatch; ///< per triangle: its index in the patches asked for
};

/// A mesh whose patches cannot be read: missing, unreadable, malformed, or lacking a patch asked
/// for. The message names the file (or the patch) and what to do; it carries no case.yaml key.
class CfdMeshError : public std::runtime_error {
public:
  using runtime_error::runtime_error;
};

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
  /// True when the participant solves the gas equations (its gas properties can vary:
  /// gas_properties.model ideal_gas is allowed); false: it prescribes the gas with constant
  /// properties.
  bool solvesGas = false;
  /// Folder of the run folder into which `cfd.case` is copied once before the first start
  /// (a resumed run keeps it); `{work_dir}` names it.
  std::string workDir;

  /// Walls from the mesh of `cfd.case` (walls.meshes[].from_cfd): the surface of the named
  /// patches of the case folder `caseFolder` (absolute); throws CfdMeshError. nullptr: the input
  /// has no mesh, and from_cfd is refused.
  CfdPatchSurface (*meshPatches)(const std::filesystem::path& caseFolder,
                                 const std::vector<std::string>& patches) = nullptr;
  /// Folder of that mesh inside `cfd.case`, e.g. constant/polyMesh (the wall's name and path).
  std::string meshFolder;
  /// gas_properties.model ideal_gas: the uniform initial mass fractions of `species` (case.yaml
  /// order) in `cfd.case`, when the input gives all of them and they sum to 1; nullopt, or
  /// nullptr: equal fractions (the participant's pre-flight checks its input).
  std::optional<std::vector<double>> (*initialMassFractions)(
      const CaseConfig& config, const std::vector<std::string>& species) = nullptr;

  /// True when the participant takes case.yaml's inlets and outlets (its `generate` writes them
  /// into its case, its `preflight` checks them against it); false: they are refused.
  bool takesBoundaries = false;
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

} // namespace coredem::orchestrator
