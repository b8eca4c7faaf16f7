// Outputs: timeseries.csv (incl. truncation on resume), XDMF of particle snapshots, inspect.
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/hdf5.h>
#include <coredem/orchestrator/outputs.h>
#include <coredem/orchestrator/progress.h>

using namespace coredem::orchestrator;
namespace fs = std::filesystem;

namespace {

fs::path tempDir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("coredem-out-test-" + std::to_string(::getpid()) + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeSnapshot(const fs::path& file, int n) {
  const hid_t f = H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t g = H5Gcreate2(f, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  std::vector<double> pos(3 * std::size_t(n));
  std::vector<double> temp(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    pos[3 * i] = i;
    temp[i] = 300.0 + i;
  }
  hsize_t d2[2] = {hsize_t(n), 3};
  hid_t s = H5Screate_simple(2, d2, nullptr);
  hid_t ds = H5Dcreate2(g, "position", H5T_IEEE_F64LE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pos.data());
  H5Dclose(ds);
  H5Sclose(s);
  hsize_t d1[1] = {hsize_t(n)};
  s = H5Screate_simple(1, d1, nullptr);
  ds = H5Dcreate2(g, "temperature", H5T_IEEE_F64LE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, temp.data());
  H5Dclose(ds);
  H5Sclose(s);
  const hid_t as = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(f, "time", H5T_IEEE_F64LE, as, H5P_DEFAULT, H5P_DEFAULT);
  const double t = 0.5;
  H5Awrite(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  H5Sclose(as);
  H5Gclose(g);
  H5Fclose(f);
}

} // namespace

TEST(Timeseries, WritesHeaderAndRowsAndTruncatesOnResume) {
  const fs::path d = tempDir("ts");
  {
    TimeseriesWriter w(d / "timeseries.csv");
    for (int s = 1; s <= 5; ++s) {
      w.write({{"step", s}, {"t", 0.1 * s}, {"mean_T_p", 300.0 + s}});
    }
  }
  EXPECT_EQ(readAll(d / "timeseries.csv").substr(0, 16), "step,t,mean_T_p\n");
  {
    TimeseriesWriter w(d / "timeseries.csv", 3); // resume after step 3
    EXPECT_EQ(w.columns().size(), 3u);
    w.write({{"t", 0.4}, {"step", 4}, {"unknown", 1.0}});
  }
  const std::string text = readAll(d / "timeseries.csv");
  EXPECT_EQ(text, "step,t,mean_T_p\n"
                  "1,0.10000000000000001,301\n"
                  "2,0.20000000000000001,302\n"
                  "3,0.30000000000000004,303\n"
                  "4,0.40000000000000002,\n");
  fs::remove_all(d);
}

TEST(Xdmf, DescribesSnapshots) {
  const fs::path d = tempDir("xdmf");
  fs::create_directories(d / "snapshots");
  writeSnapshot(d / "snapshots" / "a.h5", 4);
  writeSnapshot(d / "snapshots" / "b.h5", 4);
  writeParticleXdmf(d / "particles.xdmf", {{0.0, "snapshots/a.h5"}, {0.5, "snapshots/b.h5"}});
  const std::string x = readAll(d / "particles.xdmf");
  EXPECT_NE(x.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(x.find("<Time Value=\"0.5\"/>"), std::string::npos);
  EXPECT_NE(x.find("Dimensions=\"4 3\" NumberType=\"Float\" Precision=\"8\" "
                   "Format=\"HDF\">snapshots/b.h5:/particles/position"),
            std::string::npos)
      << x;
  EXPECT_NE(x.find("<Attribute Name=\"temperature\" AttributeType=\"Scalar\""), std::string::npos);
  fs::remove_all(d);
}

// A CLG-like snapshot: 4 solid species and two sets. describeSnapshot names and documents
// every schema dataset, adds diameter and set_index, and the XDMF shows each species column as a
// named scalar (a hyperslab of /particles/species), whatever the species count.
TEST(Xdmf, NamesEverySpeciesColumnAndDescribesTheSnapshot) {
  const fs::path d = tempDir("xdmf-species");
  fs::create_directories(d / "snapshots");
  const fs::path file = d / "snapshots" / "s.h5";
  writeSnapshot(file, 4);
  {
    const coredem::h5::Handle f = coredem::h5::openFile(file, true);
    coredem::h5::writeDataset(f, "particles/radius", std::vector<double>{1e-4, 1e-4, 2e-4, 2e-4});
    coredem::h5::writeDataset(f, "particles/global_id", std::vector<std::int64_t>{3, 0, 2, 1});
    std::vector<double> y(16);
    for (std::size_t i = 0; i < y.size(); ++i) {
      y[i] = 0.01 * double(i);
    }
    coredem::h5::writeDataset(f, "particles/species", y, {4, 4});
  }
  SnapshotLabels labels;
  labels.solidSpecies = {"C", "Fe2O3", "Fe3O4", "Al2O3"};
  labels.sets = {"carrier", "char"};
  labels.setCounts = {3, 1};
  labels.materials = {"carrier", "char"};
  describeSnapshot(file, labels);
  {
    const coredem::h5::Handle f = coredem::h5::openFile(file);
    const coredem::h5::Handle sp(H5Dopen2(f, "particles/species", H5P_DEFAULT), H5Dclose);
    EXPECT_EQ(coredem::h5::readStringAttribute(sp, "columns", "t"), "C,Fe2O3,Fe3O4,Al2O3");
    EXPECT_EQ(coredem::h5::readStringAttribute(sp, "unit", "t"), "-");
    const coredem::h5::Handle t(H5Dopen2(f, "particles/temperature", H5P_DEFAULT), H5Dclose);
    EXPECT_EQ(coredem::h5::readStringAttribute(t, "unit", "t"), "K");
    EXPECT_FALSE(coredem::h5::readStringAttribute(t, "description", "t").empty());
    EXPECT_EQ(coredem::h5::readDataset<double>(f, "particles/diameter", "t"),
              (std::vector<double>{2e-4, 2e-4, 4e-4, 4e-4}));
    // gids 0..2: carrier, 3: char
    EXPECT_EQ(coredem::h5::readDataset<std::int32_t>(f, "particles/set_index", "t"),
              (std::vector<std::int32_t>{1, 0, 0, 0}));
    EXPECT_EQ(coredem::h5::readStringAttribute(f, "species_names", "t"), "C,Fe2O3,Fe3O4,Al2O3");
    EXPECT_EQ(coredem::h5::readStringAttribute(f, "set_names", "t"), "carrier,char");
  }
  writeParticleXdmf(d / "particles.xdmf", {{0.25, "snapshots/s.h5"}});
  const std::string x = readAll(d / "particles.xdmf");
  for (const char* name : {"species_C", "species_Fe2O3", "species_Fe3O4", "species_Al2O3"}) {
    EXPECT_NE(x.find(std::string("<Attribute Name=\"") + name + "\" AttributeType=\"Scalar\""),
              std::string::npos)
        << name << "\n"
        << x;
  }
  EXPECT_NE(x.find("<DataItem Dimensions=\"3 2\" Format=\"XML\">0 3 1 1 4 1</DataItem>"),
            std::string::npos)
      << x;
  EXPECT_NE(x.find("<Attribute Name=\"diameter\" AttributeType=\"Scalar\""), std::string::npos);
  EXPECT_NE(x.find("<Attribute Name=\"set_index\" AttributeType=\"Scalar\""), std::string::npos);
  fs::remove_all(d);
}

TEST(Inspect, SummarisesHdf5) {
  const fs::path d = tempDir("inspect");
  writeSnapshot(d / "s.h5", 3);
  const std::string s = inspectSummary(d / "s.h5");
  EXPECT_NE(s.find("/@time = 0.5"), std::string::npos) << s;
  EXPECT_NE(s.find("/particles/temperature"), std::string::npos) << s;
  EXPECT_NE(s.find("min 300  mean 301  max 302"), std::string::npos) << s;
  EXPECT_THROW(inspectSummary(d / "missing.h5"), coredem::UserError);
  fs::remove_all(d);
}

// A vector's statistics are per component (x, y, z), a species array's per named column.
TEST(Inspect, StatisticsPerComponent) {
  const fs::path d = tempDir("inspect-columns");
  writeSnapshot(d / "s.h5", 3); // position (i, 0, 0)
  {
    const coredem::h5::Handle f = coredem::h5::openFile(d / "s.h5", true);
    coredem::h5::writeDataset(f, "particles/species", std::vector<double>{1, 0, 0.5, 0.5, 0, 1},
                              {3, 2});
    const coredem::h5::Handle ds(H5Dopen2(f, "particles/species", H5P_DEFAULT), H5Dclose);
    coredem::h5::writeAttribute(ds, "columns", "C,Fe2O3");
  }
  const std::string s = inspectSummary(d / "s.h5");
  EXPECT_NE(s.find("/particles/position"), std::string::npos) << s;
  EXPECT_NE(s.find("per column"), std::string::npos) << s;
  EXPECT_TRUE(std::regex_search(s, std::regex("\n    x +min 0  mean 1  max 2\n"))) << s;
  EXPECT_TRUE(std::regex_search(s, std::regex("\n    y +min 0  mean 0  max 0\n"))) << s;
  EXPECT_TRUE(std::regex_search(s, std::regex("\n    Fe2O3 +min 0  mean 0\\.5  max 1\n"))) << s;
  fs::remove_all(d);
}

TEST(Progress, LineHasTimeRateAndEta) {
  Progress p(0.0, 1.0, 0, false, 10.0);
  const auto t0 = Progress::Clock::now();
  const std::string l = p.line(50, 0.25, t0 + std::chrono::seconds(2));
  // 50 steps in ~2 s wall; a quarter done -> ETA ~6 s.
  EXPECT_NE(l.find("step 50"), std::string::npos) << l;
  EXPECT_NE(l.find("(25.0%)"), std::string::npos) << l;
  EXPECT_NE(l.find("ETA 6.0s"), std::string::npos) << l;
  EXPECT_EQ(formatDuration(3725), "1h02m");
  EXPECT_EQ(formatDuration(185), "3m05s");
}

TEST(Progress, EtaFollowsTheRecentRateNotTheAverageSinceTheStart) {
  // 20 % of the run in the first 10 s, then 10x slower: 1 % every 5 s (0.002 per s).
  Progress p(0.0, 1.0, 0, false, 1e9);
  p.setSink([](const std::string&, bool) {});
  const auto t0 = Progress::Clock::now();
  double t = 0.0;
  std::int64_t step = 0;
  for (int s = 1; s <= 100; ++s) { // one report a wall second
    t += s <= 10 ? 0.02 : 0.002;
    step += s <= 10 ? 20 : 2;
    p.update(step, t, t0 + std::chrono::seconds(s));
  }
  // t = 0.38 after 100 s; the last 30 s ran at 0.002 per s -> ETA (1 - 0.38)/0.002 = 310 s.
  // The average since the start (0.0038 per s) would say 163 s.
  const std::string l = p.line(step, t, t0 + std::chrono::seconds(100));
  EXPECT_TRUE(std::regex_search(l, std::regex("ETA 5m(09|10)s"))) << l; // round-off of 310 s
  EXPECT_NE(l.find("2.0 steps/s"), std::string::npos) << l;
}

TEST(Progress, FormatDuration) {
  EXPECT_EQ(formatDuration(185), "3m05s");
}
