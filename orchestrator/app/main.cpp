// coredem: the CoReDEM orchestrator CLI (docs/orchestrator.md).
//   coredem run CASE_DIR [--out RUN_DIR] [--auto-restart N] [--stop-after STEP] [--walltime S]
//                        (a staged case: one run per stage, RUN_DIR/stages/NN-name/run)
//   coredem resume RUN_DIR [--auto-restart N] [--stop-after STEP] [--walltime S]
//   coredem inspect FILE
//   coredem render RUN_DIR [--times T,...] [--field F] [--gas-field G] [--out DIR] [--slice F]
//                          [--particles all|none] [--particle-opacity A] [--particle-scale S]
//   coredem check CASE_DIR
//   coredem mesh VESSEL.yaml --out CASE_DIR [--openfoam NAME] [--force]
//   coredem stats RUN_DIR [--from T] [--to T] [--json] [--no-fields]
//   coredem verify [--out DIR] [--only NAME[,NAME]] [--list] [--cases DIR] [--no-plots]
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <coredem/common/files.h>
#include <coredem/common/log.h>
#include <coredem/common/process.h>
#include <coredem/common/version.h>
#include <coredem/orchestrator/campaign.h>
#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/outputs.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/session.h>
#include <coredem/orchestrator/stages.h>
#include <coredem/orchestrator/stats.h>
#include <coredem/orchestrator/verify.h>
#include <coredem/participant/foam_vessel.h>

using namespace coredem::orchestrator;
namespace fs = std::filesystem;

namespace {

/// Whether `file` is a staged case (case.yaml `stages`; a missing file is left to loadCase).
bool isStaged(const fs::path& file) {
  return fs::is_regular_file(file) && !readStages(file).empty();
}

/// A campaign sweep file (docs/campaigns.md: a top-level `base_case:` key), not a case file.
bool isSweepFile(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec) || fs::file_size(file, ec) > (std::uintmax_t{64} << 20)) {
    return false; // the case reader names what is wrong with it
  }
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("base_case", 0) == 0) {
      const auto colon = line.find_first_not_of(" \t", 9);
      return colon != std::string::npos && line[colon] == ':';
    }
  }
  return false;
}

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
              const std::string& gasField, const std::string& outDir,
              const std::vector<std::pair<std::string, std::string>>& extra) {
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
  for (const auto& [flag, value] : extra) { // --slice, --particles, ... when given
    if (!value.empty()) {
      args.insert(args.end(), {flag, value});
    }
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

/// The command line: every subcommand's options.
struct CommandLine {
  std::string caseDir, out, runDir, file;
  int autoRestart = 0;
  std::int64_t stopAfter = -1;
  bool noPlots = false;
  double walltime = 0.0;
  bool timers = false;
  VerifyOptions verifyOpts;
  std::vector<std::string> only;
  std::vector<double> renderTimes;
  std::string renderField, renderGasField, renderOut;
  std::string renderSlice, renderParticles, renderOpacity, renderScale; ///< passed on as given
  double statsFrom = 0.0, statsTo = 0.0;
  CLI::Option *statsFromOpt = nullptr, *statsToOpt = nullptr;
  bool statsJson = false, statsNoFields = false;
  std::string meshFoam = "openfoam";
  bool meshForce = false;
  CLI::App *run = nullptr, *resume = nullptr, *inspect = nullptr, *verify = nullptr,
           *render = nullptr, *check = nullptr, *stats = nullptr, *mesh = nullptr;
};

/// `coredem run` and `coredem resume`.
void addRunCommands(CLI::App& app, CommandLine& c) {
  c.run = app.add_subcommand("run", "validate CASE_DIR/case.yaml and run it");
  c.run->add_option("CASE_DIR", c.caseDir, "case folder with case.yaml (or a case file)")
      ->required();
  c.run->add_option("--out", c.out, "run folder (default runs/<name>, timestamped if it exists)");
  c.run
      ->add_option("--auto-restart", c.autoRestart,
                   "after a participant fault, relaunch and resume from the last checkpoint up "
                   "to N times")
      ->check(CLI::NonNegativeNumber);
  c.run->add_option("--stop-after", c.stopAfter,
                    "stop after this step with a checkpoint (continue with coredem resume)");
  c.run->add_flag("--no-plots", c.noPlots, "do not make the PNG plots at the end");
  c.run
      ->add_option("--walltime", c.walltime,
                   "stop with a checkpoint before this many seconds of wall time (a batch "
                   "limit; continue with coredem resume)")
      ->check(CLI::PositiveNumber);
  c.run->add_flag("--timers", c.timers,
                  "per-stage timers in coredem-dem and coredemFoam: RUN/timers-dem.json, "
                  "RUN/timers-cfd.json and tables in logs/ (docs/performance.md)");

  c.resume = app.add_subcommand(
      "resume",
      "continue a run from its latest complete checkpoint (from step 0 when it has none)");
  c.resume->add_option("RUN_DIR", c.runDir, "run folder created by coredem run")->required();
  c.resume->add_option("--auto-restart", c.autoRestart, "as for run")
      ->check(CLI::NonNegativeNumber);
  c.resume->add_option("--stop-after", c.stopAfter, "as for run");
  c.resume->add_flag("--no-plots", c.noPlots, "as for run");
  c.resume->add_option("--walltime", c.walltime, "as for run")->check(CLI::PositiveNumber);
  c.resume->add_flag("--timers", c.timers, "as for run");
}

/// `coredem inspect`, `verify`, `render` and `check`.
void addToolCommands(CLI::App& app, CommandLine& c) {
  c.inspect = app.add_subcommand("inspect", "summarise a snapshot/state HDF5 file or a checkpoint");
  c.inspect->add_option("FILE", c.file, "HDF5 file, manifest.json or checkpoint folder")
      ->required();

  c.verify = app.add_subcommand(
      "verify", "run the verification cases (docs/physics.md §8) against the analytic solutions");
  c.verify->add_option("--out", c.verifyOpts.outDir, "output folder (default runs/verify)");
  c.verify->add_option("--only", c.only, "only these cases (comma-separated names)")
      ->delimiter(',');
  c.verify->add_flag("--list", c.verifyOpts.list, "list the cases and exit");
  c.verify->add_option("--cases", c.verifyOpts.casesDir,
                       "folder of verification cases (default: the installed or source-tree "
                       "cases/verification)");
  c.verify->add_flag("--no-plots", c.noPlots, "do not make the PNG plots");
  c.verify->add_flag("--verbose", c.verifyOpts.verbose, "keep the runs' info log");

  c.render = app.add_subcommand(
      "render", "draw the particles (spheres at their radius, coloured by a field) over a slice "
                "of a gas field at the same instants with ParaView: a PNG per output time and an "
                "animation (docs/orchestrator.md \"Pictures\")");
  c.render->add_option("RUN_DIR", c.runDir, "run folder with outputs.csv")->required();
  c.render
      ->add_option("--times", c.renderTimes,
                   "times in s (comma-separated; the nearest output of "
                   "each is drawn; default: every output)")
      ->delimiter(',');
  c.render->add_option("--field", c.renderField,
                       "particle field to colour by (temperature, velocity, species_<name>, ...)");
  c.render->add_option("--gas-field", c.renderGasField,
                       "gas field of the slice (alphac, U, p, T, ...)");
  c.render->add_option("--out", c.renderOut, "picture folder (default RUN_DIR/render)");
  c.render
      ->add_option("--slice", c.renderSlice,
                   "gas slice position along the viewing axis, a fraction of the domain depth "
                   "(0 front .. 1 back; default 0.5)")
      ->check(CLI::Range(0.0, 1.0));
  c.render
      ->add_option("--particles", c.renderParticles,
                   "all (default) or none: the gas slice alone, which the particles of a bed "
                   "one cell deep hide")
      ->check(CLI::IsMember({"all", "none"}));
  c.render->add_option("--particle-opacity", c.renderOpacity, "particle opacity 0..1 (default 1)")
      ->check(CLI::Range(0.0, 1.0));
  c.render
      ->add_option("--particle-scale", c.renderScale,
                   "sphere size as a fraction of the particle diameter (0..1], default 1")
      ->check(CLI::Range(0.0, 1.0));

  c.stats = app.add_subcommand(
      "stats", "time-averaged results of a run: mean, std, min, max of every timeseries.csv "
               "column over a window, and time-averaged coupling-cell fields from the snapshots "
               "(RUN_DIR/stats/; docs/orchestrator.md \"Time-averaged results\")");
  c.stats->add_option("RUN_DIR", c.runDir, "run folder created by coredem run")->required();
  c.statsFromOpt =
      c.stats->add_option("--from", c.statsFrom,
                          "start of the window in s (exclude the start-up transient; default: the "
                          "run's start)");
  c.statsToOpt = c.stats->add_option("--to", c.statsTo,
                                     "end of the window in s (default: the run's last row)");
  c.stats->add_flag("--json", c.statsJson, "print the JSON document instead of the table");
  c.stats->add_flag("--no-fields", c.statsNoFields,
                    "only the timeseries statistics (no averaged fields from the snapshots)");

  c.check = app.add_subcommand(
      "check", "validate a case file or a campaign sweep file and exit (0 valid, 2 invalid)");
  c.check
      ->add_option("CASE_DIR", c.caseDir,
                   "case folder with case.yaml (or a case file, or a sweep file: every member)")
      ->required();

  c.mesh = app.add_subcommand(
      "mesh", "a vessel (cylinder with an optional conical bottom, or box) from one description: "
              "the OpenFOAM blockMeshDict and the matching case.yaml grid, DEM walls, inlet and "
              "outlet (docs/case-schema.md \"Vessels\")");
  c.mesh->add_option("VESSEL", c.file, "vessel description (YAML)")->required();
  c.mesh->add_option("--out", c.out, "case folder to write into")->required();
  c.mesh->add_option("--openfoam", c.meshFoam,
                     "its OpenFOAM case folder (cfd.case), written as NAME/system/blockMeshDict");
  c.mesh->add_flag("--force", c.meshForce, "replace a blockMeshDict that differs");
}

/// `coredem mesh`: CASE/<openfoam>/system/blockMeshDict and CASE/vessel.case.yaml.
int meshVessel(const CommandLine& c) {
  const fs::path file = fs::absolute(c.file);
  const VesselFiles f = vesselFiles(readVesselSpec(file), file.filename().string());
  const fs::path dict = fs::path(c.out) / c.meshFoam / "system" / "blockMeshDict";
  const fs::path part = fs::path(c.out) / "vessel.case.yaml";
  for (const auto& [path, text] : {std::pair{dict, f.blockMeshDict}, std::pair{part, f.caseYaml}}) {
    if (fs::exists(path) && !c.meshForce) {
      std::ifstream in(path, std::ios::binary);
      if (std::string((std::istreambuf_iterator<char>(in)), {}) != text) {
        throw coredem::UserError(
            fmt::format("{} exists and differs; give --force to replace it", path.string()));
      }
    }
  }
  fs::create_directories(dict.parent_path());
  for (const auto& [path, text] : {std::pair{dict, f.blockMeshDict}, std::pair{part, f.caseYaml}}) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
  }
  std::cout << f.summary << "\nwrote " << dict.string() << " (run blockMesh, or let coredem run "
            << "do it) and " << part.string() << " (copy into case.yaml):\n\n"
            << f.caseYaml;
  return kExitOk;
}

/// `coredem stats`: RUN/stats/stats.json (+ averages.h5/.xdmf) and the table (or the JSON).
int statsOf(const CommandLine& c) {
  const fs::path runDir = fs::absolute(c.runDir);
  TimeWindow window;
  if (c.statsFromOpt->count() > 0) {
    window.from = c.statsFrom;
  }
  if (c.statsToOpt->count() > 0) {
    window.to = c.statsTo;
  }
  const TimeseriesStats s = timeseriesStats(runDir, window);
  std::optional<FieldAverages> fields;
  const fs::path outDir = runDir / "stats";
  fs::create_directories(outDir);
  std::string note;
  if (!c.statsNoFields) {
    const CaseConfig config = loadRunCase(runDir);
    fields = fieldAverages(runDir, config.grid, s.from, s.to);
    if (fields) {
      writeFieldAverages(*fields, outDir / "averages.h5", outDir / "averages.xdmf");
      note = fmt::format("fields: {} (ParaView; {} snapshots at t = {:.6g} .. {:.6g} s)\n",
                         (outDir / "averages.xdmf").string(), fields->times.size(),
                         fields->times.front(), fields->times.back());
    } else {
      note = fmt::format("fields: none (no particle snapshot in t = [{:.6g}, {:.6g}] s: "
                         "outputs.csv lists the snapshots; set output.every or "
                         "output.every_seconds in case.yaml)\n",
                         s.from, s.to);
    }
  }
  const std::string json = statsJson(s, fields, fields ? "averages.xdmf" : "");
  coredem::writeFileAtomic(outDir / "stats.json", json);
  if (c.statsJson) {
    std::cout << json;
  } else {
    std::cout << statsTable(s) << note << "json: " << (outDir / "stats.json").string() << "\n";
  }
  return kExitOk;
}

/// `coredem stats` with bad input (exit 2) told apart from a fault.
int runStats(const CommandLine& c) {
  try {
    return statsOf(c);
  } catch (const coredem::UserError& e) { // a window outside the run, a folder without a run
    coredem::logger("orchestrator")->error("{}", e.what());
    return kExitBadInput;
  }
}

/// `coredem run` (a new run folder) or `coredem resume`: the coupled run and its plots.
int runOrResume(const CommandLine& c, const std::shared_ptr<spdlog::logger>& log) {
  RunOptions opts;
  opts.autoRestart = c.autoRestart;
  if (c.stopAfter >= 0) {
    opts.stopAfterStep = c.stopAfter;
  }
  opts.tty = ::isatty(STDERR_FILENO) != 0;
  opts.timers = c.timers;
  if (c.walltime > 0.0) {
    opts.walltimeSeconds = c.walltime;
  }
  const auto plots = [&](const fs::path& runDir, int rc) {
    if (rc == kExitOk) {
      std::printf("results: %s (timeseries.csv, outputs.csv, particles.xdmf, checkpoints/)\n",
                  runDir.string().c_str());
    }
    // An interrupted run (SIGINT/SIGTERM) gets its plots too, up to its last step.
    if ((rc == kExitOk || rc == kExitInterrupted) && !c.noPlots) {
      makePlots(runDir, rc == kExitInterrupted);
    }
  };
  // A staged case (case.yaml `stages`): one run per stage in one run folder.
  const fs::path given = *c.run ? caseFileOf(c.caseDir) : fs::path(c.runDir) / "staged.yaml";
  if (*c.run ? isStaged(given) : fs::is_regular_file(given)) {
    std::vector<Stage> stages = readStages(given);
    fs::path runDir;
    if (!*c.run) {
      runDir = fs::absolute(c.runDir);
    } else {
      checkStages(given, checkParticipantInput); // every stage before anything is written
      const CaseConfig first = firstStageCase(given);
      runDir = fs::absolute(
          chooseRunDir(first.name, c.out.empty() ? std::nullopt : std::optional<fs::path>(c.out)));
      log->info("run folder {} ({} stages)", runDir.string(), stages.size());
    }
    return runStages(given, runDir, !*c.run, opts, checkParticipantInput, plots);
  }
  CaseConfig config;
  if (*c.run) {
    config = loadCase(c.caseDir);  // throws CaseError: nothing written yet
    checkParticipantInput(config); // programs, cfd.case, the participant's pre-flight check
    opts.runDir =
        prepareRunDir(config, c.out.empty() ? std::nullopt : std::optional<fs::path>(c.out));
    log->info("run folder {}", opts.runDir.string());
  } else {
    opts.runDir = fs::absolute(c.runDir);
    config = loadRunCase(opts.runDir);
    opts.resume = true;
  }
  const int rc = runSession(config, opts);
  plots(opts.runDir, rc);
  return rc;
}

} // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "campaign") { // docs/campaigns.md
    return campaignMain(argc - 1, argv + 1);
  }
  CLI::App app{"coredem: orchestrates a coupled CFD-DEM run (DEM server + CFD participant)"};
  app.set_version_flag("--version", std::string("coredem ") + coredem::kVersion);
  app.require_subcommand(1);

  CommandLine cmd;
  addRunCommands(app, cmd);
  app.add_subcommand("campaign", "parameter sweeps: campaign run|resume|status|collect ...");
  addToolCommands(app, cmd);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitBadInput;
  }

  auto log = coredem::logger("orchestrator");
  try {
    if (*cmd.inspect) {
      std::cout << inspectSummary(cmd.file);
      return kExitOk;
    }
    if (*cmd.render) {
      return renderRun(fs::absolute(cmd.runDir), cmd.renderTimes, cmd.renderField,
                       cmd.renderGasField, cmd.renderOut,
                       {{"--slice", cmd.renderSlice},
                        {"--particles", cmd.renderParticles},
                        {"--particle-opacity", cmd.renderOpacity},
                        {"--particle-scale", cmd.renderScale}});
    }
    if (*cmd.stats) {
      return runStats(cmd);
    }
    if (*cmd.mesh) {
      return meshVessel(cmd);
    }
    if (*cmd.verify) {
      cmd.verifyOpts.only = cmd.only;
      cmd.verifyOpts.plots = !cmd.noPlots;
      if (cmd.verifyOpts.outDir.empty()) {
        cmd.verifyOpts.outDir = "runs/verify";
      }
      return runVerify(cmd.verifyOpts);
    }
    if (*cmd.check) {
      if (const fs::path file = caseFileOf(cmd.caseDir); isSweepFile(file)) {
        // what `campaign run` refuses before launching anything: every member pre-flighted
        const Sweep sw = loadSweep(file);
        std::cout << file.string() << ": valid sweep (" << sw.members.size() << " members of "
                  << sw.baseCase.string() << ")\n";
        return kExitOk;
      }
      if (const fs::path file = caseFileOf(cmd.caseDir); isStaged(file)) {
        checkStages(file, checkParticipantInput);
        std::cout << file.string() << ": valid (" << readStages(file).size() << " stages)\n";
        return kExitOk;
      }
      const CaseConfig c = loadCase(cmd.caseDir);
      checkParticipantInput(c);
      std::cout << c.caseFile.string() << ": valid\n";
      return kExitOk;
    }
    return runOrResume(cmd, log);
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
