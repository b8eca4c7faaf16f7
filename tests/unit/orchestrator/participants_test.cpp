// The participant table (participants.h): each row's command line, environment, restart file
// and work folder; an unknown participant names the known ones; the pre-flight check of the
// prescribed-gas participant validates the gas section in-process with file:line:col.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include <coredem/orchestrator/case_config.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/participant/gas.h>

#include "case_text.h"

using namespace coredem::orchestrator;
using coredem::orchestrator::test::errorOf;
using coredem::orchestrator::test::replace;
namespace fs = std::filesystem;

namespace {

const char* kCase = R"(name: participants
time: {end: 0.01, dt: 1.0e-4}
grid: {spacing: [0.01, 0.01, 0.01], cells: [2, 2, 4]}
materials:
  - {name: glass, density: 2500, k_n: 1000, e_n: 0.9}
particles:
  - material: glass
    count: 10
    diameter: 2.0e-3
    region: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}
cfd: {participant: coredem-gas, timeout_s: 30}
gas:
  T_g: 500.0
  u_g: [0, 0, 0.1]
)";

/// A scratch folder for one test, removed at the end.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() /
             ("coredem-participants-" + name + "-" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

/// The case text written to DIR/case.yaml and parsed from there.
CaseConfig caseIn(const fs::path& dir, const std::string& text) {
  std::ofstream(dir / "case.yaml") << text;
  return loadCase(dir);
}

LaunchInputs inputs(const fs::path& runDir) {
  LaunchInputs in;
  in.program = "/opt/coredem/bin/participant";
  in.runDir = runDir;
  in.controlEndpoint = "tcp://127.0.0.1:5001";
  in.demEndpoint = "tcp://127.0.0.1:5002";
  in.session = "s-123";
  return in;
}

} // namespace

TEST(Participants, TableHasBothParticipantsWithDistinctNames) {
  const auto names = participantNames();
  EXPECT_EQ(names, (std::vector<std::string>{"coredem-gas", "coredemFoam"}));
  EXPECT_EQ(names.front(), CfdConfig{}.participant) << "the first row is the default";
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  for (const auto& p : participantTable()) {
    EXPECT_FALSE(p.summary.empty()) << p.name;
    EXPECT_FALSE(p.restartFile.empty()) << p.name;
    EXPECT_FALSE(p.restartArgs.empty()) << p.name;
  }
}

TEST(Participants, UnknownParticipantNamesTheKnownOnes) {
  try {
    participant("coredemFaom");
    FAIL() << "no error";
  } catch (const CaseError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'coredemFaom'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("coredem-gas, coredemFoam"), std::string::npos) << msg;
  }
  // The case schema refuses it with file:line:col and the same list.
  const std::string msg =
      errorOf(replace(kCase, "participant: coredem-gas", "participant: fluent"));
  EXPECT_NE(msg.find("cases/x/case.yaml:11:20: cfd.participant: 'fluent' is not allowed; allowed: "
                     "coredem-gas, coredemFoam"),
            std::string::npos)
      << msg;
}

TEST(Participants, PrescribedGasCommandLineAndEnvironment) {
  const CaseConfig c = parseCase(kCase, "case.yaml", fs::temp_directory_path());
  const auto& p = participant("coredem-gas");
  LaunchInputs in = inputs("/runs/r1");
  LaunchCommand cmd = launchCommand(p, c, in);
  EXPECT_EQ(cmd.argv, (std::vector<std::string>{
                          "/opt/coredem/bin/participant", "--case", "/runs/r1/case.yaml", "--key",
                          "gas", "--control", "tcp://127.0.0.1:5001", "--dem",
                          "tcp://127.0.0.1:5002", "--session", "s-123", "--timeout-s", "30"}));
  EXPECT_TRUE(cmd.env.empty()) << "no CURVE key: nothing in the environment";

  // Resumed, with CURVE and `coredem run --timers` (no stage timers: nothing added for them).
  in.restartFile = "/runs/r1/checkpoints/00000010/gas.h5";
  in.demServerKey = "rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7";
  in.timers = true;
  cmd = launchCommand(p, c, in);
  ASSERT_EQ(cmd.argv.size(), 15u);
  EXPECT_EQ(cmd.argv[13], "--restart");
  EXPECT_EQ(cmd.argv[14], "/runs/r1/checkpoints/00000010/gas.h5");
  EXPECT_EQ(cmd.env, (std::map<std::string, std::string>{
                         {"COREDEM_DEM_SERVER_KEY", "rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7"}}));
  EXPECT_FALSE(p.hasTimers());
  EXPECT_TRUE(p.workDir.empty());
  EXPECT_TRUE(p.caseFolder.empty());
}

TEST(Participants, OpenFoamCommandLineAndEnvironment) {
  const std::string text =
      replace(kCase, "cfd: {participant: coredem-gas, timeout_s: 30}",
              "cfd: {participant: coredemFoam, case: openfoam, timeout_s: 120}");
  const CaseConfig c = parseCase(text, "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(c.cfd.caseFolder, "openfoam");
  const auto& p = participant("coredemFoam");
  LaunchInputs in = inputs("/runs/r2");
  LaunchCommand cmd = launchCommand(p, c, in);
  // -epsMin: the clip of the gas fraction the DEM's drag uses (models: {eps_min}, default 0.35).
  EXPECT_EQ(cmd.argv, (std::vector<std::string>{"/opt/coredem/bin/participant", "-case",
                                                "/runs/r2/openfoam", "-epsMin", "0.35"}));
  const char* wm = std::getenv("WM_PROJECT_DIR");
  EXPECT_EQ(cmd.env, (std::map<std::string, std::string>{
                         {"COREDEM_CONTROL_ENDPOINT", "tcp://127.0.0.1:5001"},
                         {"COREDEM_DEM_ENDPOINT", "tcp://127.0.0.1:5002"},
                         {"COREDEM_SESSION", "s-123"},
                         {"COREDEM_TIMEOUT_S", "120"},
                         {"WM_PROJECT_DIR", wm != nullptr ? wm : "/usr/share/openfoam"}}));

  in.restartFile = "/runs/r2/checkpoints/00000004/coredemFoam.restart";
  in.demServerKey = "key";
  in.timers = true;
  cmd = launchCommand(p, c, in);
  EXPECT_EQ(cmd.argv, (std::vector<std::string>{"/opt/coredem/bin/participant", "-case",
                                                "/runs/r2/openfoam", "-epsMin", "0.35", "-restart",
                                                "/runs/r2/checkpoints/00000004/coredemFoam.restart",
                                                "-timers"}));
  EXPECT_EQ(cmd.env.at("COREDEM_DEM_SERVER_KEY"), "key");

  // cfd.timers in the case turns the timers on as `coredem run --timers` does.
  in.timers = false;
  const CaseConfig t = parseCase(replace(text, "timeout_s: 120}", "timeout_s: 120, timers: on}"),
                                 "case.yaml", fs::temp_directory_path());
  EXPECT_TRUE(t.cfd.timers);
  EXPECT_EQ(launchCommand(p, t, in).argv.back(), "-timers");
  EXPECT_TRUE(p.hasTimers());
}

TEST(Participants, CaseSchemaFollowsTheTable) {
  // cfd.case is required by a participant with an input folder ...
  std::string msg = errorOf(replace(kCase, "participant: coredem-gas", "participant: coredemFoam"));
  EXPECT_NE(msg.find("cfd: missing required key 'case' (an OpenFOAM case folder of coredemFoam"),
            std::string::npos)
      << msg;
  // ... and cfd.timers refused by one without stage timers, naming those that have them.
  msg = errorOf(replace(kCase, "timeout_s: 30}", "timeout_s: 30, timers: on}"));
  EXPECT_NE(msg.find("cases/x/case.yaml:11:56: cfd.timers: stage timers exist in coredemFoam "
                     "only; remove the key"),
            std::string::npos)
      << msg;
}

TEST(Participants, RestartFileConvention) {
  const auto& gas = participant("coredem-gas");
  EXPECT_TRUE(isRestartFile(gas, "gas.h5"));
  EXPECT_TRUE(isRestartFile(gas, "sub/gas.h5"));
  EXPECT_FALSE(isRestartFile(gas, "gas.json"));
  const auto& foam = participant("coredemFoam");
  EXPECT_TRUE(isRestartFile(foam, "coredemFoam.restart"));
  EXPECT_TRUE(isRestartFile(foam, "openfoam/coredemFoam.restart"));
  EXPECT_FALSE(isRestartFile(foam, "openfoam/0.001/U"));
  EXPECT_FALSE(isRestartFile(foam, "gas.h5"));
}

TEST(Participants, TemplatesExpandKnownPlaceholdersOnly) {
  EXPECT_EQ(expandTemplate("{a}-{b}x", {{"a", "1"}, {"b", "two"}}), "1-twox");
  EXPECT_EQ(expandTemplate("plain", {}), "plain");
  EXPECT_THROW(expandTemplate("{nope}", {{"a", "1"}}), std::logic_error);
  EXPECT_THROW(expandTemplate("{open", {}), std::logic_error);
  // Every template of the table expands with the launch values.
  const CaseConfig c = parseCase(kCase, "case.yaml", fs::temp_directory_path());
  LaunchInputs in = inputs("/r");
  in.restartFile = "/r/x";
  in.timers = true;
  for (const auto& p : participantTable()) {
    EXPECT_NO_THROW(launchCommand(p, c, in)) << p.name;
  }
}

TEST(Participants, WorkFolderIsCopiedOnce) {
  TempDir d("work");
  fs::create_directories(d.path / "case" / "foam" / "system");
  std::ofstream(d.path / "case" / "foam" / "system" / "controlDict") << "v1";
  const std::string text = replace(kCase, "cfd: {participant: coredem-gas, timeout_s: 30}",
                                   "cfd: {participant: coredemFoam, case: foam}");
  const CaseConfig c = caseIn(d.path / "case", text);
  const fs::path run = d.path / "run";
  const auto& p = participant("coredemFoam");
  prepareWorkDir(p, c, run);
  EXPECT_TRUE(fs::is_regular_file(run / "openfoam" / "system" / "controlDict"));
  // A resumed run keeps its copy.
  std::ofstream(run / "openfoam" / "system" / "controlDict") << "edited";
  prepareWorkDir(p, c, run);
  std::ifstream in(run / "openfoam" / "system" / "controlDict");
  std::string content;
  in >> content;
  EXPECT_EQ(content, "edited");
  // No work folder: nothing made.
  prepareWorkDir(participant("coredem-gas"), c, d.path / "run2");
  EXPECT_FALSE(fs::exists(d.path / "run2"));
}

TEST(Participants, GasSectionValidatedInProcessWithFileLineColumn) {
  TempDir d("gas");
  EXPECT_NO_THROW(checkGasSection(caseIn(d.path, kCase)));
  // Unknown key in the gas section: file:line:col, the key and the allowed ones.
  try {
    checkGasSection(caseIn(d.path, replace(kCase, "  T_g: 500.0", "  T_gas: 500.0")));
    FAIL() << "no error";
  } catch (const CaseError& e) {
    const std::string msg = e.what();
    const std::string where = (d.path / "case.yaml").string() + ":13:3";
    EXPECT_NE(msg.find(where), std::string::npos) << msg;
    EXPECT_NE(msg.find("'T_gas'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("kappa_g"), std::string::npos) << msg;
  }
  // A bad value: file:line:col of the value.
  try {
    checkGasSection(caseIn(d.path, replace(kCase, "  T_g: 500.0", "  T_g: hot")));
    FAIL() << "no error";
  } catch (const CaseError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find((d.path / "case.yaml").string() + ":13:8"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'hot' is not a number"), std::string::npos) << msg;
  }
  // No gas section under cfd.gas_key.
  try {
    checkGasSection(
        caseIn(d.path, replace(kCase, "timeout_s: 30}", "timeout_s: 30, gas_key: flow}")));
    FAIL() << "no error";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("no key 'flow'"), std::string::npos) << e.what();
  }
  // The participant's row names this check.
  EXPECT_EQ(participant("coredem-gas").preflight, &checkGasSection);
}

// cfd.ranks: K > 1 starts `mpirun -np K --oversubscribe [--allow-run-as-root] -x VAR ...
// PROGRAM ARGS -parallel` with the participant's environment exported to every rank; 1 (the
// default) is today's command line; a participant without parallelArgs refuses ranks > 1.
TEST(Participants, DecomposedOpenFoamRunsUnderMpirun) {
  const std::string text =
      replace(kCase, "cfd: {participant: coredem-gas, timeout_s: 30}",
              "cfd: {participant: coredemFoam, case: openfoam, timeout_s: 120, ranks: 2}");
  const CaseConfig c = parseCase(text, "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(c.cfd.ranks, 2);
  const auto& p = participant("coredemFoam");
  EXPECT_EQ(p.parallelArgs, (std::vector<std::string>{"-parallel"}));
  EXPECT_NE(p.decompose, nullptr);
  const LaunchCommand cmd = launchCommand(p, c, inputs("/runs/r3"));
  ASSERT_GE(cmd.argv.size(), 8u);
  EXPECT_EQ(fs::path(cmd.argv[0]).filename(), "mpirun");
  EXPECT_EQ(cmd.argv[1], "-np");
  EXPECT_EQ(cmd.argv[2], "2");
  EXPECT_EQ(cmd.argv[3], "--oversubscribe");
  EXPECT_EQ(cmd.argv[4] == "--allow-run-as-root", ::geteuid() == 0);
  const auto prog = std::find(cmd.argv.begin(), cmd.argv.end(), "/opt/coredem/bin/participant");
  ASSERT_NE(prog, cmd.argv.end());
  EXPECT_EQ(std::vector<std::string>(prog, cmd.argv.end()),
            (std::vector<std::string>{"/opt/coredem/bin/participant", "-case", "/runs/r3/openfoam",
                                      "-epsMin", "0.35", "-parallel"}));
  // Every variable of the environment is exported to the ranks.
  for (const char* var : {"COREDEM_CONTROL_ENDPOINT", "COREDEM_DEM_ENDPOINT", "COREDEM_SESSION",
                          "COREDEM_TIMEOUT_S", "WM_PROJECT_DIR"}) {
    const auto x = std::find(cmd.argv.begin(), prog, var);
    ASSERT_NE(x, prog) << var;
    EXPECT_EQ(*(x - 1), "-x") << var;
  }
  EXPECT_EQ(cmd.env.at("OMPI_MCA_rmaps_base_oversubscribe"), "1");
  // One rank: the serial command line.
  const CaseConfig one =
      parseCase(replace(text, ", ranks: 2}", "}"), "case.yaml", fs::temp_directory_path());
  EXPECT_EQ(one.cfd.ranks, 1);
  EXPECT_EQ(launchCommand(p, one, inputs("/runs/r3")).argv[0], "/opt/coredem/bin/participant");
  // coredem-gas runs on one process.
  const std::string msg = errorOf(replace(kCase, "timeout_s: 30}", "timeout_s: 30, ranks: 2}"));
  EXPECT_NE(msg.find("cfd.ranks: coredem-gas runs on one process"), std::string::npos) << msg;
  EXPECT_NE(errorOf(replace(kCase, "timeout_s: 30}", "timeout_s: 30, ranks: 0}")).find("ranks"),
            std::string::npos);
}
