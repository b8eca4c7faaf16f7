#pragma once
/// @file
/// Particle–particle and particle–wall contact forces in the DEM sub-step (docs/physics.md §2.1,
/// the contact law of `models: {contact: …}`, LSD with tangential history by default), written
/// once for every backend like engine_impl.h.
///
/// Each pair is evaluated once, by its owner: the particle with the smaller global id (gid), a
/// choice that survives re-sorting, over the engine's half and low lists (pair_lists.h). No
/// atomics; the order in which a particle's force and torque receive their terms is fixed by the
/// lists (pair_lists.h "Slabs": by slab colour, then by the index of the evaluating particle),
/// so the results do not depend on the thread count or the backend:
///   cpu (scatter): the owners run slab colour by colour (CpuExec::reduceMaxOverSlabsWide); an
///     owner i evaluates its owned candidates in contact with the contact law and adds the
///     partner's share (−f; torque L_ji n × f_t) straight to the partner's force and torque,
///     then its walls, and adds its own sum (f, L_ij n × f_t of its pairs, its walls) to its
///     own force and torque, which start at the gas force (or zero) and zero;
///   other backends (gather): pass 1 per owner writes the partner's share per candidate and
///     its own sum per particle; pass 2 per particle adds them in the same order (colours, and
///     within a colour the evaluating particle's index).
/// The cpu backend evaluates a particle's owned candidates in contact up to four at once
/// (ownedPairs): three or four in the lanes of kernels::Double4 where the processor has AVX,
/// two in the lanes of kernels::Double2 (SSE2, or AVX's encoding of the same operations), one
/// alone; every lane gives the bits of ownedPair<Law, double>, the other backends' path (no
/// FMA). The LSD law is mirror-exact (lsd_contact.h): j's share is bitwise what evaluating the
/// pair from j's side gives. Forces add the gas force of the drag module in coupled runs.
///
/// Contact laws (kernels/contact_law.h): the pair table holds the rows of the run's law, and
/// the owners' pass (OwnerContacts, SlabContacts, the pair lanes) is instantiated for every law
/// of kernels::ContactLaws; sources() picks the run's once per sub-step (kernels::visitModel),
/// so a pair costs no test of the law (with one law, no test at all).
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
///
/// The pair kernels are in contact_pairs.h, the owners' pass 1 in contact_owners.h.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "contact_owners.h"
#include "contact_pairs.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "pair_lists.h"
#include "step_module.h"
#include "wall_lists.h"

namespace coredem::dem {

/// The contact module has no ledger (counts and wall forces are read from the particles).
struct ContactTotals {};

/// Contact forces of the particles: a StepModule (step_module.h).
template <class Exec>
class ContactModule {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  void setup(const EngineSetup& s) {
    _law = s.contactLaw;
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
    const kernels::ContactPair* pairs = _pairs.d();
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

    // Pass 1 (per owner): its owned pairs and its walls (OwnerContacts), with the run's contact
    // law. The largest count of history slots a particle needs goes to the status array.
    kernels::visitModel(kernels::ContactLaws{}, static_cast<int>(_law), [&](auto law) {
      using Law = typename decltype(law)::type;
#if defined(COREDEM_DEM_DOUBLE2)
      const TwoPairArgs<Law> two{x, v, w, r, m, mat, half, pairs, hc, f, tq, nMat, dt, cpuHasAvx()};
#endif
      const OwnerContacts<Exec, Law> ownerPass {
        x, v, w, r, m, mat, hk, hd, hc, f, tq, fw, nc, nwc, hs, half, wallNear, pairs, wv, nMat, K,
            n, dt, hit, share, own
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
        const SlabContacts<Exec, Law> slabPass{ownerPass,     pl.halfOwner(), _hits.d(),  _work.d(),
                                               _dense.data(), pl.slabStart(), pl.slabs(), !coupled};
        ctx.exec.reduceMaxOverSlabRanges(pl.slabStart(), pl.slabs(), slabPass, 0.0,
                                         ctx.status + kStatusHistorySlots);
#else
        ctx.exec.reduceMaxOverSlabsWide(pl.slabStart(), pl.slabs(), ownerPass, 0.0,
                                        ctx.status + kStatusHistorySlots);
#endif
      } else {
        ctx.exec.reduceMaxInto(n, ownerPass, 0.0, ctx.status + kStatusHistorySlots);
      }
    });
    if constexpr (!scatter) {
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
  kernels::ContactLaw _law = kernels::ContactLaw::LinearSpringDashpot; ///< the run's law
  Dual<kernels::ContactPair> _pairs; ///< rows of _law, [a·nMaterials + b] (walls: [a·n + a])
  Dev<unsigned char> _hit;           ///< gather backends, per candidate: in contact this sub-step
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
