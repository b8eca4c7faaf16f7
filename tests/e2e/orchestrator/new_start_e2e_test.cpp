// A new run started from another run's particles (case.yaml `initial_state`, issue 41 item 2): a
// bed settled by one run is the start of a second run with another configuration (a material
// added in front, another restitution and dt_factor), which the configuration hash used to
// refuse. The second run's first snapshot holds the first run's last particles bit for bit, its
// time starts at 0 and its particles keep their material by name. A folder without a DEM state
// and a material missing from the new case are refused, naming what is wrong.
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <hdf5.h>

#include "coredem_e2e.h"
#include "coredem_e2e_hdf5.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

const fs::path kBin = COREDEM_BIN_DIR;
const fs::path kCases = COREDEM_E2E_CASES;

using coredem::e2e::datasetsOf;
using coredem::e2e::lastSnapshot;
using coredem::e2e::readAll;
using coredem::e2e::replaceAll;
using coredem::e2e::writeAll;

int runCoredem(const std::vector<std::string>& args, const fs::path& log) {
  return coredem::e2e::waitExit(coredem::e2e::startProgram(kBin / "coredem", args, log), 90s);
}

/// The values of a dataset of raw bytes as T.
template <class T>
std::vector<T> valuesOf(const std::string& bytes) {
  std::vector<T> v(bytes.size() / sizeof(T));
  std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
  return v;
}

/// A snapshot's /meta time attribute.
double metaTime(const fs::path& file) {
  double t = -1;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f >= 0) {
    const hid_t a = H5Aopen_by_name(f, "meta", "time", H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0) {
      H5Aread(a, H5T_NATIVE_DOUBLE, &t);
      H5Aclose(a);
    }
    H5Fclose(f);
  }
  return t;
}

/// The restart case (64 beads settling for 0.1 s) as a second case starting from `from`: no
/// particle sets, a material `steel` before `glass` (whose e_n changes), dt_factor 40, 10 ms.
std::string secondCase(const std::string& from) {
  std::string yaml = readAll(kCases / "restart" / "case.yaml");
  const auto p = yaml.find("particles:");
  const auto w = yaml.find("walls:");
  yaml = yaml.substr(0, p) + "initial_state: " + from + "\n" + yaml.substr(w);
  yaml = replaceAll(yaml, "materials:\n  - name: glass",
                    "materials:\n  - {name: steel, density: 7800.0, k_n: 50.0, e_n: 0.6}\n"
                    "  - name: glass");
  yaml = replaceAll(yaml, "e_n: 0.8", "e_n: 0.5");
  yaml = replaceAll(yaml, "end: 0.1", "end: 0.01");
  return yaml + "models: {dem.dt_factor: \"40\"}\n";
}

} // namespace

TEST(NewStartE2E, SettledBedStartsARunWithAnotherConfiguration) {
  const fs::path d = coredem::e2e::tempDir("coredem-e2e", "new-start");
  const fs::path settle = d / "settle";
  ASSERT_EQ(
      runCoredem({"run", (kCases / "restart").string(), "--out", settle.string(), "--no-plots"},
                 d / "settle.log"),
      0)
      << readAll(d / "settle.log");
  const fs::path second = d / "second";
  fs::create_directories(second);
  writeAll(second / "case.yaml", secondCase("../settle")); // the run folder: its last snapshot
  const fs::path run = d / "run";
  ASSERT_EQ(
      runCoredem({"run", second.string(), "--out", run.string(), "--no-plots"}, d / "run.log"), 0)
      << readAll(d / "run.log");

  const fs::path end = lastSnapshot(settle);
  const fs::path start = run / "snapshots" / "particles_00000000.h5";
  ASSERT_TRUE(fs::is_regular_file(start));
  EXPECT_NEAR(metaTime(end), 0.1, 1e-12);
  EXPECT_EQ(metaTime(start), 0.0) << "a new start begins at t = 0";
  const auto a = datasetsOf(end);
  const auto b = datasetsOf(start);
  for (const char* field :
       {"particles/position", "particles/velocity", "particles/angular_velocity",
        "particles/radius", "particles/temperature", "particles/global_id"}) {
    ASSERT_TRUE(a.count(field) && b.count(field)) << field;
    EXPECT_EQ(a.at(field), b.at(field)) << field << " differs from the settled run's end";
  }
  // glass was material 0 of the settled run and is material 1 here: matched by name.
  const auto materials = valuesOf<std::int32_t>(b.at("particles/material"));
  ASSERT_EQ(materials.size(), 64u);
  for (const std::int32_t m : materials) {
    EXPECT_EQ(m, 1);
  }
  // The DEM server says which reading it did.
  EXPECT_NE(readAll(run / "logs" / "dem.log").find("(a new start) from"), std::string::npos)
      << readAll(run / "logs" / "dem.log");
  const auto ts = coredem::e2e::readTimeseries(run);
  ASSERT_FALSE(ts.at("t").empty());
  EXPECT_NEAR(ts.at("t").back(), 0.01, 1e-12);
  if (!HasFailure()) {
    fs::remove_all(d);
  }
}

TEST(NewStartE2E, StartWithoutAStateOrWithAMissingMaterialIsRefusedNamingIt) {
  const fs::path d = coredem::e2e::tempDir("coredem-e2e", "new-start-bad");
  // A folder that holds no DEM state: refused by check, exit 2, naming the key.
  fs::create_directories(d / "empty");
  fs::create_directories(d / "c1");
  writeAll(d / "c1" / "case.yaml", secondCase("../empty"));
  EXPECT_EQ(runCoredem({"check", (d / "c1").string()}, d / "c1.log"), 2) << readAll(d / "c1.log");
  EXPECT_NE(readAll(d / "c1.log").find("initial_state: '../empty' is a folder without a DEM state"),
            std::string::npos)
      << readAll(d / "c1.log");
  // A state whose particles' material is not in the new case: the DEM server refuses it.
  const fs::path settle = d / "settle";
  std::string yaml = readAll(kCases / "restart" / "case.yaml");
  yaml = replaceAll(yaml, "end: 0.1", "end: 0.005");
  fs::create_directories(d / "short");
  writeAll(d / "short" / "case.yaml", yaml);
  ASSERT_EQ(runCoredem({"run", (d / "short").string(), "--out", settle.string(), "--no-plots"},
                       d / "settle.log"),
            0)
      << readAll(d / "settle.log");
  fs::create_directories(d / "c2");
  writeAll(d / "c2" / "case.yaml",
           replaceAll(secondCase("../settle/snapshots/particles_00000000.h5"), "- name: glass",
                      "- name: sand"));
  const fs::path run = d / "run";
  EXPECT_NE(
      runCoredem({"run", (d / "c2").string(), "--out", run.string(), "--no-plots"}, d / "c2.log"),
      0);
  EXPECT_NE(readAll(d / "c2.log")
                .find("particles of material 'glass' have no material of that "
                      "name in this case"),
            std::string::npos)
      << readAll(d / "c2.log");
  if (!HasFailure()) {
    fs::remove_all(d);
  }
}
