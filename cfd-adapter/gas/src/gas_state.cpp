#include "gas_state.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include <fcntl.h>
#include <unistd.h>

#include "coredem/common/check.h"
#include "coredem/common/files.h"
#include "coredem/common/hdf5.h"
#include "coredem/common/version.h"

namespace coredem::gas {

namespace {

const std::string kVersion = std::string("coredem-gas ") + coredem::kVersion;

} // namespace

void writeGasState(const std::string& path, const GasState& s) {
  COREDEM_CHECK(s.names.size() == s.values.size() && s.values.size() == s.compensation.size(),
                "internal: ledger names/values/compensation sizes differ");
  const std::string tmp = path + ".tmp";
  {
    auto file = h5::createFile(tmp);
    auto meta = h5::createGroup(file, "/meta");
    h5::writeAttribute(meta, "time", s.time);
    h5::writeAttribute(meta, "step", s.step);
    h5::writeAttribute(meta, "software_version", kVersion);
    h5::writeAttribute(meta, "case_key", s.caseKey);
    auto led = h5::createGroup(file, "/ledgers");
    h5::writeDataset(led, "values", s.values);
    h5::writeDataset(led, "compensation", s.compensation);
    h5::writeStrings(led, "names", s.names);
    H5Fflush(file, H5F_SCOPE_GLOBAL);
  }
  coredem::syncFile(tmp);
  std::filesystem::rename(tmp, path);
}

GasState readGasState(const std::string& path) {
  GasState s;
  COREDEM_CHECK(std::filesystem::exists(path), "restart file {} does not exist", path);
  auto file = h5::openFile(path);
  COREDEM_CHECK(h5::exists(file, "meta"), "{}: no /meta group (not a coredem-gas checkpoint?)",
                path);
  auto meta = h5::openGroup(file, "/meta", path);
  s.time = h5::readAttribute<double>(meta, "time", path + ": /meta");
  s.step = h5::readAttribute<std::int64_t>(meta, "step", path + ": /meta");
  auto led = h5::openGroup(file, "/ledgers", path);
  s.values = h5::readDataset<double>(led, "values", path + ": /ledgers");
  s.compensation = h5::readDataset<double>(led, "compensation", path + ": /ledgers");
  s.names = h5::readStrings(led, "names", path + ": /ledgers");
  COREDEM_CHECK(s.names.size() == s.values.size() && s.values.size() == s.compensation.size(),
                "{}: /ledgers names, values and compensation have different lengths", path);
  return s;
}

} // namespace coredem::gas
