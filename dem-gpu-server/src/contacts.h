#pragma once
/// @file
/// Particle–particle and particle–wall contact forces in the DEM sub-step (docs/physics.md §2.1,
/// LSD with tangential history), written once for every backend like engine_impl.h.
///
/// Each pair is evaluated once, by its owner: the particle with the smaller global id (gid), a
/// choice that survives re-sorting, over the engine's half and low lists (pair_lists.h). No
/// atomics; the order in which a particle's force and torque receive their terms is fixed by the
/// lists (pair_lists.h "Slabs": by slab colour, then by the index of the evaluating particle),
/// so the results do not depend on the thread count or the backend:
///   cpu (scatter): the owners run slab colour by colour (CpuExec::reduceMaxOverSlabsWide); an
///     owner i evaluates its owned candidates in contact with the LSD law and adds the
///     partner's share (−f; torque L_ji n × f_t) straight to the partner's force and torque,
///     then its walls, and adds its own sum (f, L_ij n × f_t of its pairs, its walls) to its
///     own force and torque, which start at the gas force (or zero) and zero;
///   other backends (gather): pass 1 per owner writes the partner's share per candidate and
///     its own sum per particle; pass 2 per particle adds them in the same order (colours, and
///     within a colour the evaluating particle's index).
/// The cpu backend evaluates a particle's owned candidates in contact up to four at once
/// (ownedPairs): three or four in the lanes of kernels::Double4 where the processor has AVX,
/// two in the lanes of kernels::Double2 (SSE2, or AVX's encoding of the same operations), one
/// alone; every lane gives the bits of ownedPair<double>, the other backends' path (no FMA).
/// The LSD law is mirror-exact (lsd_contact.h): j's share is bitwise what evaluating the pair
/// from j's side gives. Forces add the gas force of the drag module in coupled runs.
///
/// Tangential history. Between two neighbour builds the history of a pair lives with its
/// candidate in the half list (`_hc`, three doubles per owned candidate, in half-list order:
/// read and written as one stream by the owner, no key, no search; zero when the pair is not
/// in contact). The particles' history slots (histKey, histDisp: partner gid, or for a wall
/// touch −(2 + w + nWalls·f) for feature f of analytic wall w and −(2 + nWalls·kMaxWallFeatures
/// + t) for mesh triangle t (wall_lists.h), and δ_t) are the form that follows a particle through a
/// re-sort and into a state file: flushHistory() writes the candidates' history into them (before
/// the engine re-sorts the particles or hands out its state) and loadHistory() reads them back into
/// the candidates of new lists. Walls keep their history in the slots all along, at the front of
/// the row (the first wallContacts slots). A particle's slots hold its walls and the contacts it
/// owns; slots of a state file written when both sides kept their history are read as they are (the
/// owner's is the one used; the other is dropped at the next flush).

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "pair_lists.h"
#include "step_module.h"
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

/// The contact module has no ledger (counts and wall forces are read from the particles).
struct ContactTotals {};

/// An owned pair in contact seen from its owner i: the LSD law (Eqs. 7–13) and L_ji.
template <class S>
struct OwnedPair {
  kernels::LsdResultT<S> res;
  S lji;
};

/// The pair terms of an owned pair in contact, d = x_j − x_i, l2 = |d|² < (r_i + r_j)². S: the
/// scalar type (kernels/lanes.h): double, or Double2 for two pairs at once (cpu), each lane
/// giving the bits of the double evaluation.
template <class S>
DEM_HD OwnedPair<S> ownedPair(kernels::Vec3T<S> d, S l2, S ri, S rj, S mi, S mj, S kn, S kt,
                              S dampFactor, S etatFactor, S mu, kernels::Vec3T<S> vi,
                              kernels::Vec3T<S> vj, kernels::Vec3T<S> wi, kernels::Vec3T<S> wj,
                              kernels::Vec3T<S> hist, double dt) {
  using namespace kernels;
  const S rsum = ri + rj;
  const S l = laneSqrt(l2);
  const S invL = 1.0 / l;
  const Vec3T<S> nrm = invL * d;
  const S deltaN = rsum - l;
  const S meff = effectiveMass(mi, mj);
  const S etan = dampFactor * laneSqrt(kn * meff);
  const LsdParamsT<S> lp{kn, kt, etan, etatFactor * etan, mu};
  const S lij = leverArmInv(l, invL, ri, rj);
  const S lji = leverArmInv(l, invL, rj, ri);
  const Vec3T<S> vij = relativeVelocity(vi, vj, wi, wj, lij, lji, nrm);
  return {lsdContact(lp, nrm, deltaN, vij, lij, hist, dt), lji};
}

/// Whether Exec evaluates two owned pairs at once (Exec::PairScalar, cpu: kernels::Double2).
template <class Exec, class = void>
inline constexpr bool kTwoPairs = false;
template <class Exec>
inline constexpr bool kTwoPairs<Exec, std::void_t<typename Exec::PairScalar>> = true;

#if defined(COREDEM_DEM_DOUBLE2)
/// What twoOwnedPairs reads and writes (pass 1 of ContactModule::sources).
struct TwoPairArgs {
  const double* x;
  const double* v;
  const double* w;
  const double* r;
  const double* m;
  const std::int32_t* mat;
  const std::int32_t* half;
  const PairProps* pairs;
  double* hc; ///< tangential history per owned candidate (3 doubles)
  double* f;  ///< force: the partners' shares are added to it (scatter, pair_lists.h "Slabs")
  double* tq; ///< torque, likewise
  int nMat;
  double dt;
  bool avx; ///< twoOwnedPairs runs its AVX version

  /// Properties of the pair (i, j); a one-material run reads no material index (the rows
  /// of a pass's few contacts are otherwise each one more cache line to wait for).
  DEM_HD const PairProps& props(long long i, long long j) const {
    return nMat == 1 ? pairs[0] : pairs[mat[i] * nMat + mat[j]];
  }
};

/// Owned candidates q0 < q1 of particle i, both in contact, evaluated in the two lanes of
/// Double2 (ownedPair): updates their tangential history (a.hc), adds their partners' shares
/// to the partners' force and torque (q0's partner first), and returns force and torque on i of
/// q0 in out[0..6) and of q1 in out[6..12). Called through twoOwnedPairs.
DEM_HD_FORCEINLINE void twoOwnedPairsBody(const TwoPairArgs& a, long long i, std::uint32_t q0,
                                          std::uint32_t q1, double* out) {
  using namespace kernels;
  using D = Double2;
  const long long j0 = a.half[q0];
  const long long j1 = a.half[q1];
  auto both = [](double u) { return D{u, u}; };
  auto lanes = [](double u, double v) { return D{u, v}; };
  auto gather3 = [&](const double* p) {
    return Vec3T<D>{lanes(p[3 * j0], p[3 * j1]), lanes(p[3 * j0 + 1], p[3 * j1 + 1]),
                    lanes(p[3 * j0 + 2], p[3 * j1 + 2])};
  };
  auto both3 = [&](const double* p) {
    return Vec3T<D>{both(p[3 * i]), both(p[3 * i + 1]), both(p[3 * i + 2])};
  };
  const Vec3T<D> d = gather3(a.x) - both3(a.x);
  const PairProps& p0 = a.props(i, j0);
  const PairProps& p1 = a.props(i, j1);
  const Vec3 h0 = load3(a.hc, q0);
  const Vec3 h1 = load3(a.hc, q1);
  const OwnedPair<D> op =
      ownedPair<D>(d, dot(d, d), both(a.r[i]), lanes(a.r[j0], a.r[j1]), both(a.m[i]),
                   lanes(a.m[j0], a.m[j1]), lanes(p0.kn, p1.kn), lanes(p0.kt, p1.kt),
                   lanes(p0.dampFactor, p1.dampFactor), lanes(p0.etatFactor, p1.etatFactor),
                   lanes(p0.mu, p1.mu), both3(a.v), gather3(a.v), both3(a.w), gather3(a.w),
                   Vec3T<D>{lanes(h0.x, h1.x), lanes(h0.y, h1.y), lanes(h0.z, h1.z)}, a.dt);
  const LsdResultT<D>& res = op.res;
  const Vec3T<D> shareT = op.lji * res.nxft;
  store3(a.hc, q0, Vec3{res.deltaT.x[0], res.deltaT.y[0], res.deltaT.z[0]});
  store3(a.hc, q1, Vec3{res.deltaT.x[1], res.deltaT.y[1], res.deltaT.z[1]});
  // The partners' shares: force −f, torque L_ji n × f_t.
  const Vec3 f0{res.force.x[0], res.force.y[0], res.force.z[0]};
  const Vec3 f1{res.force.x[1], res.force.y[1], res.force.z[1]};
  store3(a.f, j0, load3(a.f, j0) - f0);
  store3(a.tq, j0, load3(a.tq, j0) + Vec3{shareT.x[0], shareT.y[0], shareT.z[0]});
  store3(a.f, j1, load3(a.f, j1) - f1);
  store3(a.tq, j1, load3(a.tq, j1) + Vec3{shareT.x[1], shareT.y[1], shareT.z[1]});
  store3(out, 0, f0);
  store3(out, 1, Vec3{res.torque.x[0], res.torque.y[0], res.torque.z[0]});
  store3(out, 2, f1);
  store3(out, 3, Vec3{res.torque.x[1], res.torque.y[1], res.torque.z[1]});
}

/// twoOwnedPairsBody in SSE2 (the x86-64 baseline) and, for processors that have it, in AVX:
/// the same lane operations in the three-operand encoding, without the register copies of
/// SSE2's two-operand forms (about a quarter of the instructions), and no FMA (not part of AVX),
/// so the bits are the same. Out of line: the particle loop and this body each get the
/// registers to themselves.
[[gnu::noinline, gnu::flatten]] inline void twoOwnedPairsSse2(const TwoPairArgs& a, long long i,
                                                              std::uint32_t q0, std::uint32_t q1,
                                                              double* out) {
  twoOwnedPairsBody(a, i, q0, q1, out);
}
#if defined(__x86_64__)
[[gnu::noinline, gnu::flatten, gnu::target("avx")]] inline void
twoOwnedPairsAvx(const TwoPairArgs& a, long long i, std::uint32_t q0, std::uint32_t q1,
                 double* out) {
  twoOwnedPairsBody(a, i, q0, q1, out);
}
#endif
/// twoOwnedPairsAvx if a.avx, else twoOwnedPairsSse2. (Without AVX the group costs 443
/// instructions per two pairs against 510 for two scalar pairs, about what the call and the
/// gathers add: pass 1 then counts +0.7 %, not worth a test per pair in the loop.)
inline void twoOwnedPairs(const TwoPairArgs& a, long long i, std::uint32_t q0, std::uint32_t q1,
                          double* out) {
#if defined(__x86_64__)
  if (a.avx) {
    twoOwnedPairsAvx(a, i, q0, q1, out);
    return;
  }
#endif
  twoOwnedPairsSse2(a, i, q0, q1, out);
}

/// One owned candidate q of particle i in contact, the scalar evaluation (ownedPair<double>):
/// updates its history, adds the partner's share to the partner, returns force and torque on i
/// in out[0..6).
inline void oneOwnedPair(const TwoPairArgs& a, long long i, std::uint32_t q, double* out) {
  using namespace kernels;
  const long long j = a.half[q];
  const Vec3 d = load3(a.x, j) - load3(a.x, i);
  const PairProps& pp = a.props(i, j);
  const OwnedPair<double> op = ownedPair(
      d, dot(d, d), a.r[i], a.r[j], a.m[i], a.m[j], pp.kn, pp.kt, pp.dampFactor, pp.etatFactor,
      pp.mu, load3(a.v, i), load3(a.v, j), load3(a.w, i), load3(a.w, j), load3(a.hc, q), a.dt);
  const LsdResult& res = op.res;
  store3(a.hc, q, res.deltaT);
  store3(a.f, j, load3(a.f, j) - res.force);
  store3(a.tq, j, load3(a.tq, j) + op.lji * res.nxft);
  store3(out, 0, res.force);
  store3(out, 1, res.torque);
}

#if defined(COREDEM_DEM_DOUBLE4)
/// Three or four owned candidates q[0..count) of particle i, all in contact, in the four lanes
/// of kernels::Double4 (AVX; with three, the fourth lane repeats the third pair and is
/// dropped): as twoOwnedPairsBody, pair k's force and torque on i in out[6k..6k+6), the
/// partners' shares added in the order of q. Every lane gives the bits of ownedPair<double>
/// (no FMA: not part of AVX).
[[gnu::noinline, gnu::flatten, gnu::target("avx")]] inline void
fourOwnedPairsAvx(const TwoPairArgs& a, long long i, const std::uint32_t* q, int count,
                  double* out) {
  using namespace kernels;
  using D = Double4;
  const std::uint32_t q3 = q[count > 3 ? 3 : 2];
  const long long j0 = a.half[q[0]], j1 = a.half[q[1]], j2 = a.half[q[2]], j3 = a.half[q3];
  auto both = [](double u) { return D{u, u, u, u}; };
  auto lanes = [&](const double* p) { return D{p[j0], p[j1], p[j2], p[j3]}; };
  // Vec3 rows k0..k3 of p (the partners' rows, or the candidates' history rows) in the lanes.
  auto rows3 = [](const double* p, long long k0, long long k1, long long k2, long long k3) {
    return Vec3T<D>{D{p[3 * k0], p[3 * k1], p[3 * k2], p[3 * k3]},
                    D{p[3 * k0 + 1], p[3 * k1 + 1], p[3 * k2 + 1], p[3 * k3 + 1]},
                    D{p[3 * k0 + 2], p[3 * k1 + 2], p[3 * k2 + 2], p[3 * k3 + 2]}};
  };
  auto gather3 = [&](const double* p) { return rows3(p, j0, j1, j2, j3); };
  auto both3 = [&](const double* p) {
    return Vec3T<D>{both(p[3 * i]), both(p[3 * i + 1]), both(p[3 * i + 2])};
  };
  const Vec3T<D> d = gather3(a.x) - both3(a.x);
  // The pair properties in the lanes: one broadcast each in a one-material run (the four
  // lanes would otherwise load the same row four times), else each lane's row.
  D props[5];
  constexpr double PairProps::*kProp[5] = {&PairProps::kn, &PairProps::kt, &PairProps::dampFactor,
                                           &PairProps::etatFactor, &PairProps::mu};
  if (a.nMat == 1) {
    for (int k = 0; k < 5; ++k)
      props[k] = both(a.pairs[0].*kProp[k]);
  } else {
    const PairProps* pk[4] = {&a.props(i, j0), &a.props(i, j1), &a.props(i, j2), &a.props(i, j3)};
    for (int k = 0; k < 5; ++k)
      props[k] = D{pk[0]->*kProp[k], pk[1]->*kProp[k], pk[2]->*kProp[k], pk[3]->*kProp[k]};
  }
  const OwnedPair<D> op =
      ownedPair<D>(d, dot(d, d), both(a.r[i]), lanes(a.r), both(a.m[i]), lanes(a.m), props[0],
                   props[1], props[2], props[3], props[4], both3(a.v), gather3(a.v), both3(a.w),
                   gather3(a.w), rows3(a.hc, q[0], q[1], q[2], q3), a.dt);
  const LsdResultT<D>& res = op.res;
  const Vec3T<D> shareT = op.lji * res.nxft;
  const long long js[4] = {j0, j1, j2, j3};
  for (int k = 0; k < count; ++k) {
    const long long j = js[k];
    const Vec3 f{res.force.x[k], res.force.y[k], res.force.z[k]};
    store3(a.hc, q[k], Vec3{res.deltaT.x[k], res.deltaT.y[k], res.deltaT.z[k]});
    store3(a.f, j, load3(a.f, j) - f);
    store3(a.tq, j, load3(a.tq, j) + Vec3{shareT.x[k], shareT.y[k], shareT.z[k]});
    store3(out, 2 * k, f);
    store3(out, 2 * k + 1, Vec3{res.torque.x[k], res.torque.y[k], res.torque.z[k]});
  }
}
#endif

/// count (1..4) owned candidates q[0..count) of particle i in contact, in q order: four lanes
/// for three or four (AVX), two lanes for two, the scalar path for one; without AVX, two lanes
/// at a time and the scalar path for an odd one. Pair k's force and torque on i in
/// out[6k..6k+6).
inline void ownedPairs(const TwoPairArgs& a, long long i, const std::uint32_t* q, int count,
                       double* out) {
#if defined(COREDEM_DEM_DOUBLE4)
  if (a.avx && count >= 3) {
    fourOwnedPairsAvx(a, i, q, count, out);
    return;
  }
#endif
  int k = 0;
  for (; k + 1 < count; k += 2)
    twoOwnedPairs(a, i, q[k], q[k + 1], out + 6 * k);
  if (k < count)
    oneOwnedPair(a, i, q[k], out + 6 * k);
}

/// Whether twoOwnedPairs may use AVX (the processor and the operating system support it).
inline bool cpuHasAvx() {
#if defined(__x86_64__)
  return __builtin_cpu_supports("avx");
#else
  return false;
#endif
}
#endif

/// One owner's part of the contact pass (ContactModule::sources, pass 1): its owned pairs in
/// contact and its walls; returns the history slots it needs (owned contacts + walls). Its
/// candidates in contact come from its half list (operator(), owner<false>) or, on the cpu
/// backend, from the list SlabContacts made of its slab's (owner<true>).
template <class Exec>
struct OwnerContacts {
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
  const PairProps* pairs;
  WallView wv;
  int nMat;
  int K;
  std::size_t n;
  double dt;
  unsigned char* hit; ///< gather backends: per candidate, in contact
  double* share;      ///< gather backends: per candidate, the partner's share
  double* own;        ///< gather backends: per particle, its own sum
#if defined(COREDEM_DEM_DOUBLE2)
  TwoPairArgs two;
#endif

  DEM_HD double operator()(std::size_t i) const {
    std::uint32_t h = 0;
    return owner<false>(i, nullptr, nullptr, h, 0);
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
    // Particle–particle LSD (Eqs. 7–13) over the owned candidates. i's velocities, mass and
    // material are read only if it has some (most particles of a dilute bed do not).
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
          const PairProps pp = pairs[ai * nMat + mat[j]];
          const OwnedPair<double> op =
              ownedPair(d, l2, ri, rj, mi, m[j], pp.kn, pp.kt, pp.dampFactor, pp.etatFactor, pp.mu,
                        vi, load3(v, j), wi, load3(w, j), load3(hc, q), dt);
          const LsdResult& res = op.res;
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
    // Walls (m_eff = m_i, the particle's material): the analytic walls in ascending order (the
    // candidate bits of the first kNearBits, most particles have none, then every wall beyond
    // them), each with its touches in feature order; then the mesh walls' touches.
    Vec3 FW{0.0, 0.0, 0.0};
    int wallCount = 0;
    const std::uint32_t nearBits = wallNear[i];
    if (nearBits != 0) {
      const int ai = mat[i];
      const double mi = m[i];
      const PairProps pp = pairs[ai * nMat + ai];
      const double etan = pp.dampFactor * ::sqrt(pp.kn * mi);
      const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
      const Vec3 vi = load3(v, ii);
      const Vec3 wi = load3(w, ii);
      auto touch = [&](double h, Vec3 nw, std::int64_t key, Vec3 history) {
        const LsdResult res = wallContact(lp, nw, ri - h, vi, wi, ri, history, dt);
        FW += res.force;
        T += res.torque;
        if (slot < K) {
          hk[i * K + slot] = key;
          store3(hd, ii * K + slot, res.deltaT);
        }
        ++slot;
        ++wallCount;
      };
      wv.touches(nearBits, i, xi, ri, [&](double h, Vec3 nw, std::int64_t key) {
        // The history of this feature, else that of a neighbouring one (WallView::continues).
        int from = -1;
        for (int s = 0; s < used; ++s) {
          if (oldKey[s] == key) {
            from = s;
            break;
          }
          if (from < 0 && wv.continues(key, oldKey[s]))
            from = s;
        }
        touch(h, nw, key, from >= 0 ? oldD[from] : Vec3{0.0, 0.0, 0.0});
      });
    }
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
template <class Exec>
struct SlabContacts {
  OwnerContacts<Exec> owners;
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
    const OwnerContacts<Exec>& o = owners;
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

template <class Exec>
class ContactModule {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  void setup(const EngineSetup& s) {
    _pairs.allocate(s.pairs.size());
    for (std::size_t k = 0; k < s.pairs.size(); ++k)
      _pairs.h()[k] = s.pairs[k];
    _pairs.markHostModified();
    _pairs.toDevice();
  }

  static constexpr double StageTimes::*kStage = &StageTimes::contact;

  bool enabled() const { return true; }
  std::size_t bytes() const {
    return _pairs.bytes() + _hit.bytes() + _own.bytes() + _hc.bytes() + _hits.bytes() +
           _work.bytes() + _dense.capacity();
  }
  ContactTotals totals() const { return {}; }

  /// History slots in use in some row (slots at or beyond it are empty everywhere); the
  /// neighbour rebuild moves only these.
  int usedSlots() const { return _maxUsedSlots; }
  /// After new particles: every slot may be in use.
  void resetUsedSlots(int slots) { _maxUsedSlots = slots; }

  void beginWindow(StepContext<Exec>&) {}
  void update(StepContext<Exec>&) {}
  void endWindow(WindowContext<Exec>&) {}

  /// What loadHistory and flushHistory read and write (device pointers).
  struct HistoryArrays {
    double* hc;               ///< per owned candidate: δ_t
    std::int64_t* hk;         ///< per particle and slot: key
    double* hd;               ///< per particle and slot: δ_t
    const std::int32_t* nc;   ///< contacts
    std::int32_t* nwc;        ///< wallContacts
    const std::int64_t* gid;  ///< global ids
    const std::uint32_t* hs;  ///< half-list starts
    const std::int32_t* half; ///< half lists
    long long K;              ///< slots per particle
  };
  HistoryArrays historyArrays(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    return {_hc.d(),
            p.histKey.d(),
            p.histDisp.d(),
            p.contacts.d(),
            p.wallContacts.d(),
            p.gid.d(),
            ctx.pairs.halfStart(),
            ctx.pairs.half(),
            p.K};
  }

  /// New pair lists (a rebuild, a new state): each owned candidate's tangential history from
  /// its owner's slots (key: the partner's gid; zero if there is none), and the wall slots
  /// moved to the front of the row, the rest of the slots read emptied. Reads gid, contacts,
  /// the pair lists; writes histKey, histDisp, wallContacts (the walls found, normally
  /// unchanged).
  void loadHistory(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    _hc.reserve(3 * static_cast<std::size_t>(ctx.pairs.candidates()));
    const HistoryArrays a = historyArrays(ctx);
    ctx.exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      double* hc = a.hc;
      std::int64_t* hk = a.hk;
      double* hd = a.hd;
      const std::int32_t* half = a.half;
      const long long K = a.K;
      const long long row = static_cast<long long>(i) * K;
      // Slots in use: the last sub-step's contacts and walls (format ≤ 2 states: nc counted
      // every contact, both sides' slots are then read; the owner's is used).
      const long long used = a.nc[i] + a.nwc[i] < K ? a.nc[i] + a.nwc[i] : K;
      for (std::uint32_t q = a.hs[i]; q < a.hs[i + 1]; ++q) {
        const std::int64_t key = a.gid[half[q]];
        Vec3 d{0.0, 0.0, 0.0};
        for (long long s = 0; s < used; ++s) {
          if (hk[row + s] == key) {
            d = load3(hd, row + s);
            break;
          }
        }
        store3(hc, q, d);
      }
      int walls = 0;
      for (long long s = 0; s < used; ++s) {
        const std::int64_t key = hk[row + s];
        if (key <= -2) {
          if (s != walls) {
            hk[row + walls] = key;
            store3(hd, row + walls, load3(hd, row + s));
          }
          ++walls;
        }
      }
      for (long long s = walls; s < used; ++s)
        hk[row + s] = -1;
      if (a.nwc[i] != walls)
        a.nwc[i] = walls;
    });
    p.produced(kHistKey | kHistDisp | kWallContacts);
    _hcGeneration = ctx.pairs.generation();
  }

  /// The owned candidates' tangential history into the owners' slots, after their walls, and
  /// every other slot emptied: the slots are then complete (a re-sort moves them, a state
  /// holds them). Only while the candidates hold the history (their lists are the current
  /// ones); else the slots already are. Reads gid, wallContacts, the pair lists; writes
  /// histKey, histDisp.
  void flushHistory(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    PairLists<Exec>& pl = ctx.pairs;
    if (!pl.valid() || _hcGeneration != pl.generation() || p.n == 0)
      return;
    const HistoryArrays a = historyArrays(ctx);
    ctx.exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      std::int64_t* hk = a.hk;
      double* hd = a.hd;
      const long long K = a.K;
      const long long row = static_cast<long long>(i) * K;
      long long s = a.nwc[i] < K ? a.nwc[i] : K;
      for (std::uint32_t q = a.hs[i]; q < a.hs[i + 1]; ++q) {
        const Vec3 d = load3(a.hc, q);
        if (zeroBits(d))
          continue;
        if (s < K) { // more is an error the sub-step reported (readStatus)
          hk[row + s] = a.gid[a.half[q]];
          store3(hd, row + s, d);
        }
        ++s;
      }
      for (; s < K; ++s) // written only where a key is left (rows are mostly clean)
        if (hk[row + s] != -1)
          hk[row + s] = -1;
    });
    p.produced(kHistKey | kHistDisp);
  }

  /// Reads pos, vel, omega, radius, mass, material, gid, histKey, histDisp, the pair lists
  /// (+ the gas force of the drag module in coupled runs); writes force, torque, fwall, histKey,
  /// histDisp, contacts, wallContacts.
  void sources(StepContext<Exec>& ctx) {
    constexpr bool scatter = kScatter<Exec>;
    static_assert(scatter || !kTwoPairs<Exec>, "the two-lane pair path scatters");
    ParticleStore<Exec>& p = ctx.particles;
    PairLists<Exec>& pl = ctx.pairs;
    WallLists<Exec>& wl = ctx.walls;
    wl.ensure(ctx.exec, p, pl.generation(), ctx.setup.skin);
    if (_hcGeneration != pl.generation())
      loadHistory(ctx);
    const std::uint32_t* wallNear = wl.near();
    const double dt = ctx.dt;
    const std::size_t n = p.n;
    const double* x = p.pos.d();
    const double* v = p.vel.d();
    const double* w = p.omega.d();
    const double* r = p.radius.d();
    const double* m = p.mass.d();
    const std::int32_t* mat = p.material.d();
    std::int64_t* hk = p.histKey.d();
    double* hd = p.histDisp.d();
    double* hc = _hc.d();
    double* f = p.force.d();
    double* tq = p.torque.d();
    double* fw = p.fwall.d();
    std::int32_t* nc = p.contacts.d();
    std::int32_t* nwc = p.wallContacts.d();
    const std::uint32_t* hs = pl.halfStart();
    const std::int32_t* half = pl.half();
    const PairProps* pairs = _pairs.d();
    const WallView wv = wl.view();
    const int nMat = ctx.setup.nMaterials;
    const int K = p.K;
    const bool coupled = ctx.setup.coupled; // force holds the gas force of the drag module
    // Gather backends: per candidate, in contact this sub-step and the partner's share (force,
    // then torque, in the shared scratch); per particle, the owner's own sum.
    unsigned char* hit = nullptr;
    double* share = nullptr;
    double* own = nullptr;
    if constexpr (scatter) {
#if !defined(COREDEM_DEM_DOUBLE2) // (else inside the slabs: SlabContacts::zeroReach)
      // Force and torque start at the gas force (or zero) and zero; the slabs add the rest.
      ctx.exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        const long long ii = static_cast<long long>(i);
        if (!coupled)
          kernels::store3(f, ii, kernels::Vec3{0.0, 0.0, 0.0});
        kernels::store3(tq, ii, kernels::Vec3{0.0, 0.0, 0.0});
      });
#endif
    } else {
      _hit.reserve(pl.candidates());
      _own.reserve(6 * n);
      hit = _hit.d();
      static_assert(PairLists<Exec>::kScratchWidth >= 6);
      share = pl.scratch();
      own = _own.d();
    }

#if defined(COREDEM_DEM_DOUBLE2)
    const TwoPairArgs two{x, v, w, r, m, mat, half, pairs, hc, f, tq, nMat, dt, cpuHasAvx()};
#endif
    // Pass 1 (per owner): its owned pairs and its walls (OwnerContacts). The largest count of
    // history slots a particle needs goes to the status array.
    const OwnerContacts<Exec> ownerPass {
      x, v, w, r, m, mat, hk, hd, hc, f, tq, fw, nc, nwc, hs, half, wallNear, pairs, wv, nMat, K, n,
          dt, hit, share, own
#if defined(COREDEM_DEM_DOUBLE2)
          ,
          two
#endif
    };
    if constexpr (scatter) {
#if defined(COREDEM_DEM_DOUBLE2)
      if (_denseGeneration != pl.generation()) { // new slabs: each starts as a dilute one
        _dense.assign(static_cast<std::size_t>(pl.slabs()), 0);
        _denseGeneration = pl.generation();
      }
      _hits.reserve(pl.candidates());
      _work.reserve(n);
      const SlabContacts<Exec> slabPass{ownerPass,     pl.halfOwner(), _hits.d(),  _work.d(),
                                        _dense.data(), pl.slabStart(), pl.slabs(), !coupled};
      ctx.exec.reduceMaxOverSlabRanges(pl.slabStart(), pl.slabs(), slabPass, 0.0,
                                       ctx.status + kStatusHistorySlots);
#else
      ctx.exec.reduceMaxOverSlabsWide(pl.slabStart(), pl.slabs(), ownerPass, 0.0,
                                      ctx.status + kStatusHistorySlots);
#endif
    } else {
      ctx.exec.reduceMaxInto(n, ownerPass, 0.0, ctx.status + kStatusHistorySlots);
      // Pass 2 (per particle): the gas force (or zero), then the terms in the order the
      // scatter adds them: colour by colour, and within a colour by the evaluating particle's
      // index (its own sum at its own index among the partners of that colour).
      const std::uint32_t* ls = pl.lowStart();
      const std::uint32_t* low = pl.low();
      const std::uint32_t* lowOwner = pl.lowOwner();
      const std::uint8_t* colour = pl.colour();
      ctx.exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        using namespace kernels;
        const long long ii = static_cast<long long>(i);
        Vec3 F = coupled ? load3(f, ii) : Vec3{0.0, 0.0, 0.0};
        Vec3 T{0.0, 0.0, 0.0};
        const bool hasOwn = nc[i] + nwc[i] > 0; // as the scatter: no own sum without own contacts
        inSlabOrder(
            i, hasOwn, ls, lowOwner, colour,
            [&] {
              F += load3(own, 2 * ii);
              T += load3(own, 2 * ii + 1);
            },
            [&](std::uint32_t k) {
              const long long q = low[k];
              if (!hit[q])
                return;
              F += -load3(share, 2 * q);
              T += load3(share, 2 * q + 1);
            });
        store3(f, ii, F);
        store3(tq, ii, T);
      });
    }
    p.produced(kForce | kTorque | kFwall | kHistKey | kHistDisp | kContacts | kWallContacts);
  }

  /// After the sub-step (host): the history slots in use, and their check. A particle keeps
  /// the history of the contacts it owns and of its walls; more of them than slots is an error
  /// (the sub-step's forces lost some contacts' history).
  void readStatus(const double* status, const ParticleStore<Exec>& p) {
    const int K = p.K;
    const double maxSlots = status[kStatusHistorySlots];
    _maxUsedSlots = maxSlots < K ? static_cast<int>(maxSlots) : K;
    if (maxSlots > K) {
      backend::raiseUserError(
          "a particle keeps the tangential history of " +
          std::to_string(static_cast<int>(maxSlots)) +
          " contacts (those it owns, walls included) but has only " + std::to_string(K) +
          " tangential-history slots; raise NeighbourOptions::historySlots (case file: "
          "dem.history_slots; at most " +
          std::to_string(kMaxHistorySlots) + ")");
    }
  }

  /// Particle–particle contact pairs of the last sub-step.
  std::size_t pairContacts(ParticleStore<Exec>& p) const {
    p.toHost(kContacts);
    std::size_t s = 0;
    for (std::size_t i = 0; i < p.n; ++i)
      s += static_cast<std::size_t>(p.contacts.h()[i]); // each pair counted by its owner
    return s;
  }
  /// Particle–wall contacts of the last sub-step.
  std::size_t wallContacts(ParticleStore<Exec>& p) const {
    p.toHost(kWallContacts);
    std::size_t s = 0;
    for (std::size_t i = 0; i < p.n; ++i)
      s += static_cast<std::size_t>(p.wallContacts.h()[i]);
    return s;
  }
  /// Σ force of the walls on the particles in the last sub-step (N).
  std::array<double, 3> wallForce(ParticleStore<Exec>& p) const {
    p.toHost(kFwall);
    std::array<double, 3> s{0, 0, 0};
    for (std::size_t i = 0; i < p.n; ++i)
      for (int c = 0; c < 3; ++c)
        s[c] += p.fwall.h()[3 * i + c];
    return s;
  }

private:
  Dual<PairProps> _pairs;
  Dev<unsigned char> _hit;  ///< gather backends, per candidate: in contact this sub-step
  Dev<double> _own;         ///< gather backends, per particle: the owner's own force, torque
  Dev<std::uint32_t> _hits; ///< cpu: per owned candidate, scratch of SlabContacts
  Dev<std::uint32_t> _work; ///< cpu: per particle, scratch of SlabContacts
  std::vector<unsigned char> _dense; ///< cpu: per slab, SlabContacts goes owner by owner
  std::uint64_t _denseGeneration = ~std::uint64_t{0}; ///< pair-list build of _dense
  Dev<double> _hc; ///< per owned candidate: tangential history δ_t (zero out of contact)
  std::uint64_t _hcGeneration = ~std::uint64_t{0}; ///< pair-list build _hc belongs to
  int _maxUsedSlots =
      kMaxHistorySlots; ///< max contacts of a particle in the last sub-step (≥ slots in use)
};

} // namespace coredem::dem
