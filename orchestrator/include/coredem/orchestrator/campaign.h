#pragma once
/// @file
/// Campaigns (docs/campaigns.md): a sweep file names a base case and the case keys to vary;
/// every member is a complete case folder run by a child `coredem run`, with its state in
/// SQLite (campaign_db.h) so that `coredem campaign resume` continues after any crash.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace coredem::orchestrator {

/// One scalar result per member, taken from its timeseries.csv: `final` (last row), `max`,
/// `min` or `mean` of a column, the last three optionally over a window of simulated time
/// (from, to] (the mean time-weighted, as `coredem stats`). Written as "reduce:column" or
/// "reduce@from..to:column" (either end may be left out) in the sweep file, or as a mapping
/// {mean: column, from: T, to: T}; "column" alone means final.
struct ScalarSpec {
  std::string reduce = "final";
  std::string column;
  std::optional<double> from, to; ///< s
  /// The summary.csv column: "column", "mean:column", "mean@0.5..:column", "max@0.1..0.2:column".
  std::string label() const;
  /// The same scalar without its window ("mean:column").
  std::string baseLabel() const { return reduce == "final" ? column : reduce + ":" + column; }
};

/// Reads a label written by ScalarSpec::label(). Throws CaseError naming the text when it is
/// not one (an unknown reduction, a window on `final`, a window that is not two numbers).
ScalarSpec parseScalarLabel(const std::string& text);

/// Sweep keys with this prefix (`param.U_in`) are not case keys: the value is only recorded
/// with the member (a summary.csv column, a plot axis), e.g. the inlet velocity of a member
/// whose swept key is a whole `cfd.case` folder.
inline constexpr const char* kParamPrefix = "param.";

/// One member: the value (YAML text, flow style) of every varied key, in sweep order.
struct SweepMember {
  std::string id;                                          ///< m000, m001, ...
  std::vector<std::pair<std::string, std::string>> values; ///< key path -> YAML value text
};

/// The `slurm:` section of a sweep file (executor: slurm): what every member's array task
/// asks the scheduler for. Empty strings and zeros are not passed to sbatch.
struct SlurmOptions {
  std::string partition;
  std::string time;      ///< Slurm time limit per task ("30", "2:00:00", "1-00:00:00")
  long timeSeconds = 0;  ///< the same in seconds (0: none given)
  int cpusPerTask = 0;   ///< --cpus-per-task
  std::string gres;      ///< --gres, e.g. gpu:1
  std::string mem;       ///< --mem, e.g. 4G
  int maxConcurrent = 0; ///< array tasks at once (%N); 0: the sweep's concurrency
  int stopMargin = 0;    ///< s before the time limit at which a member checkpoints and stops
  std::vector<std::string> extra; ///< further sbatch arguments, one list entry each
};

/// A validated sweep file.
struct Sweep {
  std::filesystem::path file;     ///< absolute
  std::string text;               ///< its bytes
  std::string name;               ///< campaign name
  std::filesystem::path baseCase; ///< absolute case folder
  std::string executor = "local"; ///< local or slurm
  SlurmOptions slurm;             ///< executor: slurm only
  int concurrency = 1;
  int retries = 0;                     ///< failed attempts tolerated per member beyond the first
  std::vector<std::string> parameters; ///< key paths, in file order
  std::vector<SweepMember> members;
  std::vector<ScalarSpec> scalars;
  std::string plotX, plotY; ///< summary columns of the plot (default: first key, first scalar)
  /// collect.units: the unit of a swept key or a scalar's column for the plot's axis labels
  std::vector<std::pair<std::string, std::string>> units;
  std::vector<std::string> resolvedCases; ///< case.yaml text of every member (validated)
};

/// Loads SWEEP.yaml, resolves every member's case.yaml from the base case and validates it
/// with the case schema. Throws CaseError naming the file, line and key; writes nothing.
Sweep loadSweep(const std::filesystem::path& sweepFile);

/// Sets the key `path` ("gas.T_g", "particles[0].diameter") to the YAML value `valueYaml`
/// in the case text `caseText`; returns the new case text. Missing mapping keys are created,
/// sequence indices must exist. Throws CaseError (message names the path) otherwise.
std::string setCaseKey(const std::string& caseText, const std::string& path,
                       const std::string& valueYaml);

/// Seconds of a Slurm time limit ("minutes", "minutes:seconds", "hours:minutes:seconds",
/// "days-hours", "days-hours:minutes", "days-hours:minutes:seconds"); nullopt when malformed.
std::optional<long> parseSlurmTime(const std::string& text);

/// `coredem campaign run|resume|status|collect|member ...` (argv[0] is "campaign"). Returns the
/// exit code: 0 all members done, 1 some failed or a run-time error, 2 bad input (nothing
/// written), 130 interrupted (resumable).
int campaignMain(int argc, char** argv);

} // namespace coredem::orchestrator
