// HDF5 state I/O with the HDF5 C API. Arrays are stored with their natural shapes
// ([N], [N,3], [N,K], [N,K,3]); /meta carries the scalars as attributes.
#include "state_io.h"

#include "coredem/common/check.h"
#include "coredem/dem/particle_schema.h"

#include <hdf5.h>

#include <string>
#include <vector>

namespace coredem::dem {
namespace {

template <class T>
hid_t h5type();
template <>
hid_t h5type<double>() { return H5T_NATIVE_DOUBLE; }
template <>
hid_t h5type<std::int32_t>() { return H5T_NATIVE_INT32; }
template <>
hid_t h5type<std::int64_t>() { return H5T_NATIVE_INT64; }
template <>
hid_t h5type<std::uint64_t>() { return H5T_NATIVE_UINT64; }

/// Closes an HDF5 handle on scope exit.
struct Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  ~Handle() {
    if (id >= 0) close(id);
  }
};

template <class T>
void writeArray(hid_t group, const char* name, const std::vector<T>& v, std::vector<hsize_t> dims) {
  hsize_t total = 1;
  for (hsize_t d : dims) total *= d;
  COREDEM_ASSERT(total == v.size());
  Handle space{H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose};
  Handle ds{H5Dcreate2(group, name, h5type<T>(), space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose};
  COREDEM_CHECK(ds.id >= 0, "cannot create HDF5 dataset '{}'", name);
  if (total > 0) {
    COREDEM_CHECK(H5Dwrite(ds.id, h5type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0,
                  "cannot write HDF5 dataset '{}'", name);
  }
}

template <class T>
void readArray(hid_t group, const char* name, std::vector<T>& v, hsize_t expected,
               const std::string& path) {
  COREDEM_CHECK(H5Lexists(group, name, H5P_DEFAULT) > 0,
                "state file '{}' has no dataset '{}': it was not written by DemSystem::writeState "
                "(or is truncated)", path, name);
  Handle ds{H5Dopen2(group, name, H5P_DEFAULT), H5Dclose};
  Handle space{H5Dget_space(ds.id), H5Sclose};
  const hssize_t total = H5Sget_simple_extent_npoints(space.id);
  COREDEM_CHECK(total >= 0 && static_cast<hsize_t>(total) == expected,
                "state file '{}': dataset '{}' has {} values, expected {}", path, name, total, expected);
  v.resize(static_cast<std::size_t>(expected));
  if (expected > 0) {
    COREDEM_CHECK(H5Dread(ds.id, h5type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0,
                  "state file '{}': cannot read dataset '{}'", path, name);
  }
}

/// "[a, b, c]"
std::string shapeText(const std::vector<hsize_t>& dims) {
  std::string t = "[";
  for (std::size_t k = 0; k < dims.size(); ++k) t += (k > 0 ? ", " : "") + std::to_string(dims[k]);
  return t + "]";
}

/// Checks that dataset `name` of `group` has the shape `dims` (after its value count matched).
void checkShape(hid_t group, const char* name, const std::vector<hsize_t>& dims, const std::string& path) {
  Handle ds{H5Dopen2(group, name, H5P_DEFAULT), H5Dclose};
  Handle space{H5Dget_space(ds.id), H5Sclose};
  const int rank = H5Sget_simple_extent_ndims(space.id);
  std::vector<hsize_t> got(static_cast<std::size_t>(rank < 0 ? 0 : rank));
  H5Sget_simple_extent_dims(space.id, got.data(), nullptr);
  COREDEM_CHECK(got == dims, "state file '{}': dataset '{}' has shape {}, expected {}", path, name,
                shapeText(got), shapeText(dims));
}

template <class T>
void writeAttr(hid_t obj, const char* name, T value) {
  Handle space{H5Screate(H5S_SCALAR), H5Sclose};
  Handle a{H5Acreate2(obj, name, h5type<T>(), space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  H5Awrite(a.id, h5type<T>(), &value);
}

void writeAttr(hid_t obj, const char* name, const std::string& value) {
  Handle type{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(type.id, value.empty() ? 1 : value.size());
  H5Tset_strpad(type.id, H5T_STR_NULLTERM);
  Handle space{H5Screate(H5S_SCALAR), H5Sclose};
  Handle a{H5Acreate2(obj, name, type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  std::string buf = value.empty() ? std::string(1, '\0') : value;
  H5Awrite(a.id, type.id, buf.data());
}

template <class T>
T readAttr(hid_t obj, const char* name, const std::string& path) {
  COREDEM_CHECK(H5Aexists(obj, name) > 0, "state file '{}': /meta has no attribute '{}'", path, name);
  Handle a{H5Aopen(obj, name, H5P_DEFAULT), H5Aclose};
  T value{};
  H5Aread(a.id, h5type<T>(), &value);
  return value;
}

std::string readStringAttr(hid_t obj, const char* name, const std::string& path) {
  COREDEM_CHECK(H5Aexists(obj, name) > 0, "state file '{}': /meta has no attribute '{}'", path, name);
  Handle a{H5Aopen(obj, name, H5P_DEFAULT), H5Aclose};
  Handle type{H5Aget_type(a.id), H5Tclose};
  const std::size_t size = H5Tget_size(type.id);
  std::string buf(size, '\0');
  Handle mem{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(mem.id, size);
  H5Aread(a.id, mem.id, buf.data());
  buf.resize(buf.find('\0') == std::string::npos ? size : buf.find('\0'));
  return buf;
}

} // namespace

void writeStateFile(const std::string& path, const HostState& s, const StateMeta& meta) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  Handle file{H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose};
  COREDEM_CHECK(file.id >= 0, "cannot create state file '{}': check that the directory exists "
                              "and is writable", path);
  checkShapes(s, "writeStateFile");  // every field holds n · width values: nothing is skipped
  {
    Handle gp{H5Gcreate2(file.id, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    Handle gc{H5Gcreate2(file.id, "contacts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    schema::forEachField(s, [&](const schema::FieldInfo& f, const auto& v) {
      if (!f.has(schema::kCheckpointed)) return;
      const std::vector<std::uint64_t> dims = schema::datasetDims(f, s.n, s.extents());
      writeArray(f.group == schema::Group::Particles ? gp.id : gc.id, std::string(f.name).c_str(), v,
                 std::vector<hsize_t>(dims.begin(), dims.end()));
    });
  }
  if (meta.hasChemistry) {
    const ChemistryTotals& c = meta.chemistry;
    Handle g{H5Gcreate2(file.id, "chemistry", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    writeArray(g.id, "gas_produced_kg", c.gasProduced, {c.gasProduced.size()});
    writeArray(g.id, "solid_change_kg", c.solidChange, {c.solidChange.size()});
    writeArray(g.id, "removed_solid_kg", c.removedSolid, {c.removedSolid.size()});
    writeArray(g.id, "homogeneous_source_kg", c.homogeneousSource, {c.homogeneousSource.size()});
    writeAttr(g.id, "reaction_heat_J", c.reactionHeat);
    writeAttr(g.id, "homogeneous_heat_J", c.homogeneousHeat);
    writeAttr(g.id, "gas_sensible_heat_J", c.gasSensibleHeat);
    writeAttr(g.id, "sensible_mass_enthalpy_J", c.sensibleMassEnthalpy);
    writeAttr(g.id, "removed_count", static_cast<std::uint64_t>(c.removedCount));
  }
  Handle g{H5Gcreate2(file.id, "meta", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
  writeAttr(g.id, "format_version", static_cast<std::int32_t>(schema::kFormatVersion));
  writeAttr(g.id, "time", meta.time);
  writeAttr(g.id, "time_compensation", meta.timeCompensation);
  writeAttr(g.id, "step", meta.step);
  writeAttr(g.id, "backend", meta.backend);
  writeAttr(g.id, "config_hash", meta.configHash);
  writeAttr(g.id, "software_version", meta.softwareVersion);
  writeAttr(g.id, "protocol_version", meta.protocolVersion);
  writeAttr(g.id, "particle_count", static_cast<std::uint64_t>(s.n));
  writeAttr(g.id, "n_species", static_cast<std::int32_t>(s.nSpecies));
  writeAttr(g.id, "history_slots", static_cast<std::int32_t>(s.historySlots));
  writeAttr(g.id, "neighbour_slots", static_cast<std::int32_t>(s.neighbourSlots));
  writeAttr(g.id, "neighbour_list_valid", static_cast<std::int32_t>(s.listValid));
  writeAttr(g.id, "heat_convection_J", meta.heatConvection);
  writeAttr(g.id, "heat_radiation_J", meta.heatRadiation);
  writeAttr(g.id, "heat_wall_J", meta.heatWall);
  COREDEM_CHECK(H5Fflush(file.id, H5F_SCOPE_GLOBAL) >= 0, "cannot flush state file '{}'", path);
}

void readStateFile(const std::string& path, HostState& s, StateMeta& meta) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  COREDEM_CHECK(H5Fis_hdf5(path.c_str()) > 0,
                "state file '{}' does not exist or is not an HDF5 file", path);
  Handle file{H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  COREDEM_CHECK(file.id >= 0, "cannot open state file '{}'", path);
  COREDEM_CHECK(H5Lexists(file.id, "meta", H5P_DEFAULT) > 0 && H5Lexists(file.id, "particles", H5P_DEFAULT) > 0 &&
                    H5Lexists(file.id, "contacts", H5P_DEFAULT) > 0,
                "'{}' is not a CoReDEM DEM state file (needs /meta, /particles, /contacts)", path);
  Handle gm{H5Gopen2(file.id, "meta", H5P_DEFAULT), H5Gclose};
  // Files written before the attribute existed are version 1.
  meta.formatVersion =
      H5Aexists(gm.id, "format_version") > 0 ? readAttr<std::int32_t>(gm.id, "format_version", path) : 1;
  COREDEM_CHECK(meta.formatVersion <= schema::kFormatVersion,
                "state file '{}' has format version {}, newer than this build reads ({}); it was written "
                "by CoReDEM {}: read it with that version or a newer one",
                path, meta.formatVersion, schema::kFormatVersion,
                H5Aexists(gm.id, "software_version") > 0 ? readStringAttr(gm.id, "software_version", path)
                                                          : std::string("(unknown)"));
  meta.time = readAttr<double>(gm.id, "time", path);
  meta.timeCompensation = readAttr<double>(gm.id, "time_compensation", path);
  meta.step = readAttr<std::uint64_t>(gm.id, "step", path);
  meta.backend = readStringAttr(gm.id, "backend", path);
  meta.configHash = readStringAttr(gm.id, "config_hash", path);
  meta.softwareVersion = readStringAttr(gm.id, "software_version", path);
  meta.protocolVersion = readStringAttr(gm.id, "protocol_version", path);
  s.n = readAttr<std::uint64_t>(gm.id, "particle_count", path);
  s.nSpecies = readAttr<std::int32_t>(gm.id, "n_species", path);
  s.historySlots = readAttr<std::int32_t>(gm.id, "history_slots", path);
  s.neighbourSlots = readAttr<std::int32_t>(gm.id, "neighbour_slots", path);
  s.listValid = readAttr<std::int32_t>(gm.id, "neighbour_list_valid", path);
  // Heat totals: absent in files written before heat transfer was integrated.
  meta.heatConvection = H5Aexists(gm.id, "heat_convection_J") > 0 ? readAttr<double>(gm.id, "heat_convection_J", path) : 0.0;
  meta.heatRadiation = H5Aexists(gm.id, "heat_radiation_J") > 0 ? readAttr<double>(gm.id, "heat_radiation_J", path) : 0.0;
  meta.heatWall = H5Aexists(gm.id, "heat_wall_J") > 0 ? readAttr<double>(gm.id, "heat_wall_J", path) : 0.0;
  {
    Handle gp{H5Gopen2(file.id, "particles", H5P_DEFAULT), H5Gclose};
    Handle gc{H5Gopen2(file.id, "contacts", H5P_DEFAULT), H5Gclose};
    schema::forEachField(s, [&](const schema::FieldInfo& f, auto& v) {
      v.clear();
      if (!f.has(schema::kCheckpointed)) return;  // filled from its default below
      const hid_t g = f.group == schema::Group::Particles ? gp.id : gc.id;
      const std::string name(f.name);
      // A field newer than the file takes its default (below); from its version on it is required.
      if (meta.formatVersion < f.since && H5Lexists(g, name.c_str(), H5P_DEFAULT) <= 0) return;
      readArray(g, name.c_str(), v, s.expectedSize(f), path);
      const std::vector<std::uint64_t> dims = schema::datasetDims(f, s.n, s.extents());
      checkShape(g, name.c_str(), std::vector<hsize_t>(dims.begin(), dims.end()), path);
    });
  }
  fillDefaults(s);   // fields the file predates (schema defaults)
  checkShapes(s, "readStateFile");
  meta.hasChemistry = H5Lexists(file.id, "chemistry", H5P_DEFAULT) > 0;
  if (meta.hasChemistry) {
    Handle gc{H5Gopen2(file.id, "chemistry", H5P_DEFAULT), H5Gclose};
    auto vec = [&](const char* name, std::vector<double>& v) {
      Handle ds{H5Dopen2(gc.id, name, H5P_DEFAULT), H5Dclose};
      COREDEM_CHECK(ds.id >= 0, "state file '{}': /chemistry has no dataset '{}'", path, name);
      Handle space{H5Dget_space(ds.id), H5Sclose};
      const hssize_t count = H5Sget_simple_extent_npoints(space.id);
      readArray(gc.id, name, v, static_cast<hsize_t>(count < 0 ? 0 : count), path);
    };
    ChemistryTotals& c = meta.chemistry;
    vec("gas_produced_kg", c.gasProduced);
    vec("solid_change_kg", c.solidChange);
    vec("removed_solid_kg", c.removedSolid);
    vec("homogeneous_source_kg", c.homogeneousSource);
    c.reactionHeat = readAttr<double>(gc.id, "reaction_heat_J", path);
    c.homogeneousHeat = readAttr<double>(gc.id, "homogeneous_heat_J", path);
    // Files written before the sensible-enthalpy ledgers: they start at 0.
    c.gasSensibleHeat = H5Aexists(gc.id, "gas_sensible_heat_J") > 0
                            ? readAttr<double>(gc.id, "gas_sensible_heat_J", path) : 0.0;
    c.sensibleMassEnthalpy = H5Aexists(gc.id, "sensible_mass_enthalpy_J") > 0
                                 ? readAttr<double>(gc.id, "sensible_mass_enthalpy_J", path) : 0.0;
    c.removedCount = readAttr<std::uint64_t>(gc.id, "removed_count", path);
  }
}

} // namespace coredem::dem
