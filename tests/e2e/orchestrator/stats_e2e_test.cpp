// End-to-end test of `coredem stats` (docs/orchestrator.md "Time-averaged results"): a 40-step
// run of 64 beads (coredem-dem + coredem-gas, cases/stats) with a snapshot every 10 steps, then
//   - the timeseries statistics over a window, against the same statistics computed here from
//     timeseries.csv (time-weighted: every row stands for its dt, the run's Δt is fixed);
//   - the time-averaged cell fields (ε_g, U_p, Θ, T_p) in stats/averages.h5 and the XDMF that
//     points at them, against the same averages computed here from the snapshots' particles;
//   - bad input: --from beyond the run's end, --to before --from, a folder without a run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <yaml-cpp/yaml.h>

#include "coredem_e2e.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;

using coredem::e2e::readAll;

int runCoredem(const std::vector<std::string>& args, const fs::path& log) {
  return coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem", args, log), 90s);
}

std::vector<double> readDoubles(const fs::path& file, const std::string& path) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << file;
  const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << file << ":" << path;
  const hid_t s = H5Dget_space(d);
  std::vector<double> v(std::size_t(H5Sget_simple_extent_npoints(s)));
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

/// The expected averages, computed from the particles of each snapshot (PCM, cells of 5 mm).
struct Expected {
  std::vector<double> eps, up, theta, tp, samples;
};

Expected expectedFields(const fs::path& run, const std::vector<std::string>& files) {
  const int nx = 2, ny = 2, nz = 4, cells = nx * ny * nz;
  const double h = 0.005, vCell = h * h * h;
  Expected e;
  e.eps.assign(cells, 0.0);
  e.up.assign(3 * cells, 0.0);
  e.theta.assign(cells, 0.0);
  e.tp.assign(cells, 0.0);
  e.samples.assign(cells, 0.0);
  std::vector<double> massAll(cells, 0.0);
  for (const auto& file : files) {
    const auto x = readDoubles(run / file, "/particles/position");
    const auto v = readDoubles(run / file, "/particles/velocity");
    const auto r = readDoubles(run / file, "/particles/radius");
    const auto m = readDoubles(run / file, "/particles/mass");
    const auto T = readDoubles(run / file, "/particles/temperature");
    std::vector<int> cell(r.size());
    std::vector<double> vs(cells, 0.0), mc(cells, 0.0), mv(3 * cells, 0.0);
    for (std::size_t i = 0; i < r.size(); ++i) {
      const int a = int(x[3 * i] / h), b = int(x[3 * i + 1] / h), c = int(x[3 * i + 2] / h);
      if (!(a >= 0 && a < nx && b >= 0 && b < ny && c >= 0 && c < nz)) {
        ADD_FAILURE() << file << ": particle " << i << " outside the coupling grid";
        return e;
      }
      cell[i] = a + nx * (b + ny * c);
      vs[cell[i]] += 4.0 / 3.0 * M_PI * std::pow(r[i], 3);
      mc[cell[i]] += m[i];
      e.tp[cell[i]] += m[i] * T[i];
      for (int d = 0; d < 3; ++d) {
        mv[3 * cell[i] + d] += m[i] * v[3 * i + d];
      }
    }
    for (std::size_t i = 0; i < r.size(); ++i) {
      const int c = cell[i];
      double d2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        d2 += std::pow(v[3 * i + d] - mv[3 * c + d] / mc[c], 2);
      }
      e.theta[c] += m[i] * d2 / 3.0;
    }
    for (int c = 0; c < cells; ++c) {
      e.eps[c] += (1.0 - vs[c] / vCell) / double(files.size());
      massAll[c] += mc[c];
      e.samples[c] += mc[c] > 0.0 ? 1.0 : 0.0;
      for (int d = 0; d < 3; ++d) {
        e.up[3 * c + d] += mv[3 * c + d];
      }
    }
  }
  for (int c = 0; c < cells; ++c) {
    const double M = massAll[c];
    e.theta[c] = M > 0 ? e.theta[c] / M : std::nan("");
    e.tp[c] = M > 0 ? e.tp[c] / M : std::nan("");
    for (int d = 0; d < 3; ++d) {
      e.up[3 * c + d] = M > 0 ? e.up[3 * c + d] / M : std::nan("");
    }
  }
  return e;
}

void expectClose(const std::vector<double>& got, const std::vector<double>& want, double rel,
                 const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (std::isnan(want[i])) {
      EXPECT_TRUE(std::isnan(got[i])) << what << "[" << i << "] = " << got[i];
      continue;
    }
    EXPECT_NEAR(got[i], want[i], rel * std::abs(want[i]) + 1e-15) << what << "[" << i << "]";
  }
}

class StatsE2E : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir = coredem::e2e::tempDir("coredem-e2e", "stats");
    run = dir / "run";
    rc = runCoredem({"run", (kCases / "stats").string(), "--out", run.string(), "--no-plots"},
                    dir / "run.log");
  }
  static void TearDownTestSuite() {
    if (!HasFailure()) {
      fs::remove_all(dir);
    }
  }
  static inline fs::path dir, run;
  static inline int rc = -1;
};

TEST_F(StatsE2E, TimeseriesStatisticsOverAWindowMatchTheRows) {
  ASSERT_EQ(rc, 0) << readAll(dir / "run.log");
  // 0.0076 s falls inside step 16 (0.0075, 0.008]: that row counts for 0.4 ms, the others 0.5
  const double from = 0.0076;
  ASSERT_EQ(runCoredem({"stats", run.string(), "--from", "0.0076", "--no-fields"}, dir / "s.log"),
            0)
      << readAll(dir / "s.log");
  const std::string table = readAll(dir / "s.log");
  EXPECT_NE(table.find("mean_T_p"), std::string::npos) << table;
  const YAML::Node j = YAML::LoadFile((run / "stats" / "stats.json").string());
  const auto ts = coredem::e2e::readTimeseries(run);
  const auto& t = ts.at("t");
  ASSERT_EQ(t.size(), 40u);
  // rows with t in (0.0076, 0.02]: steps 16..40, each weighted by t_i - max(t_{i-1}, from)
  for (const std::string col : {"mean_T_p", "dem.kinetic_energy_J", "contacts", "max_T_p"}) {
    const auto& x = ts.at(col);
    double sw = 0, swx = 0, n = 0, mn = HUGE_VAL, mx = -HUGE_VAL;
    std::vector<double> w(t.size(), 0.0);
    for (std::size_t i = 1; i < t.size(); ++i) {
      if (t[i] > from) {
        w[i] = t[i] - std::max(t[i - 1], from);
        sw += w[i];
        swx += w[i] * x[i];
        n += 1;
        mn = std::min(mn, x[i]);
        mx = std::max(mx, x[i]);
      }
    }
    ASSERT_EQ(n, 25.0);
    EXPECT_NEAR(w[15], 0.0004, 1e-12); // the clipped row (step 16)
    const double mean = swx / sw;
    double var = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      var += w[i] * (x[i] - mean) * (x[i] - mean) / sw;
    }
    const YAML::Node c = j["columns"][col];
    ASSERT_TRUE(c) << col;
    EXPECT_EQ(c["rows"].as<int>(), 25) << col;
    EXPECT_NEAR(c["mean"].as<double>(), mean, 1e-12 * std::abs(mean) + 1e-300) << col;
    EXPECT_NEAR(c["std"].as<double>(), std::sqrt(var), 1e-9 * std::sqrt(var) + 1e-300) << col;
    EXPECT_EQ(c["min"].as<double>(), mn) << col;
    EXPECT_EQ(c["max"].as<double>(), mx) << col;
  }
  // the window left the start-up out: T_p rises through the run
  EXPECT_GT(j["columns"]["mean_T_p"]["min"].as<double>(), ts.at("mean_T_p").front());
  EXPECT_DOUBLE_EQ(j["window"]["from"].as<double>(), from);
  EXPECT_DOUBLE_EQ(j["window"]["to"].as<double>(), t.back());
  EXPECT_TRUE(j["fields"].IsNull());
}

TEST_F(StatsE2E, AveragedFieldsMatchTheSnapshotsInTheWindow) {
  ASSERT_EQ(rc, 0) << readAll(dir / "run.log");
  ASSERT_EQ(runCoredem({"stats", run.string(), "--from", "0.005", "--to", "0.015"}, dir / "f.log"),
            0)
      << readAll(dir / "f.log");
  // snapshots at t in [0.005, 0.015]: steps 10, 20, 30
  const std::vector<std::string> files = {"snapshots/particles_00000010.h5",
                                          "snapshots/particles_00000020.h5",
                                          "snapshots/particles_00000030.h5"};
  for (const auto& f : files) {
    ASSERT_TRUE(fs::exists(run / f)) << f << "\n" << readAll(run / "outputs.csv");
  }
  const Expected e = expectedFields(run, files);
  const fs::path h5 = run / "stats" / "averages.h5";
  expectClose(readDoubles(h5, "/cells/eps_g"), e.eps, 1e-12, "eps_g");
  expectClose(readDoubles(h5, "/cells/U_p"), e.up, 1e-9, "U_p");
  expectClose(readDoubles(h5, "/cells/theta"), e.theta, 1e-9, "theta");
  expectClose(readDoubles(h5, "/cells/T_p"), e.tp, 1e-12, "T_p");
  expectClose(readDoubles(h5, "/cells/solids_samples"), e.samples, 0.0, "solids_samples");
  // the beads sit in the lower cells: some ε_g < 1 and the top layer empty (NaN velocities)
  EXPECT_LT(*std::min_element(e.eps.begin(), e.eps.end()), 0.99);
  EXPECT_TRUE(std::isnan(e.tp.back()));
  const auto times = readDoubles(h5, "/sample_times");
  ASSERT_EQ(times.size(), 3u);
  EXPECT_DOUBLE_EQ(times[0], 0.005);
  const std::string xdmf = readAll(run / "stats" / "averages.xdmf");
  EXPECT_NE(xdmf.find("TopologyType=\"3DCoRectMesh\" Dimensions=\"5 3 3\""), std::string::npos)
      << xdmf;
  EXPECT_NE(xdmf.find("Dimensions=\"4 2 2 3\""), std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find("averages.h5:/cells/theta"), std::string::npos) << xdmf;
  const YAML::Node j = YAML::LoadFile((run / "stats" / "stats.json").string());
  EXPECT_EQ(j["fields"]["samples"].as<int>(), 3);
}

TEST_F(StatsE2E, JsonOnStdoutWithTheDefaultStartAndAnEnd) {
  ASSERT_EQ(rc, 0) << readAll(dir / "run.log");
  ASSERT_EQ(
      runCoredem({"stats", run.string(), "--to", "0.01", "--json", "--no-fields"}, dir / "j.log"),
      0)
      << readAll(dir / "j.log");
  const YAML::Node j = YAML::Load(readAll(dir / "j.log")); // stdout is the JSON document
  EXPECT_DOUBLE_EQ(j["window"]["from"].as<double>(), 0.0); // the run's start: t_1 - dt_1
  EXPECT_EQ(j["rows"].as<int>(), 20);
  // the rows of steps 1..20: the particle count, constant
  EXPECT_EQ(j["columns"]["particles"]["mean"].as<double>(), 64.0);
  EXPECT_EQ(j["columns"]["particles"]["std"].as<double>(), 0.0);
  const auto ts = coredem::e2e::readTimeseries(run);
  double sum = 0;
  for (int i = 0; i < 20; ++i) {
    sum += ts.at("dem.kinetic_energy_J")[std::size_t(i)];
  }
  EXPECT_NEAR(j["columns"]["dem.kinetic_energy_J"]["mean"].as<double>(), sum / 20,
              1e-12 * sum / 20);
}

// Issue 41 item 5: with a forced time.dt_dem the log gives the n_sub that runs (0.5 ms / 10 us =
// 50), not the DEM server's own plan for its stable step (44 sub-steps of 11.4 us).
TEST(ForcedDemStepLog, TheLoggedNSubIsTheOneThatRuns) {
  const fs::path d = coredem::e2e::tempDir("coredem-e2e", "forced-nsub");
  std::string text = readAll(kCases / "stats" / "case.yaml");
  text = coredem::e2e::replaceAll(text, "  end: 0.02\n", "  end: 0.001\n  dt_dem: 1.0e-5\n");
  fs::create_directories(d / "case");
  coredem::e2e::writeAll(d / "case" / "case.yaml", text);
  ASSERT_EQ(runCoredem({"run", (d / "case").string(), "--out", (d / "run").string(), "--no-plots"},
                       d / "log"),
            0)
      << readAll(d / "log");
  const std::string log = readAll(d / "log");
  EXPECT_NE(log.find("n_sub = 50 for dt_CFD = 0.0005 s, forced by time.dt_dem"), std::string::npos)
      << log;
  const auto ts = coredem::e2e::readTimeseries(d / "run");
  EXPECT_EQ(ts.at("n_sub").front(), 50.0);
  fs::remove_all(d);
}

TEST_F(StatsE2E, BadWindowsAndFoldersAreRefusedWithTheReason) {
  ASSERT_EQ(rc, 0) << readAll(dir / "run.log");
  EXPECT_EQ(runCoredem({"stats", run.string(), "--from", "0.5"}, dir / "b1.log"), 2);
  const std::string b1 = readAll(dir / "b1.log");
  EXPECT_NE(b1.find("--from 0.5 s is at or beyond the run's last row"), std::string::npos) << b1;
  EXPECT_NE(b1.find("0.02"), std::string::npos) << b1;
  EXPECT_EQ(runCoredem({"stats", run.string(), "--from", "0.01", "--to", "0.005"}, dir / "b2.log"),
            2);
  EXPECT_NE(readAll(dir / "b2.log").find("is not after --from"), std::string::npos)
      << readAll(dir / "b2.log");
  fs::create_directories(dir / "empty");
  EXPECT_EQ(runCoredem({"stats", (dir / "empty").string()}, dir / "b3.log"), 2);
  EXPECT_NE(readAll(dir / "b3.log").find("timeseries.csv"), std::string::npos)
      << readAll(dir / "b3.log");
}

} // namespace
