#pragma once
/// @file
/// ParticleStore: the particle state as structure of arrays (DESIGN §4, STYLE §6), each array
/// a host/device mirror. Kernels name the fields they read and write with FieldMask bits;
/// the engine syncs exactly those (`require`) and marks the written ones (`produced`).

#include "backend/arrays.h"

#include <cstddef>
#include <cstdint>

namespace coredem::dem {

enum FieldMask : std::uint32_t {
  kPos = 1u << 0, kVel = 1u << 1, kOmega = 1u << 2, kForce = 1u << 3, kTorque = 1u << 4,
  kFwall = 1u << 5, kXref = 1u << 6, kRadius = 1u << 7, kMass = 1u << 8, kDensity = 1u << 9,
  kTemperature = 1u << 10, kSpecies = 1u << 11, kMaterial = 1u << 12, kContacts = 1u << 13,
  kWallContacts = 1u << 14, kGid = 1u << 15, kHistKey = 1u << 16, kHistDisp = 1u << 17,
  kNbCount = 1u << 18, kNbList = 1u << 19,
  kD0 = 1u << 20, kChemRef = 1u << 21,  // chemistry references (chemistry.h)
  kAllFields = (1u << 22) - 1
};

template <class Exec>
struct ParticleStore {
  template <class T>
  using Arr = backend::DualArray<T, Exec>;

  std::size_t n = 0;
  int nSpecies = 0;
  int K = 0;  ///< history slots per particle
  int M = 0;  ///< neighbour-list width per particle

  Arr<double> pos, vel, omega;   ///< N*3: m, m/s, rad/s
  Arr<double> force, torque;     ///< N*3: N, N m (last sub-step; force without gravity)
  Arr<double> fwall;             ///< N*3: wall part of force (N)
  Arr<double> xref;              ///< N*3: positions at the last neighbour-list build (m)
  Arr<double> radius, mass, density, temperature;  ///< N: m, kg, kg/m³, K
  Arr<double> species;           ///< N*nSpecies mass fractions
  Arr<std::int32_t> material;    ///< N
  Arr<std::int32_t> contacts, wallContacts;  ///< N: contacts found in the last sub-step
  Arr<std::int64_t> gid;         ///< N: global id (stable through re-sorting)
  Arr<std::int64_t> histKey;     ///< N*K: partner gid, −(w+2) for wall w, −1 empty
  Arr<double> histDisp;          ///< N*K*3: accumulated tangential displacement δ_t (m)
  Arr<std::int32_t> nbCount;     ///< N
  Arr<std::int32_t> nbList;      ///< N*M: neighbour indices (internal order)
  Arr<double> d0;                ///< N: initial diameter d_p0 (m), removal reference
  Arr<double> chemRef;           ///< N*2: initial char (C) mass, initial Fe2O3-equivalent mass (kg)

  /// Calls f(array) for every array selected by mask.
  template <class F>
  void forEach(std::uint32_t mask, F&& f) {
    if (mask & kPos) f(pos);
    if (mask & kVel) f(vel);
    if (mask & kOmega) f(omega);
    if (mask & kForce) f(force);
    if (mask & kTorque) f(torque);
    if (mask & kFwall) f(fwall);
    if (mask & kXref) f(xref);
    if (mask & kRadius) f(radius);
    if (mask & kMass) f(mass);
    if (mask & kDensity) f(density);
    if (mask & kTemperature) f(temperature);
    if (mask & kSpecies) f(species);
    if (mask & kMaterial) f(material);
    if (mask & kContacts) f(contacts);
    if (mask & kWallContacts) f(wallContacts);
    if (mask & kGid) f(gid);
    if (mask & kHistKey) f(histKey);
    if (mask & kHistDisp) f(histDisp);
    if (mask & kNbCount) f(nbCount);
    if (mask & kNbList) f(nbList);
    if (mask & kD0) f(d0);
    if (mask & kChemRef) f(chemRef);
  }
  /// Makes the device copies of `mask` current (before a kernel reads them).
  void require(std::uint32_t mask) { forEach(mask, [](auto& a) { a.toDevice(); }); }
  /// Marks the device copies of `mask` as newer (after a kernel wrote them).
  void produced(std::uint32_t mask) { forEach(mask, [](auto& a) { a.markDeviceModified(); }); }
  /// Host mirror → device for `mask`, after host-side writes.
  void toDevice(std::uint32_t mask) {
    forEach(mask, [](auto& a) {
      a.markHostModified();
      a.toDevice();
    });
  }
  /// Device → host mirror for `mask`.
  void toHost(std::uint32_t mask) { forEach(mask, [](auto& a) { a.toHost(); }); }

  void allocate(std::size_t count, int nSpeciesPerParticle, int slots, int width) {
    n = count;
    nSpecies = nSpeciesPerParticle;
    K = slots;
    M = width;
    for (auto* a : {&pos, &vel, &omega, &force, &torque, &fwall, &xref}) a->allocate(3 * n);
    for (auto* a : {&radius, &mass, &density, &temperature}) a->allocate(n);
    species.allocate(n * static_cast<std::size_t>(nSpecies));
    for (auto* a : {&material, &contacts, &wallContacts, &nbCount}) a->allocate(n);
    gid.allocate(n);
    histKey.allocate(n * static_cast<std::size_t>(K));
    histDisp.allocate(3 * n * static_cast<std::size_t>(K));
    nbList.allocate(n * static_cast<std::size_t>(M));
    d0.allocate(n);
    chemRef.allocate(2 * n);
  }

  std::size_t bytes() {
    std::size_t b = 0;
    forEach(kAllFields, [&](auto& a) { b += a.bytes(); });
    return b;
  }
};

} // namespace coredem::dem
