#pragma once
/// @file
/// HDF5 with the C API, without leaks and with errors that name the file and the object:
/// RAII handles and the few read/write operations every state file, checkpoint and snapshot
/// uses (scalar attributes, string attributes, n-dimensional datasets read back as flat vectors).
///
///   auto file = h5::createFile(path);            // truncates
///   auto g = h5::createGroup(file, "particles");
///   h5::writeDataset(g, "pos", pos, {n, 3});
///   h5::writeAttribute(file, "time", 0.25);

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <hdf5.h>

#include <coredem/common/check.h>

namespace coredem::h5 {

/// Owns an HDF5 identifier and closes it with the matching H5?close on scope exit.
class Handle {
public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t))
      : _id(id)
      , _close(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept
      : _id(std::exchange(o._id, -1))
      , _close(o._close) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      _id = std::exchange(o._id, -1);
      _close = o._close;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t id() const { return _id; }
  operator hid_t() const { return _id; } // NOLINT: pass straight to the C API
  bool valid() const { return _id >= 0; }
  void reset() {
    if (_id >= 0 && _close != nullptr) {
      _close(_id);
    }
    _id = -1;
  }

private:
  hid_t _id = -1;
  herr_t (*_close)(hid_t) = nullptr;
};

/// The native HDF5 type of T (double, float, int32, int64, uint64, uint8).
template <class T>
hid_t nativeType();
template <>
inline hid_t nativeType<double>() {
  return H5T_NATIVE_DOUBLE;
}
template <>
inline hid_t nativeType<float>() {
  return H5T_NATIVE_FLOAT;
}
template <>
inline hid_t nativeType<std::int32_t>() {
  return H5T_NATIVE_INT32;
}
template <>
inline hid_t nativeType<std::int64_t>() {
  return H5T_NATIVE_INT64;
}
template <>
inline hid_t nativeType<std::uint64_t>() {
  return H5T_NATIVE_UINT64;
}
template <>
inline hid_t nativeType<std::uint8_t>() {
  return H5T_NATIVE_UINT8;
}

/// Creates (truncates) a file. Throws UserError naming the path.
Handle createFile(const std::filesystem::path& path);
/// Opens an existing file read-only (or read-write). Throws UserError naming the path and what
/// to do when it is missing or not HDF5.
Handle openFile(const std::filesystem::path& path, bool writable = false);
Handle createGroup(hid_t loc, const std::string& name);
/// Opens a group; throws UserError naming `what` (e.g. the file) when it is missing.
Handle openGroup(hid_t loc, const std::string& name, const std::string& what);
/// True if loc has a link (group or dataset) `name`.
bool exists(hid_t loc, const std::string& name);
bool hasAttribute(hid_t loc, const std::string& name);

template <class T>
void writeAttribute(hid_t loc, const std::string& name, const T& value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle a(H5Acreate2(loc, name.c_str(), nativeType<T>(), space, H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  COREDEM_CHECK(a.valid() && H5Awrite(a, nativeType<T>(), &value) >= 0,
                "cannot write HDF5 attribute '{}'", name);
}
/// A fixed-length, null-terminated string attribute.
void writeAttribute(hid_t loc, const std::string& name, const std::string& value);
inline void writeAttribute(hid_t loc, const std::string& name, const char* value) {
  writeAttribute(loc, name, std::string(value));
}

/// Reads a scalar attribute; throws UserError "what: no attribute 'name'" when it is missing.
template <class T>
T readAttribute(hid_t loc, const std::string& name, const std::string& what) {
  COREDEM_CHECK(hasAttribute(loc, name), "{}: no attribute '{}'", what, name);
  Handle a(H5Aopen(loc, name.c_str(), H5P_DEFAULT), H5Aclose);
  T value{};
  COREDEM_CHECK(a.valid() && H5Aread(a, nativeType<T>(), &value) >= 0,
                "{}: cannot read attribute '{}'", what, name);
  return value;
}
std::string readStringAttribute(hid_t loc, const std::string& name, const std::string& what);

/// Writes v (row-major) as a dataset of shape dims (product(dims) must equal v.size()).
template <class T>
void writeDataset(hid_t loc, const std::string& name, const std::vector<T>& v,
                  std::vector<hsize_t> dims) {
  hsize_t total = 1;
  for (const hsize_t d : dims) {
    total *= d;
  }
  COREDEM_CHECK(total == v.size(), "HDF5 dataset '{}': {} values for a shape of {} (internal)",
                name, v.size(), total);
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle ds(
      H5Dcreate2(loc, name.c_str(), nativeType<T>(), space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose);
  COREDEM_CHECK(ds.valid(), "cannot create HDF5 dataset '{}'", name);
  if (total > 0) {
    COREDEM_CHECK(H5Dwrite(ds, nativeType<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0,
                  "cannot write HDF5 dataset '{}'", name);
  }
}
template <class T>
void writeDataset(hid_t loc, const std::string& name, const std::vector<T>& v) {
  writeDataset(loc, name, v, {static_cast<hsize_t>(v.size())});
}

/// The shape of a dataset; throws UserError naming `what` when it is missing.
std::vector<hsize_t> datasetShape(hid_t loc, const std::string& name, const std::string& what);

/// Reads a whole dataset as a flat vector (converted to T by HDF5). When `expected` is given,
/// the element count must match, else UserError "what: dataset 'name' has n values, expected m".
template <class T>
std::vector<T> readDataset(hid_t loc, const std::string& name, const std::string& what,
                           std::int64_t expected = -1) {
  COREDEM_CHECK(exists(loc, name), "{}: no dataset '{}'", what, name);
  Handle ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  Handle space(H5Dget_space(ds), H5Sclose);
  const hssize_t total = H5Sget_simple_extent_npoints(space);
  COREDEM_CHECK(total >= 0, "{}: cannot read the shape of dataset '{}'", what, name);
  COREDEM_CHECK(expected < 0 || total == expected, "{}: dataset '{}' has {} values, expected {}",
                what, name, total, expected);
  std::vector<T> v(static_cast<std::size_t>(total));
  if (total > 0) {
    COREDEM_CHECK(H5Dread(ds, nativeType<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0,
                  "{}: cannot read dataset '{}'", what, name);
  }
  return v;
}

/// A 1-D dataset of fixed-width, null-padded strings (names of ledgers, species, sets).
void writeStrings(hid_t loc, const std::string& name, const std::vector<std::string>& v);
std::vector<std::string> readStrings(hid_t loc, const std::string& name, const std::string& what);

} // namespace coredem::h5
