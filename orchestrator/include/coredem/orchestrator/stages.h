#pragma once
/// @file
/// Staged cases (case.yaml `stages`, docs/case-schema.md "Stages"): one command runs a list of
/// stages, e.g. settle with the gas at rest, then fluidize; each stage is the case with the
/// stage's values set (dotted keys, as a campaign member's), and each stage after the first
/// starts from the previous one's end (its run folder as `initial_state`). The run folder:
///
///   RUN/staged.yaml                  the staged case file as given
///   RUN/stages/01-settle/case/       the stage's case.yaml, links to the case folder's files
///   RUN/stages/01-settle/run/        the stage's run folder (coredem run's)
///   RUN/stages/01-settle/done        written when the stage reached its end time
///
/// `coredem resume RUN` skips the stages that are done, resumes the one under way from its
/// checkpoints and starts the rest.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "coredem/orchestrator/session.h"

namespace coredem::orchestrator {

/// One stage: its name and the values it sets on the case.
struct Stage {
  std::string name;
  std::vector<std::pair<std::string, std::string>> values; ///< dotted key, value as YAML text
};

/// The stages of the case file `file` (empty: no `stages` key). Throws CaseError naming the
/// file, line and key of a malformed list.
std::vector<Stage> readStages(const std::filesystem::path& file);

/// The case text of stage `i` of the staged case `text` (from `caseDir`): without `stages`, with
/// the stage's values set; with `fromPrevious`, the particles are those of the previous stage's
/// run (`initial_state: ../../<its folder>/run`), else the case's own. A relative
/// `initial_state` of the case becomes absolute (the stage's case lives in the run folder).
std::string stageCaseText(const std::string& text, const std::filesystem::path& caseDir,
                          const std::vector<Stage>& stages, std::size_t i, bool fromPrevious);

/// The folder name of stage i: "01-settle".
std::string stageFolder(const std::vector<Stage>& stages, std::size_t i);

/// The first stage's case of the staged case `file` (its name names the run folder).
CaseConfig firstStageCase(const std::filesystem::path& file);

/// `coredem check` of a staged case: every stage's case is loaded and checked (`check`), the
/// later stages with the case's own particles (their start does not exist yet).
void checkStages(const std::filesystem::path& file,
                 const std::function<void(const CaseConfig&)>& check);

/// Runs the stages of the staged case `file` into the new run folder `runDir`, or (`resume`)
/// continues the staged run in `runDir`: each stage with `options` (its runDir set), `prepare`
/// called on each stage's loaded case before its run (the participants' input check), `after`
/// with each stage's run folder and exit code. Stops at the first stage that does not end
/// (an error, an interrupt, --stop-after or --walltime) and returns its code.
int runStages(const std::filesystem::path& file, const std::filesystem::path& runDir, bool resume,
              RunOptions options, const std::function<void(const CaseConfig&)>& prepare,
              const std::function<void(const std::filesystem::path&, int)>& after);

} // namespace coredem::orchestrator
