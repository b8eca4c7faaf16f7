#pragma once
/// @file
/// From a DemConfig to the engine: its validation and hash (config_check.cpp) and the engine's
/// plain data built from it (config_setup.cpp). Used by DemSystem (dem_system.cpp) only.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "engine.h"

namespace coredem::dem::cfg {

/// splitmix64: small, portable, reproducible.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; } // [0, 1)
};

/// Throws a user error naming the first inconsistent entry of the config.
void validate(const DemConfig& c);
/// FNV-1a over a canonical text of everything except the particle sets (16 hex digits).
std::string hashConfig(const DemConfig& c);

/// Positions of one set (x,y,z triples).
std::vector<double> placeParticles(const ParticleSet& s, const std::atomic<bool>* interrupt);
/// The engine's form of a wall (kernels/wall_contact.h).
kernels::Wall kernelWall(const Wall& w);
/// The mesh walls' triangles with vertex and edge ids unique over all meshes.
std::vector<kernels::MeshTriangle> kernelTriangles(const std::vector<MeshWall>& meshes);
/// The contact law of the run and its pair table (es.contactLaw, es.pairs): the law's row of
/// every pair of materials (kernels/contact_law.h, the law's mix()).
void setUpContacts(const DemConfig& config, EngineSetup& es);
/// The heat transfer's set-up (es.heat) from the config, and what it widens: the wall candidates'
/// reach (es.wallReachFactor) and the neighbour reach of the gas lens (es.reach).
/// @pre es.coupled is set; rmax is the largest particle radius.
void setUpHeat(const DemConfig& config, double rmax, EngineSetup& es);
/// Mass of particle i for Δt_DEM,max after a restart (the mass at d_0 with chemistry).
double restartMass(const DemConfig& c, const HostState& st, std::size_t i);

} // namespace coredem::dem::cfg
