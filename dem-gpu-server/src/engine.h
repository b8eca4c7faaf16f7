#pragma once
/// @file
/// The backend-neutral interface between DemSystem (host: config, time, I/O) and the
/// templated engine that runs the kernels (engine_impl.h, instantiated once per backend).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "chemistry_setup.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "coredem/dem/particle_schema.h"
#include "heat_setup.h"

namespace coredem::dem {

/// Everything the engine needs besides the particles. Plain data.
struct EngineSetup {
  int nMaterials = 1;
  /// The contact law of particles and walls (kernels/contact_law.h) and its pair table:
  /// nMaterials² rows of that law, [a*nMaterials + b]; walls use [a*n + a].
  kernels::ContactLaw contactLaw = kernels::ContactLaw::LinearSpringDashpot;
  std::vector<kernels::ContactPair> pairs;
  std::vector<kernels::Wall> walls;             ///< analytic walls (kernels/wall_contact.h)
  std::vector<kernels::MeshTriangle> triangles; ///< mesh walls (kernels/mesh_contact.h)
  double wallReachFactor = 1.0; ///< walls are candidates within f·R + skin/2 (wall_lists.h)
  kernels::Vec3 gravity{0, 0, 0};
  bool coupled = false;
  kernels::GridParams grid{}; ///< valid when coupled
  double cellVolume = 0;
  std::size_t nCells = 0;
  int nGasSpecies = 0;
  kernels::DragParams drag{}; ///< drag law and its parameters (kernels/drag.h)
  double skin = 0;            ///< m
  double maxRadius = 0;       ///< m
  int historySlots = 12;
  int neighbourSlots = 16;
  int threads = 0;
  HeatSetup heat;      ///< particle heat transfer (heat.h)
  double reach = 0;    ///< m, neighbour-list reach beyond R_i+R_j+skin (gas lens)
  bool frozen = false; ///< DemConfig::frozenMotion: positions fixed, velocities zeroed
  ChemistrySetup chem; ///< chemistry in the sub-step (chemistry.h)
};

/// Host copy of the full engine state (particles in internal order, contact history,
/// neighbour lists, rebuild reference). What writeState/readState store. One vector per
/// particle-schema row (`pos`, `vel`, ..., `chemRef`), each n · width values.
struct HostState {
  std::size_t n = 0;
  int nSpecies = 0;
  int historySlots = 0;
  int neighbourSlots = 0;
  std::int32_t listValid = 0; ///< 1: nbList usable as is
#define COREDEM_HOST_MEMBER_(member, Mask, T, ...) std::vector<T> member;
  COREDEM_PARTICLE_FIELDS(COREDEM_HOST_MEMBER_)
#undef COREDEM_HOST_MEMBER_

  schema::Extents extents() const {
    return {nSpecies, historySlots, neighbourSlots};
  }
  /// Values a field must hold: n · width.
  std::size_t expectedSize(const schema::FieldInfo& f) const {
    return n * schema::valuesPerParticle(f, extents());
  }
};

/// Throws InternalError naming the field when a field of `s` does not hold n · width values
/// (`where` names the caller).
void checkShapes(const HostState& s, const char* where);

/// Sizes every empty field that has a default in the schema (Zero, MinusOne, Diameter = 2 R)
/// to n · width and fills it; fields already holding values are left alone.
void fillDefaults(HostState& s);

/// Keeps the particles `keep` (ascending indices), in that order: compacted fields move with
/// their particles, the others are reset to their defaults; invalidates the neighbour lists.
/// @pre checkShapes(s) holds.
void compactParticles(HostState& s, const std::vector<std::size_t>& keep);

/// Host copies of the gas fields (per cell).
struct GasArrays {
  std::vector<double> ug, gradP, Tg, rhoG, muG, kappaG, cpG, Yg;
  std::vector<double> fluidFraction;   ///< empty: every cell all fluid
  std::vector<double> heatToParticles; ///< J/m³ of V_c per cell (Q_split); empty: none
};

/// What Engine::giveHeatSplit() did with the heat split of the gas fields (J).
struct HeatSplitBooking {
  double given = 0.0;      ///< to the particles (booked in HeatTotals::convection)
  double unassigned = 0.0; ///< of cells without particles (HeatTotals::splitUnassigned)
  std::int64_t firstUnassignedCell = -1; ///< the first such cell (-1: none)
  std::size_t unassignedCells = 0;       ///< how many
};

class Engine {
public:
  virtual ~Engine() = default;
  virtual void setState(const HostState& s) = 0;
  virtual HostState state() = 0;
  /// Host copy of the particle fields only (no contacts / neighbour lists): cheap snapshot.
  virtual void particles(ParticleData& out) = 0;
  virtual void setGas(const GasArrays& g) = 0;
  /// Freezes ε_g (PCM at the current positions) and clears the source accumulators.
  virtual void beginWindow() = 0;
  /// After beginWindow(): gives the heat split of the gas fields set last (GasArrays::
  /// heatToParticles) to the particles of each cell, once per setGas (heat.h giveHeatSplit).
  virtual HeatSplitBooking giveHeatSplit() = 0;
  /// One DEM sub-step of length dt (rebuild if needed, forces, sources, motion).
  virtual void subStep(double dt) = 0;
  /// Sub-step-averaged sources after nSub sub-steps of dtCfd/nSub each.
  virtual void endWindow(double dtCfd, int nSub, CellSources& out) = 0;
  virtual std::size_t pairContacts() = 0;
  virtual std::size_t wallContacts() = 0;
  virtual std::array<double, 3> wallForce() = 0;
  virtual std::size_t memoryBytes() const = 0;
  virtual StageTimes& times() = 0;
  virtual const char* name() const = 0;
  /// Heat received by the particles since construction (heat.h).
  virtual HeatTotals heatTotals() const = 0;
  /// Continues the heat ledger of a state file.
  virtual void restoreHeatTotals(const HeatTotals& totals) = 0;
  /// Chemistry ledgers since construction (chemistry.h).
  virtual ChemistryTotals chemistryTotals() const = 0;
  /// Continues the chemistry ledgers of a state file, or books removed particles.
  virtual void restoreChemistryTotals(const ChemistryTotals& totals) = 0;
  /// True when a particle fell below the removal diameter since the last call (clears the flag).
  virtual bool takeRemovalRequest() = 0;
};

std::unique_ptr<Engine> makeCpuEngine(const EngineSetup& setup);
/// The cpu kernels under the cuda memory model (backend/cuda_sim/cuda_sim_exec.h).
std::unique_ptr<Engine> makeCudaSimEngine(const EngineSetup& setup);
/// Defined only when the CUDA backend is built (COREDEM_CUDA_ENABLED).
std::unique_ptr<Engine> makeCudaEngine(const EngineSetup& setup);
/// The CUDA runtime's answer (backend/cuda_probe.h); defined with the CUDA backend.
CudaProbe cudaProbe();

} // namespace coredem::dem
