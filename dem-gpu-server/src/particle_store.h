#pragma once
/// @file
/// ParticleStore: the particle state as structure of arrays (docs/architecture.md, LAMMPS AtomVec
/// style), each array a host/device mirror. The arrays, their widths and the FieldMask bits are
/// generated from the particle schema (coredem/dem/particle_schema.h): one row a field. Kernels
/// name the fields they read and write with FieldMask bits; the engine syncs exactly those
/// (`require`) and marks the written ones (`produced`).

#include <cstddef>
#include <cstdint>

#include "backend/arrays.h"
#include "coredem/dem/particle_schema.h"

namespace coredem::dem {

/// One bit per schema row, in table order: kPos, kVel, ..., kChemRef.
enum FieldMask : std::uint32_t {
#define COREDEM_FIELD_MASK_(member, Mask, ...)                                                     \
  k##Mask = 1u << static_cast<int>(schema::Field::Mask),
  COREDEM_PARTICLE_FIELDS(COREDEM_FIELD_MASK_)
#undef COREDEM_FIELD_MASK_
};
/// Every field of the schema.
inline constexpr std::uint32_t kAllFields =
    schema::kFieldCount == 32 ? 0xffffffffu : (1u << schema::kFieldCount) - 1u;

template <class Exec>
struct ParticleStore {
  template <class T>
  using Arr = backend::DualArray<T, Exec>;

  std::size_t n = 0;
  int nSpecies = 0;
  int K = 0; ///< history slots per particle
  int M = 0; ///< neighbour-list width per particle

  /// One mirror per schema row (`pos`, `vel`, ..., `chemRef`); widths and units in the schema.
#define COREDEM_STORE_MEMBER_(member, Mask, T, ...) Arr<T> member;
  COREDEM_PARTICLE_FIELDS(COREDEM_STORE_MEMBER_)
#undef COREDEM_STORE_MEMBER_

  schema::Extents extents() const {
    return {nSpecies, K, M};
  }
  /// Values per particle of a field (its row's width for this store's extents).
  int width(const schema::FieldInfo& f) const {
    return static_cast<int>(schema::valuesPerParticle(f, extents()));
  }

  /// Calls f(array) for every array selected by mask.
  template <class F>
  void forEach(std::uint32_t mask, F&& f) {
    schema::forEachField(*this, [&](const schema::FieldInfo& info, auto& a) {
      if (mask & (1u << schema::indexOf(info)))
        f(a);
    });
  }
  /// Makes the device copies of `mask` current (before a kernel reads them).
  void require(std::uint32_t mask) {
    forEach(mask, [](auto& a) { a.toDevice(); });
  }
  /// Marks the device copies of `mask` as newer (after a kernel wrote them).
  void produced(std::uint32_t mask) {
    forEach(mask, [](auto& a) { a.markDeviceModified(); });
  }
  /// Host mirror → device for `mask`, after host-side writes.
  void toDevice(std::uint32_t mask) {
    forEach(mask, [](auto& a) {
      a.markHostModified();
      a.toDevice();
    });
  }
  /// Device → host mirror for `mask`.
  void toHost(std::uint32_t mask) {
    forEach(mask, [](auto& a) { a.toHost(); });
  }

  /// Sizes every field for `count` particles (contents undefined).
  void allocate(std::size_t count, int nSpeciesPerParticle, int slots, int width) {
    n = count;
    nSpecies = nSpeciesPerParticle;
    K = slots;
    M = width;
    schema::forEachField(*this, [&](const schema::FieldInfo& info, auto& a) {
      a.allocate(n * schema::valuesPerParticle(info, extents()));
    });
  }

  std::size_t bytes() {
    std::size_t b = 0;
    forEach(kAllFields, [&](auto& a) { b += a.bytes(); });
    return b;
  }
};

} // namespace coredem::dem
