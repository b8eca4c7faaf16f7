#pragma once
/// @file
/// The one interface of the DEM sub-step modules (contacts.h, drag.h, heat.h, chemistry.h).
/// The engine (engine_impl.h) owns the particles, the neighbour lists and the coupling-cell
/// binning, and drives every module through the same calls; a module keeps its data private and
/// reaches the others' results only through the particle store and the contexts below.
///
///   per CFD step (window):  beginWindow(StepContext)  → nSub × [ sources(StepContext) …
///                           motion update … update(StepContext) ] → endWindow(WindowContext)
///   totals():               the module's ledger since construction (restored on restarts
///                           with restoreTotals); each ledger is computed in one module only.
///
/// Adding a heat-transfer term with its ledger: its kernel, its call in HeatModule::sources and
/// its entry in HeatTotals (docs/architecture.md).

#include <concepts>
#include <cstddef>

#include "coupling_cells.h"
#include "engine.h"
#include "gas_fields.h"
#include "pair_lists.h"
#include "particle_store.h"
#include "wall_lists.h"

namespace coredem::dem {

/// Values a sub-step's kernels leave in device memory (Exec::reduceMaxInto into
/// StepContext::status) for the host's decisions after the sub-step: the engine reads them all
/// back in one transfer at the end of the sub-step, its only host round trip without a neighbour
/// rebuild. Each slot has one writer; a slot nobody wrote this sub-step keeps 0.
enum StatusSlot : int {
  kStatusMaxDisplacement2 = 0, ///< motion: largest displacement² since the list build (m²)
  kStatusHistorySlots,         ///< contacts: most history slots a particle uses
  kStatusBelowRemoval,         ///< chemistry: 1 when a particle fell below the removal size
  kStatusSlotCount
};

/// What a module sees in a sub-step (or at the start of a window, with dt = 0).
template <class Exec>
struct StepContext {
  Exec& exec;
  ParticleStore<Exec>& particles;
  const EngineSetup& setup;
  /// The gas fields of the CFD step; nullptr while none were set or without a coupling grid.
  const GasFields<Exec>* gas;
  /// PCM cell of every particle, the particles sorted by cell and ε_g frozen at the window
  /// start (coupling_cells.h); unused without a coupling grid.
  CouplingCells<Exec>& cells;
  /// Half and low pair lists of the current neighbour lists (pair_lists.h); valid in sources().
  PairLists<Exec>& pairs;
  /// The walls and each particle's wall candidates (wall_lists.h); ensure() before use.
  WallLists<Exec>& walls;
  double dt; ///< sub-step length Δt_DEM (s)
  /// Device array of kStatusSlotCount values (StatusSlot), read by the engine after the sub-step.
  double* status;
};

/// What a module sees at the end of a window of nSub sub-steps (host side).
template <class Exec>
struct WindowContext {
  const EngineSetup& setup;
  /// The gas fields of the CFD step (host mirrors valid); nullptr as in StepContext.
  const GasFields<Exec>* gas;
  CouplingCells<Exec>& cells;
  int nSub;         ///< sub-steps in the window
  double dtCfd;     ///< window length Δt_CFD (s), as the CFD books it
  double dtSub;     ///< sub-step length Δt_DEM (s); dtSub·nSub = Δt_CFD to round-off
  CellSources& out; ///< sized by the engine (zeros); each module fills its own sources
};

/// A DEM sub-step module: private data, one interface.
template <class M, class Exec>
concept StepModule = requires(M m, const M cm, StepContext<Exec>& step,
                              WindowContext<Exec>& window) {
  { cm.enabled() } -> std::same_as<bool>;
  m.beginWindow(step);
  m.sources(step);
  m.update(step);
  m.endWindow(window);
  cm.totals();
  { cm.bytes() } -> std::same_as<std::size_t>;
};

} // namespace coredem::dem
