#pragma once
/// @file
/// Coordinated checkpoints (docs/orchestrator.md, docs/session.md): layout of
/// `checkpoints/<step>/`, the manifest written last (temp file + fsync + rename) with the SHA-256
/// of every file, verification, resume selection and pruning to the last K.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <coredem/common/files.h> // writeFileAtomic (used with the manifests)

namespace coredem::orchestrator {

using coredem::writeFileAtomic; // common/files.h: manifests and records are written with it

/// Whether step `step` gets a coordinated checkpoint: every `everySteps` steps (0 = off), when
/// `everySeconds` of wall time (0 = off) have passed since the last checkpoint, and always at
/// the last step of a run (`lastStep`).
bool checkpointDue(std::int64_t step, bool lastStep, std::int64_t everySteps, double everySeconds,
                   double wallSecondsSinceLast);

/// One file of a checkpoint, path relative to the checkpoint folder.
struct ManifestFile {
  std::string path;
  std::string participant; ///< "dem", "cfd", "orchestrator"
  std::uint64_t bytes = 0;
  std::string sha256;
};

/// Everything needed to resume: the orchestrator's own state is stored exactly
/// (hex floats) so that a resumed run continues bit for bit.
struct Manifest {
  std::int64_t step = 0;
  double time = 0.0;             ///< simulated time after `step` [s]
  double timeCompensation = 0.0; ///< Kahan carry of the TimeHandler
  double lastDt = 0.0;           ///< Δt of the dt policy before end clipping [s]
  double lastCourant = -1.0;     ///< Courant number reported for `step` (-1: none)
  std::string softwareVersion;
  std::string protocolVersion;
  std::string configHash; ///< SHA-256 of the run's case.yaml
  std::string created;    ///< UTC ISO-8601
  std::vector<ManifestFile> files;
};

/// The folder of the checkpoint at `step` below `runDir` (checkpoints/<8-digit step>).
std::filesystem::path checkpointDir(const std::filesystem::path& runDir, std::int64_t step);

/// Hashes the given files (relative to `dir`) into `manifest.files`, then writes
/// `dir/manifest.json` atomically. Throws UserError if a file is missing.
void writeManifest(const std::filesystem::path& dir, Manifest manifest,
                   const std::vector<std::pair<std::string, std::string>>& filesAndParticipants);

/// Reads `dir/manifest.json`. Throws UserError naming the file when missing or malformed.
Manifest readManifest(const std::filesystem::path& dir);

/// Checks every file of the manifest (exists, size, SHA-256). Returns "" when the checkpoint
/// is complete and intact, else why not (naming the file).
std::string verifyCheckpoint(const std::filesystem::path& dir);

/// A checkpoint that was skipped during resume selection and why.
struct SkippedCheckpoint {
  std::filesystem::path dir;
  std::string reason;
};

struct ResumeChoice {
  std::optional<std::filesystem::path> dir; ///< the latest complete, verified checkpoint
  std::optional<Manifest> manifest;
  std::vector<SkippedCheckpoint> skipped; ///< newer ones that were incomplete or corrupted
};

/// Latest checkpoint under runDir/checkpoints whose manifest exists and whose hashes verify.
ResumeChoice selectResumeCheckpoint(const std::filesystem::path& runDir);

/// Keeps the newest `keep` checkpoints that have a manifest; removes older checkpoint
/// folders (complete or not). Never touches folders newer than the newest complete one.
/// Returns the removed folders.
std::vector<std::filesystem::path> pruneCheckpoints(const std::filesystem::path& runDir, int keep);

/// Steps of all folders under runDir/checkpoints, ascending.
std::vector<std::int64_t> listCheckpointSteps(const std::filesystem::path& runDir);

/// Exact text form of a double (hex float, e.g. "0x1.999999999999ap-4") and back.
std::string doubleToHex(double v);
double doubleFromHex(const std::string& text);

/// Current UTC time as ISO-8601 ("2026-11-22T02:19:38Z").
std::string utcNow();

} // namespace coredem::orchestrator
