#pragma once
/// @file
/// The contact module's pair kernels (contacts.h): an owned pair in contact evaluated from its
/// owner (ownedPair, the path of every backend) and the cpu backend's evaluation of two to four
/// owned pairs at once in SIMD lanes (ownedPairs: kernels::Double2, kernels::Double4 with AVX),
/// each lane giving the bits of ownedPair<Law, double>. Every function is written for a contact
/// law Law (kernels/contact_law.h); ContactModule instantiates them for the run's law.

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "backend/exec_common.h"
#include "coredem/dem/kernels/contact_common.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/vec3.h"
#include "engine.h"

namespace coredem::dem {

/// An owned pair in contact seen from its owner i: the contact law's result and L_ji.
template <class S>
struct OwnedPair {
  kernels::ContactResultT<S> res;
  S lji;
};

/// The pair terms of an owned pair in contact, d = x_j − x_i, l2 = |d|² < (r_i + r_j)², with the
/// pair's row `pair` of contact law Law (LSD: Eqs. 7–13). S: the scalar type (kernels/lanes.h):
/// double, or Double2 / Double4 for pairs at once (cpu), each lane giving the bits of the double
/// evaluation.
template <class Law, class S>
DEM_HD OwnedPair<S> ownedPair(kernels::Vec3T<S> d, S l2, S ri, S rj, S mi, S mj,
                              const typename Law::template PairT<S>& pair, kernels::Vec3T<S> vi,
                              kernels::Vec3T<S> vj, kernels::Vec3T<S> wi, kernels::Vec3T<S> wj,
                              kernels::Vec3T<S> hist, double dt) {
  using namespace kernels;
  const S rsum = ri + rj;
  const S l = laneSqrt(l2);
  const S invL = 1.0 / l;
  const Vec3T<S> nrm = invL * d;
  const S deltaN = rsum - l;
  const S meff = effectiveMass(mi, mj);
  const auto contact = Law::contact(pair, meff, effectiveMass(ri, rj)); // R* as m*
  const S lij = leverArmInv(l, invL, ri, rj);
  const S lji = leverArmInv(l, invL, rj, ri);
  const Vec3T<S> vij = relativeVelocity(vi, vj, wi, wj, lij, lji, nrm);
  return {Law::evaluate(contact, nrm, deltaN, vij, lij, hist, dt), lji};
}

/// Whether Exec evaluates two owned pairs at once (Exec::PairScalar, cpu: kernels::Double2).
template <class Exec, class = void>
inline constexpr bool kTwoPairs = false;
template <class Exec>
inline constexpr bool kTwoPairs<Exec, std::void_t<typename Exec::PairScalar>> = true;

#if defined(COREDEM_DEM_DOUBLE2)
/// What twoOwnedPairs reads and writes (pass 1 of ContactModule::sources), for contact law Law.
template <class Law>
struct TwoPairArgs {
  using Pair = typename Law::Pair;
  const double* x;
  const double* v;
  const double* w;
  const double* r;
  const double* m;
  const std::int32_t* mat;
  const std::int32_t* half;
  const kernels::ContactPair* pairs; ///< rows of Law
  double* hc;                        ///< tangential history per owned candidate (3 doubles)
  double* f;  ///< force: the partners' shares are added to it (scatter, pair_lists.h "Slabs")
  double* tq; ///< torque, likewise
  int nMat;
  double dt;
  bool avx; ///< twoOwnedPairs runs its AVX version

  /// Properties of the pair (i, j); a one-material run reads no material index (the rows
  /// of a pass's few contacts are otherwise each one more cache line to wait for).
  DEM_HD const Pair& props(long long i, long long j) const {
    return (nMat == 1 ? pairs[0] : pairs[mat[i] * nMat + mat[j]]).template of<Law>();
  }
};

/// Owned candidates q0 < q1 of particle i, both in contact, evaluated in the two lanes of
/// Double2 (ownedPair<Law>): updates their tangential history (a.hc), adds their partners' shares
/// to the partners' force and torque (q0's partner first), and returns force and torque on i of
/// q0 in out[0..6) and of q1 in out[6..12). Called through twoOwnedPairs.
template <class Law>
DEM_HD_FORCEINLINE void twoOwnedPairsBody(const TwoPairArgs<Law>& a, long long i, std::uint32_t q0,
                                          std::uint32_t q1, double* out) {
  using namespace kernels;
  using D = Double2;
  using Pair = typename Law::Pair;
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
  const Pair& p0 = a.props(i, j0);
  const Pair& p1 = a.props(i, j1);
  const Vec3 h0 = load3(a.hc, q0);
  const Vec3 h1 = load3(a.hc, q1);
  const OwnedPair<D> op = ownedPair<Law, D>(
      d, dot(d, d), both(a.r[i]), lanes(a.r[j0], a.r[j1]), both(a.m[i]), lanes(a.m[j0], a.m[j1]),
      Law::template gather<D>([&](auto member) { return lanes(p0.*member, p1.*member); }),
      both3(a.v), gather3(a.v), both3(a.w), gather3(a.w),
      Vec3T<D>{lanes(h0.x, h1.x), lanes(h0.y, h1.y), lanes(h0.z, h1.z)}, a.dt);
  const ContactResultT<D>& res = op.res;
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
template <class Law>
[[gnu::noinline, gnu::flatten]] inline void twoOwnedPairsSse2(const TwoPairArgs<Law>& a,
                                                              long long i, std::uint32_t q0,
                                                              std::uint32_t q1, double* out) {
  twoOwnedPairsBody(a, i, q0, q1, out);
}
#if defined(__x86_64__)
template <class Law>
[[gnu::noinline, gnu::flatten, gnu::target("avx")]] inline void
twoOwnedPairsAvx(const TwoPairArgs<Law>& a, long long i, std::uint32_t q0, std::uint32_t q1,
                 double* out) {
  twoOwnedPairsBody(a, i, q0, q1, out);
}
#endif
/// twoOwnedPairsAvx if a.avx, else twoOwnedPairsSse2. (Without AVX the group costs 443
/// instructions per two pairs against 510 for two scalar pairs, about what the call and the
/// gathers add: pass 1 then counts +0.7 %, not worth a test per pair in the loop.)
template <class Law>
inline void twoOwnedPairs(const TwoPairArgs<Law>& a, long long i, std::uint32_t q0,
                          std::uint32_t q1, double* out) {
#if defined(__x86_64__)
  if (a.avx) {
    twoOwnedPairsAvx(a, i, q0, q1, out);
    return;
  }
#endif
  twoOwnedPairsSse2(a, i, q0, q1, out);
}

/// One owned candidate q of particle i in contact, the scalar evaluation
/// (ownedPair<Law, double>): updates its history, adds the partner's share to the partner,
/// returns force and torque on i in out[0..6).
template <class Law>
inline void oneOwnedPair(const TwoPairArgs<Law>& a, long long i, std::uint32_t q, double* out) {
  using namespace kernels;
  const long long j = a.half[q];
  const Vec3 d = load3(a.x, j) - load3(a.x, i);
  const typename Law::Pair pp = a.props(i, j);
  const OwnedPair<double> op =
      ownedPair<Law, double>(d, dot(d, d), a.r[i], a.r[j], a.m[i], a.m[j], pp, load3(a.v, i),
                             load3(a.v, j), load3(a.w, i), load3(a.w, j), load3(a.hc, q), a.dt);
  const ContactResult& res = op.res;
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
/// partners' shares added in the order of q. Every lane gives the bits of
/// ownedPair<Law, double> (no FMA: not part of AVX).
template <class Law>
[[gnu::noinline, gnu::flatten, gnu::target("avx")]] inline void
fourOwnedPairsAvx(const TwoPairArgs<Law>& a, long long i, const std::uint32_t* q, int count,
                  double* out) {
  using namespace kernels;
  using D = Double4;
  using Pair = typename Law::Pair;
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
  // The pair's row in the lanes: one broadcast per member in a one-material run (the four
  // lanes would otherwise load the same row four times), else each lane's row.
  typename Law::template PairT<D> pair;
  if (a.nMat == 1) {
    const Pair& p = a.pairs[0].template of<Law>();
    pair = Law::template gather<D>([&](auto member) { return both(p.*member); });
  } else {
    const Pair* pk[4] = {&a.props(i, j0), &a.props(i, j1), &a.props(i, j2), &a.props(i, j3)};
    pair = Law::template gather<D>([&](auto member) {
      return D{pk[0]->*member, pk[1]->*member, pk[2]->*member, pk[3]->*member};
    });
  }
  const OwnedPair<D> op = ownedPair<Law, D>(d, dot(d, d), both(a.r[i]), lanes(a.r), both(a.m[i]),
                                            lanes(a.m), pair, both3(a.v), gather3(a.v), both3(a.w),
                                            gather3(a.w), rows3(a.hc, q[0], q[1], q[2], q3), a.dt);
  const ContactResultT<D>& res = op.res;
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
template <class Law>
inline void ownedPairs(const TwoPairArgs<Law>& a, long long i, const std::uint32_t* q, int count,
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

} // namespace coredem::dem
