// End-to-end tests of what a coupled run leaves for its user (coredem + coredem-dem +
// coredemFoam):
//   - particles and gas written at the same simulated times (output.every_seconds), listed in
//     RUN/outputs.csv with decimal times, and no gas time written at controlDict's writeInterval;
//   - a CLG snapshot (4 solid species) read by ParaView's XDMF reader (pvbatch, private Xvfb):
//     species columns by name, vectors and the added diameter/set_index equal the .h5's data;
//   - `coredem render` draws one time as a PNG that is not a single colour;
//   - the plots of an isothermal bed: pressure drop and bed height, no temperature panel;
//   - docs/tutorial.md's commands, run as written on its tiny case.
// The ParaView tests are skipped, with the reason, when pvbatch (or a display / Xvfb) is
// absent.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <hdf5.h>

#include "coredem_e2e.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kSource = COREDEM_SOURCE_DIR;
const fs::path kTemplate = COREDEM_FOAM_E2E_TEMPLATE;

using coredem::e2e::readAll;
using coredem::e2e::writeAll;

using coredem::e2e::replaceAll;

/// Runs `program args...` (output into `log`) and returns its exit code.
int runProgram(const fs::path& program, const std::vector<std::string>& args, const fs::path& log,
               std::chrono::seconds timeout = 100s) {
  return coredem::e2e::waitExit(coredem::e2e::startProgram(program, args, log), timeout);
}

std::string tail(const fs::path& log) {
  const std::string s = readAll(log);
  return s.size() > 3000 ? s.substr(s.size() - 3000) : s;
}

/// The rows of a CSV file with a header, as maps column -> text.
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& l) {
    std::vector<std::string> out;
    std::stringstream s(l);
    std::string cell;
    while (std::getline(s, cell, ',')) {
      out.push_back(cell);
    }
    if (!l.empty() && l.back() == ',') {
      out.emplace_back();
    }
    return out;
  };
  if (std::getline(in, line)) {
    header = split(line);
  }
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) {
      row[header[i]] = cells[i];
    }
    rows.push_back(row);
  }
  return rows;
}

/// The column case of the coredemFoam e2e tests (1 x 4 x 1 cm, 2 mm cells, y up) with `body`
/// appended to its case.yaml; controlDict writes every step (writeInterval 1, timeStep), so a
/// gas time that is not an output would show.
fs::path makeColumnCase(const fs::path& dir, const std::string& body) {
  const fs::path c = dir / "case";
  fs::create_directories(c);
  fs::copy(kTemplate, c / "openfoam", fs::copy_options::recursive);
  for (const auto& e : fs::recursive_directory_iterator(c / "openfoam")) {
    if (e.is_regular_file()) {
      std::string s = readAll(e.path());
      s = replaceAll(s, "@U_IN@", "0.3");
      s = replaceAll(s, "@T_IN@", "293.15");
      s = replaceAll(s, "writeControl    runTime;", "writeControl    timeStep;");
      s = replaceAll(s, "writeInterval   0.05;", "writeInterval   1;");
      writeAll(e.path(), s);
    }
  }
  writeAll(c / "case.yaml", std::string(R"(name: column
grid: {origin: [0, 0, 0], spacing: [0.002, 0.002, 0.002], cells: [5, 20, 5]}
gravity: [0.0, -9.81, 0.0]
gas_properties: {density: 1.204, viscosity: 1.81e-5, conductivity: 0.0257, cp: 1006.0,
                 temperature: 293.15, pressure: 101325.0}
walls:
  box: {min: [0.0, 0.0, 0.0], max: [0.01, 0.04, 0.01]}
  planes: [{point: [0.0, 0.004, 0.0], normal: [0.0, 1.0, 0.0]}]
cfd: {participant: coredemFoam, case: openfoam, timeout_s: 60}
dem: {backend: cpu, threads: 1, timeout_s: 60}
materials:
  - {name: glass, density: 2500.0, k_n: 100.0, e_n: 0.5, friction: 0.3}
particles:
  - {name: bed, material: glass, count: 400, diameter: 1.0e-3, packing: lattice,
     region: {min: [0.0, 0.004, 0.0], max: [0.01, 0.010, 0.01]}}
)") + body);
  return c;
}

constexpr const char* kParaviewOptOut =
    " (the paraview test group: scripts/install-deps.sh installs paraview and xvfb; opt out with "
    "-DCOREDEM_TEST_OPT_OUT=paraview)";

/// pvbatch and the way to run it here ({sh, with-xvfb.sh, pvbatch} without a display), or the
/// reason it cannot run.
struct Pvbatch {
  std::vector<std::string> command;
  std::string missing;
};

Pvbatch findPvbatch() {
  Pvbatch p;
  fs::path pv = COREDEM_PVBATCH;
  if (pv.empty() || !fs::exists(pv)) {
    pv = coredem::findProgram("pvbatch");
  }
  if (pv.empty()) {
    p.missing = "ParaView's pvbatch is not installed (Debian: apt-get install paraview xvfb)";
    return p;
  }
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    if (coredem::findProgram("Xvfb").empty()) {
      p.missing = "no display and no Xvfb for pvbatch (Debian: apt-get install xvfb)";
      return p;
    }
    p.command = {"/bin/sh", COREDEM_WITH_XVFB};
  }
  p.command.push_back(pv.string());
  return p;
}

class ResultsE2E : public coredem::e2e::RunFolderTest {
protected:
  ResultsE2E()
      : RunFolderTest(kBin, {"coredem", "coredem-dem", "coredemFoam"}, "results-e2e") {}
};

// Outputs every 4 ms with Δt = 0.7 ms: the step before each output is shortened to land on it,
// both participants write there, and nowhere else (controlDict would write every step).
TEST_F(ResultsE2E, ParticlesAndGasAreWrittenAtTheSameTimes) {
  const fs::path c = makeColumnCase(dir, R"(time: {end: 0.01, dt: 0.7e-3}
output: {every_seconds: 0.004}
)");
  const fs::path run = dir / "run";
  ASSERT_EQ(runProgram(kBin / "coredem", {"run", c.string(), "--out", run.string(), "--no-plots"},
                       dir / "coredem.log"),
            0)
      << tail(dir / "coredem.log");
  const auto rows = readCsv(run / "outputs.csv");
  const std::vector<double> expected = {0.0, 0.004, 0.008, 0.01};
  ASSERT_EQ(rows.size(), expected.size()) << readAll(run / "outputs.csv");
  std::set<std::string> listed;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    auto row = rows[i];
    const double t = std::stod(row["time_s"]);
    EXPECT_NEAR(t, expected[i], 1e-15) << "output " << i;
    ASSERT_TRUE(fs::exists(run / row["particles"])) << row["particles"];
    ASSERT_FALSE(row["gas"].empty()) << "output " << i << " has no gas folder";
    ASSERT_TRUE(fs::is_directory(run / row["gas"])) << row["gas"];
    EXPECT_TRUE(fs::exists(run / row["gas"] / "alphac") || i == 0) << row["gas"];
    // The gas folder's name is the same instant (OpenFOAM's time name, 10 digits).
    EXPECT_NEAR(std::stod(fs::path(row["gas"]).filename().string()), t, 1e-12) << row["gas"];
    // The snapshot's own time attribute is the listed time.
    const hid_t f = H5Fopen((run / row["particles"]).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    double st = -1.0;
    const hid_t a = H5Aopen(f, "time", H5P_DEFAULT);
    ASSERT_GE(a, 0) << "snapshot without a root 'time' attribute";
    H5Aread(a, H5T_NATIVE_DOUBLE, &st);
    H5Aclose(a);
    H5Fclose(f);
    EXPECT_EQ(st, t) << row["particles"];
    listed.insert(fs::path(row["gas"]).filename().string());
    // Self-describing: every /particles dataset has a unit and a description, names included.
    const hid_t rf = H5Fopen((run / row["particles"]).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    std::vector<std::string> names;
    H5Literate_by_name(
        rf, "particles", H5_INDEX_NAME, H5_ITER_INC, nullptr,
        [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
          static_cast<std::vector<std::string>*>(data)->push_back(name);
          return 0;
        },
        &names, H5P_DEFAULT);
    EXPECT_GE(names.size(), 15u);
    for (const char* must : {"position", "velocity", "temperature", "diameter", "set_index"}) {
      EXPECT_NE(std::find(names.begin(), names.end(), must), names.end()) << must;
    }
    for (const auto& n : names) {
      const std::string path = "particles/" + n;
      EXPECT_GT(H5Aexists_by_name(rf, path.c_str(), "unit", H5P_DEFAULT), 0) << n;
      EXPECT_GT(H5Aexists_by_name(rf, path.c_str(), "description", H5P_DEFAULT), 0) << n;
    }
    for (const char* a : {"species_names", "set_names", "material_names", "step"}) {
      EXPECT_GT(H5Aexists(rf, a), 0) << a;
    }
    H5Fclose(rf);
  }
  // No other gas time folder: controlDict's write interval no longer writes on its own.
  for (const auto& e : fs::directory_iterator(run / "openfoam")) {
    const std::string name = e.path().filename().string();
    if (e.is_directory() && std::regex_match(name, std::regex("[0-9.e+-]+"))) {
      EXPECT_TRUE(listed.count(name)) << "gas written at " << name << ", not an output time";
    }
  }
}

// An isothermal bed interrupted by SIGINT still gets its plots, with the panels it computes:
// pressure drop and bed height (both in timeseries.csv), no temperature or heat panel.
TEST_F(ResultsE2E, InterruptedIsothermalBedGetsItsPlots) {
  const fs::path c = makeColumnCase(dir, R"(time: {end: 1.0, dt: 0.7e-3}
)");
  const fs::path run = dir / "run";
  const pid_t pid = coredem::e2e::startProgram(
      kBin / "coredem", {"run", c.string(), "--out", run.string()}, dir / "coredem.log");
  ASSERT_GT(pid, 0);
  // Wait for a few rows of timeseries.csv, then interrupt.
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (std::chrono::steady_clock::now() < deadline) {
    const std::string ts = readAll(run / "timeseries.csv");
    if (std::count(ts.begin(), ts.end(), '\n') >= 4) {
      break;
    }
    std::this_thread::sleep_for(20ms);
  }
  ::kill(pid, SIGINT);
  ASSERT_EQ(coredem::e2e::waitExit(pid, 100s), 130) << tail(dir / "coredem.log");
  const auto ts = coredem::e2e::readTimeseries(run);
  ASSERT_TRUE(ts.count("gas.pressure_drop_Pa")) << "no pressure drop column";
  ASSERT_TRUE(ts.count("bed_height_m")) << "no bed height column";
  // 400 beads of 1 mm on a lattice filling the 6 mm high region from the distributor up (its
  // layers are along z, each 10 x 6 beads): 6 mm, give or take the first steps' settling (10 %).
  EXPECT_NEAR(ts.at("bed_height_m").back(), 6e-3, 0.6e-3);
  EXPECT_GT(ts.at("gas.pressure_drop_Pa").back(), 0.0);
  ASSERT_TRUE(fs::exists(run / "plots" / "timeseries.png")) << tail(run / "logs" / "plot.log");
  EXPECT_GT(fs::file_size(run / "plots" / "timeseries.png"), 10000u);
  const std::string plotLog = readAll(run / "logs" / "plot.log");
  EXPECT_NE(plotLog.find("Pressure drop"), std::string::npos) << plotLog;
  EXPECT_NE(plotLog.find("Bed height"), std::string::npos) << plotLog;
  EXPECT_EQ(plotLog.find("Particle temperature"), std::string::npos) << plotLog;
  EXPECT_EQ(plotLog.find("Heat exchange"), std::string::npos) << plotLog;
}

/// The reduced CLG case (4 solid species, 2 particle sets, 5291 particles) for 2 steps with an
/// output every step; shared by the ParaView tests.
class ClgRun : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = coredem::e2e::tempDir("results-e2e", "clg");
    const fs::path c = dir_ / "case";
    fs::create_directories(c);
    fs::copy(kSource / "cases" / "clg" / "openfoam-reduced", c / "openfoam-reduced",
             fs::copy_options::recursive);
    std::string yaml = readAll(kSource / "cases" / "clg" / "reduced.yaml");
    yaml = replaceAll(yaml, "output:\n  every: 100", "output:\n  every: 1");
    writeAll(c / "case.yaml", yaml);
    run_ = dir_ / "run";
    status_ =
        runProgram(kBin / "coredem",
                   {"run", c.string(), "--out", run_.string(), "--no-plots", "--stop-after", "2"},
                   dir_ / "coredem.log");
  }
  static void TearDownTestSuite() {
    if (!::testing::UnitTest::GetInstance()->Failed()) {
      fs::remove_all(dir_);
    }
  }
  void SetUp() override { ASSERT_EQ(status_, 0) << tail(dir_ / "coredem.log"); }

  static fs::path dir_, run_;
  static int status_;
};
fs::path ClgRun::dir_, ClgRun::run_;
int ClgRun::status_ = -1;

// ParaView's XDMF reader shows each species column under its name, with the .h5's values.
TEST_F(ClgRun, ParaViewReadsSpeciesByName) {
  const Pvbatch pv = findPvbatch();
  if (COREDEM_PARAVIEW_OPTED_OUT) {
    GTEST_SKIP() << "opted out (COREDEM_TEST_OPT_OUT=paraview)";
  }
  ASSERT_TRUE(pv.missing.empty()) << pv.missing << kParaviewOptOut;
  std::vector<std::string> args(pv.command.begin() + 1, pv.command.end());
  args.insert(args.end(), {COREDEM_CHECK_XDMF_SCRIPT, run_.string(), "species_C", "species_Fe2O3",
                           "species_Fe3O4", "species_Al2O3", "velocity", "temperature", "diameter",
                           "set_index", "chemistry_reference_1", "contact_count"});
  const fs::path log = dir_ / "pvbatch.log";
  int rc = runProgram(pv.command.front(), args, log);
  if (rc != 0 && readAll(log).find("bad X server connection") != std::string::npos) {
    fs::remove(log); // the virtual X server was not ready (a loaded machine): once more
    rc = runProgram(pv.command.front(), args, log);
  }
  ASSERT_EQ(rc, 0) << tail(log);
  const std::string out = readAll(log);
  EXPECT_NE(out.find("species_Fe2O3: 5291 values equal"), std::string::npos) << out;
  EXPECT_NE(out.find("velocity: 15873 values equal"), std::string::npos) << out;
  EXPECT_NE(out.find("5291 particles: OK"), std::string::npos) << out;
}

// `coredem render` draws one time: a PNG of particles over the gas slice, many colours.
TEST_F(ClgRun, RenderDrawsOneTime) {
  const Pvbatch pv = findPvbatch();
  if (COREDEM_PARAVIEW_OPTED_OUT) {
    GTEST_SKIP() << "opted out (COREDEM_TEST_OPT_OUT=paraview)";
  }
  ASSERT_TRUE(pv.missing.empty()) << pv.missing << kParaviewOptOut;
  const fs::path out = dir_ / "render";
  const fs::path log = dir_ / "render-cli.log";
  ASSERT_EQ(runProgram(kBin / "coredem",
                       {"render", run_.string(), "--times", "0.0004", "--field", "species_Fe2O3",
                        "--out", out.string()},
                       log),
            0)
      << tail(log) << tail(out / "render.log");
  std::vector<fs::path> pngs;
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().extension() == ".png") {
      pngs.push_back(e.path());
    }
  }
  ASSERT_EQ(pngs.size(), 1u) << "one time asked for";
  EXPECT_GT(fs::file_size(pngs[0]), 5000u);
  const std::string python = COREDEM_PYTHON;
  ASSERT_FALSE(python.empty()) << "no python with matplotlib to count the picture's colours "
                                  "(scripts/install-deps.sh)";
  // Distinct colours: the particles' colour map and the gas slice's, not one flat colour.
  const fs::path count = dir_ / "colours.txt";
  ASSERT_EQ(runProgram(python,
                       {"-c",
                        "import sys, numpy, matplotlib.image as m; a = m.imread(sys.argv[1]); "
                        "print(len(numpy.unique(a.reshape(-1, a.shape[-1]), axis=0)))",
                        pngs[0].string()},
                       count),
            0)
      << readAll(count);
  EXPECT_GT(std::stoi(readAll(count)), 50) << "the picture is (nearly) a single colour";
}

// Issue 41 item 5: the pictures carry a time stamp and a scale bar, and the gas can be drawn
// alone (a bed whose particles hide the slice), at another slice position, in Pa.
TEST_F(ClgRun, RenderGasAloneInPascalWithStampAndScaleBar) {
  const Pvbatch pv = findPvbatch();
  if (COREDEM_PARAVIEW_OPTED_OUT) {
    GTEST_SKIP() << "opted out (COREDEM_TEST_OPT_OUT=paraview)";
  }
  ASSERT_TRUE(pv.missing.empty()) << pv.missing << kParaviewOptOut;
  const fs::path out = dir_ / "render-p";
  const fs::path log = dir_ / "render-p-cli.log";
  ASSERT_EQ(runProgram(kBin / "coredem",
                       {"render", run_.string(), "--times", "0.0004", "--gas-field", "p_Pa",
                        "--particles", "none", "--slice", "0.25", "--out", out.string()},
                       log),
            0)
      << tail(log) << tail(out / "render.log");
  const std::string r = readAll(out / "render.log");
  EXPECT_NE(r.find("p_Pa: p is"), std::string::npos) << r;
  EXPECT_NE(r.find("scale bar: "), std::string::npos) << r;
  EXPECT_NE(r.find("slice at 0.25 of the depth; particles none"), std::string::npos) << r;
  // a bad option value is refused before ParaView starts
  EXPECT_EQ(runProgram(kBin / "coredem", {"render", run_.string(), "--slice", "2"},
                       dir_ / "render-bad.log"),
            2)
      << readAll(dir_ / "render-bad.log");
}

// docs/tutorial.md, as written: its ```bash blocks run in order, in one bash (set -euo pipefail),
// in a folder that looks like the repository root (docs/, cases/, build/bin). With the paraview
// test group opted out the render block is left out (and the test says so by skipping).
TEST_F(ResultsE2E, TutorialRunsAsWritten) {
  const std::string md = readAll(kSource / "docs" / "tutorial.md");
  std::string script = "set -euo pipefail\n";
  const Pvbatch pv = findPvbatch();
  int blocks = 0;
  bool renderSkipped = false;
  for (std::size_t at = md.find("```bash\n"); at != std::string::npos;
       at = md.find("```bash\n", at)) {
    const std::size_t begin = at + 8, end = md.find("```", begin);
    ASSERT_NE(end, std::string::npos) << "unterminated code block";
    const std::string block = md.substr(begin, end - begin);
    at = end + 3;
    if (block.find("coredem render") != std::string::npos && COREDEM_PARAVIEW_OPTED_OUT) {
      renderSkipped = true;
      continue;
    }
    script += block;
    ++blocks;
  }
  ASSERT_GE(blocks, 6) << "docs/tutorial.md lost its commands";
  fs::create_directories(dir / "root" / "build");
  fs::create_directory_symlink(kSource / "docs", dir / "root" / "docs");
  fs::create_directory_symlink(kSource / "cases", dir / "root" / "cases");
  fs::create_directory_symlink(kBin, dir / "root" / "build" / "bin");
  writeAll(dir / "root" / "tutorial.sh", script);
  const fs::path log = dir / "tutorial.log";
  ASSERT_EQ(runProgram("/bin/bash",
                       {"-c", "cd '" + (dir / "root").string() + "' && bash tutorial.sh"}, log),
            0)
      << tail(log);
  const fs::path run = dir / "root" / "runs" / "mybed";
  const auto rows = readCsv(run / "outputs.csv");
  ASSERT_EQ(rows.size(), 5u) << readAll(run / "outputs.csv");
  for (auto row : rows) {
    EXPECT_TRUE(fs::exists(run / row["particles"])) << row["particles"];
    EXPECT_TRUE(fs::is_directory(run / row["gas"])) << row["gas"];
  }
  EXPECT_TRUE(fs::exists(run / "plots" / "timeseries.png"));
  EXPECT_NE(readAll(log).find("mybed/case.yaml: valid"), std::string::npos) << tail(log);
  // Its settled start: one command, the settling stage with the inlet off, then the fluidized one.
  for (const char* stage : {"01-settle", "02-fluidize"}) {
    EXPECT_TRUE(fs::exists(dir / "root" / "runs" / "mybed-staged" / "stages" / stage / "done"))
        << stage << "\n"
        << tail(log);
  }
  const std::string settleU = readAll(dir / "root" / "runs" / "mybed-staged" / "stages" /
                                      "01-settle" / "run" / "openfoam" / "0" / "U");
  EXPECT_NE(settleU.find("superficial velocity (0 0 0) m/s"), std::string::npos) << settleU;
  // Its fluidization curve: one member per inlet velocity of case.yaml, the pressure drop growing
  // with it below minimum fluidization (the members above it are not checked).
  EXPECT_NE(readAll(log).find("curve.yaml: valid sweep (4 members"), std::string::npos)
      << tail(log);
  const auto curve = readCsv(dir / "root" / "runs" / "curve" / "summary.csv");
  ASSERT_EQ(curve.size(), 4u) << readAll(dir / "root" / "runs" / "curve" / "summary.csv");
  std::vector<double> dp;
  for (auto row : curve) {
    EXPECT_EQ(row["status"], "done");
    dp.push_back(std::stod(row["mean@0.01..:gas.pressure_drop_Pa"]));
  }
  EXPECT_LT(dp[0], dp[1]); // 0.3 and 0.6 m/s: below U_mf of the packing (~0.8 m/s)
  EXPECT_TRUE(fs::exists(dir / "root" / "runs" / "curve" / "plots" / "campaign.png"));
  if (renderSkipped) {
    GTEST_SKIP() << "opted out (COREDEM_TEST_OPT_OUT=paraview): the tutorial ran without its "
                    "render step";
  }
  ASSERT_TRUE(pv.missing.empty()) << pv.missing << kParaviewOptOut;
  EXPECT_TRUE(fs::exists(run / "render" / "velocity_00000020.png")) << tail(log);
}

} // namespace
