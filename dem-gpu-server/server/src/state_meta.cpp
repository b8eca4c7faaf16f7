#include "state_meta.h"

#include "coredem/common/check.h"

#include <hdf5.h>

namespace coredem::server {

namespace {

/// Closes an HDF5 handle on scope exit.
struct H5Handle {
  hid_t id = -1;
  herr_t (*close)(hid_t) = nullptr;
  H5Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~H5Handle() {
    if (id >= 0 && close != nullptr) {
      close(id);
    }
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
};

void writeScalarAttr(hid_t loc, const char* name, hid_t type, const void* value) {
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  H5Handle attr(H5Acreate2(loc, name, type, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  COREDEM_CHECK(attr.id >= 0 && H5Awrite(attr.id, type, value) >= 0,
                "cannot write HDF5 attribute /server/{}", name);
}

} // namespace

void writeServerLedgers(const std::string& path, const ServerLedgers& l, std::int64_t step,
                        const std::string& session) {
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  COREDEM_CHECK(file.id >= 0, "cannot open the state file {} to add the server ledgers", path);
  if (H5Lexists(file.id, "/server", H5P_DEFAULT) > 0) {
    H5Ldelete(file.id, "/server", H5P_DEFAULT);
  }
  H5Handle group(H5Gcreate2(file.id, "/server", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  COREDEM_CHECK(group.id >= 0, "cannot create /server in {}", path);
  writeScalarAttr(group.id, "step", H5T_NATIVE_INT64, &step);
  {
    H5Handle strType(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(strType.id, session.size() + 1);
    writeScalarAttr(group.id, "session", strType.id, session.c_str());
  }
  const hsize_t n = l.speciesToGas.size();
  H5Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  H5Handle ds(H5Dcreate2(group.id, "species_to_gas_kg", H5T_NATIVE_DOUBLE, space.id, H5P_DEFAULT,
                         H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  COREDEM_CHECK(ds.id >= 0 && (n == 0 || H5Dwrite(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL,
                                                  H5P_DEFAULT, l.speciesToGas.data()) >= 0),
                "cannot write /server/species_to_gas_kg in {}", path);
}

ServerLedgers readServerLedgers(const std::string& path, int species) {
  ServerLedgers l;
  l.speciesToGas.assign(static_cast<std::size_t>(species), 0.0);
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  COREDEM_CHECK(file.id >= 0, "cannot open the state file {}", path);
  if (H5Lexists(file.id, "/server", H5P_DEFAULT) <= 0) {
    return l;
  }
  H5Handle group(H5Gopen2(file.id, "/server", H5P_DEFAULT), H5Gclose);
  H5Handle ds(H5Dopen2(group.id, "species_to_gas_kg", H5P_DEFAULT), H5Dclose);
  H5Handle space(H5Dget_space(ds.id), H5Sclose);
  const auto n = H5Sget_simple_extent_npoints(space.id);
  COREDEM_CHECK(n == species, "{}: /server/species_to_gas_kg has {} entries, the case has {} gas "
                "species: restart with the case that wrote the file", path, n, species);
  if (n > 0) {
    COREDEM_CHECK(H5Dread(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                          l.speciesToGas.data()) >= 0,
                  "{}: /server/species_to_gas_kg unreadable", path);
  }
  return l;
}

} // namespace coredem::server
