#pragma once
/// @file
/// Half and low pair lists (CSR) over the neighbour lists, owned by the engine and read by every
/// module that evaluates pair terms (contacts.h, heat.h), written once for every backend like
/// engine_impl.h.
///
/// Each pair is evaluated once, by its owner: the particle with the smaller global id (gid), a
/// choice that survives re-sorting, and the canonical order of the pair kernels (the owner is
/// "lo"). After every neighbour rebuild (or a new state) the full neighbour lists give
///   half lists: each particle's owned candidates (partner gid larger), ascending index order;
///   low lists:  for each particle, the candidates its partners own, in neighbour-list order
///               (the lists are symmetric), numbered k in CSR form (`lowStart`): `low[k]` is
///               the candidate's q in its owner's half list, and `lowPos[q]` the inverse.
/// A module evaluates candidate q in a pass over owners, writes the partner's share to a
/// per-candidate buffer, and gathers its own shares in a second pass over particles, in k
/// order: a fixed order, no atomics, results independent of the thread count. The buffer may
/// be indexed by q (owner writes contiguous, partner reads at low[k]: the contact module, whose
/// few touching pairs make the scattered reads cheap, and whose two threads would otherwise
/// write into each other's cache lines) or by k = lowPos[q] (owner writes scattered, partner
/// reads contiguously: the heat module, which gathers every candidate in reach).
///
/// `scratch()` is one such per-candidate buffer of kScratchWidth doubles, shared: a module may
/// use it only inside its own sources() call (written in its first pass, read in its second),
/// so the contact and heat modules need no buffer of their own.

#include <cstddef>
#include <cstdint>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "particle_store.h"

namespace coredem::dem {

template <class Exec>
class PairLists {
public:
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  /// Doubles per candidate in scratch() (the contact module's partner force and torque).
  static constexpr int kScratchWidth = 6;

  /// The neighbour lists or the particle order changed: rebuilt by the next ensure().
  void invalidate() { _valid = false; }
  bool valid() const { return _valid; }

  /// Builds the lists if they are not valid. Reads gid, nbCount, nbList.
  void ensure(Exec& exec, ParticleStore<Exec>& p) {
    if (!_valid)
      build(exec, p);
  }

  std::size_t bytes() const {
    return _count.bytes() + _halfStart.bytes() + _half.bytes() + _lowStart.bytes() + _low.bytes() +
           _lowPos.bytes() + _scratch.bytes();
  }

  /// Counts the builds: a module that derives data from the lists rebuilds it when this changes.
  std::uint64_t generation() const { return _generation; }

  /// Owned candidates in all half lists.
  std::uint32_t candidates() const { return _total; }

  const std::uint32_t* halfStart() const { return _halfStart.d(); }
  const std::int32_t* half() const { return _half.d(); }
  const std::uint32_t* lowStart() const { return _lowStart.d(); }
  const std::uint32_t* low() const { return _low.d(); }
  const std::uint32_t* lowPos() const { return _lowPos.d(); }
  double* scratch() { return _scratch.d(); }

  /// Builds the lists from the neighbour lists (public only because nvcc requires it of a
  /// function with device lambdas; call ensure()).
  void build(Exec& exec, ParticleStore<Exec>& p) {
    const std::size_t n = p.n;
    const int M = p.M;
    const std::int64_t* gid = p.gid.d();
    const std::int32_t* cnt = p.nbCount.d();
    const std::int32_t* list = p.nbList.d();
    _count.reserve(n + 1);
    _halfStart.reserve(n + 1);
    std::uint32_t* c = _count.d();
    exec.parallelFor(n + 1, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t owned = 0;
      if (i < n) {
        for (int a = 0; a < cnt[i]; ++a)
          owned += gid[list[i * M + a]] > gid[i] ? 1u : 0u;
      }
      c[i] = owned;
    });
    std::uint32_t* hs = _halfStart.d();
    exec.exclusiveScan(c, hs, n + 1);
    std::uint32_t total = 0;
    Exec::copyToHost(&total, hs + n, sizeof(total));
    _half.reserve(total);
    _scratch.reserve(kScratchWidth * static_cast<std::size_t>(total));
    std::int32_t* half = _half.d();
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t k = hs[i];
      for (int a = 0; a < cnt[i]; ++a) {
        const std::int32_t j = list[i * M + a];
        if (gid[j] > gid[i])
          half[k++] = j;
      }
    });
    exec.parallelFor(n + 1, [=] DEM_LAMBDA(std::size_t i) {
      c[i] = i < n ? static_cast<std::uint32_t>(cnt[i]) - (hs[i + 1] - hs[i]) : 0u;
    });
    _lowStart.reserve(n + 1);
    std::uint32_t* ls = _lowStart.d();
    exec.exclusiveScan(c, ls, n + 1);
    std::uint32_t lowTotal = 0;
    Exec::copyToHost(&lowTotal, ls + n, sizeof(lowTotal));
    _low.reserve(lowTotal);
    _lowPos.reserve(total > lowTotal ? total : lowTotal);
    std::uint32_t* low = _low.d();
    std::uint32_t* lowPos = _lowPos.d();
    const double missing = exec.reduceMax(
        n,
        [=] DEM_LAMBDA(std::size_t i) {
          std::uint32_t k = ls[i];
          double miss = 0.0;
          for (int a = 0; a < cnt[i]; ++a) {
            const std::int32_t j = list[i * M + a];
            if (gid[j] > gid[i])
              continue;
            std::uint32_t at = hs[j];
            while (at < hs[j + 1] && half[at] != static_cast<std::int32_t>(i))
              ++at;
            if (at == hs[j + 1]) {
              miss = 1.0;
            } else {
              lowPos[at] = k;
            }
            low[k++] = at;
          }
          return miss;
        },
        0.0);
    if (missing > 0.0 || lowTotal != total) {
      backend::raiseUserError("the neighbour lists are not symmetric (a state file edited by "
                              "hand?); set /meta@neighbour_list_valid = 0 to rebuild them");
    }
    _total = total;
    _valid = true;
    ++_generation;
  }

private:
  Dev<std::uint32_t> _count;     ///< owned candidates per particle (scan input), n + 1
  Dev<std::uint32_t> _halfStart; ///< CSR offsets of the half lists, n + 1
  Dev<std::int32_t> _half;       ///< owned candidates (partner index), ascending per particle
  Dev<std::uint32_t> _lowStart;  ///< CSR offsets of the low lists, n + 1
  Dev<std::uint32_t> _low;       ///< per low-list entry k: the candidate's q in the half lists
  Dev<std::uint32_t> _lowPos;    ///< per half-list candidate q: its k in the partner's low list
  Dev<double> _scratch;          ///< kScratchWidth doubles per candidate, shared (see above)
  std::uint32_t _total = 0;
  std::uint64_t _generation = 0;
  bool _valid = false;
};

} // namespace coredem::dem
