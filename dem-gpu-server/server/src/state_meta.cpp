#include "state_meta.h"

#include "coredem/common/check.h"
#include "coredem/common/hdf5.h"

namespace coredem::server {

void writeServerLedgers(const std::string& path, const ServerLedgers& l, std::int64_t step,
                        const std::string& session) {
  const h5::Handle file = h5::openFile(path, true);
  if (h5::exists(file, "/server")) {
    H5Ldelete(file, "/server", H5P_DEFAULT);
  }
  const h5::Handle group = h5::createGroup(file, "/server");
  h5::writeAttribute(group, "step", step);
  h5::writeAttribute(group, "session", session);
  h5::writeDataset(group, "species_to_gas_kg", l.speciesToGas);
}

ServerLedgers readServerLedgers(const std::string& path, int species) {
  ServerLedgers l;
  l.speciesToGas.assign(static_cast<std::size_t>(species), 0.0);
  const h5::Handle file = h5::openFile(path);
  if (!h5::exists(file, "/server")) {
    return l;
  }
  const h5::Handle group = h5::openGroup(file, "/server", path);
  const std::vector<double> v = h5::readDataset<double>(group, "species_to_gas_kg", path);
  COREDEM_CHECK(v.size() == static_cast<std::size_t>(species),
                "{}: /server/species_to_gas_kg has {} entries, the case has {} gas species: "
                "restart with the case that wrote the file",
                path, v.size(), species);
  l.speciesToGas = v;
  return l;
}

} // namespace coredem::server
