#pragma once
/// @file
/// Reads every dataset of an HDF5 file as raw bytes, for bitwise state comparisons in e2e tests.

#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <hdf5.h>

namespace coredem::e2e {

namespace detail {
inline herr_t collectDataset(hid_t g, const char* name, const H5L_info_t*, void* data) {
  auto& out = *static_cast<std::map<std::string, std::string>*>(data);
  H5O_info_t info;
#if H5_VERSION_GE(1, 12, 0)
  H5Oget_info_by_name3(g, name, &info, H5O_INFO_BASIC, H5P_DEFAULT);
#else
  H5Oget_info_by_name2(g, name, &info, H5O_INFO_BASIC, H5P_DEFAULT);
#endif
  if (info.type != H5O_TYPE_DATASET) {
    return 0;
  }
  const hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
  const hid_t type = H5Dget_type(ds);
  if (H5Tis_variable_str(type) <= 0) {
    const hid_t space = H5Dget_space(ds);
    const std::size_t bytes = std::size_t(H5Sget_simple_extent_npoints(space)) * H5Tget_size(type);
    std::string buf(bytes, '\0');
    if (bytes > 0) {
      H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data());
    }
    out[name] = buf;
    H5Sclose(space);
  }
  H5Tclose(type);
  H5Dclose(ds);
  return 0;
}
} // namespace detail

/// Every dataset of an HDF5 file as raw bytes in its own file type, by path.
inline std::map<std::string, std::string> datasetsOf(const std::filesystem::path& file) {
  std::map<std::string, std::string> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << "cannot open " << file;
  if (f >= 0) {
    H5Lvisit(f, H5_INDEX_NAME, H5_ITER_INC, detail::collectDataset, &out);
    H5Fclose(f);
  }
  return out;
}

} // namespace coredem::e2e
