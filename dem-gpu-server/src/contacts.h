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
/// The LSD law is mirror-exact (lsd_contact.h): j's share is bitwise what evaluating the pair
/// from j's side gives. History slots (partner gid, −(w+2) for wall w) hold the owned contacts
/// and the walls only; slots of a state file written when both sides kept their history are
/// read as they are (the owner's slot is the one used; the other is dropped at the next sub-step).
/// Forces add the gas force of the drag module in coupled runs.

#include <array>
#include <cstddef>
#include <cstdint>
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
/// Pass 1 lists a particle's owned candidates in contact this many at a time.
constexpr int kTouchChunk = 16;

/// The contact module has no ledger (counts and wall forces are read from the particles).
struct ContactTotals {};

/// The scalar type of Exec's pair loop (kernels/lanes.h): Exec::PairScalar where the backend
/// names one (cpu: Double2, two pairs at once), else double.
template <class Exec, class = void>
struct PairScalarOf {
  using type = double;
};
template <class Exec>
struct PairScalarOf<Exec, std::void_t<typename Exec::PairScalar>> {
  using type = typename Exec::PairScalar;
};

namespace contact_lanes {

/// {p[a], p[b]} as S (one lane: p[a]).
template <class S>
DEM_HD S gather(const double* p, long long a, long long b) {
  if constexpr (kernels::kLanes<S> == 1) {
    (void)b;
    return p[a];
  } else {
    return S{p[a], p[b]};
  }
}
/// Vectors a and b of the 3-vector array p as lanes.
template <class S>
DEM_HD kernels::Vec3T<S> gather3(const double* p, long long a, long long b) {
  return {gather<S>(p, 3 * a, 3 * b), gather<S>(p, 3 * a + 1, 3 * b + 1),
          gather<S>(p, 3 * a + 2, 3 * b + 2)};
}
/// (u, v) as lanes (one lane: u).
template <class S>
DEM_HD S pack(double u, double v) {
  if constexpr (kernels::kLanes<S> == 1) {
    (void)v;
    return u;
  } else {
    return S{u, v};
  }
}
template <class S>
DEM_HD kernels::Vec3T<S> pack3(kernels::Vec3 u, kernels::Vec3 v) {
  return {pack<S>(u.x, v.x), pack<S>(u.y, v.y), pack<S>(u.z, v.z)};
}
/// Lane k.
template <int k>
DEM_HD double laneAt(double v) {
  return v;
}
#if defined(COREDEM_DEM_DOUBLE2)
template <int k>
inline double laneAt(kernels::Double2 v) {
  return v[k];
}
#endif
template <int k, class S>
DEM_HD kernels::Vec3 laneAt3(kernels::Vec3T<S> v) {
  return {laneAt<k>(v.x), laneAt<k>(v.y), laneAt<k>(v.z)};
}

} // namespace contact_lanes

/// Pass 1 of the contact module (ContactModule::sources): its arrays (device pointers) and
/// constants, copied into the loop body.
struct OwnerPass {
  const double* x;
  const double* v;
  const double* w;
  const double* r;
  const double* m;
  const std::int32_t* mat;
  const std::int64_t* gid;
  std::int64_t* hk;
  double* hd;
  double* f;
  double* tq;
  double* fw;
  std::int32_t* nc;
  std::int32_t* nwc;
  const std::uint32_t* hs;
  const std::int32_t* half;
  unsigned char* hit;
  double* share;
  const PairProps* pairs;
  const kernels::PlaneWall* walls;
  const std::uint32_t* wallNear;
  std::size_t n;
  double dt;
  int nWalls;
  int nMat;
  int K;
  bool coupled; ///< f holds the gas force of the drag module

  /// Particle i while its contacts are evaluated: the history slots it used in the last
  /// sub-step (copied, as the new ones overwrite them) and the sums.
  struct Owner {
    long long i;
    int used; ///< slots of the last sub-step
    int slot; ///< slots written in this one
    kernels::Vec3 F, T;
    std::int64_t oldKey[kMaxHistorySlots];
    kernels::Vec3 oldD[kMaxHistorySlots];

    DEM_HD kernels::Vec3 history(std::int64_t key) const {
      for (int s = 0; s < used; ++s)
        if (oldKey[s] == key)
          return oldD[s];
      return kernels::Vec3{0.0, 0.0, 0.0};
    }
  };

  DEM_HD void remember(Owner& o, std::int64_t key, kernels::Vec3 d) const {
    if (o.slot < K) {
      hk[o.i * K + o.slot] = key;
      kernels::store3(hd, o.i * K + o.slot, d);
    }
    ++o.slot;
  }

  /// Owned candidates q0 and q1 in contact, evaluated in the lanes of S (one lane: q0 only),
  /// then added to o in that order. The LSD law (Eqs. 7–13); every lane gives the bits of
  /// the scalar evaluation.
  template <class S>
  DEM_HD_FORCEINLINE void pairGroup(Owner& o, std::uint32_t q0, std::uint32_t q1) const {
    using namespace kernels;
    using namespace contact_lanes;
    const long long ii = o.i;
    const std::int32_t j0 = half[q0];
    const std::int32_t j1 = half[q1];
    const double xi0 = x[3 * ii], xi1 = x[3 * ii + 1], xi2 = x[3 * ii + 2];
    const Vec3T<S> d =
        gather3<S>(x, j0, j1) - Vec3T<S>{pack<S>(xi0, xi0), pack<S>(xi1, xi1), pack<S>(xi2, xi2)};
    const S l2 = dot(d, d);
    const S ri = pack<S>(r[ii], r[ii]);
    const S rj = gather<S>(r, j0, j1);
    const S rsum = ri + rj;
    const S l = laneSqrt(l2);
    const S invL = 1.0 / l;
    const Vec3T<S> nrm = invL * d;
    const S deltaN = rsum - l;
    const PairProps* row = pairs + mat[ii] * nMat;
    const PairProps& p0 = row[mat[j0]];
    const PairProps& p1 = row[mat[j1]];
    const S kn = pack<S>(p0.kn, p1.kn);
    const S meff = effectiveMass(pack<S>(m[ii], m[ii]), gather<S>(m, j0, j1));
    const S etan = pack<S>(p0.dampFactor, p1.dampFactor) * laneSqrt(kn * meff);
    const LsdParamsT<S> lp{kn, pack<S>(p0.kt, p1.kt), etan,
                           pack<S>(p0.etatFactor, p1.etatFactor) * etan, pack<S>(p0.mu, p1.mu)};
    const S lij = leverArmInv(l, invL, ri, rj);
    const S lji = leverArmInv(l, invL, rj, ri);
    const Vec3T<S> vij =
        relativeVelocity(gather3<S>(v, ii, ii), gather3<S>(v, j0, j1), gather3<S>(w, ii, ii),
                         gather3<S>(w, j0, j1), lij, lji, nrm);
    const std::int64_t key0 = gid[j0];
    const std::int64_t key1 = gid[j1];
    const Vec3 h0 = o.history(key0);
    const Vec3 h1 = kLanes<S> > 1 ? o.history(key1) : h0;
    const LsdResultT<S> res = lsdContact(lp, nrm, deltaN, vij, lij, pack3<S>(h0, h1), dt);
    // j's share: force −f (applied in pass 2), torque L_ji n × f_t.
    const Vec3T<S> shareT = lji * res.nxft;
    o.F += laneAt3<0>(res.force);
    o.T += laneAt3<0>(res.torque);
    remember(o, key0, laneAt3<0>(res.deltaT));
    store3(share, 2 * static_cast<long long>(q0), laneAt3<0>(res.force));
    store3(share, 2 * static_cast<long long>(q0) + 1, laneAt3<0>(shareT));
    if constexpr (kLanes < S >> 1) {
      o.F += laneAt3<1>(res.force);
      o.T += laneAt3<1>(res.torque);
      remember(o, key1, laneAt3<1>(res.deltaT));
      store3(share, 2 * static_cast<long long>(q1), laneAt3<1>(res.force));
      store3(share, 2 * static_cast<long long>(q1) + 1, laneAt3<1>(shareT));
    }
  }

  template <class S>
  __attribute__((noinline)) void pairGroupOutOfLine(Owner& o, std::uint32_t q0,
                                                    std::uint32_t q1) const {
    pairGroup<S>(o, q0, q1);
  }

  /// Particle i: its owned pairs in contact, evaluated kLanes<S> at a time (S: lanes.h; a last
  /// single pair with the scalar code), then its walls. The sums over the pairs are taken in
  /// candidate order whatever S is. Returns the history slots i needs.
  template <class S>
  DEM_HD double particle(std::size_t i) const {
    using namespace kernels;
    constexpr int L = kLanes<S>;
    const long long ii = static_cast<long long>(i);
    // The history rows of the few particles in contact are scattered through memory:
    // ask for those of a particle kPrefetchAhead further on while this one computes.
    if (i + kPrefetchAhead < n && nc[i + kPrefetchAhead] + nwc[i + kPrefetchAhead] > 0) {
      const std::size_t a = (i + kPrefetchAhead) * static_cast<std::size_t>(K);
      backend::prefetch(hk + a);
      backend::prefetch(hd + 3 * a);
      backend::prefetch(hd + 3 * a + 8);
    }
    Owner o;
    o.i = ii;
    // Slots in use are compacted at the front: the last sub-step used nc + nwc of them
    // (format ≤ 2 states: nc counted every contact, both sides' slots are then read).
    o.used = nc[i] + nwc[i] < K ? nc[i] + nwc[i] : K;
    for (int s = 0; s < o.used; ++s) {
      o.oldKey[s] = hk[i * K + s];
      o.oldD[s] = load3(hd, ii * K + s);
    }
    o.slot = 0;
    o.F = coupled ? load3(f, ii) : Vec3{0.0, 0.0, 0.0};
    o.T = Vec3{0.0, 0.0, 0.0};
    // Particle–particle LSD over the owned candidates: those in contact are listed (up to
    // kTouchChunk at a time), then evaluated L at a time.
    const Vec3 xi = load3(x, ii);
    const double ri = r[i];
    int owned = 0;
    std::uint32_t touch[kTouchChunk];
    const std::uint32_t qEnd = hs[i + 1];
    for (std::uint32_t q = hs[i]; q < qEnd;) {
      int nt = 0;
      for (; q < qEnd && nt < kTouchChunk; ++q) {
        const std::int32_t j = half[q];
        const Vec3 d = load3(x, j) - xi;
        const double l2 = dot(d, d);
        const double rsum = ri + r[j];
        const bool touching = l2 < rsum * rsum;
        hit[q] = touching ? 1 : 0;
        if (touching)
          touch[nt++] = q;
      }
      int t = 0;
      if constexpr (L > 1) {
        for (; t + 1 < nt; t += 2)
          pairGroupOutOfLine<S>(o, touch[t], touch[t + 1]);
      }
      for (; t < nt; ++t)
        pairGroup<double>(o, touch[t], touch[t]);
      owned += nt;
    }
    // Walls (m_eff = m_i, the particle's material), in ascending order: the candidate
    // bits of the first 32 (most particles have none), then every wall beyond them.
    Vec3 FW{0.0, 0.0, 0.0};
    int wallCount = 0;
    std::uint32_t bits = wallNear[i];
    for (int k = bits != 0 ? lowestBit(bits) : 32; k < nWalls;) {
      const double deltaN = wallOverlap(walls[k], xi, ri);
      if (deltaN > 0.0) {
        const int ai = mat[i];
        const double mi = m[i];
        const PairProps pp = pairs[ai * nMat + ai];
        const double etan = pp.dampFactor * ::sqrt(pp.kn * mi);
        const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
        const std::int64_t key = -(static_cast<std::int64_t>(k) + 2);
        const LsdResult res =
            wallContact(lp, walls[k], deltaN, load3(v, ii), load3(w, ii), ri, o.history(key), dt);
        FW += res.force;
        o.T += res.torque;
        remember(o, key, res.deltaT);
        ++wallCount;
      }
      if (k < 32) {
        bits &= bits - 1;
        k = bits != 0 ? lowestBit(bits) : 32;
      } else {
        ++k;
      }
    }
    Vec3 F = o.F;
    Vec3 T = o.T;
    const int slot = o.slot;
    const int used = o.used;
    F += FW;
    for (int s = slot; s < used; ++s)
      hk[i * K + s] = -1;
    store3(f, ii, F);
    store3(tq, ii, T);
    store3(fw, ii, FW);
    nc[i] = owned;
    nwc[i] = wallCount;
    return static_cast<double>(slot);
  }
};

template <class Exec>
class ContactModule {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;
  using PairScalar = typename PairScalarOf<Exec>::type;

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
  }

  bool enabled() const { return true; }
  std::size_t bytes() const { return _pairs.bytes() + _walls.bytes() + _hit.bytes(); }
  ContactTotals totals() const { return {}; }

  /// History slots in use in some row (slots at or beyond it are empty everywhere); the
  /// neighbour rebuild moves only these.
  int usedSlots() const { return _maxUsedSlots; }
  /// After new particles: every slot may be in use.
  void resetUsedSlots(int slots) { _maxUsedSlots = slots; }

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
    const std::size_t n = p.n;
    double* f = p.force.d();
    double* tq = p.torque.d();
    std::int32_t* nc = p.contacts.d();
    std::int32_t* nwc = p.wallContacts.d();
    const std::uint32_t* ls = pl.lowStart();
    const std::uint32_t* low = pl.low();
    _hit.reserve(pl.candidates());
    unsigned char* hit = _hit.d();
    // Partner shares in the shared scratch: force (3 values), then torque (3), per candidate.
    static_assert(PairLists<Exec>::kScratchWidth >= 6);
    double* share = pl.scratch();

    // Pass 1: the owned pairs and the walls of every particle. reduceMax runs the body once
    // per index (side effects on index i only) and returns the most history slots a particle
    // needs (owned contacts + walls), in the same pass.
    const OwnerPass c{.x = p.pos.d(),
                      .v = p.vel.d(),
                      .w = p.omega.d(),
                      .r = p.radius.d(),
                      .m = p.mass.d(),
                      .mat = p.material.d(),
                      .gid = p.gid.d(),
                      .hk = p.histKey.d(),
                      .hd = p.histDisp.d(),
                      .f = f,
                      .tq = tq,
                      .fw = p.fwall.d(),
                      .nc = nc,
                      .nwc = nwc,
                      .hs = pl.halfStart(),
                      .half = pl.half(),
                      .hit = hit,
                      .share = share,
                      .pairs = _pairs.d(),
                      .walls = _walls.d(),
                      .wallNear = _wallNear.d(),
                      .n = n,
                      .dt = ctx.dt,
                      .nWalls = static_cast<int>(ctx.setup.walls.size()),
                      .nMat = ctx.setup.nMaterials,
                      .K = p.K,
                      .coupled = ctx.setup.coupled};
    ctx.exec.reduceMaxInto(
        n, [=] DEM_LAMBDA(std::size_t i) { return c.template particle<PairScalar>(i); }, 0.0,
        ctx.status + kStatusHistorySlots);

    // Pass 2: the shares of the pairs owned by the partner, in neighbour-list order.
    // Returns the largest number of contacts of a particle (pairs from both sides, walls).
    ctx.exec.reduceMaxInto(
        n,
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
  int _maxUsedSlots =
      kMaxHistorySlots; ///< max contacts of a particle in the last sub-step (≥ slots in use)
};

} // namespace coredem::dem
