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
/// The engine runs the modules of the list StepModules (step_modules.h) in its order; a module
/// decides from its own options whether it runs (enabled()) and books its sub-step time into
/// its stage (kStage). Adding a module: its file (a class satisfying StepModule) and its entry
/// in StepModules. Adding a heat-transfer term with its ledger: docs/architecture.md.

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

/// Stage timing that does not make the host wait for the device: a mark (Exec::Mark: a CUDA
/// event on the cuda backend, the host clock otherwise) at the end of each stage, their
/// differences booked after the sub-step's status read, when the device has passed them all.
template <class Exec>
class StageMarks {
public:
  explicit StageMarks(StageTimes& times)
      : _times(times) {}
  void begin() {
    Exec::mark(_marks[0]);
    _n = 1;
  }
  /// Ends the stage `stage` (a StageTimes member) here.
  void end(double StageTimes::*stage) {
    Exec::mark(_marks[_n]);
    _stage[_n] = &(_times.*stage);
    ++_n;
  }
  /// Adds each stage's time to its StageTimes entry.
  void book() {
    for (int k = 1; k < _n; ++k)
      *_stage[k] += Exec::seconds(_marks[k - 1], _marks[k]);
    _n = 0;
  }

private:
  static constexpr int kMaxMarks = 10;
  StageTimes& _times;
  typename Exec::Mark _marks[kMaxMarks]; ///< stage marks of the sub-step in flight
  double* _stage[kMaxMarks] = {};        ///< the StageTimes entry each mark ends
  int _n = 0;
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
  /// The sub-step's stage marks: the engine ends a module's stage (kStage) after its sources();
  /// a module timing passes apart ends the earlier ones itself.
  StageMarks<Exec>& marks;
};

/// What a module sees at the end of a window of nSub sub-steps (host side).
template <class Exec>
struct WindowContext {
  const EngineSetup& setup;
  /// The gas fields of the CFD step (host mirrors valid); nullptr as in StepContext.
  const GasFields<Exec>* gas;
  CouplingCells<Exec>& cells;
  int nSub;          ///< sub-steps in the window
  double dtCfd;      ///< window length Δt_CFD (s), as the CFD books it
  double dtSub;      ///< sub-step length Δt_DEM (s); dtSub·nSub = Δt_CFD to round-off
  CellSources& out;  ///< sized by the engine (zeros); each module fills its own sources
  StageTimes& times; ///< a module may book its window-end time into its stage
};

/// A DEM sub-step module: private data, one interface. The engine calls, for each module of
/// StepModules in the list's order: setup once; beginWindow at each window start (after the
/// coupling cells are frozen, when coupled); per sub-step, when enabled(), sources (then ends
/// the stage kStage), and after the motion update, update; readStatus with the sub-step's
/// status values (host); endWindow at each window end. A module checks itself whether the run
/// is coupled (EngineSetup::coupled) where that matters.
template <class M, class Exec>
concept StepModule = requires(M m, const M cm, const EngineSetup& setup, StepContext<Exec>& step,
                              WindowContext<Exec>& window, const double* status,
                              const ParticleStore<Exec>& particles) {
  m.setup(setup);
  { cm.enabled() } -> std::same_as<bool>;
  m.beginWindow(step);
  m.sources(step);
  m.update(step);
  m.readStatus(status, particles);
  m.endWindow(window);
  cm.totals();
  { cm.bytes() } -> std::same_as<std::size_t>;
  { M::kStage } -> std::convertible_to<double StageTimes::*>;
};

} // namespace coredem::dem
