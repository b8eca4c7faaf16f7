#pragma once
/// @file
/// `coredem verify` (docs/verification.md): runs the verification cases of
/// cases/verification (docs/physics.md §8) through the real processes, compares the particle
/// histories of their snapshots with the analytic solutions (dem/verification/analytic.h, RK4 for
/// radiation), writes DIR/summary.json, one CSV per case and the plots, and prints a table.

#include <filesystem>
#include <string>
#include <vector>

namespace coredem::orchestrator {

struct VerifyOptions {
  std::filesystem::path outDir;   ///< DIR: DIR/<case>/ runs, DIR/summary.json, DIR/plots/
  std::filesystem::path casesDir; ///< empty: found next to the program or in the source tree
  std::vector<std::string> only;  ///< case names to run (empty: all)
  bool list = false;              ///< print the cases and exit
  bool plots = true;              ///< run scripts/plot/verify_plots.py at the end
  bool verbose = false;           ///< keep the session's info log
};

/// The folder that holds the verification cases: `casesDir` when given, else
/// <bin>/../share/coredem/cases/verification, else the source tree's cases/verification.
std::filesystem::path findVerificationCases(const std::filesystem::path& casesDir);

/// Runs `coredem verify`; returns the exit code (0 all pass, 1 a comparison failed or a case
/// did not run, 2 bad input such as an unknown --only name).
int runVerify(const VerifyOptions& options);

} // namespace coredem::orchestrator
