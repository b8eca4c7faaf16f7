// HDF5 state I/O on the common HDF5 layer (coredem/common/hdf5.h). The per-particle datasets
// are the checkpointed rows of the particle schema, stored with their natural shapes ([N],
// [N,3], [N,K], [N,K,3]); /meta carries the scalars as attributes, /chemistry the ledgers.
#include "state_io.h"

#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "coredem/common/check.h"
#include "coredem/common/hdf5.h"
#include "coredem/dem/particle_schema.h"

namespace coredem::dem {
namespace {

std::vector<hsize_t> dimsOf(const schema::FieldInfo& f, const HostState& s) {
  const std::vector<std::uint64_t> d = schema::datasetDims(f, s.n, s.extents());
  return {d.begin(), d.end()};
}

/// "[a, b, c]"
std::string shapeText(const std::vector<hsize_t>& dims) {
  std::string t = "[";
  for (std::size_t k = 0; k < dims.size(); ++k)
    t += (k > 0 ? ", " : "") + std::to_string(dims[k]);
  return t + "]";
}

/// An attribute of /meta or /chemistry that older files lack: `fallback` then.
template <class T>
T optionalAttribute(hid_t loc, const std::string& name, T fallback, const std::string& what) {
  return h5::hasAttribute(loc, name) ? h5::readAttribute<T>(loc, name, what) : fallback;
}

/// /chemistry attributes of ChemistryTotals::releasedMomentum.
constexpr const char* kReleasedMomentumAttributes[3] = {
    "released_momentum_x_Ns", "released_momentum_y_Ns", "released_momentum_z_Ns"};

} // namespace

void writeStateFile(const std::string& path, const HostState& s, const StateMeta& meta) {
  checkShapes(s, "writeStateFile"); // every field holds n · width values: nothing is skipped
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); // errors are reported by the checks, not on stderr
  h5::Handle file = h5::createFile(path);
  {
    h5::Handle gp = h5::createGroup(file, "particles");
    h5::Handle gc = h5::createGroup(file, "contacts");
    schema::forEachField(s, [&](const schema::FieldInfo& f, const auto& v) {
      if (!f.has(schema::kCheckpointed))
        return;
      h5::writeDataset(f.group == schema::Group::Particles ? gp : gc, std::string(f.name), v,
                       dimsOf(f, s));
    });
  }
  if (meta.hasChemistry) {
    const ChemistryTotals& c = meta.chemistry;
    h5::Handle g = h5::createGroup(file, "chemistry");
    h5::writeDataset(g, "gas_produced_kg", c.gasProduced);
    h5::writeDataset(g, "solid_change_kg", c.solidChange);
    h5::writeDataset(g, "removed_solid_kg", c.removedSolid);
    h5::writeDataset(g, "homogeneous_source_kg", c.homogeneousSource);
    h5::writeAttribute(g, "reaction_heat_J", c.reactionHeat);
    h5::writeAttribute(g, "homogeneous_heat_J", c.homogeneousHeat);
    h5::writeAttribute(g, "gas_sensible_heat_J", c.gasSensibleHeat);
    h5::writeAttribute(g, "sensible_mass_enthalpy_J", c.sensibleMassEnthalpy);
    h5::writeAttribute(g, "removed_count", static_cast<std::uint64_t>(c.removedCount));
    for (int a = 0; a < 3; ++a)
      h5::writeAttribute(g, kReleasedMomentumAttributes[a], c.releasedMomentum[a]);
  }
  h5::Handle g = h5::createGroup(file, "meta");
  h5::writeAttribute(g, "format_version", static_cast<std::int32_t>(schema::kFormatVersion));
  h5::writeAttribute(g, "time", meta.time);
  h5::writeAttribute(g, "time_compensation", meta.timeCompensation);
  h5::writeAttribute(g, "step", meta.step);
  h5::writeAttribute(g, "backend", meta.backend);
  h5::writeAttribute(g, "config_hash", meta.configHash);
  h5::writeAttribute(g, "software_version", meta.softwareVersion);
  h5::writeAttribute(g, "protocol_version", meta.protocolVersion);
  h5::writeAttribute(g, "particle_count", static_cast<std::uint64_t>(s.n));
  h5::writeAttribute(g, "n_species", static_cast<std::int32_t>(s.nSpecies));
  h5::writeAttribute(g, "history_slots", static_cast<std::int32_t>(s.historySlots));
  h5::writeAttribute(g, "neighbour_slots", static_cast<std::int32_t>(s.neighbourSlots));
  h5::writeAttribute(g, "neighbour_list_valid", static_cast<std::int32_t>(s.listValid));
  {
    std::string names;
    for (const std::string& n : meta.materialNames)
      names += (names.empty() ? "" : "\n") + n;
    if (!names.empty())
      h5::writeAttribute(g, "material_names", names);
  }
  for (const HeatLedgerEntry& e : kHeatLedger)
    h5::writeAttribute(g, e.stateAttribute, meta.heat.*e.value);
  COREDEM_CHECK(H5Fflush(file, H5F_SCOPE_GLOBAL) >= 0, "cannot flush state file '{}'", path);
}

void readStateFile(const std::string& path, HostState& s, StateMeta& meta) {
  const std::string what = "state file '" + path + "'";
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); // errors are reported by the checks, not on stderr
  h5::Handle file = h5::openFile(path);
  COREDEM_CHECK(h5::exists(file, "meta") && h5::exists(file, "particles") &&
                    h5::exists(file, "contacts"),
                "'{}' is not a CoReDEM DEM state file (needs /meta, /particles, /contacts)", path);
  h5::Handle gm = h5::openGroup(file, "meta", what);
  // Files written before the attribute existed are version 1.
  meta.formatVersion = optionalAttribute<std::int32_t>(gm, "format_version", 1, what);
  COREDEM_CHECK(meta.formatVersion <= schema::kFormatVersion,
                "{} has format version {}, newer than this build reads ({}); it was written by "
                "CoReDEM {}: read it with that version or a newer one",
                what, meta.formatVersion, schema::kFormatVersion,
                h5::hasAttribute(gm, "software_version")
                    ? h5::readStringAttribute(gm, "software_version", what)
                    : std::string("(unknown)"));
  meta.time = h5::readAttribute<double>(gm, "time", what);
  meta.timeCompensation = h5::readAttribute<double>(gm, "time_compensation", what);
  meta.step = h5::readAttribute<std::uint64_t>(gm, "step", what);
  meta.backend = h5::readStringAttribute(gm, "backend", what);
  meta.configHash = h5::readStringAttribute(gm, "config_hash", what);
  meta.softwareVersion = h5::readStringAttribute(gm, "software_version", what);
  meta.protocolVersion = h5::readStringAttribute(gm, "protocol_version", what);
  s.n = h5::readAttribute<std::uint64_t>(gm, "particle_count", what);
  s.nSpecies = h5::readAttribute<std::int32_t>(gm, "n_species", what);
  s.historySlots = h5::readAttribute<std::int32_t>(gm, "history_slots", what);
  s.neighbourSlots = h5::readAttribute<std::int32_t>(gm, "neighbour_slots", what);
  s.listValid = h5::readAttribute<std::int32_t>(gm, "neighbour_list_valid", what);
  if (h5::hasAttribute(gm, "material_names")) {
    std::istringstream names(h5::readStringAttribute(gm, "material_names", what));
    for (std::string n; std::getline(names, n);)
      meta.materialNames.push_back(n);
  }
  // Heat totals: absent in files written before heat transfer was integrated (or the term).
  for (const HeatLedgerEntry& e : kHeatLedger)
    meta.heat.*e.value = optionalAttribute(gm, e.stateAttribute, 0.0, what);
  {
    h5::Handle gp = h5::openGroup(file, "particles", what);
    h5::Handle gc = h5::openGroup(file, "contacts", what);
    schema::forEachField(s, [&](const schema::FieldInfo& f, auto& v) {
      using T = typename std::decay_t<decltype(v)>::value_type;
      v.clear();
      if (!f.has(schema::kCheckpointed))
        return; // filled from its default below
      const hid_t g = f.group == schema::Group::Particles ? gp.id() : gc.id();
      const std::string name(f.name);
      const bool present = h5::exists(g, name);
      // A field newer than the file takes its default (below); from its version on it is required.
      if (!present && meta.formatVersion < f.since)
        return;
      COREDEM_CHECK(present,
                    "{} has no dataset '/{}/{}' (format version {}): it was not written by "
                    "DemSystem::writeState (or is truncated)",
                    what, schema::groupName(f.group), name, meta.formatVersion);
      v = h5::readDataset<T>(g, name, what, static_cast<std::int64_t>(s.expectedSize(f)));
      const std::vector<hsize_t> want = dimsOf(f, s);
      const std::vector<hsize_t> got = h5::datasetShape(g, name, what);
      COREDEM_CHECK(got == want, "{}: dataset '{}' has shape {}, expected {}", what, name,
                    shapeText(got), shapeText(want));
    });
  }
  fillDefaults(s); // fields the file predates (schema defaults)
  checkShapes(s, "readStateFile");
  meta.hasChemistry = h5::exists(file, "chemistry");
  if (meta.hasChemistry) {
    h5::Handle gc = h5::openGroup(file, "chemistry", what);
    ChemistryTotals& c = meta.chemistry;
    c.gasProduced = h5::readDataset<double>(gc, "gas_produced_kg", what);
    c.solidChange = h5::readDataset<double>(gc, "solid_change_kg", what);
    c.removedSolid = h5::readDataset<double>(gc, "removed_solid_kg", what);
    c.homogeneousSource = h5::readDataset<double>(gc, "homogeneous_source_kg", what);
    c.reactionHeat = h5::readAttribute<double>(gc, "reaction_heat_J", what);
    c.homogeneousHeat = h5::readAttribute<double>(gc, "homogeneous_heat_J", what);
    // Files written before the sensible-enthalpy ledgers: they start at 0.
    c.gasSensibleHeat = optionalAttribute(gc, "gas_sensible_heat_J", 0.0, what);
    c.sensibleMassEnthalpy = optionalAttribute(gc, "sensible_mass_enthalpy_J", 0.0, what);
    c.removedCount = h5::readAttribute<std::uint64_t>(gc, "removed_count", what);
    // Files written before protocol 1.5's released momentum: it starts at 0.
    for (int a = 0; a < 3; ++a)
      c.releasedMomentum[a] = optionalAttribute(gc, kReleasedMomentumAttributes[a], 0.0, what);
  }
}

} // namespace coredem::dem
