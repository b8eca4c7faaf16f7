#pragma once
/// @file
/// The particle schema: the one table of per-particle fields (LAMMPS `AtomVec` style).
///
/// Every per-particle array of the DEM core is one row of COREDEM_PARTICLE_FIELDS below. From
/// that row the code generates, with nothing else to edit:
///   * the member `ParticleStore::<member>` (host/device mirror) and `HostState::<member>`,
///   * the FieldMask bit `k<Mask>` kernels name when they read or write the field,
///   * allocation (width × particle count), `require/produced/toDevice/toHost`,
///   * the re-sort permutation at neighbour-list rebuilds (flag kResorted),
///   * compaction after particle removal (kCompacted; otherwise reset to the default),
///   * HDF5 state read/write as `/<group>/<name>` (kCheckpointed), with the default used
///     for files older than the row's `since` format version,
///   * the snapshot/XDMF node attributes (kSnapshot, see snapshotFields()).
///
/// Columns of a row:
///   member    C++ member name in ParticleStore and HostState (`store.pos`, `state.pos`)
///   Mask      suffix of the FieldMask bit (`kPos`) and of schema::Field (`Field::Pos`)
///   type      C++ element type: double, std::int32_t or std::int64_t
///   name      HDF5 dataset and snapshot/XDMF attribute name
///   group     HDF5 group: Particles (/particles) or Contacts (/contacts)
///   comps     components per particle (per slot for History, per species for Species)
///   per       Particle (comps values), Species (comps × nSpecies), History (comps × history
///             slots K), Neighbour (comps × neighbour slots M)
///   unit      SI unit ("-" dimensionless, "" for ids and indices)
///   flags     kResorted | kCompacted | kCheckpointed | kSnapshot
///   since     state-file format version that introduced the field (1 = from the start)
///   def       initial value for fields a constructor leaves empty, and value for files
///             older than `since`: Required (must be set), Zero, MinusOne, Diameter (2·radius)
///   doc       one line: what it is
///
/// To add a field: add a row (and bump kFormatVersion with `since` = the new version when
/// the field is checkpointed), then write its physics. See docs/architecture.md.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

// clang-format off
//      member        Mask          type          name                    group     comps per        unit       flags                                                since def       doc
#define COREDEM_PARTICLE_FIELDS(X) \
  X(pos,          Pos,          double,       "position",             Particles, 3, Particle,  "m",      kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "centre position") \
  X(vel,          Vel,          double,       "velocity",             Particles, 3, Particle,  "m/s",    kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "translational velocity") \
  X(omega,        Omega,        double,       "angular_velocity",     Particles, 3, Particle,  "rad/s",  kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "angular velocity") \
  X(force,        Force,        double,       "force",                Particles, 3, Particle,  "N",      kCompacted | kCheckpointed | kSnapshot, 1, Zero, "force of the last sub-step without gravity (contacts, walls, gas); recomputed after a rebuild") \
  X(torque,       Torque,       double,       "torque",               Particles, 3, Particle,  "N m",    kCompacted | kCheckpointed | kSnapshot, 1, Zero, "torque of the last sub-step; recomputed after a rebuild") \
  X(fwall,        Fwall,        double,       "wall_force",           Particles, 3, Particle,  "N",      kCompacted | kCheckpointed | kSnapshot, 1, Zero, "wall part of force; recomputed after a rebuild") \
  X(xref,         Xref,         double,       "position_at_rebuild",  Particles, 3, Particle,  "m",      kCompacted | kCheckpointed | kSnapshot, 1, Required, "position at the last neighbour-list build; reset by a rebuild") \
  X(radius,       Radius,       double,       "radius",               Particles, 1, Particle,  "m",      kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "radius R") \
  X(mass,         Mass,         double,       "mass",                 Particles, 1, Particle,  "kg",     kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "mass m") \
  X(density,      Density,      double,       "density",              Particles, 1, Particle,  "kg/m^3", kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "solid density") \
  X(temperature,  Temperature,  double,       "temperature",          Particles, 1, Particle,  "K",      kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "temperature T_p") \
  X(species,      Species,      double,       "species",              Particles, 1, Species,   "-",      kResorted | kCompacted | kCheckpointed, 1, Required, "solid species mass fractions") \
  X(material,     Material,     std::int32_t, "material",             Particles, 1, Particle,  "",       kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "material index") \
  X(contacts,     Contacts,     std::int32_t, "contact_count",        Contacts,  1, Particle,  "",       kResorted | kCompacted | kCheckpointed, 1, Zero, "particle contacts this particle owned (partner gid larger) in the last sub-step; format <= 2: all its particle contacts") \
  X(wallContacts, WallContacts, std::int32_t, "wall_contact_count",   Contacts,  1, Particle,  "",       kResorted | kCompacted | kCheckpointed, 1, Zero, "wall contacts found in the last sub-step") \
  X(gid,          Gid,          std::int64_t, "global_id",            Particles, 1, Particle,  "",       kResorted | kCompacted | kCheckpointed | kSnapshot, 1, Required, "global id, stable through re-sorting and removal") \
  X(histKey,      HistKey,      std::int64_t, "history_key",          Contacts,  1, History,   "",       kResorted | kCompacted | kCheckpointed, 1, MinusOne, "tangential-history key: partner gid (contacts this particle owns: partner gid larger), -(w+2) for wall w, -1 empty") \
  X(histDisp,     HistDisp,     double,       "history_displacement", Contacts,  3, History,   "m",      kResorted | kCompacted | kCheckpointed, 1, Zero, "accumulated tangential displacement delta_t") \
  X(nbCount,      NbCount,      std::int32_t, "neighbour_count",      Contacts,  1, Particle,  "",       kCompacted | kCheckpointed, 1, Zero, "neighbour-list length; rebuilt after a re-sort") \
  X(nbList,       NbList,       std::int32_t, "neighbour_list",       Contacts,  1, Neighbour, "",       kCompacted | kCheckpointed, 1, Zero, "neighbour indices (internal order); rebuilt after a re-sort") \
  X(d0,           D0,           double,       "initial_diameter",     Particles, 1, Particle,  "m",      kResorted | kCompacted | kCheckpointed | kSnapshot, 2, Diameter, "initial diameter d_p0, the removal reference (chemistry)") \
  X(chemRef,      ChemRef,      double,       "chemistry_reference",  Particles, 2, Particle,  "kg",     kResorted | kCompacted | kCheckpointed, 2, Zero, "initial C mass, initial Fe2O3-equivalent mass (chemistry)")
// clang-format on

namespace coredem::dem::schema {

/// Version of the HDF5 state-file layout this build writes (/meta attribute `format_version`).
/// Files without the attribute are version 1. A file with a larger version is refused.
/// 2: `format_version` written; initial_diameter and chemistry_reference always present.
/// 3: each contact's tangential history is kept once, by its owner (the particle with the
///    smaller gid; src/contacts.h); versions 1–2 kept it on both sides, which reads as is (the
///    owner's slot is used, the partner's dropped at the next sub-step, results unchanged).
inline constexpr int kFormatVersion = 3;

enum class Type { Float64, Int32, Int64 };
enum class Group { Particles, Contacts };
/// What the per-particle width is a multiple of.
enum class Per { Particle, Species, History, Neighbour };
/// Initial value of a field left empty by a constructor, and its value when a state file
/// predates the field.
enum class Default { Required, Zero, MinusOne, Diameter };

enum Flag : unsigned {
  kResorted = 1u << 0,     ///< moved with its particle when particles are re-sorted
  kCompacted = 1u << 1,    ///< kept with its particle when particles are removed (else reset)
  kCheckpointed = 1u << 2, ///< written to and read from the HDF5 state file
  kSnapshot = 1u << 3,     ///< a node attribute of the snapshot XDMF (position: the geometry)
};

/// One row of the table.
struct FieldInfo {
  std::string_view member;
  std::string_view name;
  Type type;
  Group group;
  int components;
  Per per;
  std::string_view unit;
  unsigned flags;
  int since;
  Default def;
  std::string_view doc;

  constexpr bool has(unsigned flag) const { return (flags & flag) != 0; }
};

template <class T>
constexpr Type typeOf();
template <>
constexpr Type typeOf<double>() {
  return Type::Float64;
}
template <>
constexpr Type typeOf<std::int32_t>() {
  return Type::Int32;
}
template <>
constexpr Type typeOf<std::int64_t>() {
  return Type::Int64;
}

/// Field identifiers in table order (bit k of FieldMask is field k).
enum class Field : int {
#define COREDEM_SCHEMA_ENUM_(member, Mask, ...) Mask,
  COREDEM_PARTICLE_FIELDS(COREDEM_SCHEMA_ENUM_)
#undef COREDEM_SCHEMA_ENUM_
};

/// The table as data.
inline constexpr FieldInfo kFields[] = {
// clang-format off
#define COREDEM_SCHEMA_ROW_(member, Mask, T, name, group, comps, per, unit, flags, since, def, doc) \
  FieldInfo{#member, name, typeOf<T>(), Group::group, comps, Per::per, unit, flags, since, Default::def, doc},
    // clang-format on
    COREDEM_PARTICLE_FIELDS(COREDEM_SCHEMA_ROW_)
#undef COREDEM_SCHEMA_ROW_
};

inline constexpr int kFieldCount = static_cast<int>(sizeof(kFields) / sizeof(kFields[0]));

constexpr const FieldInfo& fieldInfo(Field f) {
  return kFields[static_cast<int>(f)];
}
/// Row index of a FieldInfo of kFields (its FieldMask bit).
constexpr int indexOf(const FieldInfo& f) {
  return static_cast<int>(&f - kFields);
}

/// Per-run extents the widths depend on.
struct Extents {
  int nSpecies = 0;       ///< solid species per particle
  int historySlots = 0;   ///< K, tangential-history slots per particle
  int neighbourSlots = 0; ///< M, neighbour-list width per particle
};

/// Values per particle of a field.
constexpr std::size_t valuesPerParticle(const FieldInfo& f, const Extents& e) {
  const auto c = static_cast<std::size_t>(f.components);
  switch (f.per) {
  case Per::Species:
    return c * static_cast<std::size_t>(e.nSpecies);
  case Per::History:
    return c * static_cast<std::size_t>(e.historySlots);
  case Per::Neighbour:
    return c * static_cast<std::size_t>(e.neighbourSlots);
  case Per::Particle:
    break;
  }
  return c;
}

/// HDF5 dataset shape of a field for n particles: [n], [n, comps], [n, slots] or [n, slots, comps].
inline std::vector<std::uint64_t> datasetDims(const FieldInfo& f, std::uint64_t n,
                                              const Extents& e) {
  std::vector<std::uint64_t> dims{n};
  if (f.per != Per::Particle) {
    dims.push_back(valuesPerParticle(f, e) / static_cast<std::size_t>(f.components));
  }
  if (f.components > 1)
    dims.push_back(static_cast<std::uint64_t>(f.components));
  return dims;
}

/// HDF5 group of a field ("particles" or "contacts").
constexpr const char* groupName(Group g) {
  return g == Group::Particles ? "particles" : "contacts";
}

/// The snapshot field that is the XDMF geometry (every other snapshot field is an attribute).
inline constexpr std::string_view kGeometryField = "position";

/// The fields of a particle snapshot, in table order: what the snapshot writer lists as
/// XDMF node attributes (`/particles/<name>`, Scalar for 1 component, Vector for 3), after the
/// geometry kGeometryField.
inline std::vector<FieldInfo> snapshotFields() {
  std::vector<FieldInfo> out;
  for (const FieldInfo& f : kFields) {
    if (f.has(kSnapshot))
      out.push_back(f);
  }
  return out;
}

// ---- compile-time consistency of the table ------------------------------------------------
namespace detail {
constexpr bool uniqueNames() {
  for (int a = 0; a < kFieldCount; ++a)
    for (int b = a + 1; b < kFieldCount; ++b)
      if (kFields[a].name == kFields[b].name || kFields[a].member == kFields[b].member)
        return false;
  return true;
}
constexpr bool rowsValid() {
  for (const FieldInfo& f : kFields) {
    if (f.components < 1 || f.since < 1 || f.since > kFormatVersion)
      return false;
    // A field introduced after version 1 needs a default for older files.
    if (f.since > 1 && f.def == Default::Required)
      return false;
    // A field that is not compacted is reset after a removal: it needs a default.
    if (!f.has(kCompacted) && f.def == Default::Required)
      return false;
    // Neighbour indices are in internal order: re-sorting them would make them wrong.
    if (f.per == Per::Neighbour && f.has(kResorted))
      return false;
    // Snapshot attributes are node attributes of /particles: scalars or 3-vectors.
    if (f.has(kSnapshot) && (f.group != Group::Particles || f.per != Per::Particle ||
                             (f.components != 1 && f.components != 3) || !f.has(kCheckpointed)))
      return false;
  }
  return true;
}
} // namespace detail
static_assert(kFieldCount <= 32, "FieldMask is 32 bits wide");
static_assert(detail::uniqueNames(), "particle schema: duplicate member or dataset name");
static_assert(detail::rowsValid(),
              "particle schema: inconsistent row (see the rules in detail::rowsValid)");
static_assert(kFields[0].name == kGeometryField && kFields[0].has(kSnapshot),
              "position is the first field");

} // namespace coredem::dem::schema

/// Calls `f(info, a.member, b.member)` for every row (a, b: ParticleStore or HostState).
#define COREDEM_SCHEMA_ZIP_(member, Mask, ...)                                                     \
  f(::coredem::dem::schema::fieldInfo(::coredem::dem::schema::Field::Mask), a.member, b.member);
/// Calls `f(info, a.member)` for every row.
#define COREDEM_SCHEMA_VISIT_(member, Mask, ...)                                                   \
  f(::coredem::dem::schema::fieldInfo(::coredem::dem::schema::Field::Mask), a.member);

namespace coredem::dem::schema {

/// Calls f(const FieldInfo&, field) for every field of `a` (a ParticleStore or a HostState).
template <class A, class F>
void forEachField(A& a, F&& f) {
  COREDEM_PARTICLE_FIELDS(COREDEM_SCHEMA_VISIT_)
}

/// Calls f(const FieldInfo&, a-field, b-field) for every field, e.g. to copy a HostState into a
/// ParticleStore.
template <class A, class B, class F>
void forEachField(A& a, B& b, F&& f) {
  COREDEM_PARTICLE_FIELDS(COREDEM_SCHEMA_ZIP_)
}

} // namespace coredem::dem::schema
