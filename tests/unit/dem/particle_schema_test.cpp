// The particle schema (coredem/dem/particle_schema.h): every row is allocated, re-sorted,
// compacted and round-trips through the HDF5 state file exactly; older files read with the
// table's defaults, newer ones are refused, and a size mismatch fails loudly.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include "backend/cpu/cpu_exec.h"
#include "coredem/common/check.h"
#include "coredem/dem/particle_schema.h"
#include "engine.h"
#include "particle_store.h"
#include "state_io.h"

namespace fs = std::filesystem;
using namespace coredem::dem;
namespace sc = coredem::dem::schema;

namespace {

using Lsd = kernels::LinearSpringDashpot;

/// An LSD row of the pair table: {k_n, k_t, dampFactor, etatFactor, μ}.
kernels::ContactPair lsdRow(double kn, double kt, double damp, double etat, double mu) {
  return kernels::ContactPair::make<Lsd>(Lsd::Pair{kn, kt, damp, etat, mu});
}

constexpr int kTestSpecies = 2;
constexpr int kTestSlots = 3;      // K
constexpr int kTestNeighbours = 4; // M

/// A value that identifies (field, particle gid, component) and is exact in every field type.
double tag(int field, std::int64_t gid, std::size_t k) {
  return static_cast<double>(1000000 * (field + 1) + 1000 * gid + static_cast<std::int64_t>(k));
}

/// n particles on a line in reverse gid order (so a rebuild re-sorts them), far apart (no
/// contacts), at rest; every other field holds tag() values unless `physical` needs a sane value.
HostState taggedState(std::size_t n) {
  HostState s;
  s.n = n;
  s.nSpecies = kTestSpecies;
  s.historySlots = kTestSlots;
  s.neighbourSlots = kTestNeighbours;
  sc::forEachField(s, [&](const sc::FieldInfo& f, auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const std::size_t w = sc::valuesPerParticle(f, s.extents());
    v.resize(n * w);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < w; ++k)
        v[i * w + k] = static_cast<T>(tag(sc::indexOf(f), static_cast<std::int64_t>(n - 1 - i), k));
  });
  for (std::size_t i = 0; i < n; ++i) {
    const auto g = static_cast<std::int64_t>(n - 1 - i);
    s.gid[i] = g;
    for (int d = 0; d < 3; ++d) {
      s.pos[3 * i + d] = d == 0 ? 0.01 * static_cast<double>(g) : 0.0; // 1 cm apart, r < 1 mm
      s.xref[3 * i + d] = s.pos[3 * i + d];
      s.vel[3 * i + d] = s.omega[3 * i + d] = 0.0;
    }
    s.radius[i] = 1e-4 * (1.0 + 0.01 * static_cast<double>(g));
    s.mass[i] = 1e-6 * (1.0 + static_cast<double>(g));
    s.material[i] = 0;
    s.contacts[i] = s.wallContacts[i] = 0;
    s.nbCount[i] = 0;
  }
  return s;
}

template <class A, class B>
void expectFieldsEqual(const A& a, const B& b, unsigned flag, const std::string& what) {
  sc::forEachField(a, b, [&](const sc::FieldInfo& f, const auto& va, const auto& vb) {
    if (flag != 0 && !f.has(flag))
      return;
    ASSERT_EQ(va.size(), vb.size()) << what << ": " << f.name;
    for (std::size_t k = 0; k < va.size(); ++k) {
      ASSERT_EQ(va[k], vb[k]) << what << ": field " << f.name << " value "
                              << k; // bitwise for doubles
    }
  });
}

fs::path tempFile(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("coredem_schema_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

StateMeta someMeta() {
  StateMeta m;
  m.time = 0.125;
  m.step = 7;
  m.backend = "cpu";
  m.configHash = "abc";
  m.softwareVersion = "0.1.0";
  m.protocolVersion = "1.1";
  return m;
}

/// Opens `path` read-write and hands the file id to f.
template <class F>
void editFile(const fs::path& path, F&& f) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  f(file);
  H5Fclose(file);
}

std::string dataset(const sc::FieldInfo& f) {
  return "/" + std::string(sc::groupName(f.group)) + "/" + std::string(f.name);
}

} // namespace

TEST(ParticleSchema, TableIsConsistent) {
  std::set<std::string> names;
  std::uint32_t seen = 0;
  ParticleStore<backend::CpuExec> p;
  int visited = 0;
  p.forEach(kAllFields, [&](auto&) { ++visited; });
  EXPECT_EQ(visited, sc::kFieldCount);
  sc::forEachField(p, [&](const sc::FieldInfo& f, auto&) {
    EXPECT_TRUE(names.insert(std::string(f.name)).second) << f.name;
    seen |= 1u << sc::indexOf(f);
    EXPECT_FALSE(f.doc.empty()) << f.name;
  });
  EXPECT_EQ(seen, static_cast<std::uint32_t>(kAllFields));
  EXPECT_EQ(kPos, 1u << static_cast<int>(sc::Field::Pos));
  EXPECT_EQ(kChemRef, 1u << static_cast<int>(sc::Field::ChemRef));
  EXPECT_EQ(sc::fieldInfo(sc::Field::Temperature).name, "temperature");
  EXPECT_EQ(sc::fieldInfo(sc::Field::HistDisp).per, sc::Per::History);
  // The snapshot list: geometry first, then node attributes of /particles.
  const auto snap = sc::snapshotFields();
  ASSERT_FALSE(snap.empty());
  EXPECT_EQ(snap.front().name, sc::kGeometryField);
  auto has = [&](std::string_view n) {
    return std::any_of(snap.begin(), snap.end(),
                       [&](const sc::FieldInfo& f) { return f.name == n; });
  };
  EXPECT_TRUE(has("temperature"));
  EXPECT_TRUE(has("velocity"));
  EXPECT_FALSE(has("species"));        // [N, nSpecies]: not a Scalar or Vector attribute
  EXPECT_FALSE(has("neighbour_list")); // /contacts
}

TEST(ParticleSchema, EveryRowIsAllocatedWithItsWidth) {
  ParticleStore<backend::CpuExec> p;
  p.allocate(5, kTestSpecies, kTestSlots, kTestNeighbours);
  sc::forEachField(p, [&](const sc::FieldInfo& f, auto& a) {
    EXPECT_EQ(a.size(), 5u * sc::valuesPerParticle(f, {kTestSpecies, kTestSlots, kTestNeighbours}))
        << f.name;
  });
  EXPECT_EQ(sc::valuesPerParticle(sc::fieldInfo(sc::Field::HistDisp),
                                  {kTestSpecies, kTestSlots, kTestNeighbours}),
            3u * kTestSlots);
  EXPECT_EQ(sc::valuesPerParticle(sc::fieldInfo(sc::Field::Species),
                                  {kTestSpecies, kTestSlots, kTestNeighbours}),
            2u);
  EXPECT_EQ(sc::datasetDims(sc::fieldInfo(sc::Field::HistDisp), 5,
                            {kTestSpecies, kTestSlots, kTestNeighbours}),
            (std::vector<std::uint64_t>{5, kTestSlots, 3}));
  EXPECT_EQ(sc::datasetDims(sc::fieldInfo(sc::Field::Radius), 5, {}),
            (std::vector<std::uint64_t>{5}));
  EXPECT_EQ(sc::datasetDims(sc::fieldInfo(sc::Field::ChemRef), 5, {}),
            (std::vector<std::uint64_t>{5, 2}));
}

TEST(ParticleSchema, EveryResortedRowFollowsItsParticle) {
  const std::size_t n = 9;
  const HostState before = taggedState(n);
  EngineSetup setup;
  setup.pairs = {lsdRow(1e3, 1e3, 0.0, 0.0, 0.3)};
  setup.maxRadius = 2e-4;
  setup.skin = 1e-4;
  setup.historySlots = kTestSlots;
  setup.neighbourSlots = kTestNeighbours;
  setup.threads = 1;
  auto engine = makeCpuEngine(setup);
  engine->setState(before);
  engine->subStep(1e-6); // rebuild: re-sorts by cell (ascending x, the reverse of the input)
  const HostState after = engine->state();
  ASSERT_EQ(after.n, n);
  EXPECT_NE(after.gid, before.gid) << "the rebuild did not re-sort: the test proves nothing";
  std::map<std::int64_t, std::size_t> rowOf;
  for (std::size_t i = 0; i < n; ++i)
    rowOf[before.gid[i]] = i;
  sc::forEachField(after, before, [&](const sc::FieldInfo& f, const auto& va, const auto& vb) {
    if (!f.has(sc::kResorted))
      return;
    const std::size_t w = sc::valuesPerParticle(f, after.extents());
    ASSERT_EQ(va.size(), n * w) << f.name;
    if (f.per == sc::Per::History) {
      // The contact module rewrites the history slots from the contacts (contacts.h:
      // loadHistory, flushHistory): tags that are not the history of a contact are emptied.
      // That history follows its particle through re-sorts is checked with real contacts
      // (ContactPairs.HistoryFollowsItsPairThroughNeighbourRebuilds).
      return;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = rowOf.at(after.gid[i]);
      for (std::size_t k = 0; k < w; ++k) {
        ASSERT_EQ(va[i * w + k], vb[j * w + k])
            << f.name << " of gid " << after.gid[i] << " value " << k;
      }
    }
  });
}

TEST(ParticleSchema, EveryCompactedRowKeepsItsParticle) {
  const std::size_t n = 6;
  const HostState before = taggedState(n);
  HostState s = before;
  s.listValid = 1;
  const std::vector<std::size_t> keep{0, 2, 3, 5};
  compactParticles(s, keep);
  EXPECT_EQ(s.n, keep.size());
  EXPECT_EQ(s.listValid, 0);
  checkShapes(s, "test");
  sc::forEachField(s, before, [&](const sc::FieldInfo& f, const auto& va, const auto& vb) {
    if (!f.has(sc::kCompacted))
      return; // reset to its default; sized by checkShapes above
    const std::size_t w = sc::valuesPerParticle(f, s.extents());
    for (std::size_t a = 0; a < keep.size(); ++a)
      for (std::size_t k = 0; k < w; ++k)
        ASSERT_EQ(va[a * w + k], vb[keep[a] * w + k]) << f.name;
  });
}

TEST(ParticleSchema, EveryRowRoundTripsThroughTheStateFileExactly) {
  const HostState s = taggedState(7);
  const fs::path file = tempFile("roundtrip.h5");
  writeStateFile(file.string(), s, someMeta());
  HostState r;
  StateMeta m;
  readStateFile(file.string(), r, m);
  EXPECT_EQ(m.formatVersion, sc::kFormatVersion);
  EXPECT_EQ(m.protocolVersion, "1.1");
  EXPECT_EQ(r.n, s.n);
  EXPECT_EQ(r.extents().historySlots, kTestSlots);
  expectFieldsEqual(r, s, sc::kCheckpointed, "round trip");
  // Each checkpointed field is its own dataset with the schema's shape.
  editFile(file, [&](hid_t f) {
    for (const sc::FieldInfo& info : sc::kFields) {
      if (!info.has(sc::kCheckpointed))
        continue;
      const hid_t ds = H5Dopen2(f, dataset(info).c_str(), H5P_DEFAULT);
      ASSERT_GE(ds, 0) << dataset(info);
      const hid_t space = H5Dget_space(ds);
      std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
      H5Sget_simple_extent_dims(space, dims.data(), nullptr);
      const auto want = sc::datasetDims(info, s.n, s.extents());
      EXPECT_EQ(std::vector<std::uint64_t>(dims.begin(), dims.end()), want) << info.name;
      H5Sclose(space);
      H5Dclose(ds);
    }
  });
  fs::remove_all(file.parent_path());
}

TEST(ParticleSchema, OlderFileReadsWithTheTableDefaults) {
  const HostState s = taggedState(4);
  const fs::path file = tempFile("old.h5");
  writeStateFile(file.string(), s, someMeta());
  // Make it a version-1 file: no format_version, none of the fields introduced later.
  int dropped = 0;
  editFile(file, [&](hid_t f) {
    ASSERT_GE(H5Adelete_by_name(f, "meta", "format_version", H5P_DEFAULT), 0);
    for (const sc::FieldInfo& info : sc::kFields) {
      if (info.since > 1) {
        ASSERT_GE(H5Ldelete(f, dataset(info).c_str(), H5P_DEFAULT), 0);
        ++dropped;
      }
    }
  });
  ASSERT_GT(dropped, 0);
  HostState r;
  StateMeta m;
  readStateFile(file.string(), r, m);
  EXPECT_EQ(m.formatVersion, 1);
  checkShapes(r, "test");
  for (std::size_t i = 0; i < r.n; ++i) {
    EXPECT_EQ(r.d0[i], 2.0 * s.radius[i]); // Default::Diameter
    EXPECT_EQ(r.chemRef[2 * i], 0.0);      // Default::Zero
    EXPECT_EQ(r.chemRef[2 * i + 1], 0.0);
  }
  // The fields the old file has are read as they are.
  sc::forEachField(r, s, [&](const sc::FieldInfo& f, const auto& va, const auto& vb) {
    if (f.since == 1) {
      EXPECT_EQ(va, vb) << f.name;
    }
  });
  fs::remove_all(file.parent_path());
}

TEST(ParticleSchema, CurrentFileMissingAFieldIsRefused) {
  const HostState s = taggedState(3);
  const fs::path file = tempFile("missing.h5");
  writeStateFile(file.string(), s, someMeta());
  editFile(file, [&](hid_t f) {
    ASSERT_GE(H5Ldelete(f, "/particles/initial_diameter", H5P_DEFAULT), 0);
  });
  HostState r;
  StateMeta m;
  try {
    readStateFile(file.string(), r, m);
    FAIL() << "a version-2 file without initial_diameter was accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("initial_diameter"), std::string::npos) << e.what();
  }
  fs::remove_all(file.parent_path());
}

TEST(ParticleSchema, NewerFormatIsRefusedWithAClearError) {
  const HostState s = taggedState(3);
  const fs::path file = tempFile("newer.h5");
  writeStateFile(file.string(), s, someMeta());
  editFile(file, [&](hid_t f) {
    ASSERT_GE(H5Adelete_by_name(f, "meta", "format_version", H5P_DEFAULT), 0);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate_by_name(f, "meta", "format_version", H5T_NATIVE_INT32, space,
                                      H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(a, 0);
    const std::int32_t v = sc::kFormatVersion + 1;
    ASSERT_GE(H5Awrite(a, H5T_NATIVE_INT32, &v), 0);
    H5Sclose(space);
    H5Aclose(a);
  });
  HostState r;
  StateMeta m;
  try {
    readStateFile(file.string(), r, m);
    FAIL() << "a newer file was accepted";
  } catch (const coredem::UserError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("format version " + std::to_string(sc::kFormatVersion + 1)), std::string::npos)
        << w;
    EXPECT_NE(w.find("newer"), std::string::npos) << w;
  }
  fs::remove_all(file.parent_path());
}

TEST(ParticleSchema, SizeMismatchFailsLoudly) {
  // In memory: put (setState), compaction and writing check every field.
  HostState s = taggedState(4);
  s.chemRef.pop_back();
  EngineSetup setup;
  setup.pairs = {lsdRow(1e3, 1e3, 0.0, 0.0, 0.3)};
  setup.maxRadius = 2e-4;
  setup.historySlots = kTestSlots;
  auto engine = makeCpuEngine(setup);
  EXPECT_THROW(engine->setState(s), coredem::InternalError);
  const std::vector<std::size_t> keep{0, 1};
  EXPECT_THROW(compactParticles(s, keep), coredem::InternalError);
  EXPECT_THROW(writeStateFile(tempFile("bad.h5").string(), s, someMeta()), coredem::InternalError);
  HostState t = taggedState(4);
  t.histKey.push_back(-1);
  EXPECT_THROW(engine->setState(t), coredem::InternalError);
  try {
    checkShapes(t, "here");
    FAIL();
  } catch (const coredem::InternalError& e) {
    EXPECT_NE(std::string(e.what()).find("history_key"), std::string::npos) << e.what();
  }

  // In a file: a dataset with the wrong number of values is a UserError naming it.
  const fs::path file = tempFile("short.h5");
  writeStateFile(file.string(), taggedState(4), someMeta());
  editFile(file, [&](hid_t f) {
    ASSERT_GE(H5Ldelete(f, "/particles/temperature", H5P_DEFAULT), 0);
    const hsize_t three = 3;
    const hid_t space = H5Screate_simple(1, &three, nullptr);
    const hid_t ds = H5Dcreate2(f, "/particles/temperature", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT,
                                H5P_DEFAULT, H5P_DEFAULT);
    const double t3[3] = {300, 300, 300};
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, t3);
    H5Dclose(ds);
    H5Sclose(space);
  });
  HostState r;
  StateMeta m;
  try {
    readStateFile(file.string(), r, m);
    FAIL() << "a short dataset was accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("'temperature' has 3 values, expected 4"),
              std::string::npos)
        << e.what();
  }
  // The right number of values in the wrong shape ([3N] for [N, 3]) is refused too.
  const fs::path flat = tempFile("flat.h5");
  writeStateFile(flat.string(), taggedState(4), someMeta());
  editFile(flat, [&](hid_t f) {
    ASSERT_GE(H5Ldelete(f, "/particles/velocity", H5P_DEFAULT), 0);
    const hsize_t twelve = 12;
    const hid_t space = H5Screate_simple(1, &twelve, nullptr);
    const hid_t ds = H5Dcreate2(f, "/particles/velocity", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT,
                                H5P_DEFAULT, H5P_DEFAULT);
    const std::vector<double> zeros(12, 0.0);
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros.data());
    H5Dclose(ds);
    H5Sclose(space);
  });
  try {
    readStateFile(flat.string(), r, m);
    FAIL() << "a flattened dataset was accepted";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("'velocity' has shape [12], expected [4, 3]"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(file.parent_path());
}

TEST(ParticleSchema, DefaultsFillFieldsAConstructorLeavesEmpty) {
  HostState s = taggedState(3);
  s.force.clear();
  s.histKey.clear();
  s.d0.clear();
  fillDefaults(s);
  checkShapes(s, "test");
  EXPECT_EQ(s.force, std::vector<double>(9, 0.0));
  EXPECT_EQ(s.histKey, std::vector<std::int64_t>(3 * kTestSlots, -1));
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(s.d0[i], 2.0 * s.radius[i]);
  s.radius.clear(); // Required: no default
  fillDefaults(s);
  EXPECT_THROW(checkShapes(s, "test"), coredem::InternalError);
}
