#pragma once
/// @file
/// The coupling-cell binning the drag, heat and chemistry modules share (PCM, docs/physics.md
/// §1.1): the coupling cell of every particle (sentinel nCells outside the grid), the particles
/// sorted by cell (perm, cStart/cEnd ranges) and ε_g frozen at the start of the CFD step. Owned by
/// the engine; the modules read it through StepContext::cells.
///
/// Cost O(particles), independent of the grid size: only the ranges of OCCUPIED cells (and of the
/// sentinel) are written; those of the other cells are stale and must not be read. Per-cell work
/// therefore runs over segment heads (k is a head when k == 0 or pcell[perm[k-1]] differs),
/// summing cStart[c]..cEnd[c] in sorted order, which is the order of a loop over all cells, so
/// the sums are bitwise the same.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/pressure_gradient.h" // sphereVolume
#include "coredem/dem/kernels/vec3.h"
#include "engine.h"
#include "particle_store.h"

namespace coredem::dem {

template <class Exec>
class CouplingCells {
public:
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;
  template <class T>
  using Dual = backend::DualArray<T, Exec>;

  /// Sizes the per-cell arrays (nCells = 0: no coupling grid, nothing allocated).
  void setup(std::size_t nCells) {
    _nCells = nCells;
    if (nCells == 0)
      return;
    _epsFrozen.allocate(nCells);
    for (std::size_t c = 0; c < nCells; ++c)
      _epsFrozen.h()[c] = 1.0;
    _epsFrozen.markHostModified();
    _epsFrozen.toDevice();
    _cStart.reserve(nCells + 1);
    _cEnd.reserve(nCells + 1);
  }

  /// Sizes the per-particle arrays for n particles.
  void reserveParticles(std::size_t n) {
    _pcell.reserve(n);
    _perm.reserve(n);
    _sortedN = kNoSort;
  }

  /// Per particle: coupling cell (written by computeCells or by the drag pass), nCells outside.
  std::uint32_t* pcell() { return _pcell.d(); }
  const std::uint32_t* pcell() const { return _pcell.d(); }
  /// Particle indices sorted by cell (valid after sort()).
  const std::uint32_t* perm() const { return _perm.d(); }
  /// Sorted range [cStart[c], cEnd[c]) of occupied cell c (valid after sort()).
  const std::uint32_t* cStart() const { return _cStart.d(); }
  const std::uint32_t* cEnd() const { return _cEnd.d(); }
  /// ε_g per cell at the window start (device); epsFrozenHost() after a host copy.
  const double* epsFrozen() const { return _epsFrozen.d(); }
  const double* epsFrozenHost() {
    _epsFrozen.toHost();
    return _epsFrozen.h();
  }

  /// pcell from the positions. Reads pos.
  void computeCells(Exec& exec, ParticleStore<Exec>& p, const kernels::GridParams& grid) {
    const double* x = p.pos.d();
    std::uint32_t* pc = _pcell.d();
    const kernels::GridParams g = grid;
    const std::uint32_t nc = static_cast<std::uint32_t>(_nCells);
    exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      const long long c = kernels::pcmCell(g, kernels::load3(x, static_cast<long long>(i)));
      pc[i] = c < 0 ? nc : static_cast<std::uint32_t>(c);
    });
  }

  /// Sorts the n particles by pcell into perm and the cStart/cEnd ranges: perm is the stable
  /// order of pcell (by cell, then index), which depends only on the pcell values. On the cpu
  /// backend, where the pcell of the last sort is kept, a sort in which no particle changed
  /// cell keeps perm and the ranges as they are, and one in which a few did (particles cross a
  /// cell face every few hundred sub-steps) merges them into the last order (mergeChanged):
  /// the same perm as the full sort (tested), in one sequential pass.
  void sort(Exec& exec, std::size_t n) {
    const std::uint32_t nc = static_cast<std::uint32_t>(_nCells);
    if constexpr (!Exec::separateDevice) {
      if (_sortedN == n) {
        const std::size_t changed = collectChanged(n);
        if (changed == 0)
          return;
        if (changed <= n / kMergeFraction) {
          mergeChanged(n, changed);
          ranges(exec, n);
          return;
        }
      }
    }
    exec.sortByKeyRadix(_pcell.d(), n, nc + 1, _perm.d());
    if constexpr (!Exec::separateDevice) {
      _prevPcell.reserve(n);
      std::copy(_pcell.d(), _pcell.d() + n, _prevPcell.d());
      _sortedN = n;
    }
    ranges(exec, n);
  }

  /// cStart/cEnd of the occupied cells from perm.
  void ranges(Exec& exec, std::size_t n) {
    std::uint32_t* cs = _cStart.d();
    std::uint32_t* ce = _cEnd.d();
    const std::uint32_t* pc = _pcell.d();
    const std::uint32_t* perm = _perm.d();
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t k) {
      const std::uint32_t c = pc[perm[k]];
      if (k == 0 || pc[perm[k - 1]] != c)
        cs[c] = static_cast<std::uint32_t>(k);
      if (k + 1 == n || pc[perm[k + 1]] != c)
        ce[c] = static_cast<std::uint32_t>(k + 1);
    });
  }

  /// Window start: cells and sort from the current positions, then ε_g of every cell (PCM).
  /// `fluid` (device, nCells; nullptr: 1 everywhere) is the fluid fraction φ_f of each cell:
  /// ε_g = 1 − V_s/(φ_f V_c); a cell without fluid keeps ε_g = 1 − V_s/V_c (a particle there is
  /// refused by the engine). Reads pos, radius; writes pcell, perm, cStart, cEnd, epsFrozen.
  void freeze(Exec& exec, ParticleStore<Exec>& p, const kernels::GridParams& grid,
              double cellVolume, const double* fluid = nullptr) {
    computeCells(exec, p, grid);
    sort(exec, p.n);
    const std::uint32_t* cs = _cStart.d();
    const std::uint32_t* ce = _cEnd.d();
    const std::uint32_t* perm = _perm.d();
    const double* r = p.radius.d();
    double* eps = _epsFrozen.d();
    const double vc = cellVolume;
    const std::uint32_t* pc = _pcell.d();
    const std::uint32_t nc = static_cast<std::uint32_t>(_nCells);
    // Every cell (empty ones get ε_g of zero solid volume) ...
    exec.parallelFor(_nCells,
                     [=] DEM_LAMBDA(std::size_t c) { eps[c] = kernels::pcmGasFraction(0.0, vc); });
    // ... then the occupied cells, one segment head each (cs/ce are valid only there).
    exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t h) {
      const std::size_t c = pc[perm[h]];
      if (c >= nc || (h > 0 && pc[perm[h - 1]] == c))
        return;
      double vs = 0.0;
      for (std::uint32_t k = cs[c]; k < ce[c]; ++k)
        vs += kernels::sphereVolume(r[perm[k]]);
      eps[c] = fluid != nullptr && fluid[c] > 0.0 ? kernels::pcmGasFraction(vs, vc * fluid[c])
                                                  : kernels::pcmGasFraction(vs, vc);
    });
    _epsFrozen.markDeviceModified();
  }

  std::size_t bytes() const {
    return _pcell.bytes() + _perm.bytes() + _cStart.bytes() + _cEnd.bytes() + _epsFrozen.bytes() +
           _prevPcell.bytes() + _changed.capacity() * sizeof(std::uint32_t) + _permTmp.bytes();
  }

private:
  static constexpr std::size_t kNoSort = ~std::size_t{0};
  /// Above n / kMergeFraction changed particles the full sort is cheaper than the merge.
  static constexpr std::size_t kMergeFraction = 16;

  /// Host backend: the particles whose pcell differs from the last sort's, ascending, into
  /// _changed; returns their count.
  std::size_t collectChanged(std::size_t n) {
    const std::uint32_t* pc = _pcell.d();
    const std::uint32_t* prev = _prevPcell.d();
    _changed.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (pc[i] != prev[i])
        _changed.push_back(static_cast<std::uint32_t>(i));
    }
    return _changed.size();
  }

  /// Host backend: the stable order of pcell from the last one, whose entries that did not
  /// change cell are still in (cell, index) order: the changed particles sorted by (new cell,
  /// index) and merged in; then the kept pcell updated.
  void mergeChanged(std::size_t n, std::size_t changed) {
    const std::uint32_t* pc = _pcell.d();
    std::uint32_t* prev = _prevPcell.d();
    auto before = [pc](std::uint32_t a, std::uint32_t b) {
      return pc[a] != pc[b] ? pc[a] < pc[b] : a < b;
    };
    std::sort(_changed.begin(), _changed.end(), before);
    _permTmp.reserve(n);
    std::uint32_t* out = _permTmp.d();
    const std::uint32_t* old = _perm.d();
    std::size_t o = 0, c = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t i = old[k];
      if (pc[i] != prev[i])
        continue; // a changed particle: it comes from _changed
      while (c < changed && before(_changed[c], i))
        out[o++] = _changed[c++];
      out[o++] = i;
    }
    while (c < changed)
      out[o++] = _changed[c++];
    std::copy(out, out + n, _perm.d());
    for (const std::uint32_t i : _changed)
      prev[i] = pc[i];
  }

  std::size_t _nCells = 0;
  Dev<std::uint32_t> _pcell, _perm, _cStart, _cEnd;
  Dev<std::uint32_t> _prevPcell, _permTmp; ///< host backend: pcell of the last sort; merge buffer
  std::vector<std::uint32_t> _changed;     ///< host backend: particles that changed cell
  std::size_t _sortedN = kNoSort;          ///< particles of the last sort (kNoSort: none)
  Dual<double> _epsFrozen; ///< nCells: PCM ε_g at the window start (drag, heat, WGS)
};

} // namespace coredem::dem
