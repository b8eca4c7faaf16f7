#pragma once
/// @file
/// Particle heat transfer in the DEM sub-step (docs/physics.md §3, Eq. 18; docs/architecture.md),
/// written once for every backend like engine_impl.h. Per sub-step, after the contact forces and
/// the drag deposition (which leaves the particles sorted by PCM cell):
///   1. cell means of T_p for the radiation environment (§3.4 (a), including the particle)
///   2. pair terms once per pair by its owner over the half lists, the partner's share added in
///      a fixed order (pair_lists.h "Slabs", no atomics): contact conduction (Eqs. 22–23) and
///      gas-lens conduction (Eqs. 24–26); then per particle convection with the gas of its PCM cell
///      (Eqs. 19–21) and radiation (Eqs. 27–28); the sum Q_i (W) is stored
///   3. per cell: H = Σ G_i/V_c, H_Tp = Σ G_i T_i/V_c (G_i = h_i A_i) and Σ Q_rad,i/V_c, added
///      to the window accumulators (averaged over the sub-steps at the window end; the radiation
///      sum, negated, is the Sources array Q_rad: the heat the gas receives with protocol 1.3)
///   4. after the motion update: T_i += Δt Q_i/(m_i c_p,i) (explicit Euler, Eq. 18)
/// At the start of a window whose gas fields carry a heat split (protocol 1.5 Q_split, J/m³ of
/// V_c: what the gas removed in its last step beyond what the DEM booked), giveHeatSplit() gives
/// R_c = Q_split[c] V_c to the particles of cell c in proportion to their gas conductance G_i of
/// the window start (all zero: to m_i c_p,i), T_i += R_i/(m_i c_p,i); R_c of an occupied cell is
/// booked in HeatTotals::convection, of an empty one in HeatTotals::splitUnassigned.
/// Fixed-temperature walls (HeatSetup::walls, kernels/wall_conduction.h) add their contact and
/// gas-lens conduction to Q_i in step 2; their heat Σ_i Q_w,i Δt is summed in kWallSlots fixed
/// slots per sub-step (deterministic) and booked in HeatTotals::wall at the window end.
/// Heat sources are evaluated on the configuration and temperatures of the contact forces
/// (start of the sub-step), as MFiX does (CALC_THERMO_DES before CFNEWVALUES), so that the
/// neighbour list is exact for them and they share the PCM cells of the drag deposition.
///
/// Pair terms: the owner (smaller global id, the canonical first argument of the pair kernels)
/// evaluates G_ab (T_b − T_a) once and its partner subtracts the stored value: Q_ab = −Q_ba
/// exactly on every backend, whatever the evaluation order or FMA contraction.

#include <cstdint>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "coredem/dem/kernels/conduction_contact.h"
#include "coredem/dem/kernels/conduction_gas_lens.h"
#include "coredem/dem/kernels/convection.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/particle_energy.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/radiation.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_conduction.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "heat_setup.h"
#include "pair_lists.h"
#include "step_module.h"

// The heat passes' loop bodies are large: without this GCC calls them once per particle from
// the OpenMP loop, reloading every capture each time (host builds only; nvcc inlines anyway).
#if defined(__CUDACC__)
#define COREDEM_HEAT_INLINE
#else
#define COREDEM_HEAT_INLINE __attribute__((always_inline))
#endif

namespace coredem::dem {

/// κ_g of a pair (W/(m K)): the mean of the two PCM cells' (a particle outside the grid uses the
/// other's; both outside: 0) [C]; `same` is the owner's 0.5 (κ_lo + κ_lo) (its cell's, or 0).
DEM_HD double pairGasConductivity(const double* kap, std::uint32_t clo, std::uint32_t chi,
                                  std::uint32_t nCells, double same) {
  if (chi == clo)
    return same;
  if (clo < nCells && chi < nCells)
    return 0.5 * (kap[clo] + kap[chi]);
  if (clo < nCells)
    return kap[clo];
  if (chi < nCells)
    return kap[chi];
  return 0.0;
}

/// Partial-sum slots of the wall heat (fixed count, so the sum order does not depend on threads).
constexpr std::size_t kWallSlots = 64;

/// Heat transfer of the particles: a StepModule (step_module.h) with the ledger HeatTotals.
template <class Exec>
class HeatModule {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  static constexpr double StageTimes::*kStage = &StageTimes::heat;

  void setup(const EngineSetup& s) { setup(s.heat, s.coupled ? s.nCells : 0); }
  void setup(const HeatSetup& h, std::size_t nCells) {
    _h = h;
    _on = HeatTerms::of(h, nCells > 0);
    _mat.allocate(h.materials.size());
    for (std::size_t k = 0; k < h.materials.size(); ++k)
      _mat.h()[k] = h.materials[k];
    _mat.markHostModified();
    _mat.toDevice();
    if (h.walls.enabled) {
      _wallAcc.allocate(kWallSlots);
      for (std::size_t k = 0; k < kWallSlots; ++k)
        _wallAcc.h()[k] = 0.0;
      _wallAcc.markHostModified();
      _wallAcc.toDevice();
    }
    if (nCells > 0) {
      _splitGiven.allocate(nCells);
      _acc.allocate(3 * nCells);
      for (std::size_t k = 0; k < 3 * nCells; ++k)
        _acc.h()[k] = 0.0;
      _acc.markHostModified();
      _acc.toDevice();
      _cellT.reserve(nCells);
    }
  }

  bool enabled() const { return _on.enabled; }
  void readStatus(const double*, const ParticleStore<Exec>&) {}

  std::size_t bytes() const {
    return _mat.bytes() + _q.bytes() + _g.bytes() + _qrad.bytes() + _cellT.bytes() + _acc.bytes() +
           _qw.bytes() + _wallAcc.bytes() + _convFactors.bytes() + _splitGiven.bytes();
  }

  /// Heat the particles received since construction (or the restored totals).
  const HeatTotals& totals() const { return _totals; }
  /// Continues the ledger of a state file.
  void restoreTotals(const HeatTotals& t) { _totals = t; }

  void beginWindow(StepContext<Exec>& ctx) {
    const std::size_t nCells = ctx.setup.coupled ? ctx.setup.nCells : 0;
    if (!_on.enabled || nCells == 0)
      return;
    double* acc = _acc.d();
    ctx.exec.parallelFor(3 * nCells, [=] DEM_LAMBDA(std::size_t k) { acc[k] = 0.0; });
    _acc.markDeviceModified();
    // The Nusselt factors of every cell (ε frozen, gas fixed for the window): once per window.
    const GasFields<Exec>* gf = ctx.gas;
    _convFactorsValid = gf != nullptr && _on.convection && gf->has(gf->Tg) && gf->has(gf->kappaG) &&
                        gf->has(gf->cpG);
    if (_convFactorsValid) {
      _convFactors.reserve(nCells);
      kernels::NusseltFactors* nf = _convFactors.d();
      const kernels::ConvectionParams cp = _h.convectionParams;
      const double* eps = ctx.cells.epsFrozen();
      const double* rhoG = gf->rhoG.d();
      const double* muG = gf->muG.d();
      const double* kap = gf->kappaG.d();
      const double* cpg = gf->cpG.d();
      const double* tg = gf->Tg.d();
      ctx.exec.parallelFor(nCells, [=] DEM_LAMBDA(std::size_t c) {
        const kernels::GasState gs{rhoG[c], muG[c], kap[c], cpg[c], tg[c], eps[c]};
        nf[c] = kernels::nusseltFactors(cp, gs);
      });
    }
  }

  /// The heat split of the window's gas fields (GasFields::heatSplit, J/m³ of V_c) into the
  /// particles, after beginWindow (cells frozen and sorted, Nusselt factors of the window): per
  /// occupied cell c (one segment head each, its particles in the sorted order) R_c =
  /// Q_split[c] V_c, split in proportion to G_i = h_i A_i of the window start (convection with
  /// the window's gas and the particle's slip; 0 when convection is off or lacks its fields) or,
  /// when every G_i of the cell is 0, to m_i c_p,i; T_i += R_i/(m_i c_p,i). Each particle is
  /// written by its cell's head only: deterministic on every backend. Books the totals (host).
  /// Writes _g (G_i), temperature, _splitGiven.
  HeatSplitBooking giveHeatSplit(StepContext<Exec>& ctx) {
    HeatSplitBooking b;
    const GasFields<Exec>* gf = ctx.gas;
    const EngineSetup& s = ctx.setup;
    if (!s.coupled || gf == nullptr || !gf->has(gf->heatSplit))
      return b;
    Exec& exec = ctx.exec;
    ParticleStore<Exec>& p = ctx.particles;
    const std::size_t n = p.n;
    const std::uint32_t nCells = static_cast<std::uint32_t>(s.nCells);
    double* given = _splitGiven.d();
    exec.parallelFor(s.nCells, [=] DEM_LAMBDA(std::size_t c) { given[c] = 0.0; });
    if (n > 0) {
      _g.reserve(n);
      const ActiveTerms on = activeTerms(gf);
      splitConductances(ctx, on.conv && _convFactorsValid);
      const std::uint32_t* pcell = ctx.cells.pcell();
      const std::uint32_t* perm = ctx.cells.perm();
      const std::uint32_t* cs = ctx.cells.cStart();
      const std::uint32_t* ce = ctx.cells.cEnd();
      const double* qs = gf->heatSplit.d();
      const double* g = _g.d();
      const double* m = p.mass.d();
      const std::int32_t* mat = p.material.d();
      const HeatMaterial* hm = _mat.d();
      double* T = p.temperature.d();
      const double vc = s.cellVolume;
      exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t h) {
        const std::uint32_t c = pcell[perm[h]];
        if (c >= nCells || (h > 0 && pcell[perm[h - 1]] == c))
          return;
        const double rc = qs[c] * vc;
        given[c] = rc;
        if (rc == 0.0)
          return;
        double sumG = 0.0, sumC = 0.0;
        for (std::uint32_t k = cs[c]; k < ce[c]; ++k) {
          const std::uint32_t i = perm[k];
          sumG += g[i];
          sumC += m[i] * hm[mat[i]].cp;
        }
        const bool byConductance = sumG > 0.0;
        for (std::uint32_t k = cs[c]; k < ce[c]; ++k) {
          const std::uint32_t i = perm[k];
          const double mc = m[i] * hm[mat[i]].cp;
          const double share = byConductance ? g[i] / sumG : mc / sumC;
          T[i] = T[i] + (rc * share) / mc;
        }
      });
      p.produced(kTemperature);
    }
    _splitGiven.markDeviceModified();
    _splitGiven.toHost();
    const double* givenH = _splitGiven.h();
    const double* qH = gf->heatSplit.h();
    for (std::size_t c = 0; c < s.nCells; ++c) {
      if (givenH[c] != 0.0) {
        b.given += givenH[c];
      } else if (qH[c] != 0.0) {
        b.unassigned += qH[c] * s.cellVolume;
        if (b.firstUnassignedCell < 0)
          b.firstUnassignedCell = static_cast<std::int64_t>(c);
        ++b.unassignedCells;
      }
    }
    _totals.convection += b.given;
    _totals.splitUnassigned += b.unassigned;
    return b;
  }

  /// giveHeatSplit's G_i = h_i A_i of every particle in a cell (0 outside the grid and when
  /// `conv` is false), as particleRates() evaluates it. Writes _g.
  void splitConductances(StepContext<Exec>& ctx, bool conv) {
    const std::size_t n = ctx.particles.n;
    double* gOut = _g.d();
    if (!conv) {
      ctx.exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) { gOut[i] = 0.0; });
      return;
    }
    const GasFields<Exec>* gf = ctx.gas;
    const std::uint32_t nCells = static_cast<std::uint32_t>(ctx.setup.nCells);
    const std::uint32_t* pcell = ctx.cells.pcell();
    const double* eps = ctx.cells.epsFrozen();
    const kernels::NusseltFactors* nf = _convFactors.d();
    const kernels::ConvectionParams cp = _h.convectionParams;
    const double* ug = gf->ug.d();
    const double* rhoG = gf->rhoG.d();
    const double* muG = gf->muG.d();
    const double* kap = gf->kappaG.d();
    const double* cpg = gf->cpG.d();
    const double* tg = gf->Tg.d();
    const double* v = ctx.particles.vel.d();
    const double* r = ctx.particles.radius.d();
    const double* T = ctx.particles.temperature.d();
    ctx.exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      const std::uint32_t c = pcell[i];
      if (c >= nCells) {
        gOut[i] = 0.0;
        return;
      }
      const double slip = norm(load3(ug, c) - load3(v, static_cast<long long>(i)));
      const GasState gs{rhoG[c], muG[c], kap[c], cpg[c], tg[c], eps[c]};
      gOut[i] = convectionFromFactors(cp, nf[c], gs, 2.0 * r[i], slip, T[i]).conductance;
    });
  }

  /// The terms this sub-step evaluates: the options, and the gas fields the CFD sent.
  struct ActiveTerms {
    bool coupled; ///< gas fields present (ctx.gas: set, with a coupling grid)
    bool hasTg, hasKappa, hasCp;
    bool conv, rad, lens, contact;
  };
  ActiveTerms activeTerms(const GasFields<Exec>* gasFields) const {
    ActiveTerms a{};
    a.coupled = gasFields != nullptr;
    a.hasTg = a.coupled && gasFields->has(gasFields->Tg);
    a.hasKappa = a.coupled && gasFields->has(gasFields->kappaG);
    a.hasCp = a.coupled && gasFields->has(gasFields->cpG);
    a.conv = a.coupled && _on.convection && a.hasTg && a.hasKappa && a.hasCp;
    a.rad = a.coupled && _on.radiation && a.hasTg;
    a.lens = a.coupled && _on.lensConduction && a.hasKappa;
    a.contact = _on.contactConduction;
    return a;
  }

  /// Heat sources of one sub-step. When coupled, the particles are sorted by PCM cell
  /// (ctx.cells) as the drag module leaves them.
  /// Reads pos, vel, radius, temperature, material, the pair lists; writes _q, _g, _qrad,
  /// _acc.
  void sources(StepContext<Exec>& ctx) {
    if (!_on.enabled)
      return;
    const std::size_t n = ctx.particles.n;
    _q.reserve(n);
    _g.reserve(n);
    _qrad.reserve(n);
    const ActiveTerms on = activeTerms(ctx.gas); // ctx.gas nullptr: no gas fields or no grid
    if (on.conv && !_convFactorsValid) {
      backend::raiseUserError("internal: heat sources without the window's Nusselt factors "
                              "(beginWindow was not called after the gas fields were set)");
    }
    if (on.rad)
      cellTemperatures(ctx);
    if (_h.walls.enabled) {
      ctx.walls.ensure(ctx.exec, ctx.particles, ctx.pairs.generation(), ctx.setup.skin);
      _qw.reserve(n);
    }
    if (on.contact || on.lens)
      pairTerms(ctx, on);
    particleRates(ctx, on);
    if (_h.walls.enabled)
      wallHeat(ctx);
    if (ctx.setup.coupled)
      cellSources(ctx);
  }

  // The passes of sources(), in their order (public: nvcc's extended lambdas may not live in
  // private member functions).

  /// 1. Σ T_p per cell (radiation environment, variant (a)). Writes _cellT.
  void cellTemperatures(StepContext<Exec>& ctx) {
    Exec& exec = ctx.exec;
    const std::size_t n = ctx.particles.n;
    const std::uint32_t nCells = static_cast<std::uint32_t>(ctx.setup.nCells);
    const std::uint32_t* pcell = ctx.cells.pcell();
    const std::uint32_t* perm = ctx.cells.perm();
    const std::uint32_t* cStart = ctx.cells.cStart();
    const std::uint32_t* cEnd = ctx.cells.cEnd();
    double* cellT = _cellT.d();
    const double* T = ctx.particles.temperature.d();
    // Occupied cells only (one segment head each); cellT is read only at a particle's cell.
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t h) {
      const std::size_t c = pcell[perm[h]];
      if (c >= nCells || (h > 0 && pcell[perm[h - 1]] == c))
        return;
      double sum = 0.0;
      for (std::uint32_t k = cStart[c]; k < cEnd[c]; ++k)
        sum += T[perm[k]];
      cellT[c] = sum;
    });
  }

  /// 2a. Pair terms, each pair once by its owner (the smaller global id, which is also the
  ///     canonical "lo" of the pair kernels) over the half lists (pair_lists.h): the owner
  ///     keeps +Q_ab (heat into lo = G (T_hi − T_lo)) and gives −Q_ab to the partner. Q_ab =
  ///     −Q_ba exactly. Each particle's pair sums (contact, lens) receive their terms in the
  ///     order of pair_lists.h "Slabs" (by colour, then by the evaluating particle's index;
  ///     its own sum at its own index): the cpu backend (scatter) runs the owners slab colour
  ///     by colour and subtracts Q_ab from the partner's sums directly; the gather backends
  ///     write Q_ab to the per-candidate scratch at the partner's low-list position (0 when
  ///     the pair is out of reach) and the owner's sums to qOwn, lOwn, and 2b adds them up in
  ///     that order.
  void pairTerms(StepContext<Exec>& ctx, const ActiveTerms& on) {
    Exec& exec = ctx.exec;
    ParticleStore<Exec>& p = ctx.particles;
    const std::size_t n = p.n;
    const bool lens = on.lens;
    const bool contact = on.contact;
    const std::uint32_t nCells = static_cast<std::uint32_t>(ctx.setup.nCells);
    const std::uint32_t* pcell = ctx.cells.pcell();
    const double* x = p.pos.d();
    const double* r = p.radius.d();
    const double* T = p.temperature.d();
    const std::int32_t* mat = p.material.d();
    const HeatMaterial* hm = _mat.d();
    const double* kap = on.hasKappa ? ctx.gas->kappaG.d() : nullptr;
    const kernels::GasLensParams lp = _h.lensParams;
    const double lensFactor = 1.0 + lp.lensFraction;
    constexpr bool scatter = kScatter<Exec>;
    PairLists<Exec>& pl = ctx.pairs;
    const std::uint32_t* hs = pl.halfStart();
    const std::int32_t* half = pl.half();
    const std::uint32_t* lowPos = pl.lowPos();
    static_assert(PairLists<Exec>::kScratchWidth >= 2);
    double* share = pl.scratch(); // per candidate: Q_ab contact, Q_ab lens (W)
    double* qOwn = _q.d(); // pair sums, contact and lens (scatter: complete; gather: the owner's)
    double* lOwn = _g.d(); //   in _q and _g until 2b
    if constexpr (scatter) {
      exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        qOwn[i] = 0.0;
        lOwn[i] = 0.0;
      });
    }
    auto ownerPass = [=] DEM_LAMBDA(std::size_t i) COREDEM_HEAT_INLINE {
      using namespace kernels;
      (void)share, (void)lowPos, (void)qOwn, (void)lOwn; // nvcc: captured outside if constexpr
      const long long lo = static_cast<long long>(i);
      const Vec3 xlo = load3(x, lo);
      const double rlo = r[lo];
      const double tlo = T[lo];
      const std::int32_t mlo = mat[lo];
      const double klo = hm[mlo].k;
      const std::uint32_t clo = lens ? pcell[lo] : nCells;
      // The owner's invariants. Partners of the same radius (a monodisperse bed: all) take
      // the equal-radii kernels (conduction_contact.h: within 2^-52 of the exact contact
      // radius; conduction_gas_lens.h: within kGasLensEqualRadiiRelDiff of the general lens
      // form); of the same material, the owner's contact conductivity; in the same PCM cell,
      // its κ_g (both bitwise as before).
      const double kcSame = contactConductivity(klo, klo);
      const bool kSamePos = klo + klo > 0.0;
      const double kgSame = clo < nCells ? 0.5 * (kap[clo] + kap[clo]) : 0.0;
      const double reachSame = lens ? lensFactor * rlo + rlo : rlo + rlo;
      const double reachSame2 = reachSame * reachSame;
      const double twoR = rlo + rlo;
      const GasLensEqualRadii lensSame = gasLensEqualRadii(lp, rlo);
      double qc = 0.0, ql = 0.0;
      const std::uint32_t qEnd = hs[i + 1];
      for (std::uint32_t q = hs[i]; q < qEnd; ++q) {
        const long long hi = half[q];
        double qcab = 0.0, qlab = 0.0;
        const Vec3 d = load3(x, hi) - xlo;
        const double l2 = dot(d, d);
        const double rhi = r[hi];
        if (rhi == rlo) {
          // Same radius: the equal-radii kernels and the owner's reach.
          if (l2 < reachSame2) {
            const double l = ::sqrt(l2);
            const double dT = T[hi] - tlo; // heat into lo = G (T_hi − T_lo)
            if (contact && l < twoR) {
              const std::int32_t mhi = mat[hi];
              const double rc = l >= rlo ? intersectionCircleRadiusEqual(rlo, l)
                                         : intersectionCircleRadius(rlo, rlo, l);
              if (mhi == mlo) {
                if (kSamePos)
                  qcab = (kcSame * rc) * dT;
              } else {
                const double khi = hm[mhi].k;
                if (klo + khi > 0.0)
                  qcab = (contactConductivity(klo, khi) * rc) * dT;
              }
            }
            if (lens) {
              const double kg = pairGasConductivity(kap, clo, pcell[hi], nCells, kgSame);
              if (kg > 0.0)
                qlab = kg * gasLensIntegralEqualRadii(lp, lensSame, l) * dT;
            }
          }
        } else {
          const double big = rlo > rhi ? rlo : rhi;
          const double small = rlo > rhi ? rhi : rlo;
          const double reach = lens ? lensFactor * big + small : rlo + rhi;
          if (l2 < reach * reach) {
            const double l = ::sqrt(l2);
            const double dT = T[hi] - tlo;
            if (contact && l < rlo + rhi) {
              const double khi = hm[mat[hi]].k;
              if (klo + khi > 0.0)
                qcab = contactConductance(klo, khi, rlo, rhi, l) * dT;
            }
            if (lens) {
              const double kg = pairGasConductivity(kap, clo, pcell[hi], nCells, kgSame);
              if (kg > 0.0)
                qlab = kg * gasLensIntegral(lp, rlo, rhi, l).value * dT;
            }
          }
        }
        qc += qcab;
        ql += qlab;
        if constexpr (kScatter<Exec>) {
          qOwn[hi] -= qcab;
          lOwn[hi] -= qlab;
        } else {
          const std::size_t kq = lowPos[q]; // the partner's slot for its share
          share[2 * kq] = qcab;
          share[2 * kq + 1] = qlab;
        }
      }
      if constexpr (kScatter<Exec>) { // after the terms of the particles before it
        qOwn[i] += qc;
        lOwn[i] += ql;
      } else {
        qOwn[i] = qc;
        lOwn[i] = ql;
      }
      return 0.0;
    };
    if constexpr (scatter) {
      exec.reduceMaxOverSlabsWide(pl.slabStart(), pl.slabs(), ownerPass, 0.0, &_unused);
    } else {
      exec.parallelFor(n, ownerPass);
    }
  }

  /// 2b. Per-particle heat rate: the pair sums of 2a (gather backends: the owner's sums and
  ///     −Q_ab of the pairs the partners own, in the slab order), convection with the gas of
  ///     the PCM cell, radiation, walls. Writes _q, _g, _qrad, _qw.
  void particleRates(StepContext<Exec>& ctx, const ActiveTerms& on) {
    Exec& exec = ctx.exec;
    ParticleStore<Exec>& p = ctx.particles;
    const EngineSetup& s = ctx.setup;
    const std::size_t n = p.n;
    const GasFields<Exec>* gasFields = ctx.gas;
    const bool coupled = on.coupled;
    const bool conv = on.conv, rad = on.rad, lens = on.lens, contact = on.contact;
    const kernels::NusseltFactors* convFactors = conv ? _convFactors.d() : nullptr;
    const std::uint32_t nCells = static_cast<std::uint32_t>(s.nCells);
    const std::uint32_t* pcell = ctx.cells.pcell();
    const double* epsFrozen = s.coupled ? ctx.cells.epsFrozen() : nullptr;
    const double* ug = coupled ? gasFields->ug.d() : nullptr;
    const double* rhoG = coupled ? gasFields->rhoG.d() : nullptr;
    const double* muG = coupled ? gasFields->muG.d() : nullptr;
    const double* cellT = _cellT.d();
    const double* T = p.temperature.d();
    const double* x = p.pos.d();
    const double* v = p.vel.d();
    const double* r = p.radius.d();
    const std::int32_t* mat = p.material.d();
    const HeatMaterial* hm = _mat.d();
    const double* tg = on.hasTg ? gasFields->Tg.d() : nullptr;
    const double* kap = on.hasKappa ? gasFields->kappaG.d() : nullptr;
    const double* cpg = on.hasCp ? gasFields->cpG.d() : nullptr;
    double* q = _q.d();
    double* gOut = _g.d();
    double* qr = _qrad.d();
    const kernels::ConvectionParams cp = _h.convectionParams;
    const std::uint32_t* cs = ctx.cells.cStart();
    const std::uint32_t* ce = ctx.cells.cEnd();
    const bool thermalWalls = _h.walls.enabled;
    const ThermalWalls tw = _h.walls;
    const WallView wv = ctx.walls.view();
    const std::uint32_t* wallNear = thermalWalls ? ctx.walls.near() : nullptr;
    const kernels::WallConductionParams wp = _h.wallParams;
    const bool wallLens = wp.lens && coupled && on.hasKappa;
    // A wall is reached within R (contact) or (1 + FLPC) R (lens).
    const double wallReach = wallLens ? 1.0 + wp.lensFraction : 1.0;
    double* qwOut = thermalWalls ? _qw.d() : nullptr;
    PairLists<Exec>& pl = ctx.pairs;
    const std::uint32_t* ls = pl.lowStart();
    const std::uint32_t* lowOwner = pl.lowOwner();
    const std::uint8_t* colour = pl.colour();
    double* share = pl.scratch(); // 2a's per-candidate Q_ab (gather backends)
    double* qOwn = _q.d();        // 2a's pair sums, contact and lens
    double* lOwn = _g.d();
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) COREDEM_HEAT_INLINE {
      using namespace kernels;
      (void)share, (void)ls, (void)lowOwner, (void)colour, (void)qOwn, (void)lOwn; // nvcc, as 2a
      const long long ii = static_cast<long long>(i);
      const double ti = T[i];
      const HeatMaterial mi = hm[mat[i]];
      const std::uint32_t celli = coupled ? pcell[i] : nCells;
      ParticleHeatSources src;
      if (contact || lens) {
        if constexpr (kScatter<Exec>) {
          src.contactConduction = qOwn[i];
          src.lensConduction = lOwn[i];
        } else { // the scatter's order: by colour, then by the evaluating particle's index
          double qc = 0.0, ql = 0.0;
          inSlabOrder(
              i, true, ls, lowOwner, colour,
              [&] {
                qc += qOwn[i];
                ql += lOwn[i];
              },
              [&](std::uint32_t k) {
                qc -= share[2 * static_cast<std::size_t>(k)];
                ql -= share[2 * static_cast<std::size_t>(k) + 1];
              });
          src.contactConduction = qc;
          src.lensConduction = ql;
        }
      }
      double g = 0.0;
      if (celli < nCells && (conv || rad)) {
        const double eps = epsFrozen[celli];
        if (conv) {
          const double slip = norm(load3(ug, celli) - load3(v, ii));
          const GasState gs{rhoG[celli], muG[celli], kap[celli], cpg[celli], tg[celli], eps};
          const ConvectionResult cr =
              convectionFromFactors(cp, convFactors[celli], gs, 2.0 * r[i], slip, ti);
          g = cr.conductance;
          src.convection = cr.heat;
        }
        if (rad && mi.emissivity > 0.0) {
          const int count = static_cast<int>(ce[celli] - cs[celli]);
          const double tEnv = radiationEnvironmentTemperature(eps, tg[celli], cellT[celli], count);
          src.radiation = radiationHeat(mi.emissivity, 2.0 * r[i], tEnv, ti);
        }
      }
      double qw = 0.0;
      if (thermalWalls) {
        // The touches the contact module finds (wall_lists.h), within the lens's reach; each
        // conducts as a plane at the touch's distance (kernels/wall_conduction.h).
        const std::uint32_t nearBits = wallNear[i];
        if (nearBits != 0) {
          const Vec3 xi = load3(x, ii);
          const double kgw = (wallLens && celli < nCells) ? kap[celli] : 0.0;
          wv.touches(nearBits, i, xi, wallReach * r[i], [&](double h, Vec3, std::int64_t) {
            qw += wallConductionHeat(wp, mi.k, tw.k, kgw, r[i], h, tw.temperature, ti);
          });
        }
        qwOut[i] = qw;
      }
      q[i] = particleHeatRate(src) + qw;
      gOut[i] = g;
      qr[i] = src.radiation;
    });
  }

  /// Wall heat of this sub-step, in kWallSlots fixed partial sums (J). Writes _wallAcc.
  void wallHeat(StepContext<Exec>& ctx) {
    Exec& exec = ctx.exec;
    const std::size_t n = ctx.particles.n;
    const double dt = ctx.dt;
    double* wa = _wallAcc.d();
    const double* qwIn = _qw.d();
    exec.parallelFor(kWallSlots, [=] DEM_LAMBDA(std::size_t sl) {
      const std::size_t lo = n * sl / kWallSlots, hi = n * (sl + 1) / kWallSlots;
      double sum = 0.0;
      for (std::size_t i = lo; i < hi; ++i)
        sum += qwIn[i];
      wa[sl] += sum * dt;
    });
    _wallAcc.markDeviceModified();
  }

  /// 4. Cell sources (gather per cell in the PCM order the drag module sorted). Writes _acc.
  void cellSources(StepContext<Exec>& ctx) {
    Exec& exec = ctx.exec;
    const EngineSetup& s = ctx.setup;
    const std::size_t n = ctx.particles.n;
    const std::uint32_t nCells = static_cast<std::uint32_t>(s.nCells);
    const std::uint32_t* pcell = ctx.cells.pcell();
    const std::uint32_t* perm = ctx.cells.perm();
    const std::uint32_t* cs = ctx.cells.cStart();
    const std::uint32_t* ce = ctx.cells.cEnd();
    const double* T = ctx.particles.temperature.d();
    const double* gOut = _g.d();
    const double* qr = _qrad.d();
    double* acc = _acc.d();
    const double invVc = 1.0 / s.cellVolume;
    // Occupied cells only: one segment head each, same order as a loop over all cells.
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t h) {
      const std::size_t c = pcell[perm[h]];
      if (c >= nCells || (h > 0 && pcell[perm[h - 1]] == c))
        return;
      kernels::ConvectionCellSource cellSrc;
      double rs = 0.0;
      for (std::uint32_t k = cs[c]; k < ce[c]; ++k) {
        const std::uint32_t i = perm[k];
        kernels::addConvectionToCell(cellSrc, gOut[i], T[i], invVc);
        rs += qr[i];
      }
      acc[3 * c] += cellSrc.H;
      acc[3 * c + 1] += cellSrc.HTp;
      acc[3 * c + 2] += rs * invVc;
    });
    _acc.markDeviceModified();
  }

  /// After the motion update: T_i += Δt Q_i/(m_i c_p,i) (Eq. 18, explicit Euler).
  /// Reads _q, mass, material; writes temperature.
  void update(StepContext<Exec>& ctx) {
    if (!_on.enabled)
      return;
    Exec& exec = ctx.exec;
    ParticleStore<Exec>& p = ctx.particles;
    const double dt = ctx.dt;
    const double* q = _q.d();
    const double* m = p.mass.d();
    const std::int32_t* mat = p.material.d();
    const HeatMaterial* hm = _mat.d();
    double* T = p.temperature.d();
    exec.parallelFor(
        p.n, [=] DEM_LAMBDA(std::size_t i) { T[i] = T[i] + dt * (q[i] / (m[i] * hm[mat[i]].cp)); });
    p.produced(kTemperature);
  }

  /// Averages the heat sources over nSub sub-steps into out.heatH / out.heatHTp / out.qRad
  /// (already sized) and adds the window's energies to the totals (host). The heat from the gas
  /// is booked over Δt_CFD, Σ_c (H T_g − H_Tp) V_c Δt_CFD, exactly as the CFD side books its
  /// loss, so that the two ledgers cancel to round-off (balance.heat_residual_J). The radiation
  /// the particles received, ⟨Σ_i Q_rad,i⟩ Δt_CFD, is booked in HeatTotals::radiation; out.qRad
  /// is its negative per cell and V_c (the heat the gas receives with protocol 1.3).
  void endWindow(WindowContext<Exec>& w) {
    const EngineSetup& s = w.setup;
    CellSources& out = w.out;
    const int nSub = w.nSub;
    if (_on.enabled && _h.walls.enabled) {
      _wallAcc.toHost();
      double wall = 0.0;
      for (std::size_t k = 0; k < kWallSlots; ++k) {
        wall += _wallAcc.h()[k];
        _wallAcc.h()[k] = 0.0;
      }
      _wallAcc.markHostModified();
      _wallAcc.toDevice();
      _totals.wall += wall;
    }
    if (!_on.enabled || !s.coupled)
      return;
    _acc.toHost();
    const double* acc = _acc.h();
    const double avg = 1.0 / static_cast<double>(nSub);
    const double window = w.dtSub * nSub;
    const double* tg = (w.gas != nullptr && w.gas->has(w.gas->Tg)) ? w.gas->Tg.h() : nullptr;
    double conv = 0.0, rad = 0.0;
    for (std::size_t c = 0; c < s.nCells; ++c) {
      out.heatH[c] = acc[3 * c] * avg;
      out.heatHTp[c] = acc[3 * c + 1] * avg;
      if (tg != nullptr)
        conv += out.heatH[c] * tg[c] - out.heatHTp[c];
      const double received = acc[3 * c + 2] * avg; // W/m³ into the cell's particles
      rad += received;
      out.qRad[c] = -received;
    }
    _totals.convection += conv * s.cellVolume * w.dtCfd;
    _totals.radiation += rad * s.cellVolume * window;
  }

private:
  HeatSetup _h;
  HeatTerms _on; ///< what this run evaluates (from _h.options and the run)
  Dual<HeatMaterial> _mat;
  Dev<double> _q, _g, _qrad; ///< per particle: Q_i (W), G_i (W/K), Q_rad,i (W)
  double _unused = 0.0;      ///< the pair pass's reduction result (cpu slabs), not read
  Dev<double> _cellT;        ///< per cell: Σ T_p (radiation environment)
  Dual<double> _acc;         ///< per cell: Σ_sub H, Σ_sub H_Tp, Σ_sub Q_rad/V_c
  Dev<double> _qw;           ///< per particle: Q_wall,i (W)
  Dual<double> _wallAcc;     ///< kWallSlots partial sums of Σ_sub Σ_i Q_wall,i Δt (J)
  Dev<kernels::NusseltFactors> _convFactors; ///< per cell: Nusselt factors of the window
  Dual<double> _splitGiven; ///< per cell: R_c given to its particles (0: none) (giveHeatSplit)
  bool _convFactorsValid = false;
  HeatTotals _totals;
};

} // namespace coredem::dem
