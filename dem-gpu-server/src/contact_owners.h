#pragma once
/// @file
/// The contact module's pass 1 (contacts.h, ContactModule::sources): one owner's pairs in
/// contact and walls (OwnerContacts), and on the cpu backend a slab's owners at a time
/// (SlabContacts), each for the run's contact law Law (kernels/contact_law.h).

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "backend/exec_common.h"
#include "contact_pairs.h"
#include "coredem/dem/kernels/contact_common.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "pair_lists.h"
#include "wall_lists.h"

namespace coredem::dem {

/// Particles ahead whose history rows pass 1 prefetches (CPU; a hint only).
constexpr std::size_t kPrefetchAhead = 8;

/// Whether v is +0 in every component, bit for bit: no tangential history (−0 is kept as the
/// history it is, so that flushing and loading it gives back the same bits).
DEM_HD bool zeroBits(kernels::Vec3 v) {
  std::uint64_t b[3];
  memcpy(&b[0], &v.x, sizeof(double));
  memcpy(&b[1], &v.y, sizeof(double));
  memcpy(&b[2], &v.z, sizeof(double));
  return (b[0] | b[1] | b[2]) == 0;
}
/// One owner's part of the contact pass (ContactModule::sources, pass 1): its owned pairs in
/// contact and its walls; returns the history slots it needs (owned contacts + walls). Its
/// candidates in contact come from its half list (operator(), owner<false>) or, on the cpu
/// backend, from the list SlabContacts made of its slab's (owner<true>). Law: the contact law of
/// the pairs and the walls.
template <class Exec, class Law>
struct OwnerContacts {
  using Pair = typename Law::Pair;
  const double* x;
  const double* v;
  const double* w;
  const double* r;
  const double* m;
  const std::int32_t* mat;
  std::int64_t* hk;
  double* hd;
  double* hc;
  double* f;
  double* tq;
  double* fw;
  std::int32_t* nc;
  std::int32_t* nwc;
  const std::uint32_t* hs;
  const std::int32_t* half;
  const std::uint32_t* wallNear;
  const kernels::ContactPair* pairs; ///< rows of Law
  WallView wv;
  int nMat;
  int K;
  std::size_t n;
  double dt;
  unsigned char* hit; ///< gather backends: per candidate, in contact
  double* share;      ///< gather backends: per candidate, the partner's share
  double* own;        ///< gather backends: per particle, its own sum
#if defined(COREDEM_DEM_DOUBLE2)
  TwoPairArgs<Law> two;
#endif

  DEM_HD double operator()(std::size_t i) const {
    std::uint32_t h = 0;
    return owner<false>(i, nullptr, nullptr, h, 0);
  }

  /// i's wall contacts (the law with m_eff = m_i, R* = R_i, the particle's and the wall's
  /// material): their force (returned), their torque added to T, their history written from slot
  /// `slot` on (`slot` and `wallCount` advanced); oldKey/oldD: the first `used` history slots as
  /// the last sub-step left them.
  DEM_HD_FORCEINLINE kernels::Vec3 walls(std::size_t i, kernels::Vec3 xi, double ri, int used,
                                         const std::int64_t* oldKey, const kernels::Vec3* oldD,
                                         int& slot, int& wallCount, kernels::Vec3& T) const {
    using namespace kernels;
    const long long ii = static_cast<long long>(i);
    // Walls (the law with m_eff = m_i, the particle's material): the analytic walls in ascending
    // order (the candidate bits of the first kNearBits, most particles have none, then every wall
    // beyond them), each with its touches in feature order; then the mesh walls' touches.
    Vec3 FW{0.0, 0.0, 0.0};
    const std::uint32_t nearBits = wallNear[i];
    if (nearBits != 0) {
      const int ai = mat[i];
      const double mi = m[i];
      const Vec3 vi = load3(v, ii);
      const Vec3 wi = load3(w, ii);
      auto touch = [&](double h, Vec3 nw, std::int64_t key, Vec3 history) {
        // The row of i's material and the wall's (a wall without one: i's material with itself).
        const int wm = wv.materialOf(key);
        const Pair pp = pairs[ai * nMat + (wm < 0 ? ai : wm)].template of<Law>();
        const auto lp = Law::contact(pp, mi, ri);
        const ContactResult res = wallContact<Law>(lp, nw, ri - h, vi, wi, ri, history, dt);
        FW += res.force;
        T += res.torque;
        if (slot < K) {
          hk[i * K + slot] = key;
          store3(hd, ii * K + slot, res.deltaT);
        }
        ++slot;
        ++wallCount;
      };
      // The touches first (at most kMaxHistorySlots: more cannot keep their history, an error
      // readStatus reports; those are evaluated at once, without history), then each one's
      // history: its own feature's, else that of a neighbouring feature the sphere no longer
      // touches (WallView::continues), each old history handed to one new touch at most (a
      // valley's two faces, a vessel's floor and side: the floor's spring stays the floor's).
      double th[kMaxHistorySlots];
      Vec3 tn[kMaxHistorySlots];
      std::int64_t tk[kMaxHistorySlots];
      int nt = 0;
      wv.touches(nearBits, i, xi, ri, [&](double h, Vec3 nw, std::int64_t key) {
        if (nt == kMaxHistorySlots) {
          touch(h, nw, key, Vec3{0.0, 0.0, 0.0});
          return;
        }
        th[nt] = h, tn[nt] = nw, tk[nt] = key;
        ++nt;
      });
      int from[kMaxHistorySlots];
      std::uint32_t taken = 0; // old slots whose history is handed on
      for (int t = 0; t < nt; ++t) {
        from[t] = -1;
        for (int s = 0; s < used && from[t] < 0; ++s)
          if (oldKey[s] == tk[t])
            from[t] = s, taken |= 1u << s;
      }
      for (int t = 0; t < nt; ++t)
        for (int s = 0; s < used && from[t] < 0; ++s)
          if (!(taken >> s & 1u) && wv.continues(tk[t], oldKey[s]))
            from[t] = s, taken |= 1u << s;
      for (int t = 0; t < nt; ++t)
        touch(th[t], tn[t], tk[t], from[t] >= 0 ? oldD[from[t]] : Vec3{0.0, 0.0, 0.0});
    }
    return FW;
  }

  /// kFromHits: i's candidates in contact are hits[h..) while their owner (qOwner) is i; h
  /// ends past them.
  template <bool kFromHits>
  DEM_HD_FORCEINLINE double owner(std::size_t i, const std::uint32_t* hits,
                                  const std::uint32_t* qOwner, std::uint32_t& h,
                                  std::uint32_t nh) const {
    (void)hits, (void)qOwner, (void)h, (void)nh;
    using namespace kernels;
    const long long ii = static_cast<long long>(i);
    const Vec3 xi = load3(x, ii);
    const double ri = r[i];
    // The history slots of the few particles touching walls are scattered through memory:
    // ask for those of a particle kPrefetchAhead further on while this one computes.
    if (i + kPrefetchAhead < n && nwc[i + kPrefetchAhead] > 0) {
      const std::size_t a = (i + kPrefetchAhead) * static_cast<std::size_t>(K);
      backend::prefetch(hk + a);
      backend::prefetch(hd + 3 * a);
    }
    // A particle without owned candidates and without walls, now or in the last sub-step
    // (most particles of a dilute bed), has nothing to evaluate, no history and no force to
    // add: only its contact count to clear. (From a slab's list: the slab pass skips them.)
    if constexpr (!kFromHits) {
      if (hs[i] == hs[i + 1] && wallNear[i] == 0 && nwc[i] == 0) {
        if (nc[i] != 0)
          nc[i] = 0;
        return 0.0;
      }
    }
    // Wall history: the first nwc slots (the walls of the last sub-step), read before they
    // are rewritten.
    const int used = nwc[i] < K ? nwc[i] : K;
    std::int64_t oldKey[kMaxHistorySlots];
    Vec3 oldD[kMaxHistorySlots];
    for (int s = 0; s < used; ++s) {
      oldKey[s] = hk[i * K + s];
      oldD[s] = load3(hd, ii * K + s);
    }
    int slot = 0;
    Vec3 F{0.0, 0.0, 0.0}; // i's own sum: its owned pairs, then its walls
    Vec3 T{0.0, 0.0, 0.0};
    // Particle–particle contacts (the law; LSD: Eqs. 7–13) over the owned candidates. i's
    // velocities, mass and material are read only if it has some (most particles of a dilute
    // bed do not).
    int owned = 0;
#if defined(COREDEM_DEM_DOUBLE2)
    std::uint32_t pending[4]; // cpu: candidates in contact not yet evaluated
    int nPending = 0;
    auto evaluatePending = [&] {
      double out[24];
      ownedPairs(two, ii, pending, nPending, out);
      for (int k = 0; k < nPending; ++k) {
        F += load3(out, 2 * k);
        T += load3(out, 2 * k + 1);
      }
      owned += nPending;
      nPending = 0;
    };
#endif
#if defined(COREDEM_DEM_DOUBLE2)
    if constexpr (kFromHits) {
      // The slab's candidates in contact (SlabContacts), i's first at hits[h].
      for (; h < nh && qOwner[hits[h]] == i; ++h) {
        pending[nPending++] = hits[h];
        if (nPending == 4)
          evaluatePending();
      }
      if (nPending > 0)
        evaluatePending();
    } else
#endif
    {
      const std::uint32_t qEnd = hs[i + 1];
      if (hs[i] < qEnd) {
        const Vec3 vi = load3(v, ii);
        const Vec3 wi = load3(w, ii);
        const double mi = m[i];
        const int ai = mat[i];
        for (std::uint32_t q = hs[i]; q < qEnd; ++q) {
          const std::int32_t j = half[q];
          const Vec3 d = load3(x, j) - xi;
          const double l2 = dot(d, d);
          const double rj = r[j];
          const double rsum = ri + rj;
          const bool touching = l2 < rsum * rsum;
          if constexpr (!kScatter<Exec>)
            hit[q] = touching ? 1 : 0;
          if (!touching) {
            // Out of contact: no history (written only if there was some).
            if (!zeroBits(load3(hc, q)))
              store3(hc, q, Vec3{0.0, 0.0, 0.0});
            continue;
          }
#if defined(COREDEM_DEM_DOUBLE2)
          if constexpr (kTwoPairs<Exec>) {
            // Up to four candidates in contact at once, in this order (ownedPairs).
            pending[nPending++] = q;
            if (nPending == 4)
              evaluatePending();
            continue;
          }
#endif
          const Pair pp = pairs[ai * nMat + mat[j]].template of<Law>();
          const OwnedPair<double> op = ownedPair<Law, double>(
              d, l2, ri, rj, mi, m[j], pp, vi, load3(v, j), wi, load3(w, j), load3(hc, q), dt);
          const ContactResult& res = op.res;
          F += res.force;
          T += res.torque;
          store3(hc, q, res.deltaT);
          // j's share: force −f, torque L_ji n × f_t.
          if constexpr (kScatter<Exec>) {
            store3(f, j, load3(f, j) - res.force);
            store3(tq, j, load3(tq, j) + op.lji * res.nxft);
          } else {
            store3(share, 2 * static_cast<long long>(q), res.force);
            store3(share, 2 * static_cast<long long>(q) + 1, op.lji * res.nxft);
          }
          ++owned;
        }
#if defined(COREDEM_DEM_DOUBLE2)
        if (nPending > 0)
          evaluatePending();
#endif
      }
    }
    int wallCount = 0;
    const Vec3 FW = walls(i, xi, ri, used, oldKey, oldD, slot, wallCount, T);
    F += FW;
    for (int s = slot; s < used; ++s)
      hk[i * K + s] = -1;
    // i's own sum, after the shares of the particles before it (pair_lists.h), if i has
    // contacts of its own (most particles of a dilute bed have none: no load, no store).
    if constexpr (kScatter<Exec>) {
      if (owned + wallCount > 0) {
        store3(f, ii, load3(f, ii) + F);
        store3(tq, ii, load3(tq, ii) + T);
      }
    } else {
      store3(own, 2 * ii, F);
      store3(own, 2 * ii + 1, T);
    }
    // fwall is zero in every row without wall contacts (zeroed at each rebuild: rows do not
    // follow their particles), so only rows with wall contacts now or in the last sub-step
    // are written: most particles never touch a wall, and a store is a cache line read and
    // written back.
    if (wallCount > 0 || nwc[i] > 0)
      store3(fw, ii, FW);
    if (nc[i] != owned) // mostly unchanged: no store, the line stays clean
      nc[i] = owned;
    if (nwc[i] != wallCount)
      nwc[i] = wallCount;
    return static_cast<double>(owned + wallCount); // history slots i needs
  }
};

#if defined(COREDEM_DEM_DOUBLE2)
/// The cpu backend's contact pass over one slab [lo, hi) (CpuExec::reduceMaxOverSlabRanges):
/// the same owner by owner work, in the same order (same bits), arranged for how many
/// candidates are in contact. In a dilute slab (most candidates apart) first one loop over all
/// its owned candidates, in half-list order, which lists those in contact and clears the
/// history of the others, then the owners with something to do (a contact listed, walls now or
/// in the last sub-step, a contact count to clear), each with OwnerContacts::owner<true>: one
/// branch per candidate that is almost always "apart", instead of a loop per owner whose length
/// (0 to 5) the processor cannot predict. A dense slab (most candidates in contact: a packed
/// bed) goes owner by owner (OwnerContacts::operator()), where the contacts are found and
/// evaluated in one visit. Which of the two is decided per slab from its last sub-step.
template <class Exec, class Law>
struct SlabContacts {
  OwnerContacts<Exec, Law> owners;
  const std::uint32_t* qOwner;    ///< owner of each owned candidate (PairLists::halfOwner)
  std::uint32_t* hits;            ///< per candidate: the slabs' candidates in contact (scratch)
  std::uint32_t* work;            ///< per particle: the slabs' owners with work (scratch)
  unsigned char* dense;           ///< per slab: most of its candidates were in contact
  const std::uint32_t* slabStart; ///< host: the slabs (PairLists::slabStart)
  int slabs;                      ///< PairLists::slabs
  bool zeroForce;                 ///< force starts at zero (not at the gas force)

  /// A slab of colour 0 (the first colour run) first zeroes the torque (and the force, unless
  /// it holds the gas force) of the slabs slabsClearedBy gives: each row once, before any slab
  /// adds to it (the slabs within two of a slab of colour 0 wait for it), and still in the
  /// cache when its own pairs add to it.
  void zeroReach(int s) const {
    const SlabSpan span = slabsClearedBy(s, slabs);
    const std::size_t lo = slabStart[span.first], hi = slabStart[span.last];
    if (zeroForce)
      std::memset(owners.f + 3 * lo, 0, 3 * (hi - lo) * sizeof(double));
    std::memset(owners.tq + 3 * lo, 0, 3 * (hi - lo) * sizeof(double));
  }

  double operator()(int s, std::int64_t lo, std::int64_t hi) const {
    using namespace kernels;
    const OwnerContacts<Exec, Law>& o = owners;
    if (s % 3 == 0)
      zeroReach(s);
    const std::uint32_t qa = o.hs[lo], qb = o.hs[hi];
    double most = -HUGE_VAL;
    if (dense[s]) {
      double found = 0.0; // contacts and walls
      for (std::int64_t i = lo; i < hi; ++i) {
        const double k = o(static_cast<std::size_t>(i));
        most = k > most ? k : most;
        found += k;
      }
      dense[s] = 2.0 * found > static_cast<double>(qb - qa) ? 1 : 0;
      return most;
    }
    std::uint32_t* has = work + lo; // per particle of the slab: a candidate in contact
    std::memset(has, 0, static_cast<std::size_t>(hi - lo) * sizeof(std::uint32_t));
    std::uint32_t nh = qa; // hits[qa, nh): this slab's candidates in contact
    for (std::uint32_t q = qa; q < qb; ++q) {
      const std::uint32_t i = qOwner[q];
      const std::int32_t j = o.half[q];
      const Vec3 d = load3(o.x, j) - load3(o.x, static_cast<long long>(i));
      const double rsum = o.r[i] + o.r[j];
      const bool touching = dot(d, d) < rsum * rsum; // as OwnerContacts::owner<false>
      hits[nh] = q;
      nh += touching ? 1u : 0u;
      has[i - lo] |= touching ? 1u : 0u;
      if (!touching && !zeroBits(load3(o.hc, q)))
        store3(o.hc, q, Vec3{0.0, 0.0, 0.0}); // out of contact: no history
    }
    // The owners with something to do, in order, listed without a branch per particle (over
    // `has` itself: entry k is written after entry i >= k was read).
    std::uint32_t nw = 0;
    for (std::int64_t is = lo; is < hi; ++is) {
      const auto i = static_cast<std::uint32_t>(is);
      const std::uint32_t any =
          has[i - lo] | o.wallNear[i] | static_cast<std::uint32_t>(o.nwc[i] | o.nc[i]);
      has[nw] = i;
      nw += any != 0 ? 1u : 0u;
    }
    std::uint32_t h = qa;
    for (std::uint32_t k = 0; k < nw; ++k) {
      const double c = o.template owner<true>(has[k], hits, qOwner, h, nh);
      most = c > most ? c : most;
    }
    dense[s] = 2 * (nh - qa) > qb - qa ? 1 : 0;
    return most;
  }
};
#endif

} // namespace coredem::dem
