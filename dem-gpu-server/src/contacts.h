#pragma once
/// @file
/// Particle–particle and particle–wall contact forces in the DEM sub-step (docs/physics.md §2.1,
/// LSD with tangential history), written once for every backend like engine_impl.h.
///
/// Each pair is evaluated once, by its owner: the particle with the smaller global id (gid), a
/// choice that survives re-sorting, over the engine's half and low lists (pair_lists.h). Per
/// sub-step, no atomics:
///   pass 1 (per owner i): every owned candidate in contact is evaluated with the LSD law; the
///     owner adds f and L_ij n × f_t to its own force and torque, keeps δ_t in its history
///     slots, and writes the partner's share (−f is implied; L_ji n × f_t) to the pair lists'
///     per-candidate scratch; then its walls;
///   pass 2 (per particle j): adds the partner shares of the contacts it does not own, in the
///     ascending index order of its neighbour list (a fixed order).
/// Both passes write only their own index, so the result does not depend on the thread count.
/// The cpu backend gathers the owned pairs in contact of a run of consecutive particles into a
/// PairBatch and evaluates them several at a time, one pair per lane of a SIMD register (8 with
/// AVX-512, 4 with AVX, 2 with SSE2: evalPairBatch; every lane gives the bits of
/// ownedPair<double>, the other backends' path), then sums them per particle in the same order;
/// both passes run compiled for AVX where the processor has it (CpuExec::reduceMaxIntoWide,
/// reduceMaxRangesIntoWide; same operations, no FMA contraction).
/// The LSD law is mirror-exact (lsd_contact.h): j's share is bitwise what evaluating the pair
/// from j's side gives. History slots (partner gid, −(w+2) for wall w) hold the owned contacts
/// and the walls only; slots of a state file written when both sides kept their history are
/// read as they are (the owner's slot is the one used; the other is dropped at the next sub-step).
/// Forces add the gas force of the drag module in coupled runs.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <type_traits>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "pair_lists.h"
#include "step_module.h"

namespace coredem::dem {

/// Particles ahead whose history rows pass 1 prefetches (CPU; a hint only).
constexpr std::size_t kPrefetchAhead = 8;

/// Candidate j of a particle at xi with radius ri: d = x_j − x_i, |d|², r_j, and whether the two
/// touch (|d| < r_i + r_j).
struct Candidate {
  kernels::Vec3 d;
  double l2;
  double rj;
  bool touching;
};
DEM_HD Candidate candidateOf(const double* x, const double* r, kernels::Vec3 xi, double ri,
                             std::int32_t j) {
  const kernels::Vec3 d = kernels::load3(x, j) - xi;
  const double l2 = kernels::dot(d, d);
  const double rj = r[j];
  const double rsum = ri + rj;
  return {d, l2, rj, l2 < rsum * rsum};
}

/// Asks for the history row of particle i (K slots) when it had contacts in the last sub-step:
/// the rows of the few particles in contact are scattered through memory, so pass 1 asks for
/// those of a particle kPrefetchAhead further on while it computes (a hint only).
DEM_HD void prefetchHistoryRow(const std::int64_t* hk, const double* hd, const std::int32_t* nc,
                               const std::int32_t* nwc, int K, std::size_t i, std::size_t n) {
  if (i < n && nc[i] + nwc[i] > 0) {
    const std::size_t a = i * static_cast<std::size_t>(K);
    backend::prefetch(hk + a);
    backend::prefetch(hd + 3 * a);
    backend::prefetch(hd + 3 * a + 8);
  }
}

/// Where pass 1 leaves a particle's results.
struct Pass1Out {
  double* f;
  double* tq;
  double* fw;
  std::int64_t* hk;
  std::int32_t* nc;
  std::int32_t* nwc;
  int K;
};

/// Pass 1's results of particle i: F = its force (gas + owned pairs + walls), T its torque, FW
/// the walls' part of F; history slots from `slot` to `used` (the last sub-step's) emptied.
DEM_HD void storePass1(const Pass1Out& o, long long i, kernels::Vec3 F, kernels::Vec3 T,
                       kernels::Vec3 FW, int slot, int used, int owned, int walls) {
  for (int s = slot; s < used; ++s)
    o.hk[i * o.K + s] = -1;
  kernels::store3(o.f, i, F);
  kernels::store3(o.tq, i, T);
  kernels::store3(o.fw, i, FW);
  o.nc[i] = owned;
  o.nwc[i] = walls;
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

/// exec.reduceMaxIntoWide where Exec has it (cpu: the body compiled for AVX where the
/// processor has it), else exec.reduceMaxInto.
template <class Exec, class F>
void reduceMaxIntoWide(Exec& exec, std::size_t n, F f, double init, double* out) {
  if constexpr (requires { exec.reduceMaxIntoWide(n, f, init, out); })
    exec.reduceMaxIntoWide(n, f, init, out);
  else
    exec.reduceMaxInto(n, f, init, out);
}

/// The LSD law of particle i against wall w with overlap deltaN > 0 (m_eff = m_i, the
/// particle's own material pair); hist: the contact's tangential displacement.
DEM_HD kernels::LsdResult wallPair(const PairProps& pp, const kernels::PlaneWall& wall,
                                   double deltaN, double mi, kernels::Vec3 vi, kernels::Vec3 wi,
                                   double ri, kernels::Vec3 hist, double dt) {
  using namespace kernels;
  const double etan = pp.dampFactor * ::sqrt(pp.kn * mi);
  const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
  return wallContact(lp, wall, deltaN, vi, wi, ri, hist, dt);
}

/// Calls f(k, deltaN) for every wall k that particle i (at xi, radius ri) overlaps, in
/// ascending order: the candidate bits of the first 32 walls (bits: wall candidates of the last
/// neighbour build; most particles have none), then every wall beyond them.
template <class F>
DEM_HD void forEachWallOverlap(std::uint32_t bits, int nWalls, const kernels::PlaneWall* walls,
                               kernels::Vec3 xi, double ri, F f) {
  for (int k = bits != 0 ? kernels::lowestBit(bits) : 32; k < nWalls;) {
    const double deltaN = kernels::wallOverlap(walls[k], xi, ri);
    if (deltaN > 0.0)
      f(k, deltaN);
    if (k < 32) {
      bits &= bits - 1;
      k = bits != 0 ? kernels::lowestBit(bits) : 32;
    } else {
      ++k;
    }
  }
}

/// Whether Exec evaluates the owned pairs in batches (Exec::kPairBatches, cpu).
template <class Exec>
inline constexpr bool kPairBatches = requires {
  requires Exec::kPairBatches;
};

#if defined(COREDEM_DEM_DOUBLE2)
/// Owned pairs in contact, gathered by pass 1 of the cpu backend from a run of consecutive
/// particles (one column per pair, structure of arrays) and evaluated several at a time in the
/// lanes of a SIMD register by evalPairBatch; then their results, read back in candidate order.
struct PairBatch {
  /// Columns (pairs); a run of particles ends before its owned candidates could exceed it.
  static constexpr int kCapacity = 64;
  /// Inputs of ownedPair: d, |d|², r_i, r_j, m_i, m_j, the pair's material constants, v_i, v_j,
  /// ω_i, ω_j and the old tangential displacement.
  enum In : int {
    Dx,
    Dy,
    Dz,
    L2,
    Ri,
    Rj,
    Mi,
    Mj,
    Kn,
    Kt,
    Damp,
    Etat,
    Mu,
    Vix,
    Viy,
    Viz,
    Vjx,
    Vjy,
    Vjz,
    Wix,
    Wiy,
    Wiz,
    Wjx,
    Wjy,
    Wjz,
    Hx,
    Hy,
    Hz,
    kIn
  };
  /// Results: force and torque on i, new tangential displacement, the partner's torque.
  enum Out : int { Fx, Fy, Fz, Tx, Ty, Tz, DTx, DTy, DTz, Sx, Sy, Sz, kOut };
  alignas(64) double in[kIn][kCapacity];
  alignas(64) double out[kOut][kCapacity];
  std::int64_t key[kCapacity]; ///< history key of the pair (the partner's gid)
};

/// Pairs [g, g + kLanes<S>) of b in the lanes of S: the bits of ownedPair<double> per lane.
template <class S>
[[gnu::always_inline]] inline void evalPairGroup(PairBatch& b, int g, double dt) {
  using namespace kernels;
  using B = PairBatch;
  // Loads and stores straight from and to the columns (no copies through the stack).
  auto in = [&](int k) {
    S s;
    __builtin_memcpy(&s, &b.in[k][g], sizeof(S));
    return s;
  };
  auto in3 = [&](int k) { return Vec3T<S>{in(k), in(k + 1), in(k + 2)}; };
  auto out3 = [&](int k, Vec3T<S> u) {
    __builtin_memcpy(&b.out[k][g], &u.x, sizeof(S));
    __builtin_memcpy(&b.out[k + 1][g], &u.y, sizeof(S));
    __builtin_memcpy(&b.out[k + 2][g], &u.z, sizeof(S));
  };
  const OwnedPair<S> op =
      ownedPair<S>(in3(B::Dx), in(B::L2), in(B::Ri), in(B::Rj), in(B::Mi), in(B::Mj), in(B::Kn),
                   in(B::Kt), in(B::Damp), in(B::Etat), in(B::Mu), in3(B::Vix), in3(B::Vjx),
                   in3(B::Wix), in3(B::Wjx), in3(B::Hx), dt);
  out3(B::Fx, op.res.force);
  out3(B::Tx, op.res.torque);
  out3(B::DTx, op.res.deltaT);
  out3(B::Sx, op.lji * op.res.nxft);
}

/// Pairs [0, count) of b: groups of S, the rest in narrower lanes (no padding).
template <class S>
[[gnu::always_inline]] inline void evalPairsAs(PairBatch& b, int count, double dt) {
  int g = 0;
  for (; g + kernels::kLanes<S> <= count; g += kernels::kLanes<S>)
    evalPairGroup<S>(b, g, dt);
#if defined(COREDEM_DEM_WIDE_LANES)
  if constexpr (kernels::kLanes < S >> 4) {
    if (g + 4 <= count) {
      evalPairGroup<kernels::Double4>(b, g, dt);
      g += 4;
    }
  }
#endif
  if constexpr (kernels::kLanes < S >> 2) {
    if (g + 2 <= count) {
      evalPairGroup<kernels::Double2>(b, g, dt);
      g += 2;
    }
  }
  if (g < count)
    evalPairGroup<double>(b, g, dt);
}

// One out-of-line copy per instruction set: the gathering loop and the lane arithmetic each get
// the registers to themselves, and AVX / AVX-512 code runs only where the processor has it.
[[gnu::noinline, gnu::flatten]] inline void evalPairBatch1(PairBatch& b, int count, double dt) {
  for (int g = 0; g < count; ++g)
    evalPairGroup<double>(b, g, dt);
}
[[gnu::noinline, gnu::flatten]] inline void evalPairBatch2(PairBatch& b, int count, double dt) {
  evalPairsAs<kernels::Double2>(b, count, dt);
}
#if defined(COREDEM_DEM_WIDE_LANES)
[[gnu::noinline, gnu::flatten, gnu::target("avx")]] inline void
evalPairBatch4(PairBatch& b, int count, double dt) {
  evalPairsAs<kernels::Double4>(b, count, dt);
}
[[gnu::noinline, gnu::flatten, gnu::target("avx512f")]] inline void
evalPairBatch8(PairBatch& b, int count, double dt) {
  evalPairsAs<kernels::Double8>(b, count, dt);
}
#endif

/// The widest lane count this processor runs: 8 (AVX-512F), 4 (AVX) or 2 (SSE2).
inline int widestPairLanes() {
#if defined(COREDEM_DEM_WIDE_LANES)
  if (__builtin_cpu_supports("avx512f"))
    return 8;
  if (__builtin_cpu_supports("avx"))
    return 4;
#endif
  return 2;
}

/// Evaluates the pairs [0, count) of b, at most `lanes` at a time (1, 2, 4 or 8, at most
/// widestPairLanes()): every lane count gives the same bits (tested).
inline void evalPairBatch(PairBatch& b, int count, double dt, int lanes) {
#if defined(COREDEM_DEM_WIDE_LANES)
  if (lanes >= 8)
    return evalPairBatch8(b, count, dt);
  if (lanes >= 4)
    return evalPairBatch4(b, count, dt);
#endif
  if (lanes >= 2)
    return evalPairBatch2(b, count, dt);
  evalPairBatch1(b, count, dt);
}

/// The lane count of the contact pass: widestPairLanes(), or COREDEM_DEM_PAIR_LANES (1, 2, 4 or
/// 8, capped at widestPairLanes()) to compare lane counts in a benchmark (results are the same).
inline int pairLanesToUse() {
  const int widest = widestPairLanes();
  if (const char* e = std::getenv("COREDEM_DEM_PAIR_LANES")) {
    const int want = std::atoi(e);
    if (want == 1 || want == 2 || want == 4 || want == 8)
      return want < widest ? want : widest;
  }
  return widest;
}
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
    _walls.allocate(s.walls.size());
    for (std::size_t k = 0; k < s.walls.size(); ++k)
      _walls.h()[k] = s.walls[k];
    _walls.markHostModified();
    _walls.toDevice();
#if defined(COREDEM_DEM_DOUBLE2)
    _pairLanes = pairLanesToUse();
#endif
  }

  bool enabled() const {
    return true;
  }
  std::size_t bytes() const {
    return _pairs.bytes() + _walls.bytes() + _hit.bytes();
  }
  ContactTotals totals() const {
    return {};
  }

  /// History slots in use in some row (slots at or beyond it are empty everywhere); the
  /// neighbour rebuild moves only these.
  int usedSlots() const {
    return _maxUsedSlots;
  }
  /// After new particles: every slot may be in use.
  void resetUsedSlots(int slots) {
    _maxUsedSlots = slots;
  }

  void beginWindow(StepContext<Exec>&) {}
  void update(StepContext<Exec>&) {}
  void endWindow(WindowContext<Exec>&) {}

  /// Wall candidates per particle, a bit per wall (all bits beyond 32 walls), from the positions
  /// of the last neighbour build (xref): a particle moves at most skin/2 from xref before the
  /// next build, so one whose gap to a wall at xref is at least skin/2 cannot touch it until
  /// then (radii only shrink). Rebuilt with the pair lists; reads xref, radius.
  void buildWallCandidates(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    _wallNear.reserve(p.n);
    std::uint32_t* near = _wallNear.d();
    const double* xr = p.xref.d();
    const double* r = p.radius.d();
    const kernels::PlaneWall* walls = _walls.d();
    const int nWalls = static_cast<int>(ctx.setup.walls.size());
    const double halfSkin = 0.5 * ctx.setup.skin;
    ctx.exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t bits = 0;
      if (nWalls > 32) {
        bits = 0xffffffffu;
      } else {
        const kernels::Vec3 xi = kernels::load3(xr, static_cast<long long>(i));
        for (int k = 0; k < nWalls; ++k) {
          // Not "≥ skin/2 away" (also catches NaN): a candidate.
          if (!(-kernels::wallOverlap(walls[k], xi, r[i]) >= halfSkin))
            bits |= 1u << k;
        }
      }
      near[i] = bits;
    });
    _wallGeneration = ctx.pairs.generation();
  }

  /// Reads pos, vel, omega, radius, mass, material, gid, histKey, histDisp, the pair lists
  /// (+ the gas force of the drag module in coupled runs); writes force, torque, fwall, histKey,
  /// histDisp, contacts, wallContacts.
  void sources(StepContext<Exec>& ctx) {
    ParticleStore<Exec>& p = ctx.particles;
    PairLists<Exec>& pl = ctx.pairs;
    if (_wallGeneration != pl.generation())
      buildWallCandidates(ctx);
    const std::uint32_t* wallNear = _wallNear.d();
    const double dt = ctx.dt;
    const std::size_t n = p.n;
    const double* x = p.pos.d();
    const double* v = p.vel.d();
    const double* w = p.omega.d();
    const double* r = p.radius.d();
    const double* m = p.mass.d();
    const std::int32_t* mat = p.material.d();
    const std::int64_t* gid = p.gid.d();
    std::int64_t* hk = p.histKey.d();
    double* hd = p.histDisp.d();
    double* f = p.force.d();
    double* tq = p.torque.d();
    double* fw = p.fwall.d();
    std::int32_t* nc = p.contacts.d();
    std::int32_t* nwc = p.wallContacts.d();
    const std::uint32_t* hs = pl.halfStart();
    const std::int32_t* half = pl.half();
    const std::uint32_t* ls = pl.lowStart();
    const std::uint32_t* low = pl.low();
    _hit.reserve(pl.candidates());
    unsigned char* hit = _hit.d();
    // Partner shares in the shared scratch: force (3 values), then torque (3), per candidate.
    static_assert(PairLists<Exec>::kScratchWidth >= 6);
    double* share = pl.scratch();
    const PairProps* pairs = _pairs.d();
    const kernels::PlaneWall* walls = _walls.d();
    const int nWalls = static_cast<int>(ctx.setup.walls.size());
    const int nMat = ctx.setup.nMaterials;
    const int K = p.K;
    const bool coupled = ctx.setup.coupled; // force holds the gas force of the drag module

    const Pass1Out out{f, tq, fw, hk, nc, nwc, K};
    // Pass 1, one particle: its owned pairs and its walls. Returns the history slots it needs
    // (owned contacts + walls); writes only index i.
    auto pass1 = [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      const long long ii = static_cast<long long>(i);
      const Vec3 xi = load3(x, ii);
      const double ri = r[i];
      prefetchHistoryRow(hk, hd, nc, nwc, K, i + kPrefetchAhead, n);
      // Slots in use are compacted at the front: the last sub-step used nc + nwc of them
      // (format ≤ 2 states: nc counted every contact, both sides' slots are then read).
      const int used = nc[i] + nwc[i] < K ? nc[i] + nwc[i] : K;
      std::int64_t oldKey[kMaxHistorySlots];
      Vec3 oldD[kMaxHistorySlots];
      for (int s = 0; s < used; ++s) {
        oldKey[s] = hk[i * K + s];
        oldD[s] = load3(hd, ii * K + s);
      }
      int slot = 0;
      auto history = [&](std::int64_t key) {
        for (int s = 0; s < used; ++s)
          if (oldKey[s] == key)
            return oldD[s];
        return Vec3{0.0, 0.0, 0.0};
      };
      auto remember = [&](std::int64_t key, Vec3 d) {
        if (slot < K) {
          hk[i * K + slot] = key;
          store3(hd, ii * K + slot, d);
        }
        ++slot;
      };
      Vec3 F = coupled ? load3(f, ii) : Vec3{0.0, 0.0, 0.0};
      Vec3 T{0.0, 0.0, 0.0};
      // Particle–particle LSD (Eqs. 7–13) over the owned candidates. i's velocities, mass
      // and material are read only if it has some (most particles of a dilute bed do not).
      int owned = 0;
      const std::uint32_t qEnd = hs[i + 1];
      if (hs[i] < qEnd) {
        const Vec3 vi = load3(v, ii);
        const Vec3 wi = load3(w, ii);
        const double mi = m[i];
        const int ai = mat[i];
        for (std::uint32_t q = hs[i]; q < qEnd; ++q) {
          const std::int32_t j = half[q];
          const Candidate cj = candidateOf(x, r, xi, ri, j);
          hit[q] = cj.touching ? 1 : 0;
          if (!cj.touching)
            continue;
          const PairProps pp = pairs[ai * nMat + mat[j]];
          const std::int64_t key = gid[j];
          const OwnedPair<double> op =
              ownedPair(cj.d, cj.l2, ri, cj.rj, mi, m[j], pp.kn, pp.kt, pp.dampFactor,
                        pp.etatFactor, pp.mu, vi, load3(v, j), wi, load3(w, j), history(key), dt);
          const LsdResult& res = op.res;
          F += res.force;
          T += res.torque;
          remember(key, res.deltaT);
          // j's share: force −f (applied in pass 2), torque L_ji n × f_t.
          store3(share, 2 * static_cast<long long>(q), res.force);
          store3(share, 2 * static_cast<long long>(q) + 1, op.lji * res.nxft);
          ++owned;
        }
      }
      // Walls, in ascending order.
      Vec3 FW{0.0, 0.0, 0.0};
      int wallCount = 0;
      forEachWallOverlap(wallNear[i], nWalls, walls, xi, ri, [&](int k, double deltaN) {
        const std::int64_t key = -(static_cast<std::int64_t>(k) + 2);
        const LsdResult res = wallPair(pairs[mat[i] * nMat + mat[i]], walls[k], deltaN, m[i],
                                       load3(v, ii), load3(w, ii), ri, history(key), dt);
        FW += res.force;
        T += res.torque;
        remember(key, res.deltaT);
        ++wallCount;
      });
      F += FW;
      storePass1(out, ii, F, T, FW, slot, used, owned, wallCount);
      return static_cast<double>(slot);
    };

    // Pass 1: the owned pairs and the walls of every particle. reduceMax runs the body once
    // per index (side effects on index i only) and returns the most history slots a particle
    // needs (owned contacts + walls), in the same pass.
#if defined(COREDEM_DEM_DOUBLE2)
    if constexpr (kPairBatches<Exec>) {
      // cpu: runs of consecutive particles, each in three steps: (a) per particle, its owned
      // candidates in contact are found and their inputs gathered into a PairBatch (history
      // read from the particle's unchanged row); (b) the batch is evaluated several pairs at a
      // time in SIMD lanes; (c) per particle, in candidate order, the results are summed and
      // stored exactly as pass1 does (walls evaluated first, on the unchanged row, and added
      // after the pairs): the bits of pass1, which serves a particle with more owned
      // candidates than a batch holds.
      const int lanes = _pairLanes;
      auto run = [=](std::size_t lo, std::size_t hi) {
        using namespace kernels;
        using B = PairBatch;
        B batch;
        double most = 0.0;
        std::size_t i = lo;
        while (i < hi) {
          // (a) gather
          int count = 0;
          std::size_t end = i;
          for (; end < hi; ++end) {
            const std::uint32_t q0 = hs[end];
            const std::uint32_t q1 = hs[end + 1];
            if (count + static_cast<int>(q1 - q0) > B::kCapacity)
              break;
            prefetchHistoryRow(hk, hd, nc, nwc, K, end + kPrefetchAhead, n);
            if (q0 == q1)
              continue;
            const long long ii = static_cast<long long>(end);
            const Vec3 xi = load3(x, ii);
            const double ri = r[end];
            const int used = nc[end] + nwc[end] < K ? nc[end] + nwc[end] : K;
            const std::int64_t* keys = hk + ii * K;
            int nth = 0; // touching candidates of this particle so far
            for (std::uint32_t q = q0; q < q1; ++q) {
              const std::int32_t j = half[q];
              const Candidate cj = candidateOf(x, r, xi, ri, j);
              hit[q] = cj.touching ? 1 : 0;
              if (!cj.touching)
                continue;
              const std::int64_t key = gid[j];
              // A row holds each key once, and a contact that lasts keeps its slot (the nth
              // touching candidate wrote slot nth): look there first.
              Vec3 h{0.0, 0.0, 0.0};
              if (nth < used && keys[nth] == key) {
                h = load3(hd, ii * K + nth);
              } else {
                for (int s = 0; s < used; ++s) {
                  if (keys[s] == key) {
                    h = load3(hd, ii * K + s);
                    break;
                  }
                }
              }
              ++nth;
              const PairProps& pp = pairs[mat[end] * nMat + mat[j]];
              const int c = count++;
              auto put = [&](int k, double u) { batch.in[k][c] = u; };
              put(B::Dx, cj.d.x);
              put(B::Dy, cj.d.y);
              put(B::Dz, cj.d.z);
              put(B::L2, cj.l2);
              put(B::Ri, ri);
              put(B::Rj, cj.rj);
              put(B::Mi, m[end]);
              put(B::Mj, m[j]);
              put(B::Kn, pp.kn);
              put(B::Kt, pp.kt);
              put(B::Damp, pp.dampFactor);
              put(B::Etat, pp.etatFactor);
              put(B::Mu, pp.mu);
              for (int k = 0; k < 3; ++k) {
                put(B::Vix + k, v[3 * ii + k]);
                put(B::Vjx + k, v[3 * j + k]);
                put(B::Wix + k, w[3 * ii + k]);
                put(B::Wjx + k, w[3 * j + k]);
              }
              put(B::Hx, h.x);
              put(B::Hy, h.y);
              put(B::Hz, h.z);
              batch.key[c] = key;
            }
          }
          if (end == i) { // more owned candidates than a batch holds
            most = std::max(most, pass1(i));
            ++i;
            continue;
          }
          // (b) evaluate
          evalPairBatch(batch, count, dt, lanes);
          // (c) sum and store
          int c = 0;
          for (; i < end; ++i) {
            const long long ii = static_cast<long long>(i);
            const Vec3 xi = load3(x, ii);
            const double ri = r[i];
            const int used = nc[i] + nwc[i] < K ? nc[i] + nwc[i] : K;
            // Walls first, while i's history row is unchanged.
            std::int64_t wallKey[kMaxHistorySlots];
            LsdResult wallRes[kMaxHistorySlots];
            int wallCount = 0;
            forEachWallOverlap(wallNear[i], nWalls, walls, xi, ri, [&](int k, double deltaN) {
              const std::int64_t key = -(static_cast<std::int64_t>(k) + 2);
              Vec3 h{0.0, 0.0, 0.0};
              for (int s = 0; s < used; ++s) {
                if (hk[ii * K + s] == key) {
                  h = load3(hd, ii * K + s);
                  break;
                }
              }
              if (wallCount < kMaxHistorySlots) {
                wallKey[wallCount] = key;
                wallRes[wallCount] = wallPair(pairs[mat[i] * nMat + mat[i]], walls[k], deltaN, m[i],
                                              load3(v, ii), load3(w, ii), ri, h, dt);
              }
              ++wallCount;
            });
            Vec3 F = coupled ? load3(f, ii) : Vec3{0.0, 0.0, 0.0};
            Vec3 T{0.0, 0.0, 0.0};
            int slot = 0;
            const std::uint32_t qEnd = hs[i + 1];
            for (std::uint32_t q = hs[i]; q < qEnd; ++q) {
              if (!hit[q])
                continue;
              const Vec3 fc{batch.out[B::Fx][c], batch.out[B::Fy][c], batch.out[B::Fz][c]};
              F += fc;
              T += Vec3{batch.out[B::Tx][c], batch.out[B::Ty][c], batch.out[B::Tz][c]};
              if (slot < K) {
                hk[ii * K + slot] = batch.key[c];
                store3(hd, ii * K + slot,
                       Vec3{batch.out[B::DTx][c], batch.out[B::DTy][c], batch.out[B::DTz][c]});
              }
              ++slot;
              store3(share, 2 * static_cast<long long>(q), fc);
              store3(share, 2 * static_cast<long long>(q) + 1,
                     Vec3{batch.out[B::Sx][c], batch.out[B::Sy][c], batch.out[B::Sz][c]});
              ++c;
            }
            const int owned = slot;
            Vec3 FW{0.0, 0.0, 0.0};
            for (int k = 0; k < wallCount && k < kMaxHistorySlots; ++k) {
              FW += wallRes[k].force;
              T += wallRes[k].torque;
              if (slot < K) {
                hk[ii * K + slot] = wallKey[k];
                store3(hd, ii * K + slot, wallRes[k].deltaT);
              }
              ++slot;
            }
            slot += wallCount > kMaxHistorySlots ? wallCount - kMaxHistorySlots : 0;
            F += FW;
            storePass1(out, ii, F, T, FW, slot, used, owned, wallCount);
            most = std::max(most, static_cast<double>(slot));
          }
        }
        return most;
      };
      ctx.exec.reduceMaxRangesIntoWide(n, run, 0.0, ctx.status + kStatusHistorySlots);
    } else
#endif
    {
      reduceMaxIntoWide(ctx.exec, n, pass1, 0.0, ctx.status + kStatusHistorySlots);
    }

    // Pass 2: the shares of the pairs owned by the partner, in neighbour-list order.
    // Returns the largest number of contacts of a particle (pairs from both sides, walls).
    reduceMaxIntoWide(
        ctx.exec, n,
        [=] DEM_LAMBDA(std::size_t i) {
          using namespace kernels;
          const long long ii = static_cast<long long>(i);
          Vec3 F = load3(f, ii);
          Vec3 T = load3(tq, ii);
          int pairCount = nc[i]; // + the contacts the partners own
          const std::uint32_t kEnd = ls[i + 1];
          for (std::uint32_t k = ls[i]; k < kEnd; ++k) {
            const long long q = low[k];
            if (!hit[q])
              continue;
            F += -load3(share, 2 * q);
            T += load3(share, 2 * q + 1);
            ++pairCount;
          }
          store3(f, ii, F);
          store3(tq, ii, T);
          return static_cast<double>(pairCount + nwc[i]);
        },
        0.0, ctx.status + kStatusContactsPerParticle);
    p.produced(kForce | kTorque | kFwall | kHistKey | kHistDisp | kContacts | kWallContacts);
  }

  /// After the sub-step (host): the history slots in use and the contact-count check of the
  /// values sources() left in the status array. More contacts than slots is an error (the
  /// sub-step's forces lost some contacts' history).
  void readStatus(const double* status, int K) {
    const double maxSlots = status[kStatusHistorySlots];
    const double maxContacts = status[kStatusContactsPerParticle];
    _maxUsedSlots = maxSlots < K ? static_cast<int>(maxSlots) : K;
    if (maxContacts > K) {
      backend::raiseUserError("a particle has " + std::to_string(static_cast<int>(maxContacts)) +
                              " simultaneous contacts but only " + std::to_string(K) +
                              " tangential-history slots; raise NeighbourOptions::historySlots "
                              "(at most " +
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
  Dual<kernels::PlaneWall> _walls;
  Dev<unsigned char> _hit;      ///< per candidate: in contact this sub-step (pass 1)
  Dev<std::uint32_t> _wallNear; ///< per particle: wall candidates (buildWallCandidates)
  std::uint64_t _wallGeneration = ~std::uint64_t{0}; ///< pair-list build of _wallNear
#if defined(COREDEM_DEM_DOUBLE2)
  int _pairLanes = 2; ///< pairs evaluated at a time (cpu: PairBatch)
#endif
  int _maxUsedSlots =
      kMaxHistorySlots; ///< max contacts of a particle in the last sub-step (≥ slots in use)
};

} // namespace coredem::dem
