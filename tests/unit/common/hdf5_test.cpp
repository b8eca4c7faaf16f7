// h5:: handles and helpers: exact round trips, and errors that name the file and the object.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <unistd.h>

#include <coredem/common/hdf5.h>

namespace fs = std::filesystem;

namespace {

fs::path tempFile(const char* name) {
  const fs::path dir =
      fs::temp_directory_path() / ("coredem-common-h5-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

TEST(Hdf5, RoundTripIsExact) {
  const fs::path p = tempFile("rt.h5");
  const std::vector<double> x = {0.1,       -2.5e-300, std::numeric_limits<double>::max(),
                                 1.0 / 3.0, 0.0,       -0.0};
  const std::vector<std::int64_t> ids = {1, -7, std::numeric_limits<std::int64_t>::max()};
  {
    auto f = coredem::h5::createFile(p);
    auto g = coredem::h5::createGroup(f, "particles");
    coredem::h5::writeDataset(g, "x", x, {3, 2});
    coredem::h5::writeDataset(g, "ids", ids);
    coredem::h5::writeAttribute(f, "time", 0.25);
    coredem::h5::writeAttribute(f, "step", std::int64_t{42});
    coredem::h5::writeAttribute(f, "version", std::string("0.1.0"));
    coredem::h5::writeAttribute(f, "empty", std::string());
  }
  auto f = coredem::h5::openFile(p);
  auto g = coredem::h5::openGroup(f, "particles", p.string());
  const auto xr = coredem::h5::readDataset<double>(g, "x", p.string(), 6);
  ASSERT_EQ(xr.size(), x.size());
  EXPECT_EQ(std::memcmp(xr.data(), x.data(), x.size() * sizeof(double)), 0);
  EXPECT_EQ(coredem::h5::readDataset<std::int64_t>(g, "ids", p.string()), ids);
  EXPECT_EQ(coredem::h5::datasetShape(g, "x", p.string()), (std::vector<hsize_t>{3, 2}));
  EXPECT_EQ(coredem::h5::readAttribute<double>(f, "time", p.string()), 0.25);
  EXPECT_EQ(coredem::h5::readAttribute<std::int64_t>(f, "step", p.string()), 42);
  EXPECT_EQ(coredem::h5::readStringAttribute(f, "version", p.string()), "0.1.0");
  EXPECT_EQ(coredem::h5::readStringAttribute(f, "empty", p.string()), "");
  EXPECT_TRUE(coredem::h5::exists(g, "x"));
  EXPECT_FALSE(coredem::h5::exists(g, "y"));
}

TEST(Hdf5, ErrorsNameTheFileAndTheObject) {
  const fs::path p = tempFile("err.h5");
  {
    auto f = coredem::h5::createFile(p);
    coredem::h5::writeDataset(f, "v", std::vector<double>{1, 2, 3});
  }
  auto f = coredem::h5::openFile(p);
  try {
    (void)coredem::h5::readDataset<double>(f, "v", p.string(), 4);
    FAIL();
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("dataset 'v' has 3 values, expected 4"),
              std::string::npos);
  }
  EXPECT_THROW((void)coredem::h5::readDataset<double>(f, "w", p.string()), coredem::UserError);
  EXPECT_THROW((void)coredem::h5::readAttribute<double>(f, "t", p.string()), coredem::UserError);
  EXPECT_THROW((void)coredem::h5::openGroup(f, "g", p.string()), coredem::UserError);
  EXPECT_THROW((void)coredem::h5::writeDataset(f, "bad", std::vector<double>{1, 2}, {3}),
               coredem::UserError);

  const fs::path text = tempFile("not.h5");
  std::ofstream(text) << "not hdf5";
  EXPECT_THROW((void)coredem::h5::openFile(text), coredem::UserError);
  EXPECT_THROW((void)coredem::h5::openFile(tempFile("missing.h5")), coredem::UserError);
}

} // namespace
