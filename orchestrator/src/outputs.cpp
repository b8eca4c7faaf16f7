#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

#include <coredem/common/check.h>
#include <coredem/common/hdf5.h>
#include <coredem/dem/particle_schema.h>
#include <coredem/orchestrator/checkpoint.h>
#include <coredem/orchestrator/outputs.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {

std::vector<std::string> csvFields(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

TimeseriesWriter::TimeseriesWriter(fs::path path, std::int64_t resumeAfterStep)
    : _path(std::move(path)) {
  if (resumeAfterStep >= 0 && fs::is_regular_file(_path)) {
    // Keep the header and rows with step <= resumeAfterStep; rewrite atomically.
    std::ifstream in(_path);
    std::string line;
    std::string kept;
    bool header = true;
    while (std::getline(in, line)) {
      if (header) {
        _columns = csvFields(line);
        kept += line + "\n";
        header = false;
        continue;
      }
      if (line.empty()) {
        continue;
      }
      const auto cells = csvFields(line);
      if (cells.size() != _columns.size()) {
        break; // a torn last line from a crash
      }
      if (std::stoll(cells[0]) > resumeAfterStep) {
        break;
      }
      kept += line + "\n";
    }
    in.close();
    writeFileAtomic(_path, kept);
  } else {
    writeFileAtomic(_path, "");
  }
  _fd = ::open(_path.c_str(), O_WRONLY | O_APPEND);
  COREDEM_CHECK(_fd >= 0, "cannot open '{}' for writing: {}", _path.string(), std::strerror(errno));
}

TimeseriesWriter::~TimeseriesWriter() {
  if (_fd >= 0) {
    ::close(_fd);
  }
}

void TimeseriesWriter::write(const std::vector<std::pair<std::string, double>>& row) {
  std::string text;
  if (_columns.empty()) {
    for (const auto& [name, v] : row) {
      _columns.push_back(name);
    }
    for (std::size_t i = 0; i < _columns.size(); ++i) {
      text += (i ? "," : "") + _columns[i];
    }
    text += "\n";
  }
  for (std::size_t i = 0; i < _columns.size(); ++i) {
    if (i) {
      text += ",";
    }
    for (const auto& [name, v] : row) {
      if (name == _columns[i]) {
        if (i == 0) {
          text += fmt::format("{}", static_cast<long long>(v));
        } else {
          text += fmt::format("{:.17g}", v);
        }
        break;
      }
    }
  }
  text += "\n";
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(_fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) {
      continue;
    }
    COREDEM_CHECK(n >= 0, "cannot write '{}': {}", _path.string(), std::strerror(errno));
    done += std::size_t(n);
  }
}

// ---- HDF5 scanning ---------------------------------------------------------------------

namespace {

struct ScanState {
  std::vector<DatasetInfo>* datasets;
  std::vector<AttributeInfo>* attributes;
  bool statistics;
};

std::string typeName(hid_t type) {
  const H5T_class_t cls = H5Tget_class(type);
  const std::size_t size = H5Tget_size(type);
  switch (cls) {
  case H5T_FLOAT:
    return size == 8 ? "float64" : "float32";
  case H5T_INTEGER: {
    const bool isSigned = H5Tget_sign(type) == H5T_SGN_2;
    return fmt::format("{}int{}", isSigned ? "" : "u", size * 8);
  }
  case H5T_STRING:
    return "string";
  default:
    return "other";
  }
}

std::string attributeText(hid_t attr) {
  const h5::Handle type(H5Aget_type(attr), H5Tclose);
  const h5::Handle space(H5Aget_space(attr), H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  std::string out;
  const H5T_class_t cls = H5Tget_class(type);
  if (cls == H5T_STRING) {
    if (H5Tis_variable_str(type) > 0) {
      std::vector<char*> ptrs(std::size_t(std::max<hssize_t>(n, 1)), nullptr);
      const h5::Handle mem(H5Tget_native_type(type, H5T_DIR_ASCEND), H5Tclose);
      if (H5Aread(attr, mem, ptrs.data()) >= 0) {
        for (hssize_t i = 0; i < n; ++i) {
          out += (i ? ", " : "") + std::string(ptrs[std::size_t(i)] ? ptrs[std::size_t(i)] : "");
        }
        H5Dvlen_reclaim(mem, space, H5P_DEFAULT, ptrs.data());
      }
    } else {
      const std::size_t size = H5Tget_size(type);
      std::vector<char> buf(size * std::size_t(std::max<hssize_t>(n, 1)) + 1, '\0');
      if (H5Aread(attr, type, buf.data()) >= 0) {
        out.assign(buf.data(), strnlen(buf.data(), buf.size()));
      }
    }
  } else if (cls == H5T_FLOAT || cls == H5T_INTEGER) {
    std::vector<double> v(std::size_t(std::max<hssize_t>(n, 1)));
    if (H5Aread(attr, H5T_NATIVE_DOUBLE, v.data()) >= 0) {
      for (hssize_t i = 0; i < n; ++i) {
        out += (i ? ", " : "") + fmt::format("{:.17g}", v[std::size_t(i)]);
      }
    }
  } else {
    out = "(" + typeName(type) + ")";
  }
  return out;
}

void scanAttributes(hid_t obj, const std::string& path, ScanState& st) {
  H5O_info_t info;
#if H5_VERSION_GE(1, 12, 0)
  H5Oget_info3(obj, &info, H5O_INFO_NUM_ATTRS);
#else
  H5Oget_info2(obj, &info, H5O_INFO_NUM_ATTRS);
#endif
  for (hsize_t i = 0; i < info.num_attrs; ++i) {
    const h5::Handle attr(
        H5Aopen_by_idx(obj, ".", H5_INDEX_NAME, H5_ITER_INC, i, H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose);
    if (!attr.valid()) {
      continue;
    }
    char name[256] = {0};
    H5Aget_name(attr, sizeof name, name);
    st.attributes->push_back({path + "@" + name, attributeText(attr)});
  }
}

herr_t visit(hid_t group, const char* name, const H5L_info_t*, void* data) {
  auto& st = *static_cast<ScanState*>(data);
  H5O_info_t info;
#if H5_VERSION_GE(1, 12, 0)
  if (H5Oget_info_by_name3(group, name, &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
#else
  if (H5Oget_info_by_name2(group, name, &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
#endif
    return 0;
  }
  const std::string path = std::string("/") + name;
  if (info.type == H5O_TYPE_GROUP) {
    const h5::Handle g(H5Gopen2(group, name, H5P_DEFAULT), H5Gclose);
    scanAttributes(g, path, st);
  } else if (info.type == H5O_TYPE_DATASET) {
    const h5::Handle ds(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    const h5::Handle space(H5Dget_space(ds), H5Sclose);
    const h5::Handle type(H5Dget_type(ds), H5Tclose);
    DatasetInfo d;
    d.path = path;
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> dims(std::size_t(std::max(rank, 0)));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    d.dims.assign(dims.begin(), dims.end());
    d.type = typeName(type);
    const H5T_class_t cls = H5Tget_class(type);
    d.numeric = cls == H5T_FLOAT || cls == H5T_INTEGER;
    if (d.numeric && st.statistics) {
      const hssize_t n = H5Sget_simple_extent_npoints(space);
      std::vector<double> v(std::size_t(std::max<hssize_t>(n, 0)));
      if (n > 0 && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0) {
        d.min = *std::min_element(v.begin(), v.end());
        d.max = *std::max_element(v.begin(), v.end());
        double sum = 0;
        for (double x : v) {
          sum += x;
        }
        d.mean = sum / double(n);
        if (dims.size() == 2 && dims[1] > 1 && dims[0] > 0) {
          const std::size_t rows = dims[0], w = dims[1];
          d.columnMin.assign(w, std::numeric_limits<double>::infinity());
          d.columnMax.assign(w, -std::numeric_limits<double>::infinity());
          d.columnMean.assign(w, 0.0);
          for (std::size_t i = 0; i < rows; ++i) {
            for (std::size_t k = 0; k < w; ++k) {
              const double x = v[i * w + k];
              d.columnMin[k] = std::min(d.columnMin[k], x);
              d.columnMax[k] = std::max(d.columnMax[k], x);
              d.columnMean[k] += x;
            }
          }
          for (auto& m : d.columnMean) {
            m /= double(rows);
          }
        }
      }
    }
    st.datasets->push_back(d);
    scanAttributes(ds, path, st);
  }
  return 0;
}

} // namespace

void scanHdf5(const fs::path& file, std::vector<DatasetInfo>& datasets,
              std::vector<AttributeInfo>& attributes, bool statistics) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  COREDEM_CHECK(H5Fis_hdf5(file.c_str()) > 0, "'{}' is not an HDF5 file", file.string());
  const h5::Handle f(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  COREDEM_CHECK(f.valid(), "cannot open HDF5 file '{}'", file.string());
  ScanState st{&datasets, &attributes, statistics};
  scanAttributes(f, "/", st);
  H5Lvisit(f, H5_INDEX_NAME, H5_ITER_INC, visit, &st);
}

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    out += (i ? "," : "") + v[i];
  }
  return out;
}

std::vector<std::string> splitNames(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, ',')) {
    out.push_back(cur);
  }
  return out;
}

/// The column names of a multi-column field: its `columns` attribute or 0..w-1.
std::vector<std::string> columnNames(const std::vector<AttributeInfo>& attrs,
                                     const std::string& path, std::uint64_t width) {
  for (const auto& a : attrs) {
    if (a.path == path + "@columns") {
      auto names = splitNames(a.value);
      if (names.size() == width) {
        return names;
      }
    }
  }
  std::vector<std::string> out;
  for (std::uint64_t k = 0; k < width; ++k) {
    out.push_back(std::to_string(k));
  }
  return out;
}

} // namespace

void describeSnapshot(const fs::path& file, const SnapshotLabels& labels) {
  namespace sc = dem::schema;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const h5::Handle f = h5::openFile(file, true);
  for (const sc::FieldInfo& info : sc::kFields) {
    const std::string path =
        std::string("/") + sc::groupName(info.group) + "/" + std::string(info.name);
    if (!h5::exists(f, std::string(sc::groupName(info.group))) || !h5::exists(f, path.substr(1))) {
      continue;
    }
    const h5::Handle ds(H5Dopen2(f, path.c_str(), H5P_DEFAULT), H5Dclose);
    if (!ds.valid() || h5::hasAttribute(ds, "unit")) {
      continue;
    }
    h5::writeAttribute(ds, "unit",
                       info.unit.empty() ? std::string("none") : std::string(info.unit));
    h5::writeAttribute(ds, "description", std::string(info.doc));
    if (info.per == sc::Per::Species && !labels.solidSpecies.empty()) {
      h5::writeAttribute(ds, "columns", join(labels.solidSpecies));
    } else if (info.per == sc::Per::Particle && info.components == 3) {
      h5::writeAttribute(ds, "columns", std::string("x,y,z"));
    } else if (info.per == sc::Per::Particle && info.components > 1) {
      std::vector<std::string> k;
      for (int c = 0; c < info.components; ++c) {
        k.push_back(std::to_string(c));
      }
      h5::writeAttribute(ds, "columns", join(k));
    }
  }
  const auto radius = h5::readDataset<double>(f, "particles/radius", file.string());
  if (!h5::exists(f, "particles/diameter")) {
    std::vector<double> d(radius.size());
    for (std::size_t i = 0; i < d.size(); ++i) {
      d[i] = 2.0 * radius[i];
    }
    h5::writeDataset(f, "particles/diameter", d);
    const h5::Handle ds(H5Dopen2(f, "particles/diameter", H5P_DEFAULT), H5Dclose);
    h5::writeAttribute(ds, "unit", "m");
    h5::writeAttribute(ds, "description", "diameter d_p = 2 R");
  }
  // Global ids are given set by set in the order of particles[] (DemSystem's constructor).
  if (!labels.sets.empty() && labels.sets.size() == labels.setCounts.size() &&
      h5::exists(f, "particles/global_id") && !h5::exists(f, "particles/set_index")) {
    const auto gid = h5::readDataset<std::int64_t>(f, "particles/global_id", file.string());
    std::vector<std::int32_t> set(gid.size(), -1);
    for (std::size_t i = 0; i < gid.size(); ++i) {
      std::int64_t offset = 0;
      for (std::size_t k = 0; k < labels.setCounts.size(); ++k) {
        if (gid[i] >= offset && gid[i] < offset + std::int64_t(labels.setCounts[k])) {
          set[i] = std::int32_t(k);
          break;
        }
        offset += std::int64_t(labels.setCounts[k]);
      }
    }
    h5::writeDataset(f, "particles/set_index", set);
    const h5::Handle ds(H5Dopen2(f, "particles/set_index", H5P_DEFAULT), H5Dclose);
    h5::writeAttribute(ds, "unit", "none");
    h5::writeAttribute(ds, "description",
                       "index of the particle set (case.yaml particles[]) the particle belongs to");
    h5::writeAttribute(ds, "names", join(labels.sets));
    h5::writeAttribute(ds, "columns", join(labels.sets));
  }
  if (!h5::hasAttribute(f, "title")) {
    h5::writeAttribute(f, "title",
                       "CoReDEM particle snapshot: /particles/<field> [N] or [N, columns], SI "
                       "units; each dataset has the attributes unit and description");
    if (h5::exists(f, "meta")) {
      const h5::Handle meta = h5::openGroup(f, "meta", file.string());
      if (h5::hasAttribute(meta, "time")) {
        h5::writeAttribute(f, "time", h5::readAttribute<double>(meta, "time", file.string()));
      }
      if (h5::hasAttribute(meta, "step")) {
        h5::writeAttribute(f, "step", h5::readAttribute<std::int64_t>(meta, "step", file.string()));
      }
    }
    h5::writeAttribute(f, "species_names", join(labels.solidSpecies));
    h5::writeAttribute(f, "set_names", join(labels.sets));
    h5::writeAttribute(f, "material_names", join(labels.materials));
  }
}

void writeParticleXdmf(const fs::path& xdmfPath,
                       const std::vector<std::pair<double, std::string>>& snapshots) {
  namespace sc = dem::schema;
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n";
  x << "<Xdmf Version=\"3.0\">\n <Domain>\n";
  x << "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  const fs::path base = xdmfPath.parent_path();
  for (const auto& [time, rel] : snapshots) {
    std::vector<DatasetInfo> ds;
    std::vector<AttributeInfo> attrs;
    scanHdf5(base / rel, ds, attrs, false);
    const DatasetInfo* pos = nullptr;
    for (const auto& d : ds) {
      if (d.path == "/particles/position") {
        pos = &d;
      }
    }
    COREDEM_CHECK(pos && pos->dims.size() == 2 && pos->dims[1] == 3,
                  "snapshot '{}' has no /particles/position [N,3] dataset", rel);
    const std::uint64_t n = pos->dims[0];
    x << fmt::format("   <Grid Name=\"t={:.9g}\" GridType=\"Uniform\">\n", time);
    x << fmt::format("    <Time Value=\"{:.17g}\"/>\n", time);
    x << fmt::format("    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" "
                     "NodesPerElement=\"1\"/>\n",
                     n);
    x << "    <Geometry GeometryType=\"XYZ\">\n";
    x << fmt::format("     <DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"8\" "
                     "Format=\"HDF\">{}:/particles/position</DataItem>\n",
                     n, rel);
    x << "    </Geometry>\n";
    // The node attributes: every per-particle field of the DEM particle schema the file holds
    // (per particle or per species), then the fields describeSnapshot adds.
    std::vector<std::string> paths;
    for (const sc::FieldInfo& f : sc::kFields) {
      if (f.name == sc::kGeometryField ||
          (f.per != sc::Per::Particle && f.per != sc::Per::Species)) {
        continue;
      }
      paths.push_back(std::string("/") + sc::groupName(f.group) + "/" + std::string(f.name));
    }
    paths.push_back("/particles/diameter");
    paths.push_back("/particles/set_index");
    for (const std::string& path : paths) {
      const auto it =
          std::find_if(ds.begin(), ds.end(), [&](const DatasetInfo& d) { return d.path == path; });
      if (it == ds.end()) {
        continue;
      }
      const DatasetInfo& d = *it;
      if (!d.numeric || d.dims.empty() || d.dims[0] != n || d.dims.size() > 2) {
        continue;
      }
      const std::string name = path.substr(path.rfind('/') + 1);
      const bool isFloat = d.type.rfind("float", 0) == 0;
      const std::string numberType =
          isFloat ? "Float" : (d.type.rfind("u", 0) == 0 ? "UInt" : "Int");
      const std::string precision = d.type.find("64") != std::string::npos ? "8" : "4";
      const std::uint64_t width = d.dims.size() == 2 ? d.dims[1] : 1;
      const std::string item =
          fmt::format("DataItem Dimensions=\"{}{}\" NumberType=\"{}\" Precision=\"{}\" "
                      "Format=\"HDF\">{}:{}</DataItem>",
                      n, width > 1 ? fmt::format(" {}", width) : std::string(), numberType,
                      precision, rel, d.path);
      if (width == 1 || width == 3) {
        x << fmt::format("    <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n", name,
                         width == 3 ? "Vector" : "Scalar");
        x << "     <" << item << "\n    </Attribute>\n";
        continue;
      }
      // Any other width (species, ...): one named scalar per column, a hyperslab of the column.
      const auto columns = columnNames(attrs, d.path, width);
      for (std::uint64_t k = 0; k < width; ++k) {
        x << fmt::format("    <Attribute Name=\"{}_{}\" AttributeType=\"Scalar\" "
                         "Center=\"Node\">\n",
                         name, columns[k]);
        x << fmt::format("     <DataItem ItemType=\"HyperSlab\" Dimensions=\"{} 1\" "
                         "Type=\"HyperSlab\">\n",
                         n);
        x << fmt::format("      <DataItem Dimensions=\"3 2\" Format=\"XML\">0 {} 1 1 {} 1"
                         "</DataItem>\n",
                         k, n);
        x << "      <" << item << "\n     </DataItem>\n    </Attribute>\n";
      }
    }
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  writeFileAtomic(xdmfPath, x.str());
}

std::string inspectSummary(const fs::path& file) {
  std::ostringstream out;
  fs::path dir;
  if (fs::is_directory(file) && fs::exists(file / "manifest.json")) {
    dir = file;
  } else if (file.filename() == "manifest.json") {
    dir = file.parent_path();
  }
  if (fs::is_directory(file) && dir.empty()) {
    COREDEM_CHECK(false,
                  "'{}' is a folder without manifest.json: give a checkpoint folder, a "
                  "manifest.json or an HDF5 file",
                  file.string());
  }
  if (!dir.empty()) {
    const Manifest m = readManifest(dir);
    out << fmt::format("checkpoint {}\n", dir.string());
    out << fmt::format("  step {}  time {:.9g} s  created {}\n", m.step, m.time, m.created);
    out << fmt::format("  software {}  protocol {}  config {}\n", m.softwareVersion,
                       m.protocolVersion, m.configHash.substr(0, 16));
    for (const auto& f : m.files) {
      out << fmt::format("  {:<10} {:<40} {:>12} bytes  sha256 {}\n", f.participant, f.path,
                         f.bytes, f.sha256.substr(0, 16));
    }
    const std::string problem = verifyCheckpoint(dir);
    out << (problem.empty() ? "  hashes: OK (complete and intact)\n"
                            : "  hashes: FAILED: " + problem + "\n");
    return out.str();
  }
  COREDEM_CHECK(fs::is_regular_file(file), "'{}' does not exist", file.string());
  std::vector<DatasetInfo> ds;
  std::vector<AttributeInfo> attrs;
  scanHdf5(file, ds, attrs, true);
  out << fmt::format("HDF5 file {} ({} bytes)\n", file.string(), fs::file_size(file));
  for (const auto& a : attrs) {
    out << fmt::format("  {} = {}\n", a.path, a.value);
  }
  for (const auto& d : ds) {
    std::string dims;
    for (std::size_t i = 0; i < d.dims.size(); ++i) {
      dims += (i ? "x" : "") + std::to_string(d.dims[i]);
    }
    if (d.numeric && !d.columnMin.empty()) {
      // Per component (x, y, z of a vector; species and other columns by name): statistics
      // over all components together would mix quantities.
      out << fmt::format("  {:<36} {:<8} [{}]  per column:\n", d.path, d.type, dims);
      const std::size_t w = d.columnMin.size();
      const auto names = w == 3 && columnNames(attrs, d.path, w)[0] == "0"
                             ? std::vector<std::string>{"x", "y", "z"}
                             : columnNames(attrs, d.path, w);
      for (std::size_t k = 0; k < w; ++k) {
        out << fmt::format("    {:<34} {:<8}      min {:.6g}  mean {:.6g}  max {:.6g}\n", names[k],
                           "", d.columnMin[k], d.columnMean[k], d.columnMax[k]);
      }
    } else if (d.numeric) {
      out << fmt::format("  {:<36} {:<8} [{}]  min {:.6g}  mean {:.6g}  max {:.6g}\n", d.path,
                         d.type, dims, d.min, d.mean, d.max);
    } else {
      out << fmt::format("  {:<36} {:<8} [{}]\n", d.path, d.type, dims);
    }
  }
  return out.str();
}

} // namespace coredem::orchestrator
