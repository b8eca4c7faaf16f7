#include "gas_state.h"

#include "coredem/common/check.h"

#include <hdf5.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include <fcntl.h>
#include <unistd.h>

namespace coredem::gas {

namespace {

struct H5 {
  hid_t id;
  herr_t (*close)(hid_t);
  H5(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~H5() {
    if (id >= 0) close(id);
  }
  H5(const H5&) = delete;
  H5& operator=(const H5&) = delete;
};

constexpr const char* kVersion = "coredem-gas 0.1.0";

void attr(hid_t loc, const char* name, hid_t type, const void* v) {
  H5 space(H5Screate(H5S_SCALAR), H5Sclose);
  H5 a(H5Acreate2(loc, name, type, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  COREDEM_CHECK(a.id >= 0 && H5Awrite(a.id, type, v) >= 0, "cannot write attribute {}", name);
}

void strAttr(hid_t loc, const char* name, const std::string& value) {
  H5 t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.id, value.size() + 1);
  attr(loc, name, t.id, value.c_str());
}

void doubles(hid_t loc, const char* name, const std::vector<double>& v) {
  const hsize_t n = v.size();
  H5 space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  H5 d(H5Dcreate2(loc, name, H5T_NATIVE_DOUBLE, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  COREDEM_CHECK(d.id >= 0 && (n == 0 || H5Dwrite(d.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0),
                "cannot write dataset {}", name);
}

std::vector<double> readDoubles(hid_t loc, const char* name, const std::string& path) {
  H5 d(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose);
  COREDEM_CHECK(d.id >= 0, "{}: no dataset /ledgers/{} (not a coredem-gas checkpoint?)", path, name);
  H5 space(H5Dget_space(d.id), H5Sclose);
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.id)));
  COREDEM_CHECK(v.empty() || H5Dread(d.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0,
                "{}: cannot read /ledgers/{}", path, name);
  return v;
}

} // namespace

void writeGasState(const std::string& path, const GasState& s) {
  COREDEM_CHECK(s.names.size() == s.values.size() && s.values.size() == s.compensation.size(),
                "internal: ledger names/values/compensation sizes differ");
  const std::string tmp = path + ".tmp";
  {
    H5 file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    COREDEM_CHECK(file.id >= 0, "cannot create {}: check that the checkpoint directory exists and "
                  "is writable", tmp);
    H5 meta(H5Gcreate2(file.id, "/meta", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    attr(meta.id, "time", H5T_NATIVE_DOUBLE, &s.time);
    attr(meta.id, "step", H5T_NATIVE_INT64, &s.step);
    strAttr(meta.id, "software_version", kVersion);
    strAttr(meta.id, "case_key", s.caseKey);
    H5 led(H5Gcreate2(file.id, "/ledgers", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    doubles(led.id, "values", s.values);
    doubles(led.id, "compensation", s.compensation);
    std::size_t width = 1;
    for (const auto& n : s.names) width = std::max(width, n.size() + 1);
    std::vector<char> buf(width * s.names.size(), '\0');
    for (std::size_t i = 0; i < s.names.size(); ++i) {
      std::copy(s.names[i].begin(), s.names[i].end(), buf.begin() + static_cast<std::ptrdiff_t>(i * width));
    }
    H5 t(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(t.id, width);
    const hsize_t n = s.names.size();
    H5 space(H5Screate_simple(1, &n, nullptr), H5Sclose);
    H5 d(H5Dcreate2(led.id, "names", t.id, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
    COREDEM_CHECK(d.id >= 0 && (n == 0 || H5Dwrite(d.id, t.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) >= 0),
                  "cannot write /ledgers/names in {}", tmp);
    H5Fflush(file.id, H5F_SCOPE_GLOBAL);
  }
  const int fd = ::open(tmp.c_str(), O_RDONLY);
  COREDEM_CHECK(fd >= 0 && ::fsync(fd) == 0, "cannot flush {} to disk", tmp);
  ::close(fd);
  std::filesystem::rename(tmp, path);
}

GasState readGasState(const std::string& path) {
  GasState s;
  COREDEM_CHECK(std::filesystem::exists(path), "restart file {} does not exist", path);
  H5 file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  COREDEM_CHECK(file.id >= 0, "cannot open {} as HDF5", path);
  H5 meta(H5Gopen2(file.id, "/meta", H5P_DEFAULT), H5Gclose);
  COREDEM_CHECK(meta.id >= 0, "{}: no /meta group (not a coredem-gas checkpoint?)", path);
  {
    H5 a(H5Aopen(meta.id, "time", H5P_DEFAULT), H5Aclose);
    COREDEM_CHECK(a.id >= 0 && H5Aread(a.id, H5T_NATIVE_DOUBLE, &s.time) >= 0, "{}: /meta time", path);
  }
  {
    H5 a(H5Aopen(meta.id, "step", H5P_DEFAULT), H5Aclose);
    COREDEM_CHECK(a.id >= 0 && H5Aread(a.id, H5T_NATIVE_INT64, &s.step) >= 0, "{}: /meta step", path);
  }
  H5 led(H5Gopen2(file.id, "/ledgers", H5P_DEFAULT), H5Gclose);
  COREDEM_CHECK(led.id >= 0, "{}: no /ledgers group", path);
  s.values = readDoubles(led.id, "values", path);
  s.compensation = readDoubles(led.id, "compensation", path);
  H5 d(H5Dopen2(led.id, "names", H5P_DEFAULT), H5Dclose);
  COREDEM_CHECK(d.id >= 0, "{}: no /ledgers/names", path);
  H5 t(H5Dget_type(d.id), H5Tclose);
  const std::size_t width = H5Tget_size(t.id);
  H5 space(H5Dget_space(d.id), H5Sclose);
  const auto n = static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.id));
  std::vector<char> buf(width * n + 1, '\0');
  COREDEM_CHECK(n == 0 || H5Dread(d.id, t.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) >= 0,
                "{}: cannot read /ledgers/names", path);
  for (std::size_t i = 0; i < n; ++i) {
    const char* p = buf.data() + i * width;
    s.names.emplace_back(p, strnlen(p, width));
  }
  COREDEM_CHECK(s.names.size() == s.values.size() && s.values.size() == s.compensation.size(),
                "{}: /ledgers names, values and compensation have different lengths", path);
  return s;
}

} // namespace coredem::gas
