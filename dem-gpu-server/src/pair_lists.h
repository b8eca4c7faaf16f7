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
/// so the contact and heat modules need no buffer of their own. The low lists, `lowPos`,
/// `lowOwner`, the colours and the scratch exist on the gather backends only (kScatter below:
/// the cpu backend writes straight into the partner and needs none of them).
///
/// Slabs. The build also cuts the particle order into slabs, contiguous index ranges such that
/// every pair joins particles of the same or of adjacent slabs (from the neighbour lists
/// themselves: any particle order is valid, a badly sorted one only gives fewer, larger slabs),
/// and colours them k mod 3. Slabs of one colour share no particle and no neighbour, so a pass
/// may run them in parallel, each slab in index order, and write pair terms straight into both
/// particles, the three colours one after another: the cpu backend's contact pass (contacts.h).
/// The order in which a particle receives its terms is then fixed by the lists alone: by colour,
/// then by the index of the particle that evaluates them; a backend that gathers instead
/// (pass 2 over the low lists) follows the same order with colour() and lowOwner(), and gives
/// the same bits. The contact and heat modules both work this way (kScatter: which one).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "particle_store.h"

namespace coredem::dem {

/// Whether Exec runs slabs colour by colour (cpu: reduceMaxOverSlabsWide), so that an owner
/// adds the partner's share straight to the partner (scatter), else the two gather passes.
template <class Exec>
inline constexpr bool kScatter = requires(const Exec& e, double* o) {
  e.reduceMaxOverSlabsWide(
      static_cast<const std::uint32_t*>(nullptr), 0, [](std::size_t) { return 0.0; }, 0.0, o);
};

/// The slabs [first, last) whose accumulators slab s of colour 0 clears before its pair terms,
/// when a scatter pass clears them inside its first colour instead of in a pass of its own
/// (contacts.h, SlabContacts): the slabs its pairs reach, s − 1, s and s + 1, and the last slab
/// where that is s + 2 (no slab of colour 0 follows it). Over the slabs of colour 0 every slab
/// is cleared once, and no two of them clear the same slab (they may run at the same time).
struct SlabSpan {
  int first, last;
};
inline SlabSpan slabsClearedBy(int s, int slabs) {
  const int first = s > 0 ? s - 1 : 0;
  int last = s + 2 < slabs ? s + 2 : slabs;
  if (last == slabs - 1)
    last = slabs;
  return {first, last};
}

/// The gather backends' pass 2 for particle i: calls own() for i's own sum (if hasOwn) and
/// partner(k) for each of its low-list entries k, in the order the cpu backend's slabs add the
/// terms (by colour, then by the evaluating particle's index; i's own sum at its own index).
template <class Own, class Partner>
DEM_HD void inSlabOrder(std::size_t i, bool hasOwn, const std::uint32_t* lowStart,
                        const std::uint32_t* lowOwner, const std::uint8_t* colour, Own&& own,
                        Partner&& partner) {
  const std::uint32_t kEnd = lowStart[i + 1];
  for (int c = 0; c < 3; ++c) {
    bool self = hasOwn && colour[i] == c;
    for (std::uint32_t k = lowStart[i]; k < kEnd; ++k) {
      const std::uint32_t o = lowOwner[k];
      if (colour[o] != c)
        continue;
      if (self && o > i) {
        own();
        self = false;
      }
      partner(k);
    }
    if (self)
      own();
  }
}

template <class Exec>
class PairLists {
public:
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  /// Doubles per candidate in scratch() (the contact module's partner force and torque).
  static constexpr int kScratchWidth = 6;
  /// Smallest slab (particles), but the last (buildSlabs).
  static constexpr std::uint32_t kMinSlab = 512;

  /// The neighbour lists or the particle order changed: rebuilt by the next ensure().
  void invalidate() { _valid = false; }
  bool valid() const { return _valid; }

  /// Builds the lists if they are not valid. Reads gid, nbCount, nbList.
  void ensure(Exec& exec, ParticleStore<Exec>& p) {
    if (!_valid)
      build(exec, p);
  }

  std::size_t bytes() const {
    return _count.bytes() + _halfStart.bytes() + _half.bytes() + _halfOwner.bytes() +
           _lowStart.bytes() + _low.bytes() + _lowPos.bytes() + _lowOwner.bytes() +
           _colour.bytes() + _scratch.bytes() + _slabStart.capacity() * sizeof(std::uint32_t) +
           _reachHost.capacity() * sizeof(std::uint32_t) + _colourHost.capacity();
  }

  /// Counts the builds: a module that derives data from the lists rebuilds it when this changes.
  std::uint64_t generation() const { return _generation; }

  /// Owned candidates in all half lists.
  std::uint32_t candidates() const { return _total; }

  const std::uint32_t* halfStart() const { return _halfStart.d(); }
  const std::int32_t* half() const { return _half.d(); }
  /// Per owned candidate q: its owner, the particle whose half list holds it (scatter backends).
  const std::uint32_t* halfOwner() const { return _halfOwner.d(); }
  const std::uint32_t* lowStart() const { return _lowStart.d(); }
  const std::uint32_t* low() const { return _low.d(); }
  const std::uint32_t* lowPos() const { return _lowPos.d(); }
  double* scratch() { return _scratch.d(); }
  /// Per low-list entry k: the index of the particle that owns the candidate (gather backends).
  const std::uint32_t* lowOwner() const { return _lowOwner.d(); }
  /// Per particle: its slab's colour, 0..2 (gather backends).
  const std::uint8_t* colour() const { return _colour.d(); }
  /// Host: slab s is the index range [slabStart()[s], slabStart()[s + 1]), s < slabs().
  const std::uint32_t* slabStart() const { return _slabStart.data(); }
  int slabs() const { return static_cast<int>(_slabStart.size()) - 1; }

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
    constexpr bool gather = !kScatter<Exec>; // low lists, owners, scratch: gather backends only
    if constexpr (gather)
      _scratch.reserve(kScratchWidth * static_cast<std::size_t>(total));
    std::int32_t* half = _half.d();
    if constexpr (!gather)
      _halfOwner.reserve(total + 1);
    std::uint32_t* halfOwner = gather ? nullptr : _halfOwner.d();
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t k = hs[i];
      for (int a = 0; a < cnt[i]; ++a) {
        const std::int32_t j = list[i * M + a];
        if (gid[j] > gid[i]) {
          if (halfOwner != nullptr)
            halfOwner[k] = static_cast<std::uint32_t>(i);
          half[k++] = j;
        }
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
    if constexpr (gather) {
      _low.reserve(lowTotal);
      _lowOwner.reserve(lowTotal);
      _lowPos.reserve(total > lowTotal ? total : lowTotal);
    }
    // The scatter backends walk the low lists only to check that the lists are symmetric.
    std::uint32_t* low = gather ? _low.d() : nullptr;
    std::uint32_t* lowOwner = gather ? _lowOwner.d() : nullptr;
    std::uint32_t* lowPos = gather ? _lowPos.d() : nullptr;
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
            } else if (lowPos != nullptr) {
              lowPos[at] = k;
            }
            if (low != nullptr) {
              lowOwner[k] = static_cast<std::uint32_t>(j);
              low[k] = at;
            }
            ++k;
          }
          return miss;
        },
        0.0);
    if (missing > 0.0 || lowTotal != total) {
      backend::raiseUserError("the neighbour lists are not symmetric (a state file edited by "
                              "hand?); set /meta@neighbour_list_valid = 0 to rebuild them");
    }
    buildSlabs(exec, p);
    _total = total;
    _valid = true;
    ++_generation;
  }

  /// The slabs and their colours (see the file comment). Greedy over the particle order, with
  /// reach(i) = the largest index among i and its neighbours: slab 0 = the first kMinSlab
  /// particles; each next slab ends where it holds every neighbour of the slab before it,
  ///   b_{s+2} = max(b_{s+1} + kMinSlab, 1 + max reach over slab s),
  /// so that a pair never skips a slab. In a cell-sorted order a slab is about a layer of
  /// neighbour cells; kMinSlab keeps a dilute bed's slabs (few neighbours, short reach) from
  /// being single particles, each a scheduling step. Fixed, not from the thread count: the
  /// slabs decide the order of the sums. Reads nbCount, nbList; on a device backend one
  /// n-value copy to the host and one back (the colours), per build.
  void buildSlabs(Exec& exec, ParticleStore<Exec>& p) {
    const std::size_t n = p.n;
    const int M = p.M;
    const std::int32_t* cnt = p.nbCount.d();
    const std::int32_t* list = p.nbList.d();
    std::uint32_t* reach = _count.d(); // n + 1 values, free after the scans above
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t r = static_cast<std::uint32_t>(i);
      for (int a = 0; a < cnt[i]; ++a) {
        const std::uint32_t j = static_cast<std::uint32_t>(list[i * M + a]);
        r = j > r ? j : r;
      }
      reach[i] = r;
    });
    const std::uint32_t* reachHost = reach; // one memory on the cpu backend
    if constexpr (Exec::separateDevice) {
      _reachHost.resize(n);
      if (n > 0)
        Exec::copyToHost(_reachHost.data(), reach, n * sizeof(std::uint32_t));
      reachHost = _reachHost.data();
    }
    constexpr bool colours = !kScatter<Exec>; // only the gather backends read the colours
    _slabStart.assign(1, 0u);
    if constexpr (colours)
      _colourHost.resize(n);
    std::uint32_t lo = 0; // slab s = [lo, hi), its successor [hi, next)
    std::uint32_t hi = n < kMinSlab ? static_cast<std::uint32_t>(n) : kMinSlab;
    const auto count = static_cast<std::uint32_t>(n);
    while (lo < count) {
      std::uint32_t need = hi; // 1 + the largest reach of slab s: where slab s + 1 must end
      for (std::uint32_t i = lo; i < hi; ++i)
        need = reachHost[i] + 1 > need ? reachHost[i] + 1 : need;
      if constexpr (colours) {
        const auto colour = static_cast<std::uint8_t>((_slabStart.size() - 1) % 3);
        for (std::uint32_t i = lo; i < hi; ++i)
          _colourHost[i] = colour;
      }
      _slabStart.push_back(hi);
      std::uint32_t next = need > hi + kMinSlab ? need : hi + kMinSlab;
      lo = hi;
      hi = next < count ? next : count;
    }
    if constexpr (colours) {
      _colour.reserve(n);
      if (n > 0)
        Exec::copyToDevice(_colour.d(), _colourHost.data(), n);
    }
  }

private:
  Dev<std::uint32_t> _count;     ///< owned candidates per particle (scan input), n + 1
  Dev<std::uint32_t> _halfStart; ///< CSR offsets of the half lists, n + 1
  Dev<std::int32_t> _half;       ///< owned candidates (partner index), ascending per particle
  Dev<std::uint32_t> _halfOwner; ///< scatter backends: owner of each owned candidate
  Dev<std::uint32_t> _lowStart;  ///< CSR offsets of the low lists, n + 1
  Dev<std::uint32_t> _low;       ///< per low-list entry k: the candidate's q in the half lists
  Dev<std::uint32_t> _lowPos;    ///< per half-list candidate q: its k in the partner's low list
  Dev<std::uint32_t> _lowOwner;  ///< per low-list entry k: the owner's index
  Dev<std::uint8_t> _colour;     ///< per particle: its slab's colour (0..2)
  std::vector<std::uint32_t> _slabStart; ///< host: slab offsets, slabs + 1
  std::vector<std::uint32_t> _reachHost; ///< host scratch of buildSlabs
  std::vector<std::uint8_t> _colourHost; ///< host scratch of buildSlabs
  Dev<double> _scratch; ///< kScratchWidth doubles per candidate, shared (see above)
  std::uint32_t _total = 0;
  std::uint64_t _generation = 0;
  bool _valid = false;
};

} // namespace coredem::dem
