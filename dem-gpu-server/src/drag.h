#pragma once
/// @file
/// The gas forces of coupled runs in the DEM sub-step (docs/physics.md §1.1, §2.2) and their cell
/// sources, written once for every backend like engine_impl.h:
///   sources:    per particle the PCM cell, the drag coefficient β V_p/(1−ε) of the law chosen
///               by `models: {drag: ...}` (kernels/drag.h) with ε_g frozen at the window start,
///               the drag force and −V_p ∇p (written to `force`, which the contact module then
///               adds to); the particles are sorted by cell and Σ V_s, Σ K, Σ K v are added to
///               the window accumulators per cell (gather over sorted segments, no atomics)
///   endWindow:  ε_g, K_sl and K_sl U_s averaged over the sub-steps (CellSources)
/// Only coupled runs (a coupling grid) have this module enabled.

#include <cstddef>
#include <cstdint>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "coredem/dem/kernels/cell_sources.h"
#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/kernels/vec3.h"
#include "step_module.h"

namespace coredem::dem {

/// The drag module has no ledger of its own (the momentum it exchanges is in the sources).
struct DragTotals {};

template <class Exec>
class DragModule {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  void setup(const EngineSetup& s) {
    _enabled = s.coupled;
    _params = s.drag;
    if (!_enabled)
      return;
    _acc.allocate(s.nCells * 5);
  }

  /// Stage of the second pass (the first ends in stage drag: sources()).
  static constexpr double StageTimes::*kStage = &StageTimes::coupling;

  bool enabled() const { return _enabled; }
  std::size_t bytes() const { return _kcoef.bytes() + _acc.bytes(); }
  DragTotals totals() const { return {}; }

  /// Clears the window accumulators.
  void beginWindow(StepContext<Exec>& ctx) {
    if (!_enabled)
      return;
    double* acc = _acc.d();
    ctx.exec.parallelFor(5 * ctx.setup.nCells, [=] DEM_LAMBDA(std::size_t k) { acc[k] = 0.0; });
    _acc.markDeviceModified();
  }

  /// Gas force and PCM cell per particle, then the cell sums of this sub-step.
  /// Reads pos, vel, radius (+ gas fields, ε_g); writes force (the gas force), pcell, the sort.
  /// The two passes are timed apart: gasForces in stage drag, sortAndDeposit in kStage.
  void sources(StepContext<Exec>& ctx) {
    if (!_enabled)
      return;
    gasForces(ctx);
    ctx.marks.end(&StageTimes::drag);
    sortAndDeposit(ctx);
  }

  void update(StepContext<Exec>&) {}
  void readStatus(const double*, const ParticleStore<Exec>&) {}

  /// ε_g, K_sl, K_sl U_s averaged over the window into out (sized by the engine).
  void endWindow(WindowContext<Exec>& w) {
    if (!_enabled)
      return;
    _acc.toHost();
    const double* acc = _acc.h();
    CellSources& out = w.out;
    for (std::size_t c = 0; c < w.setup.nCells; ++c) {
      const kernels::CellAccumulator a{
          acc[5 * c], acc[5 * c + 1], {acc[5 * c + 2], acc[5 * c + 3], acc[5 * c + 4]}};
      const kernels::CellAverages avg = kernels::averageSources(a, w.nSub, w.setup.cellVolume);
      out.epsG[c] = avg.epsG;
      out.kSl[c] = avg.kSl;
      out.kSlUs[3 * c] = avg.kSlUs.x;
      out.kSlUs[3 * c + 1] = avg.kSlUs.y;
      out.kSlUs[3 * c + 2] = avg.kSlUs.z;
    }
  }

  // The passes below are public because nvcc refuses extended (device) lambdas in private
  // member functions. Together the first two are sources().

  /// First pass: PCM cell, drag and −V_p ∇p per particle. The sums are in the order of the former
  /// fused kernel (bitwise the same forces).
  void gasForces(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    _kcoef.reserve(p.n);
    const double* x = p.pos.d();
    const double* v = p.vel.d();
    const double* r = p.radius.d();
    double* f = p.force.d();
    const bool gas = ctx.gas != nullptr;
    const kernels::GridParams grid = ctx.setup.grid;
    const std::uint32_t nCells = static_cast<std::uint32_t>(ctx.setup.nCells);
    const double* ug = gas ? ctx.gas->ug.d() : nullptr;
    const double* gp = gas ? ctx.gas->gradP.d() : nullptr;
    const double* rho = gas ? ctx.gas->rhoG.d() : nullptr;
    const double* mu = gas ? ctx.gas->muG.d() : nullptr;
    const double* eps = ctx.cells.epsFrozen();
    double* kc = _kcoef.d();
    std::uint32_t* pc = ctx.cells.pcell();
    const kernels::DragParams drag = _params;
    ctx.exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      const long long ii = static_cast<long long>(i);
      const Vec3 xi = load3(x, ii);
      const long long cell = pcmCell(grid, xi);
      Vec3 F{0.0, 0.0, 0.0};
      double kcoef = 0.0;
      if (gas && cell >= 0) {
        const double ri = r[i];
        const Vec3 vi = load3(v, ii);
        const double vol = sphereVolume(ri);
        const Vec3 u = load3(ug, cell);
        const double slip = norm(u - vi);
        kcoef = particleDragCoefficient(drag, eps[cell], rho[cell], mu[cell], 2.0 * ri, vol, slip);
        F += dragForce(kcoef, u, vi);
        F += pressureGradientForce(vol, load3(gp, cell));
      }
      store3(f, ii, F);
      kc[i] = kcoef;
      pc[i] = cell < 0 ? nCells : static_cast<std::uint32_t>(cell);
    });
    p.produced(kForce);
  }

  /// Second pass: the particles sorted by cell, then their sums added to the window accumulators.
  void sortAndDeposit(StepContext<Exec>& ctx) {
    ctx.cells.sort(ctx.exec, ctx.particles.n);
    deposit(ctx);
  }

  /// Reads pos, vel, radius, _kcoef and the sort; adds this sub-step's PCM sums into _acc.
  void deposit(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    const std::uint32_t* cs = ctx.cells.cStart();
    const std::uint32_t* ce = ctx.cells.cEnd();
    const std::uint32_t* perm = ctx.cells.perm();
    const std::uint32_t* pc = ctx.cells.pcell();
    const double* r = p.radius.d();
    const double* v = p.vel.d();
    const double* kc = _kcoef.d();
    double* acc = _acc.d();
    const std::uint32_t nc = static_cast<std::uint32_t>(ctx.setup.nCells);
    // One segment head per occupied cell; segments are disjoint, so no atomics.
    ctx.exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t h) {
      const std::size_t c = pc[perm[h]];
      if (c >= nc || (h > 0 && pc[perm[h - 1]] == c))
        return;
      kernels::CellAccumulator a{0.0, 0.0, {0.0, 0.0, 0.0}};
      for (std::uint32_t k = cs[c]; k < ce[c]; ++k) {
        const std::uint32_t i = perm[k];
        kernels::accumulate(
            a, kernels::cellContribution(kernels::sphereVolume(r[i]), kc[i], kernels::load3(v, i)));
      }
      acc[5 * c] += a.solidVolume;
      acc[5 * c + 1] += a.kCoeff;
      acc[5 * c + 2] += a.kVel.x;
      acc[5 * c + 3] += a.kVel.y;
      acc[5 * c + 4] += a.kVel.z;
    });
    _acc.markDeviceModified();
  }

private:
  bool _enabled = false;
  kernels::DragParams _params{};
  Dev<double> _kcoef; ///< per particle: β V_p/(1−ε) (kg/s)
  Dual<double> _acc;  ///< nCells*5: Σ_sub V_s, Σ_sub K, Σ_sub K v
};

} // namespace coredem::dem
