// coredem: the CoReDEM orchestrator CLI (docs/orchestrator.md).
//   coredem run CASE_DIR [--out RUN_DIR] [--auto-restart N] [--stop-after STEP] [--walltime S]
//   coredem resume RUN_DIR [--auto-restart N] [--stop-after STEP] [--walltime S]
//   coredem inspect FILE
//   coredem render RUN_DIR [--times T,...] [--field F] [--gas-field G] [--out DIR]
//   coredem check CASE_DIR
//   coredem verify [--out DIR] [--only NAME[,NAME]] [--list] [--cases DIR] [--no-plots]
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/common/version.h>
#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/outputs.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/session.h>
#include <coredem/orchestrator/verify.h>

using namespace coredem::orchestrator;
namespace fs = std::filesystem;

namespace {

/// Runs scripts/plot/plot_run.py with the Python that CMake found (COREDEM_PYTHON); a failure
/// is a warning, never an error of the run.
void makePlots(const fs::path& runDir, bool interrupted) {
  auto log = coredem::logger("orchestrator");
  const fs::path python = COREDEM_PYTHON;
  const fs::path script = COREDEM_PLOT_SCRIPT;
  if (python.empty() || !fs::exists(python) || !fs::exists(script)) {
    log->warn("no plots: python with matplotlib/h5py ('{}') or {} not found", python.string(),
              script.string());
    return;
  }
  std::vector<std::string> args = {python.string(), script.string(), runDir.string()};
  if (interrupted) {
    args.push_back("--interrupted");
  }
  coredem::ChildProcess plot("plot script", args, {}, runDir / "logs" / "plot.log");
  if (!plot.waitFor(std::chrono::seconds(120))) {
    plot.stop();
  }
  if (plot.exitCode() != 0) {
    log->warn("plot script failed (see {})", (runDir / "logs" / "plot.log").string());
    return;
  }
  std::printf("plots: %s\n", (runDir / "plots").string().c_str());
}

/// `coredem render`: scripts/render/render_run.py under ParaView's pvbatch (found at configure
/// time or on PATH), on a private Xvfb when there is no display.
int renderRun(const fs::path& runDir, const std::vector<double>& times, const std::string& field,
              const std::string& gasField, const std::string& outDir) {
  auto log = coredem::logger("orchestrator");
  fs::path pvbatch = COREDEM_PVBATCH;
  if (pvbatch.empty() || !fs::exists(pvbatch)) {
    pvbatch = coredem::findProgram("pvbatch");
  }
  if (pvbatch.empty()) {
    log->error("coredem render needs ParaView's pvbatch, which was found neither at configure time "
               "nor on PATH: install ParaView (Debian: apt-get install paraview xvfb, or "
               "scripts/install-deps.sh) or put pvbatch on PATH");
    return kExitBadInput;
  }
  const fs::path script = COREDEM_RENDER_SCRIPT;
  if (!fs::exists(script)) {
    log->error("the render script {} is missing (a build outside its source tree?)",
               script.string());
    return kExitBadInput;
  }
  if (!fs::exists(runDir / "outputs.csv")) {
    log->error("{}: no outputs.csv: give a run folder whose case writes synchronized outputs "
               "(output.every or output.every_seconds in case.yaml)",
               runDir.string());
    return kExitBadInput;
  }
  // Without a display pvbatch runs on a private virtual X server (scripts/render/with-xvfb.sh).
  std::vector<std::string> args;
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    if (coredem::findProgram("Xvfb").empty()) {
      log->error("no display (DISPLAY unset) and no Xvfb: pvbatch needs one of them "
                 "(Debian: apt-get install xvfb)");
      return kExitBadInput;
    }
    args = {"/bin/sh", (script.parent_path() / "with-xvfb.sh").string()};
  }
  args.insert(args.end(), {pvbatch.string(), script.string(), runDir.string()});
  if (!times.empty()) {
    std::string t;
    for (std::size_t i = 0; i < times.size(); ++i) {
      t += (i ? "," : "") + fmt::format("{}", times[i]);
    }
    args.insert(args.end(), {"--times", t});
  }
  if (!field.empty()) {
    args.insert(args.end(), {"--field", field});
  }
  if (!gasField.empty()) {
    args.insert(args.end(), {"--gas-field", gasField});
  }
  const fs::path out = outDir.empty() ? runDir / "render" : fs::absolute(outDir);
  args.insert(args.end(), {"--out", out.string()});
  fs::create_directories(out);
  const fs::path logFile = out / "render.log";
  // A virtual X server that is not ready in time (a loaded machine) makes pvbatch abort with
  // "bad X server connection": one more try.
  int exitCode = -1;
  for (int attempt = 0; attempt < 2; ++attempt) {
    fs::remove(logFile);
    coredem::ChildProcess render("pvbatch", args, {}, logFile);
    render.waitFor(std::chrono::hours(24));
    exitCode = render.exitCode();
    std::ifstream in(logFile);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (exitCode == 0 || text.find("bad X server connection") == std::string::npos) {
      break;
    }
    log->warn("pvbatch lost its X server; trying once more");
  }
  if (exitCode != 0) {
    std::ifstream in(logFile);
    std::string line, last;
    while (std::getline(in, line)) {
      if (!line.empty()) {
        last = line;
      }
    }
    log->error("render failed ({}): {}", logFile.string(), last);
    return kExitFault;
  }
  std::printf("pictures: %s (log %s)\n", out.string().c_str(), logFile.string().c_str());
  return kExitOk;
}

} // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "campaign") { // docs/campaigns.md
    return campaignMain(argc - 1, argv + 1);
  }
  CLI::App app{"coredem: orchestrates a coupled CFD-DEM run (DEM server + CFD participant)"};
  app.set_version_flag("--version", std::string("coredem ") + coredem::kVersion);
  app.require_subcommand(1);

  std::string caseDir, out, runDir, file;
  int autoRestart = 0;
  std::int64_t stopAfter = -1;
  bool noPlots = false;

  auto* run = app.add_subcommand("run", "validate CASE_DIR/case.yaml and run it");
  run->add_option("CASE_DIR", caseDir, "case folder with case.yaml (or a case file)")->required();
  run->add_option("--out", out, "run folder (default runs/<name>, timestamped if it exists)");
  run->add_option("--auto-restart", autoRestart,
                  "after a participant fault, relaunch and resume from the last checkpoint up "
                  "to N times")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--stop-after", stopAfter,
                  "stop after this step with a checkpoint (continue with coredem resume)");
  run->add_flag("--no-plots", noPlots, "do not make the PNG plots at the end");
  double walltime = 0.0;
  run->add_option("--walltime", walltime,
                  "stop with a checkpoint before this many seconds of wall time (a batch "
                  "limit; continue with coredem resume)")
      ->check(CLI::PositiveNumber);
  bool timers = false;
  run->add_flag("--timers", timers,
                "per-stage timers in coredem-dem and coredemFoam: RUN/timers-dem.json, "
                "RUN/timers-cfd.json and tables in logs/ (docs/performance.md)");

  auto* resume = app.add_subcommand(
      "resume",
      "continue a run from its latest complete checkpoint (from step 0 when it has none)");
  resume->add_option("RUN_DIR", runDir, "run folder created by coredem run")->required();
  resume->add_option("--auto-restart", autoRestart, "as for run")->check(CLI::NonNegativeNumber);
  resume->add_option("--stop-after", stopAfter, "as for run");
  resume->add_flag("--no-plots", noPlots, "as for run");
  resume->add_option("--walltime", walltime, "as for run")->check(CLI::PositiveNumber);
  resume->add_flag("--timers", timers, "as for run");

  app.add_subcommand("campaign", "parameter sweeps: campaign run|resume|status|collect ...");
  auto* inspect =
      app.add_subcommand("inspect", "summarise a snapshot/state HDF5 file or a checkpoint");
  inspect->add_option("FILE", file, "HDF5 file, manifest.json or checkpoint folder")->required();

  VerifyOptions verifyOpts;
  std::vector<std::string> only;
  auto* verify = app.add_subcommand(
      "verify", "run the verification cases (docs/physics.md §8) against the analytic solutions");
  verify->add_option("--out", verifyOpts.outDir, "output folder (default runs/verify)");
  verify->add_option("--only", only, "only these cases (comma-separated names)")->delimiter(',');
  verify->add_flag("--list", verifyOpts.list, "list the cases and exit");
  verify->add_option("--cases", verifyOpts.casesDir,
                     "folder of verification cases (default: the installed or source-tree "
                     "cases/verification)");
  verify->add_flag("--no-plots", noPlots, "do not make the PNG plots");
  verify->add_flag("--verbose", verifyOpts.verbose, "keep the runs' info log");

  std::vector<double> renderTimes;
  std::string renderField, renderGasField, renderOut;
  auto* render = app.add_subcommand(
      "render", "draw the particles (spheres at their radius, coloured by a field) over a slice "
                "of a gas field at the same instants with ParaView: a PNG per output time and an "
                "animation (docs/orchestrator.md \"Pictures\")");
  render->add_option("RUN_DIR", runDir, "run folder with outputs.csv")->required();
  render
      ->add_option("--times", renderTimes,
                   "times in s (comma-separated; the nearest output of "
                   "each is drawn; default: every output)")
      ->delimiter(',');
  render->add_option("--field", renderField,
                     "particle field to colour by (temperature, velocity, species_<name>, ...)");
  render->add_option("--gas-field", renderGasField,
                     "gas field of the slice (alphac, U, p, T, ...)");
  render->add_option("--out", renderOut, "picture folder (default RUN_DIR/render)");

  auto* check = app.add_subcommand("check", "validate a case file and exit (0 valid, 2 invalid)");
  check->add_option("CASE_DIR", caseDir, "case folder with case.yaml (or a case file)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitBadInput;
  }

  auto log = coredem::logger("orchestrator");
  try {
    if (*inspect) {
      std::cout << inspectSummary(file);
      return kExitOk;
    }
    if (*render) {
      return renderRun(fs::absolute(runDir), renderTimes, renderField, renderGasField, renderOut);
    }
    if (*verify) {
      verifyOpts.only = only;
      verifyOpts.plots = !noPlots;
      if (verifyOpts.outDir.empty()) {
        verifyOpts.outDir = "runs/verify";
      }
      return runVerify(verifyOpts);
    }
    if (*check) {
      const CaseConfig c = loadCase(caseDir);
      checkParticipantInput(c);
      std::cout << c.caseFile.string() << ": valid\n";
      return kExitOk;
    }
    RunOptions opts;
    opts.autoRestart = autoRestart;
    if (stopAfter >= 0) {
      opts.stopAfterStep = stopAfter;
    }
    opts.tty = ::isatty(STDERR_FILENO) != 0;
    opts.timers = timers;
    if (walltime > 0.0) {
      opts.walltimeSeconds = walltime;
    }
    CaseConfig config;
    if (*run) {
      config = loadCase(caseDir);    // throws CaseError: nothing written yet
      checkParticipantInput(config); // programs, cfd.case, the participant's pre-flight check
      opts.runDir =
          prepareRunDir(config, out.empty() ? std::nullopt : std::optional<fs::path>(out));
      log->info("run folder {}", opts.runDir.string());
    } else {
      opts.runDir = fs::absolute(runDir);
      config = loadRunCase(opts.runDir);
      opts.resume = true;
    }
    const int rc = runSession(config, opts);
    if (rc == kExitOk) {
      std::printf("results: %s (timeseries.csv, outputs.csv, particles.xdmf, checkpoints/)\n",
                  opts.runDir.string().c_str());
    }
    // An interrupted run (SIGINT/SIGTERM) gets its plots too, up to its last step.
    if ((rc == kExitOk || rc == kExitInterrupted) && !noPlots) {
      makePlots(opts.runDir, rc == kExitInterrupted);
    }
    return rc;
  } catch (const CaseError& e) {
    log->error("{}", e.what());
    return kExitBadInput;
  } catch (const coredem::UserError& e) {
    log->error("{}", e.what());
    return kExitFault;
  } catch (const std::exception& e) {
    log->error("internal error: {}", e.what());
    return kExitFault;
  }
}
