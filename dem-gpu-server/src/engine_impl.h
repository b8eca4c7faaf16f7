#pragma once
/// @file
/// The DEM engine, written once and instantiated per backend (cpu: backend/cpu/cpu_engine.cpp,
/// cuda: backend/cuda/cuda_engine.cu). All loops are Exec::parallelFor over particles or
/// cells; each index writes only its own outputs (full neighbour lists, gather, no atomics),
/// so results are deterministic and independent of the thread count.
///
/// Sub-step (DESIGN §4 step order, symplectic Euler):
///   1. neighbour lists rebuilt if a particle moved more than skin/2 since the last build
///      (cell keys → stable sort → particles reordered → 27-cell search)
///   2. forces: gas (PCM cell: Gidaspow drag, −V_p∇p), particle–particle LSD, walls
///   3. cell sources deposited (PCM, sorted by cell, gathered per cell)
///   3b. heat sources on the same configuration: conduction, lens, convection, radiation,
///      H and H_Tp deposited (heat.h; the lens widens the neighbour cut-off by EngineSetup::reach)
///   4. motion: v += Δt (F/m + g), ω += Δt T/I, x += Δt v
///   5. temperatures: T += Δt Q/(m c_p) (heat.h)
/// Why symplectic Euler: one force evaluation per step (the cost is all in the forces), it is
/// MFiX's default DEM integrator, it is second order in x for conservative forces (leapfrog),
/// and for the velocity-dependent LSD law velocity Verlet (LIGGGHTS) gave the same rebound
/// ratios in a binary-collision check (docs/performance.md "Integrator").

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "engine.h"
#include "gas_fields.h"
#include "heat.h"
#include "chemistry.h"
#include "particle_store.h"

#include "coredem/dem/kernels/body_force.h"
#include "coredem/dem/kernels/cell_sources.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/drag_gidaspow.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/kernels/wall_contact.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>

namespace coredem::dem {

/// Compile-time bound on history slots (local arrays in the contact kernel).
constexpr int kMaxHistorySlots = 32;
constexpr std::uint32_t kEmptyCell = 0xffffffffu;
/// Columns moved per pass when particles are reordered (scratch = N·4 doubles).
constexpr int kReorderBlock = 4;

template <class Exec>
class EngineImpl final : public Engine {
public:
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  using Clock = std::chrono::steady_clock;

  EngineSetup _s;
  Exec _exec;
  ParticleStore<Exec> _p;
  Dual<PairProps> _pairs;
  Dual<kernels::PlaneWall> _walls;
  GasFields<Exec> _gas;  ///< per-cell gas fields of the CFD step, shared with _heat and _chem
  bool _hasGas = false;
  Dual<double> _epsFrozen;  // nCells: PCM ε_g at the window start (drag)
  Dual<double> _acc;        // nCells*5: Σ V_s, Σ K, Σ K v over the window
  Dev<std::uint32_t> _keys, _perm, _cellStart, _cellEnd, _pcell, _cStart, _cEnd;
  Dev<double> _kcoef;
  Dev<unsigned char> _scratch;
  bool _listValid = false;
  int _maxUsedSlots = kMaxHistorySlots;  ///< max contacts of a particle in the last sub-step (≥ slots in use)
  StageTimes _t;
  HeatModule<Exec> _heat;  ///< particle heat transfer (heat.h)
  ChemistryModule<Exec> _chem;  ///< chemistry (chemistry.h)

  explicit EngineImpl(const EngineSetup& s) : _s(s) {
    _exec.threads = s.threads;
    if (_s.historySlots > kMaxHistorySlots || _s.historySlots < 1) {
      backend::raiseUserError("NeighbourOptions::historySlots = " + std::to_string(_s.historySlots) +
                              " is out of range; use 1.." + std::to_string(kMaxHistorySlots));
    }
    _pairs.allocate(_s.pairs.size());
    for (std::size_t k = 0; k < _s.pairs.size(); ++k) _pairs.h()[k] = _s.pairs[k];
    _pairs.markHostModified();
    _pairs.toDevice();
    _walls.allocate(_s.walls.size());
    for (std::size_t k = 0; k < _s.walls.size(); ++k) _walls.h()[k] = _s.walls[k];
    _walls.markHostModified();
    _walls.toDevice();
    if (_s.coupled) {
      _epsFrozen.allocate(_s.nCells);
      _acc.allocate(_s.nCells * 5);
      for (std::size_t c = 0; c < _s.nCells; ++c) _epsFrozen.h()[c] = 1.0;
      _epsFrozen.markHostModified();
      _epsFrozen.toDevice();
      _cStart.reserve(_s.nCells + 1);
      _cEnd.reserve(_s.nCells + 1);
    }
    _heat.setup(_s.heat, _s.coupled ? _s.nCells : 0);
    _chem.setup(_s.chem, _s.coupled ? _s.nCells : 0);
  }

  const char* name() const override { return Exec::name; }
  StageTimes& times() override { return _t; }
  HeatTotals& heatTotals() override { return _heat._totals; }
  ChemistryTotals& chemistryTotals() override { return _chem._totals; }
  bool takePendingRemoval() override {
    const bool p = _chem._pending;
    _chem._pending = false;
    return p;
  }

  // ---------------------------------------------------------------- state transfer
  void setState(const HostState& s) override {
    checkShapes(s, "Engine::setState");  // every schema field holds n · width values
    _p.allocate(s.n, s.nSpecies, s.historySlots, s.neighbourSlots);
    schema::forEachField(_p, s, [](const schema::FieldInfo&, auto& arr, const auto& vec) {
      for (std::size_t k = 0; k < vec.size(); ++k) arr.h()[k] = vec[k];
    });
    _p.toDevice(kAllFields);
    _maxUsedSlots = _p.K;
    _listValid = s.listValid != 0;
    reserveScratch();
  }

  HostState state() override {
    _p.toHost(kAllFields);
    HostState s;
    s.n = _p.n;
    s.nSpecies = _p.nSpecies;
    s.historySlots = _p.K;
    s.neighbourSlots = _p.M;
    schema::forEachField(s, _p, [](const schema::FieldInfo&, auto& vec, const auto& arr) {
      vec.assign(arr.h(), arr.h() + arr.size());
    });
    s.listValid = _listValid ? 1 : 0;
    return s;
  }

  void particles(ParticleData& out) override {
    const std::uint32_t mask = kPos | kVel | kOmega | kForce | kRadius | kMass | kDensity |
                               kTemperature | kSpecies | kMaterial | kGid | kD0;
    _p.toHost(mask);
    out.count = _p.n;
    out.nSpecies = _p.nSpecies;
    auto get = [](const auto& arr, auto& vec) { vec.assign(arr.h(), arr.h() + arr.size()); };
    get(_p.pos, out.position); get(_p.vel, out.velocity); get(_p.omega, out.angularVelocity);
    get(_p.force, out.force); get(_p.radius, out.radius); get(_p.mass, out.mass);
    get(_p.density, out.density); get(_p.temperature, out.temperature);
    get(_p.species, out.species); get(_p.material, out.material); get(_p.gid, out.globalId);
    get(_p.d0, out.initialDiameter);
  }

  void setGas(const GasArrays& g) override {
    _gas.set(g);
    _hasGas = true;
    _heat.setGas(_gas);
    _chem.setGas(_gas);
  }

  void reserveScratch() {
    const std::size_t n = _p.n;
    _keys.reserve(n);
    _perm.reserve(n);
    _pcell.reserve(n);
    _kcoef.reserve(n);
    _scratch.reserve(n * kReorderBlock * sizeof(double));
  }

  std::size_t memoryBytes() const override {
    auto& self = const_cast<EngineImpl&>(*this);
    return self._p.bytes() + _keys.bytes() + _perm.bytes() + _cellStart.bytes() +
           _cellEnd.bytes() + _pcell.bytes() + _kcoef.bytes() + _scratch.bytes() +
           _cStart.bytes() + _cEnd.bytes() + self._epsFrozen.bytes() + self._acc.bytes() +
           _heat.bytes() + _chem.bytes() + _gas.bytes();
  }

  // ---------------------------------------------------------------- neighbour search
  /// Reorders the first `columns` of the `width` entries per particle of one array by _perm,
  /// kReorderBlock columns at a time through an N·kReorderBlock scratch buffer.
  template <class T>
  void reorder(Dual<T>& arr, int width, int columns = -1) {
    const std::size_t n = _p.n;
    if (columns < 0 || columns > width) columns = width;
    T* a = arr.d();
    T* tmp = reinterpret_cast<T*>(_scratch.d());
    const std::uint32_t* perm = _perm.d();
    for (int c0 = 0; c0 < columns; c0 += kReorderBlock) {
      const int w = columns - c0 < kReorderBlock ? columns - c0 : kReorderBlock;
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        const T* src = a + static_cast<std::size_t>(perm[i]) * width + c0;
        for (int q = 0; q < w; ++q) tmp[i * w + q] = src[q];
      });
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        for (int q = 0; q < w; ++q) a[i * width + c0 + q] = tmp[i * w + q];
      });
    }
  }

  /// Neighbour grid over the particles' bounding box; cell size 2 R_max + skin.
  struct NbGrid {
    double lo[3];
    double inv;
    int dims[3];
    std::uint32_t cells;
  };

  NbGrid neighbourGrid() {
    const std::size_t n = _p.n;
    const double* x = _p.pos.d();
    NbGrid g{};
    double hi[3];
    for (int c = 0; c < 3; ++c) {
      // NaN → +inf, so a non-finite position is reported below instead of being skipped by max.
      hi[c] = _exec.reduceMax(n, [=] DEM_LAMBDA(std::size_t i) {
        const double v = x[3 * i + c];
        return v == v ? v : HUGE_VAL;
      }, -HUGE_VAL);
      g.lo[c] = -_exec.reduceMax(n, [=] DEM_LAMBDA(std::size_t i) {
        const double v = x[3 * i + c];
        return v == v ? -v : HUGE_VAL;
      }, -HUGE_VAL);
      if (!std::isfinite(hi[c]) || !std::isfinite(g.lo[c])) {
        backend::raiseUserError("a particle position is not finite (NaN/inf): the DEM step is "
                                "unstable; reduce the time step (dtCfd/nSub) or check the forces");
      }
    }
    double cs = 2.0 * _s.maxRadius + _s.skin + _s.reach;
    const double limit = 4.0 * static_cast<double>(n) + 4096.0;
    for (;;) {
      double total = 1.0;
      double dims[3];
      for (int c = 0; c < 3; ++c) {
        dims[c] = std::floor((hi[c] - g.lo[c]) / cs) + 1.0;
        total *= dims[c];
      }
      if (!std::isfinite(total)) {
        backend::raiseUserError("the particles spread over a non-representable region (a particle "
                                "flew off): the DEM step is unstable; check the forces and time step");
      }
      if (total <= limit) {
        for (int c = 0; c < 3; ++c) g.dims[c] = static_cast<int>(dims[c]);
        break;
      }
      cs *= 1.25 * std::cbrt(total / limit);  // sparse domain: coarser cells, still correct
    }
    g.inv = 1.0 / cs;
    g.cells = static_cast<std::uint32_t>(g.dims[0]) * g.dims[1] * g.dims[2];
    return g;
  }

  void computeKeys(const NbGrid& g) {
    const double* x = _p.pos.d();
    std::uint32_t* keys = _keys.d();
    const NbGrid gg = g;
    _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t i) {
      int c[3];
      for (int d = 0; d < 3; ++d) {
        int k = static_cast<int>(::floor((x[3 * i + d] - gg.lo[d]) * gg.inv));
        c[d] = k < 0 ? 0 : (k >= gg.dims[d] ? gg.dims[d] - 1 : k);
      }
      keys[i] = static_cast<std::uint32_t>(c[0] + gg.dims[0] * (c[1] + gg.dims[1] * c[2]));
    });
  }

  /// Rebuild: reads pos, radius; reorders every per-particle field; writes nbCount, nbList, xref.
  void rebuild() {
    const std::size_t n = _p.n;
    _p.require(kAllFields);
    NbGrid g = neighbourGrid();
    computeKeys(g);
    _exec.sortByKey(_keys.d(), n, g.cells, _perm.d());
    // Every kResorted schema field follows its particle. (force, torque, fwall are recomputed
    // right after the rebuild, xref is reset and the neighbour lists rebuilt: not moved.)
    // History slots at or beyond the largest count in use are empty in every row: not moved.
    schema::forEachField(_p, [&](const schema::FieldInfo& f, auto& arr) {
      if (!f.has(schema::kResorted)) return;
      const int width = _p.width(f);
      if (width == 0) return;
      reorder(arr, width, f.per == schema::Per::History ? f.components * _maxUsedSlots : width);
    });
    computeKeys(g);  // keys of the sorted order (ascending)

    _cellStart.reserve(g.cells);
    _cellEnd.reserve(g.cells);
    std::uint32_t* cs = _cellStart.d();
    std::uint32_t* ce = _cellEnd.d();
    const std::uint32_t* keys = _keys.d();
    _exec.parallelFor(g.cells, [=] DEM_LAMBDA(std::size_t c) { cs[c] = kEmptyCell; ce[c] = 0; });
    _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      if (i == 0 || keys[i] != keys[i - 1]) cs[keys[i]] = static_cast<std::uint32_t>(i);
      if (i + 1 == n || keys[i] != keys[i + 1]) ce[keys[i]] = static_cast<std::uint32_t>(i + 1);
    });

    for (;;) {
      const int width = _p.M;
      const double* x = _p.pos.d();
      const double* r = _p.radius.d();
      std::int32_t* cnt = _p.nbCount.d();
      std::int32_t* list = _p.nbList.d();
      const double skin = _s.skin + _s.reach;
      const NbGrid gg = g;
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        const kernels::Vec3 xi = kernels::load3(x, static_cast<long long>(i));
        const double ri = r[i];
        const std::uint32_t key = keys[i];
        const int cx = static_cast<int>(key % gg.dims[0]);
        const int cy = static_cast<int>((key / gg.dims[0]) % gg.dims[1]);
        const int cz = static_cast<int>(key / (static_cast<std::uint32_t>(gg.dims[0]) * gg.dims[1]));
        int count = 0;
        for (int dz = -1; dz <= 1; ++dz) {
          const int z = cz + dz;
          if (z < 0 || z >= gg.dims[2]) continue;
          for (int dy = -1; dy <= 1; ++dy) {
            const int y = cy + dy;
            if (y < 0 || y >= gg.dims[1]) continue;
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = cx + dx;
              if (xx < 0 || xx >= gg.dims[0]) continue;
              const std::uint32_t c = static_cast<std::uint32_t>(xx + gg.dims[0] * (y + gg.dims[1] * z));
              const std::uint32_t b = cs[c];
              if (b == kEmptyCell) continue;
              for (std::uint32_t j = b; j < ce[c]; ++j) {
                if (j == i) continue;
                const kernels::Vec3 d = kernels::load3(x, j) - xi;
                const double cut = ri + r[j] + skin;
                if (kernels::dot(d, d) < cut * cut) {
                  if (count < width) list[i * width + count] = static_cast<std::int32_t>(j);
                  ++count;
                }
              }
            }
          }
        }
        cnt[i] = count;
      });
      const double maxCount = _exec.reduceMax(
          n, [=] DEM_LAMBDA(std::size_t i) { return static_cast<double>(cnt[i]); }, 0.0);
      if (maxCount <= width) break;
      _p.M = static_cast<int>(maxCount) + 4;  // grow and redo
      _p.nbList.allocate(n * static_cast<std::size_t>(_p.M));
    }
    double* xr = _p.xref.d();
    const double* x = _p.pos.d();
    _exec.parallelFor(3 * n, [=] DEM_LAMBDA(std::size_t k) { xr[k] = x[k]; });
    _p.produced(kAllFields);
    _listValid = true;
    ++_t.rebuilds;
  }

  // ---------------------------------------------------------------- coupling
  /// Sorts particles by PCM cell (_pcell, sentinel nCells outside) into _cStart/_cEnd ranges.
  /// Cost O(particles), independent of the grid size: only the entries of OCCUPIED cells (and
  /// of the sentinel) are written; those of the other cells are stale and must not be read.
  /// Per-cell work therefore runs over segment heads (k is a
  /// head when k == 0 or pcell[perm[k-1]] differs), summing cs[c]..ce[c] in sorted order, which
  /// is the same order as a loop over all cells, so the sums are bitwise the same.
  void sortByCouplingCell() {
    const std::size_t n = _p.n;
    const std::uint32_t nc = static_cast<std::uint32_t>(_s.nCells);
    _exec.sortByKeyRadix(_pcell.d(), n, nc + 1, _perm.d());
    std::uint32_t* cs = _cStart.d();
    std::uint32_t* ce = _cEnd.d();
    const std::uint32_t* pc = _pcell.d();
    const std::uint32_t* perm = _perm.d();
    _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t k) {
      const std::uint32_t c = pc[perm[k]];
      if (k == 0 || pc[perm[k - 1]] != c) cs[c] = static_cast<std::uint32_t>(k);
      if (k + 1 == n || pc[perm[k + 1]] != c) ce[c] = static_cast<std::uint32_t>(k + 1);
    });
  }

  void computeCouplingCells() {
    const double* x = _p.pos.d();
    std::uint32_t* pc = _pcell.d();
    const kernels::GridParams grid = _s.grid;
    const std::uint32_t nc = static_cast<std::uint32_t>(_s.nCells);
    _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t i) {
      const long long c = kernels::pcmCell(grid, kernels::load3(x, static_cast<long long>(i)));
      pc[i] = c < 0 ? nc : static_cast<std::uint32_t>(c);
    });
  }

  /// Reads pos, radius; writes _epsFrozen (PCM ε_g used by drag during the window).
  void beginWindow() override {
    _chem.beginWindow(_exec);  // chemistry window accumulators (also uncoupled: ledgers)
    if (!_s.coupled) return;
    const auto t0 = Clock::now();
    _p.require(kPos | kRadius);
    computeCouplingCells();
    sortByCouplingCell();
    const std::uint32_t* cs = _cStart.d();
    const std::uint32_t* ce = _cEnd.d();
    const std::uint32_t* perm = _perm.d();
    const double* r = _p.radius.d();
    double* eps = _epsFrozen.d();
    double* acc = _acc.d();
    const double vc = _s.cellVolume;
    const std::uint32_t* pc = _pcell.d();
    const std::uint32_t nc = static_cast<std::uint32_t>(_s.nCells);
    // Per window: every cell (empty ones get ε_g of zero solid volume) ...
    _exec.parallelFor(_s.nCells, [=] DEM_LAMBDA(std::size_t c) {
      eps[c] = kernels::pcmGasFraction(0.0, vc);
      for (int q = 0; q < 5; ++q) acc[5 * c + q] = 0.0;
    });
    // ... then the occupied cells, one segment head each (cs/ce are valid only there).
    _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t h) {
      const std::size_t c = pc[perm[h]];
      if (c >= nc || (h > 0 && pc[perm[h - 1]] == c)) return;
      double vs = 0.0;
      for (std::uint32_t k = cs[c]; k < ce[c]; ++k) vs += kernels::sphereVolume(r[perm[k]]);
      eps[c] = kernels::pcmGasFraction(vs, vc);
    });
    _epsFrozen.markDeviceModified();
    _acc.markDeviceModified();
    _heat.beginWindow(_exec, _s.nCells);
    Exec::synchronize();
    _t.coupling += std::chrono::duration<double>(Clock::now() - t0).count();
  }

  /// Reads pos, vel, radius, _kcoef, _pcell; adds this sub-step's PCM sums into _acc.
  void deposit() {
    sortByCouplingCell();
    const std::uint32_t* cs = _cStart.d();
    const std::uint32_t* ce = _cEnd.d();
    const std::uint32_t* perm = _perm.d();
    const double* r = _p.radius.d();
    const double* v = _p.vel.d();
    const double* kc = _kcoef.d();
    double* acc = _acc.d();
    const std::uint32_t* pc = _pcell.d();
    const std::uint32_t nc = static_cast<std::uint32_t>(_s.nCells);
    // One segment head per occupied cell; segments are disjoint, so no atomics.
    _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t h) {
      const std::size_t c = pc[perm[h]];
      if (c >= nc || (h > 0 && pc[perm[h - 1]] == c)) return;
      kernels::CellAccumulator a{0.0, 0.0, {0.0, 0.0, 0.0}};
      for (std::uint32_t k = cs[c]; k < ce[c]; ++k) {
        const std::uint32_t i = perm[k];
        kernels::accumulate(a, kernels::cellContribution(kernels::sphereVolume(r[i]), kc[i],
                                                         kernels::load3(v, i)));
      }
      acc[5 * c] += a.solidVolume;
      acc[5 * c + 1] += a.kCoeff;
      acc[5 * c + 2] += a.kVel.x;
      acc[5 * c + 3] += a.kVel.y;
      acc[5 * c + 4] += a.kVel.z;
    });
    _acc.markDeviceModified();
  }

  void endWindow(int nSub, CellSources& out) override {
    if (!_s.coupled) {
      out = CellSources{};
      _chem.endWindow(nSub, _s, nullptr, out);  // ledgers only
      _heat.endWindow(nSub, _s, out);           // wall heat totals only
      return;
    }
    _acc.toHost();
    const std::size_t nc = _s.nCells;
    out.epsG.assign(nc, 1.0);
    out.kSl.assign(nc, 0.0);
    out.kSlUs.assign(3 * nc, 0.0);
    out.heatH.assign(nc, 0.0);
    out.heatHTp.assign(nc, 0.0);
    out.rSpecies.assign(nc * static_cast<std::size_t>(_s.nGasSpecies), 0.0);
    out.qHom.assign(nc, 0.0);
    const double* acc = _acc.h();
    for (std::size_t c = 0; c < nc; ++c) {
      const kernels::CellAccumulator a{acc[5 * c], acc[5 * c + 1], {acc[5 * c + 2], acc[5 * c + 3], acc[5 * c + 4]}};
      const kernels::CellAverages avg = kernels::averageSources(a, nSub, _s.cellVolume);
      out.epsG[c] = avg.epsG;
      out.kSl[c] = avg.kSl;
      out.kSlUs[3 * c] = avg.kSlUs.x;
      out.kSlUs[3 * c + 1] = avg.kSlUs.y;
      out.kSlUs[3 * c + 2] = avg.kSlUs.z;
    }
    _heat.endWindow(nSub, _s, out);
    if (_chem.enabled()) {  // R_species, WGS, chemistry ledgers (chemistry.h)
      const auto tc = Clock::now();
      _epsFrozen.toHost();
      _chem.endWindow(nSub, _s, _epsFrozen.h(), out);
      _t.chemistry += std::chrono::duration<double>(Clock::now() - tc).count();
    }
  }

  // ---------------------------------------------------------------- forces
  /// Gas forces of coupled runs (PHYSICS §1.1, §2.2): PCM cell, Gidaspow drag and −V_p ∇p.
  /// Reads pos, vel, radius (+ gas fields, _epsFrozen); writes force (the gas force, which
  /// computeForces then adds the contacts to), _kcoef, _pcell. A pass of its own so that drag
  /// has its own stage time; the sums are in the order of the former fused kernel (bitwise
  /// the same forces).
  void computeDrag() {
    const double* x = _p.pos.d();
    const double* v = _p.vel.d();
    const double* r = _p.radius.d();
    double* f = _p.force.d();
    const bool gas = _hasGas;
    const kernels::GridParams grid = _s.grid;
    const std::uint32_t nCells = static_cast<std::uint32_t>(_s.nCells);
    const double* ug = gas ? _gas.ug.d() : nullptr;
    const double* gp = gas ? _gas.gradP.d() : nullptr;
    const double* rho = gas ? _gas.rhoG.d() : nullptr;
    const double* mu = gas ? _gas.muG.d() : nullptr;
    const double* eps = _epsFrozen.d();
    double* kc = _kcoef.d();
    std::uint32_t* pc = _pcell.d();
    kernels::GidaspowParams drag;
    drag.epsMin = _s.epsMin;
    _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      const long long ii = static_cast<long long>(i);
      const Vec3 xi = load3(x, ii);
      const long long cell = pcmCell(grid, xi);
      Vec3 F{0.0, 0.0, 0.0};
      double kcoef = 0.0;
      if (gas && cell >= 0) {
        const double ri = r[i];
        const Vec3 vi = load3(v, ii);
        const double vol = sphereVolume(ri);
        const Vec3 u = load3(ug, cell);
        const double slip = norm(u - vi);
        kcoef = gidaspowParticleCoefficient(drag, eps[cell], rho[cell], mu[cell], 2.0 * ri, vol, slip);
        F += dragForce(kcoef, u, vi);
        F += pressureGradientForce(vol, load3(gp, cell));
      }
      store3(f, ii, F);
      kc[i] = kcoef;
      pc[i] = cell < 0 ? nCells : static_cast<std::uint32_t>(cell);
    });
    _p.produced(kForce);
  }

  /// Reads pos, vel, omega, radius, mass, material, gid, histKey, histDisp, nbCount, nbList
  /// (+ the gas force of computeDrag in coupled runs); writes force, torque, fwall, histKey,
  /// histDisp, contacts, wallContacts.
  void computeForces(double dt) {
    const std::size_t n = _p.n;
    const double* x = _p.pos.d();
    const double* v = _p.vel.d();
    const double* w = _p.omega.d();
    const double* r = _p.radius.d();
    const double* m = _p.mass.d();
    const std::int32_t* mat = _p.material.d();
    const std::int64_t* gid = _p.gid.d();
    std::int64_t* hk = _p.histKey.d();
    double* hd = _p.histDisp.d();
    const std::int32_t* cnt = _p.nbCount.d();
    const std::int32_t* list = _p.nbList.d();
    double* f = _p.force.d();
    double* tq = _p.torque.d();
    double* fw = _p.fwall.d();
    std::int32_t* nc = _p.contacts.d();
    std::int32_t* nwc = _p.wallContacts.d();
    const PairProps* pairs = _pairs.d();
    const kernels::PlaneWall* walls = _walls.d();
    const int nWalls = static_cast<int>(_s.walls.size());
    const int nMat = _s.nMaterials;
    const int K = _p.K;
    const int M = _p.M;
    const bool coupled = _s.coupled;  // force holds the gas force of computeDrag

    // reduceMax runs the kernel body once per index (side effects on index i only) and
    // returns the largest number of contacts of a particle, in the same pass.
    const double maxSlots = _exec.reduceMax(n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      const long long ii = static_cast<long long>(i);
      const Vec3 xi = load3(x, ii);
      const Vec3 vi = load3(v, ii);
      const Vec3 wi = load3(w, ii);
      const double ri = r[i];
      const double mi = m[i];
      const int ai = mat[i];
      // Slots in use are compacted at the front: the last sub-step used nc + nwc of them.
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
          if (oldKey[s] == key) return oldD[s];
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
      // Particle–particle LSD (Eqs. 7–13), gathered over the full neighbour list.
      int pairCount = 0;
      const int nb = cnt[i];
      for (int a = 0; a < nb; ++a) {
        const std::int32_t j = list[i * M + a];
        const Vec3 d = load3(x, j) - xi;
        const double l2 = dot(d, d);
        const double rj = r[j];
        const double rsum = ri + rj;
        if (l2 >= rsum * rsum) continue;
        const double l = ::sqrt(l2);
        const Vec3 nrm = (1.0 / l) * d;
        const double deltaN = rsum - l;
        const PairProps pp = pairs[ai * nMat + mat[j]];
        const double meff = effectiveMass(mi, m[j]);
        const double etan = pp.dampFactor * ::sqrt(pp.kn * meff);
        const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
        const double lij = leverArm(l, ri, rj);
        const double lji = leverArm(l, rj, ri);
        const Vec3 vij = relativeVelocity(vi, load3(v, j), wi, load3(w, j), lij, lji, nrm);
        const std::int64_t key = gid[j];
        const LsdResult res = lsdContact(lp, nrm, deltaN, vij, lij, history(key), dt);
        F += res.force;
        T += res.torque;
        remember(key, res.deltaT);
        ++pairCount;
      }
      // Walls (m_eff = m_i, the particle's material).
      Vec3 FW{0.0, 0.0, 0.0};
      int wallCount = 0;
      for (int k = 0; k < nWalls; ++k) {
        const double deltaN = wallOverlap(walls[k], xi, ri);
        if (deltaN <= 0.0) continue;
        const PairProps pp = pairs[ai * nMat + ai];
        const double etan = pp.dampFactor * ::sqrt(pp.kn * mi);
        const LsdParams lp{pp.kn, pp.kt, etan, pp.etatFactor * etan, pp.mu};
        const std::int64_t key = -(static_cast<std::int64_t>(k) + 2);
        const LsdResult res = wallContact(lp, walls[k], deltaN, vi, wi, ri, history(key), dt);
        FW += res.force;
        T += res.torque;
        remember(key, res.deltaT);
        ++wallCount;
      }
      F += FW;
      for (int s = slot; s < used; ++s) hk[i * K + s] = -1;
      store3(f, ii, F);
      store3(tq, ii, T);
      store3(fw, ii, FW);
      nc[i] = pairCount;
      nwc[i] = wallCount;
      return static_cast<double>(pairCount + wallCount);
    }, 0.0);
    _p.produced(kForce | kTorque | kFwall | kHistKey | kHistDisp | kContacts | kWallContacts);
    _maxUsedSlots = maxSlots < K ? static_cast<int>(maxSlots) : K;
    if (maxSlots > K) {
      backend::raiseUserError("a particle has " + std::to_string(static_cast<int>(maxSlots)) +
                              " simultaneous contacts but only " + std::to_string(K) +
                              " tangential-history slots; raise NeighbourOptions::historySlots "
                              "(at most " + std::to_string(kMaxHistorySlots) + ")");
    }
  }

  /// Symplectic Euler. Reads force, torque, mass, radius; writes pos, vel, omega.
  /// Returns the largest displacement² since the last neighbour-list build.
  double integrate(double dt) {
    const double* f = _p.force.d();
    const double* tq = _p.torque.d();
    const double* m = _p.mass.d();
    const double* r = _p.radius.d();
    double* x = _p.pos.d();
    double* v = _p.vel.d();
    double* w = _p.omega.d();
    const double* xr = _p.xref.d();
    const kernels::Vec3 g = _s.gravity;
    if (_s.frozen) {  // held in place (MFiX verification cases): no motion, zero velocities
      _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t i) {
        const long long ii = static_cast<long long>(i);
        store3(v, ii, kernels::Vec3{0.0, 0.0, 0.0});
        store3(w, ii, kernels::Vec3{0.0, 0.0, 0.0});
      });
      _p.produced(kVel | kOmega);
      return 0.0;
    }
    const double maxDisp2 = _exec.reduceMax(_p.n, [=] DEM_LAMBDA(std::size_t i) {
      using namespace kernels;
      const long long ii = static_cast<long long>(i);
      const double invM = 1.0 / m[i];
      const Vec3 vn = load3(v, ii) + (dt * invM) * (load3(f, ii) + gravityForce(m[i], g));  // Eq. 6
      const double invI = 1.0 / (0.4 * m[i] * r[i] * r[i]);  // I = 2/5 m R² (Eq. 7)
      store3(w, ii, load3(w, ii) + (dt * invI) * load3(tq, ii));
      store3(v, ii, vn);
      const Vec3 xn = load3(x, ii) + dt * vn;
      store3(x, ii, xn);
      const Vec3 d = xn - load3(xr, ii);
      const double d2 = dot(d, d);
      return d2 == d2 ? d2 : HUGE_VAL;  // NaN forces a rebuild, which reports it
    }, 0.0);
    _p.produced(kPos | kVel | kOmega);
    return maxDisp2;
  }

  void subStep(double dt) override {
    _chem._dt = dt;  // window length for the per-cell WGS, also without particles
    if (_p.n == 0) return;
    auto t0 = Clock::now();
    if (!_listValid) {
      rebuild();
      Exec::synchronize();
      auto t1 = Clock::now();
      _t.neighbour += std::chrono::duration<double>(t1 - t0).count();
      t0 = t1;
    }
    _p.require(kAllFields);
    if (_s.coupled) {
      computeDrag();
      Exec::synchronize();
      auto t1 = Clock::now();
      _t.drag += std::chrono::duration<double>(t1 - t0).count();
      t0 = t1;
    }
    computeForces(dt);
    Exec::synchronize();
    auto t1 = Clock::now();
    _t.contact += std::chrono::duration<double>(t1 - t0).count();
    if (_s.coupled) {
      deposit();
      Exec::synchronize();
      auto t2 = Clock::now();
      _t.coupling += std::chrono::duration<double>(t2 - t1).count();
      t1 = t2;
    }
    if (_heat.enabled()) {
      const bool gas = _hasGas && _s.coupled;
      _heat.sources(_exec, _p, _s, gas, _pcell.d(), _perm.d(), _cStart.d(), _cEnd.d(),
                    _s.coupled ? _epsFrozen.d() : nullptr, gas ? _gas.ug.d() : nullptr,
                    gas ? _gas.rhoG.d() : nullptr, gas ? _gas.muG.d() : nullptr, dt);
      Exec::synchronize();
      auto t2 = Clock::now();
      _t.heat += std::chrono::duration<double>(t2 - t1).count();
      t1 = t2;
    }
    if (_chem.enabled()) {  // rates -> mass/diameter, before the motion (chemistry.h)
      const bool gas = _hasGas && _s.coupled;
      _chem.react(_exec, _p, _s, gas, _pcell.d(), _perm.d(), _cStart.d(), _cEnd.d(), dt);
      Exec::synchronize();
      auto t2 = Clock::now();
      _t.chemistry += std::chrono::duration<double>(t2 - t1).count();
      t1 = t2;
    }
    const double half = 0.5 * _s.skin;
    if (integrate(dt) > half * half) _listValid = false;
    _heat.updateTemperature(_exec, _p, dt);
    _chem.updateTemperature(_exec, _p, dt);  // + Δt Q_rxn/(m c_p)
    Exec::synchronize();
    _t.integrate += std::chrono::duration<double>(Clock::now() - t1).count();
  }

  std::size_t pairContacts() override {
    _p.toHost(kContacts);
    std::size_t s = 0;
    for (std::size_t i = 0; i < _p.n; ++i) s += static_cast<std::size_t>(_p.contacts.h()[i]);
    return s / 2;
  }
  std::size_t wallContacts() override {
    _p.toHost(kWallContacts);
    std::size_t s = 0;
    for (std::size_t i = 0; i < _p.n; ++i) s += static_cast<std::size_t>(_p.wallContacts.h()[i]);
    return s;
  }
  std::array<double, 3> wallForce() override {
    _p.toHost(kFwall);
    std::array<double, 3> s{0, 0, 0};
    for (std::size_t i = 0; i < _p.n; ++i)
      for (int c = 0; c < 3; ++c) s[c] += _p.fwall.h()[3 * i + c];
    return s;
  }
};

} // namespace coredem::dem
