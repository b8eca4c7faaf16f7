#include <algorithm>
#include <cstring>

#include <coredem/common/hdf5.h>

namespace coredem::h5 {

Handle createFile(const std::filesystem::path& path) {
  Handle f(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  COREDEM_CHECK(f.valid(),
                "cannot create HDF5 file '{}': check that its folder exists and is "
                "writable",
                path.string());
  return f;
}

Handle openFile(const std::filesystem::path& path, bool writable) {
  COREDEM_CHECK(std::filesystem::exists(path), "HDF5 file '{}' does not exist", path.string());
  Handle f;
  H5E_BEGIN_TRY { // no HDF5 error stack on stderr: the message below says it
    f = Handle(H5Fopen(path.c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT),
               H5Fclose);
  }
  H5E_END_TRY;
  COREDEM_CHECK(f.valid(),
                "cannot open '{}' as HDF5: the file is not HDF5, is truncated or is "
                "open for writing elsewhere",
                path.string());
  return f;
}

Handle createGroup(hid_t loc, const std::string& name) {
  Handle g(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  COREDEM_CHECK(g.valid(), "cannot create HDF5 group '{}'", name);
  return g;
}

Handle openGroup(hid_t loc, const std::string& name, const std::string& what) {
  COREDEM_CHECK(exists(loc, name), "{}: no group '{}'", what, name);
  Handle g(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), H5Gclose);
  COREDEM_CHECK(g.valid(), "{}: cannot open group '{}'", what, name);
  return g;
}

bool exists(hid_t loc, const std::string& name) {
  htri_t r = -1;
  H5E_BEGIN_TRY {
    r = H5Lexists(loc, name.c_str(), H5P_DEFAULT);
  }
  H5E_END_TRY;
  return r > 0;
}

bool hasAttribute(hid_t loc, const std::string& name) {
  return H5Aexists(loc, name.c_str()) > 0;
}

void writeAttribute(hid_t loc, const std::string& name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type, value.size() + 1);
  H5Tset_strpad(type, H5T_STR_NULLTERM);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle a(H5Acreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  COREDEM_CHECK(a.valid() && H5Awrite(a, type, value.c_str()) >= 0,
                "cannot write HDF5 attribute '{}'", name);
}

std::string readStringAttribute(hid_t loc, const std::string& name, const std::string& what) {
  COREDEM_CHECK(hasAttribute(loc, name), "{}: no attribute '{}'", what, name);
  Handle a(H5Aopen(loc, name.c_str(), H5P_DEFAULT), H5Aclose);
  Handle type(H5Aget_type(a), H5Tclose);
  COREDEM_CHECK(H5Tget_class(type) == H5T_STRING, "{}: attribute '{}' is not a string", what, name);
  if (H5Tis_variable_str(type) > 0) {
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem, H5T_VARIABLE);
    char* p = nullptr;
    COREDEM_CHECK(H5Aread(a, mem, &p) >= 0, "{}: cannot read attribute '{}'", what, name);
    std::string out = p ? p : "";
    H5free_memory(p);
    return out;
  }
  const std::size_t size = H5Tget_size(type);
  std::string buf(size, '\0');
  Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(mem, size);
  COREDEM_CHECK(H5Aread(a, mem, buf.data()) >= 0, "{}: cannot read attribute '{}'", what, name);
  buf.resize(buf.find('\0') == std::string::npos ? size : buf.find('\0'));
  return buf;
}

std::vector<hsize_t> datasetShape(hid_t loc, const std::string& name, const std::string& what) {
  COREDEM_CHECK(exists(loc, name), "{}: no dataset '{}'", what, name);
  Handle ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  Handle space(H5Dget_space(ds), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space);
  COREDEM_CHECK(rank >= 0, "{}: cannot read the shape of dataset '{}'", what, name);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return dims;
}

void writeStrings(hid_t loc, const std::string& name, const std::vector<std::string>& v) {
  std::size_t width = 1;
  for (const auto& x : v) {
    width = std::max(width, x.size() + 1);
  }
  std::vector<char> buf(width * v.size(), '\0');
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::copy(v[i].begin(), v[i].end(), buf.begin() + static_cast<std::ptrdiff_t>(i * width));
  }
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type, width);
  const hsize_t n = v.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  Handle ds(H5Dcreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
            H5Dclose);
  COREDEM_CHECK(ds.valid() &&
                    (n == 0 || H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) >= 0),
                "cannot write HDF5 string dataset '{}'", name);
}

std::vector<std::string> readStrings(hid_t loc, const std::string& name, const std::string& what) {
  COREDEM_CHECK(exists(loc, name), "{}: no dataset '{}'", what, name);
  Handle ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  Handle type(H5Dget_type(ds), H5Tclose);
  COREDEM_CHECK(H5Tget_class(type) == H5T_STRING && H5Tis_variable_str(type) <= 0,
                "{}: dataset '{}' is not a fixed-width string list", what, name);
  const std::size_t width = H5Tget_size(type);
  Handle space(H5Dget_space(ds), H5Sclose);
  const auto n = static_cast<std::size_t>(H5Sget_simple_extent_npoints(space));
  std::vector<char> buf(width * n + 1, '\0');
  COREDEM_CHECK(n == 0 || H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) >= 0,
                "{}: cannot read dataset '{}'", what, name);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n; ++i) {
    const char* p = buf.data() + i * width;
    out.emplace_back(p, strnlen(p, width));
  }
  return out;
}

} // namespace coredem::h5
