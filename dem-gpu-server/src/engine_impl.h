#pragma once
/// @file
/// The DEM engine, written once and instantiated per backend (cpu: backend/cpu/cpu_engine.cpp,
/// cuda: backend/cuda/cuda_engine.cu). All loops are Exec::parallelFor over particles or
/// cells; each index writes only its own outputs (no atomics; contacts.h and heat.h evaluate each
/// pair once, by its owner, and gather the partner's share in a fixed order: pair_lists.h), so
/// results are deterministic and independent of the thread count.
///
/// The engine owns the particles, the neighbour lists and the coupling-cell binning
/// (coupling_cells.h) and drives the sub-step modules of the list StepModules (step_modules.h:
/// drag.h, contacts.h, heat.h, chemistry.h) through one interface (step_module.h). Sub-step
/// (docs/architecture.md step order, symplectic Euler):
///   1. neighbour lists rebuilt if a particle moved more than skin/2 since the last build
///      (cell keys → stable sort → particles reordered → 27-cell search)
///   2. sources of every module, in this order, on the same configuration:
///      drag (PCM cell, drag of the chosen law, −V_p∇p; particles sorted by cell; K_sl deposited),
///      contacts (particle–particle LSD and walls, added to the gas force),
///      heat (conduction, lens, convection, radiation; H and H_Tp deposited; the lens widens the
///      neighbour cut-off by EngineSetup::reach), chemistry (rates, mass and diameter)
///   3. motion: v += Δt (F/m + g), ω += Δt T/I, x += Δt v
///   4. update of every module: temperatures T += Δt Q/(m c_p) (heat, then reaction heat)
/// Why symplectic Euler: one force evaluation per step (the cost is all in the forces), it is
/// MFiX's default DEM integrator, it is second order in x for conservative forces (leapfrog),
/// and for the velocity-dependent LSD law velocity Verlet (LIGGGHTS) gave the same rebound
/// ratios in a binary-collision check (docs/performance.md "Integrator").

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "coredem/dem/kernels/body_force.h"
#include "coredem/dem/kernels/pcm.h"
#include "coredem/dem/kernels/vec3.h"
#include "coupling_cells.h"
#include "engine.h"
#include "gas_fields.h"
#include "motion.h"
#include "pair_lists.h"
#include "particle_store.h"
#include "step_module.h"
#include "step_modules.h"

namespace coredem::dem {

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

  explicit EngineImpl(const EngineSetup& s)
      : _s(s) {
    _exec.threads = s.threads;
    if (_s.historySlots > kMaxHistorySlots || _s.historySlots < 1) {
      backend::raiseUserError(
          "NeighbourOptions::historySlots = " + std::to_string(_s.historySlots) +
          " is out of range; use 1.." + std::to_string(kMaxHistorySlots));
    }
    _cells.setup(_s.coupled ? _s.nCells : 0);
    _wallLists.setup(_s);
    _modules.forEach([&](auto& m) { m.setup(_s); });
    _status.allocate(kStatusSlotCount);
    for (int k = 0; k < kStatusSlotCount; ++k)
      _status.h()[k] = 0.0;
    _status.markHostModified();
    _status.toDevice();
  }

  const char* name() const override { return Exec::name; }
  StageTimes& times() override { return _t; }
  HeatTotals heatTotals() const override { return heat().totals(); }
  void restoreHeatTotals(const HeatTotals& t) override { heat().restoreTotals(t); }
  ChemistryTotals chemistryTotals() const override { return chem().totals(); }
  void restoreChemistryTotals(const ChemistryTotals& t) override { chem().restoreTotals(t); }
  bool takeRemovalRequest() override { return chem().takeRemovalRequest(); }

  // The modules the Engine interface reaches by name (ledgers, contact history).
  ContactModule<Exec>& contacts() { return _modules.template get<ContactModule<Exec>>(); }
  HeatModule<Exec>& heat() { return _modules.template get<HeatModule<Exec>>(); }
  const HeatModule<Exec>& heat() const { return _modules.template get<HeatModule<Exec>>(); }
  ChemistryModule<Exec>& chem() { return _modules.template get<ChemistryModule<Exec>>(); }
  const ChemistryModule<Exec>& chem() const {
    return _modules.template get<ChemistryModule<Exec>>();
  }

  // ---------------------------------------------------------------- state transfer
  void setState(const HostState& s) override {
    checkShapes(s, "Engine::setState"); // every schema field holds n · width values
    _p.allocate(s.n, s.nSpecies, s.historySlots, s.neighbourSlots);
    schema::forEachField(_p, s, [](const schema::FieldInfo&, auto& arr, const auto& vec) {
      for (std::size_t k = 0; k < vec.size(); ++k)
        arr.h()[k] = vec[k];
    });
    _p.toDevice(kAllFields);
    contacts().resetUsedSlots(_p.K);
    _pairLists.invalidate();
    _listValid = s.listValid != 0;
    reserveScratch();
  }

  HostState state() override {
    StepContext<Exec> ctx = stepContext(0.0);
    contacts().flushHistory(ctx); // the history slots complete
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
    get(_p.pos, out.position);
    get(_p.vel, out.velocity);
    get(_p.omega, out.angularVelocity);
    get(_p.force, out.force);
    get(_p.radius, out.radius);
    get(_p.mass, out.mass);
    get(_p.density, out.density);
    get(_p.temperature, out.temperature);
    get(_p.species, out.species);
    get(_p.material, out.material);
    get(_p.gid, out.globalId);
    get(_p.d0, out.initialDiameter);
  }

  void setGas(const GasArrays& g) override {
    _gas.set(g);
    _hasGas = true;
    _splitPending = !g.heatToParticles.empty();
  }

  /// The heat split of the gas fields set last, once (heat.h giveHeatSplit): after beginWindow,
  /// on the frozen cells and the window's Nusselt factors.
  HeatSplitBooking giveHeatSplit() override {
    if (!_splitPending)
      return {};
    _splitPending = false;
    const GasFields<Exec>* gas = gasOrNull();
    if (gas == nullptr)
      return {};
    const auto t0 = Clock::now();
    _p.require(kPos | kVel | kRadius | kMass | kMaterial | kTemperature);
    StepContext<Exec> ctx = stepContext(0.0);
    const HeatSplitBooking b = heat().giveHeatSplit(ctx);
    _t.heat += std::chrono::duration<double>(Clock::now() - t0).count();
    return b;
  }

  void reserveScratch() {
    const std::size_t n = _p.n;
    _keys.reserve(n);
    _perm.reserve(n);
    _cells.reserveParticles(n);
    _scratch.reserve(n * kReorderBlock * sizeof(double));
  }

  std::size_t memoryBytes() const override {
    auto& self = const_cast<EngineImpl&>(*this);
    std::size_t spares = 0;
    for (const auto& sp : _spares)
      spares += sp->bytes();
    return self._p.bytes() + spares + _keys.bytes() + _perm.bytes() + _cellOffset.bytes() +
           _scratch.bytes() + _cells.bytes() + _pairLists.bytes() + _wallLists.bytes() +
           _modules.bytes() + _gas.bytes();
  }

  // ---------------------------------------------------------------- neighbour search
  /// Reorders the `width` entries per particle of one array by _perm in one pass: gathered
  /// into a spare buffer of its size in bytes, which then takes its place; the array's old
  /// buffer is the spare of the next array of that size. One spare per size (e.g. 24, 8 and
  /// 4 bytes per particle), not one per field.
  template <class T>
  void reorderInto(Dual<T>& arr, int width) {
    const std::size_t n = _p.n;
    Dual<unsigned char>& spare = spareOfBytes(arr.bytes());
    const T* a = arr.d();
    T* b = reinterpret_cast<T*>(spare.d());
    const std::uint32_t* perm = _perm.d();
    _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      const T* src = a + static_cast<std::size_t>(perm[i]) * width;
      for (int q = 0; q < width; ++q)
        b[i * width + q] = src[q];
    });
    arr.swapBuffers(spare);
  }
  /// Frees the spares of sizes no re-sorted field has any more (particles added or removed).
  void dropUnusedSpares() {
    std::vector<std::size_t> sizes;
    schema::forEachField(_p, [&](const schema::FieldInfo& f, auto& arr) {
      if (f.has(schema::kResorted) && f.per != schema::Per::History)
        sizes.push_back(arr.bytes());
    });
    std::erase_if(_spares, [&](const auto& sp) {
      return std::find(sizes.begin(), sizes.end(), sp->size()) == sizes.end();
    });
  }
  Dual<unsigned char>& spareOfBytes(std::size_t bytes) {
    for (auto& s : _spares)
      if (s->size() == bytes)
        return *s;
    _spares.push_back(std::make_unique<Dual<unsigned char>>());
    _spares.back()->allocate(bytes);
    return *_spares.back();
  }

  /// Reorders the first `columns` of the `width` entries per particle of one array by _perm,
  /// kReorderBlock columns at a time through an N·kReorderBlock scratch buffer (the history
  /// slots: mostly unused, too wide for a spare).
  template <class T>
  void reorder(Dual<T>& arr, int width, int columns = -1) {
    const std::size_t n = _p.n;
    if (columns < 0 || columns > width)
      columns = width;
    T* a = arr.d();
    T* tmp = reinterpret_cast<T*>(_scratch.d());
    const std::uint32_t* perm = _perm.d();
    for (int c0 = 0; c0 < columns; c0 += kReorderBlock) {
      const int w = columns - c0 < kReorderBlock ? columns - c0 : kReorderBlock;
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        const T* src = a + static_cast<std::size_t>(perm[i]) * width + c0;
        for (int q = 0; q < w; ++q)
          tmp[i * w + q] = src[q];
      });
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        for (int q = 0; q < w; ++q)
          a[i * width + c0 + q] = tmp[i * w + q];
      });
    }
  }

  /// Reorders the history slots in use (the first `used`: keys, and δ_t up to the last key in
  /// use of each row) by _perm, through the scratch: the keys in blocks of kReorderBlock
  /// columns, then δ_t slot by slot and only in the rows whose slot holds history (most rows of a
  /// dilute bed hold none: their δ_t lines are not touched). δ_t of an empty slot is never read
  /// (contacts.h), and stays what the row held. _keys holds each row's slot count meanwhile
  /// (computeKeys rewrites it after the re-sort).
  void reorderHistory(int used) {
    const std::size_t n = _p.n;
    const int K = _p.K;
    if (used > K)
      used = K;
    if (used <= 0)
      return;
    std::int64_t* hk = _p.histKey.d();
    double* hd = _p.histDisp.d();
    std::uint32_t* count = _keys.d(); // slots to move per row (new order)
    const std::uint32_t* perm = _perm.d();
    auto* tk = reinterpret_cast<std::int64_t*>(_scratch.d());
    for (int c0 = 0; c0 < used; c0 += kReorderBlock) {
      const int w = used - c0 < kReorderBlock ? used - c0 : kReorderBlock;
      const bool first = c0 == 0;
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        const std::int64_t* src = hk + static_cast<std::size_t>(perm[i]) * K + c0;
        std::uint32_t last = first ? 0u : count[i];
        for (int q = 0; q < w; ++q) {
          tk[i * w + q] = src[q];
          if (src[q] != -1)
            last = static_cast<std::uint32_t>(c0 + q + 1);
        }
        count[i] = last;
      });
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        for (int q = 0; q < w; ++q)
          hk[i * K + c0 + q] = tk[i * w + q];
      });
    }
    double* td = reinterpret_cast<double*>(_scratch.d());
    static_assert(kReorderBlock >= 3, "one slot's δ_t per particle in the scratch");
    for (int c = 0; c < used; ++c) {
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        if (static_cast<int>(count[i]) > c) {
          const double* src = hd + 3 * (static_cast<std::size_t>(perm[i]) * K + c);
          for (int q = 0; q < 3; ++q)
            td[3 * i + q] = src[q];
        }
      });
      _exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
        if (static_cast<int>(count[i]) > c)
          for (int q = 0; q < 3; ++q)
            hd[3 * (i * K + c) + q] = td[3 * i + q];
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
      hi[c] = _exec.reduceMax(
          n,
          [=] DEM_LAMBDA(std::size_t i) {
            const double v = x[3 * i + c];
            return v == v ? v : HUGE_VAL;
          },
          -HUGE_VAL);
      g.lo[c] = -_exec.reduceMax(
          n,
          [=] DEM_LAMBDA(std::size_t i) {
            const double v = x[3 * i + c];
            return v == v ? -v : HUGE_VAL;
          },
          -HUGE_VAL);
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
        backend::raiseUserError(
            "the particles spread over a non-representable region (a particle "
            "flew off): the DEM step is unstable; check the forces and time step");
      }
      if (total <= limit) {
        for (int c = 0; c < 3; ++c)
          g.dims[c] = static_cast<int>(dims[c]);
        break;
      }
      cs *= 1.25 * std::cbrt(total / limit); // sparse domain: coarser cells, still correct
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
    StepContext<Exec> ctx = stepContext(0.0);
    contacts().flushHistory(ctx); // the history follows its particle in the slots
    NbGrid g = neighbourGrid();
    computeKeys(g);
    _exec.sortByKey(_keys.d(), n, g.cells, _perm.d());
    // Every kResorted schema field follows its particle. (force, torque, fwall are recomputed
    // right after the rebuild (fwall zeroed below), xref is reset and the neighbour lists
    // rebuilt: not moved.)
    // History slots at or beyond the largest count in use are empty in every row: not moved.
    const int usedSlots = contacts().usedSlots();
    dropUnusedSpares();
    schema::forEachField(_p, [&](const schema::FieldInfo& f, auto& arr) {
      if (!f.has(schema::kResorted))
        return;
      const int width = _p.width(f);
      if (width == 0)
        return;
      if (f.per != schema::Per::History)
        reorderInto(arr, width);
      else if (f.member != "histKey" && f.member != "histDisp") // (those: reorderHistory)
        reorder(arr, width, f.components * usedSlots);
    });
    reorderHistory(usedSlots);
    computeKeys(g); // keys of the sorted order (ascending)

    // Cell offsets (CSR over the sorted keys): the particles of cell c are [off[c], off[c + 1]);
    // cells of one x-row are consecutive keys, so a row of the 27-cell stencil is one index
    // range. Index i writes off[c] = i for the cells after key[i − 1] up to key[i].
    _cellOffset.reserve(static_cast<std::size_t>(g.cells) + 1);
    std::uint32_t* off = _cellOffset.d();
    const std::uint32_t* keys = _keys.d();
    const std::uint32_t cells = g.cells;
    _exec.parallelFor(n + 1, [=] DEM_LAMBDA(std::size_t i) {
      const std::uint32_t lo = i == 0 ? 0u : keys[i - 1] + 1u;
      const std::uint32_t hi = i == n ? cells : keys[i];
      for (std::uint32_t c = lo; c <= hi; ++c)
        off[c] = static_cast<std::uint32_t>(i);
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
        const int cz =
            static_cast<int>(key / (static_cast<std::uint32_t>(gg.dims[0]) * gg.dims[1]));
        int count = 0;
        const int x0 = cx > 0 ? cx - 1 : 0;
        const int x1 = cx + 1 < gg.dims[0] ? cx + 1 : gg.dims[0] - 1;
        for (int dz = -1; dz <= 1; ++dz) {
          const int z = cz + dz;
          if (z < 0 || z >= gg.dims[2])
            continue;
          for (int dy = -1; dy <= 1; ++dy) {
            const int y = cy + dy;
            if (y < 0 || y >= gg.dims[1])
              continue;
            // Cells x0..x1 of row (y, z): one index range, in the order of the cells.
            const std::uint32_t row = static_cast<std::uint32_t>(gg.dims[0] * (y + gg.dims[1] * z));
            const std::uint32_t end = off[row + x1 + 1];
            for (std::uint32_t j = off[row + x0]; j < end; ++j) {
              if (j == i)
                continue;
              const kernels::Vec3 d = kernels::load3(x, j) - xi;
              const double cut = ri + r[j] + skin;
              if (kernels::dot(d, d) < cut * cut) {
                if (count < width)
                  list[i * width + count] = static_cast<std::int32_t>(j);
                ++count;
              }
            }
          }
        }
        cnt[i] = count;
      });
      const double maxCount = _exec.reduceMax(
          n, [=] DEM_LAMBDA(std::size_t i) { return static_cast<double>(cnt[i]); }, 0.0);
      if (maxCount <= width)
        break;
      _p.M = static_cast<int>(maxCount) + 4; // grow and redo
      _p.nbList.allocate(n * static_cast<std::size_t>(_p.M));
    }
    double* xr = _p.xref.d();
    double* fw = _p.fwall.d(); // zero in rows without wall contacts (contacts.h writes the rest)
    const double* x = _p.pos.d();
    _exec.parallelFor(3 * n, [=] DEM_LAMBDA(std::size_t k) {
      xr[k] = x[k];
      fw[k] = 0.0;
    });
    _p.produced(kAllFields);
    _pairLists.invalidate(); // half and low lists follow the new order and lists
    _listValid = true;
    ++_t.rebuilds;
  }

  // ---------------------------------------------------------------- window and sub-step
  /// What the modules see this sub-step (dt = 0 at the window boundaries).
  StepContext<Exec> stepContext(double dt) {
    return StepContext<Exec>{_exec,      _p,         _s, gasOrNull(), _cells,
                             _pairLists, _wallLists, dt, _status.d(), _marks};
  }
  const GasFields<Exec>* gasOrNull() const { return _hasGas && _s.coupled ? &_gas : nullptr; }

  /// A particle in a coupling cell without fluid (φ_f = 0: outside the CFD domain) is an error
  /// naming it (host check of the frozen ε_g; particle positions copied only on error).
  void refuseParticlesOutsideTheFluid(const GasFields<Exec>& gas) {
    const double* f = gas.fluid.h();
    const double* eps = _cells.epsFrozenHost();
    for (std::size_t c = 0; c < _s.nCells; ++c) {
      if (f[c] > 0.0 || eps[c] >= 1.0)
        continue;
      ParticleData pd;
      particles(pd);
      for (std::size_t i = 0; i < pd.count; ++i) {
        const kernels::Vec3 x{pd.position[3 * i], pd.position[3 * i + 1], pd.position[3 * i + 2]};
        if (kernels::pcmCell(_s.grid, x) == static_cast<long long>(c)) {
          const auto num = [](double v) {
            char b[32];
            std::snprintf(b, sizeof b, "%.6g", v);
            return std::string(b);
          };
          backend::raiseUserError(
              "particle " + std::to_string(pd.globalId[i]) + " at (" + num(x.x) + ", " + num(x.y) +
              ", " + num(x.z) + ") m lies in coupling cell " + std::to_string(c) +
              ", which holds no fluid (fluid_fraction 0: outside the CFD domain); check the "
              "walls against the CFD mesh");
        }
      }
      backend::raiseUserError("coupling cell " + std::to_string(c) +
                              " holds solid but no fluid (fluid_fraction 0)");
    }
  }

  /// Freezes ε_g (PCM at the current positions, coupled runs) and clears every module's window
  /// accumulators.
  void beginWindow() override {
    StepContext<Exec> ctx = stepContext(0.0);
    const auto t0 = Clock::now();
    if (_s.coupled) {
      _p.require(kPos | kRadius);
      const GasFields<Exec>* gas = gasOrNull();
      const bool fluid = gas != nullptr && gas->has(gas->fluid);
      _cells.freeze(_exec, _p, _s.grid, _s.cellVolume, fluid ? gas->fluid.d() : nullptr);
      if (fluid) {
        refuseParticlesOutsideTheFluid(*gas);
      }
    }
    _modules.forEach([&](auto& m) { m.beginWindow(ctx); }); // (uncoupled: chemistry's ledgers)
    if (_s.coupled) {
      Exec::synchronize();
      _t.coupling += std::chrono::duration<double>(Clock::now() - t0).count();
    }
  }

  /// Sub-step-averaged sources of the window; uncoupled runs only close the modules' ledgers.
  void endWindow(double dtCfd, int nSub, CellSources& out) override {
    WindowContext<Exec> w{_s, gasOrNull(), _cells, nSub, dtCfd, dtCfd / nSub, out, _t};
    if (!_s.coupled) {
      out = CellSources{};
    } else {
      const std::size_t nc = _s.nCells;
      out.epsG.assign(nc, 1.0);
      out.kSl.assign(nc, 0.0);
      out.kSlUs.assign(3 * nc, 0.0);
      out.heatH.assign(nc, 0.0);
      out.heatHTp.assign(nc, 0.0);
      out.rSpecies.assign(nc * static_cast<std::size_t>(_s.nGasSpecies), 0.0);
      out.qHom.assign(nc, 0.0);
      out.qRad.assign(nc, 0.0);
      out.momP.assign(3 * nc, 0.0);
    }
    _modules.forEach([&](auto& m) { m.endWindow(w); });
  }

  /// Symplectic Euler (motion.h). Reads force, torque, mass, radius; writes pos, vel, omega,
  /// and the largest displacement² since the last neighbour-list build
  /// (kStatusMaxDisplacement2).
  void integrate(double dt) {
    const double* f = _p.force.d();
    const double* tq = _p.torque.d();
    const double* m = _p.mass.d();
    const double* r = _p.radius.d();
    double* x = _p.pos.d();
    double* v = _p.vel.d();
    double* w = _p.omega.d();
    const double* xr = _p.xref.d();
    const kernels::Vec3 g = _s.gravity;
    if (_s.frozen) { // held in place (MFiX verification cases): no motion, zero velocities
      _exec.parallelFor(_p.n, [=] DEM_LAMBDA(std::size_t i) {
        const long long ii = static_cast<long long>(i);
        store3(v, ii, kernels::Vec3{0.0, 0.0, 0.0});
        store3(w, ii, kernels::Vec3{0.0, 0.0, 0.0});
      });
      _p.produced(kVel | kOmega);
      return;
    }
    const MotionArrays a{f, tq, m, r, xr, x, v, w, g, dt};
    double* out = _status.d() + kStatusMaxDisplacement2;
    auto one = [=] DEM_LAMBDA(std::size_t i) { return moveParticle(a, static_cast<long long>(i)); };
    if constexpr (kRangeLoops<Exec>) { // cpu: four particles at a time where it has AVX
      (void)one;
      const bool avx = Exec::hasAvx();
      _exec.reduceMaxOverRangesInto(
          _p.n, [a, avx](std::int64_t lo, std::int64_t hi) { return moveRange(a, lo, hi, avx); },
          0.0, out);
    } else {
      _exec.reduceMaxInto(_p.n, one, 0.0, out);
    }
    _p.produced(kPos | kVel | kOmega);
  }

  /// One sub-step. Without a neighbour rebuild the host waits for the device once: the status
  /// read at the end (the values the kernels left in _status; step_module.h StatusSlot).
  void subStep(double dt) override {
    if (_p.n == 0)
      return;
    _marks.begin();
    if (!_listValid || !_pairLists.valid()) {
      if (!_listValid)
        rebuild();
      _pairLists.ensure(_exec, _p);
      _marks.end(&StageTimes::neighbour);
    }
    _p.require(kAllFields);
    StepContext<Exec> ctx = stepContext(dt);
    // Sources of every module on the same configuration, in the list's order (step_modules.h).
    _modules.forEach([&](auto& m) {
      if (m.enabled()) {
        m.sources(ctx);
        _marks.end(std::remove_reference_t<decltype(m)>::kStage);
      }
    });
    integrate(dt);
    _modules.forEach([&](auto& m) { // heat: T += Δt Q/(m c_p); chemistry: + Δt Q_rxn/(m c_p)
      if (m.enabled())
        m.update(ctx);
    });
    _marks.end(&StageTimes::integrate);
    _status.markDeviceModified();
    _status.toHost(); // the sub-step's one host round trip
    _marks.book();
    const double* status = _status.h();
    _modules.forEach([&](auto& m) { m.readStatus(status, _p); });
    const double half = 0.5 * _s.skin;
    if (!_s.frozen && status[kStatusMaxDisplacement2] > half * half)
      _listValid = false;
  }

  std::size_t pairContacts() override { return contacts().pairContacts(_p); }
  std::size_t wallContacts() override { return contacts().wallContacts(_p); }
  std::array<double, 3> wallForce() override { return contacts().wallForce(_p); }

private:
  EngineSetup _s;
  Exec _exec;
  ParticleStore<Exec> _p;
  /// rebuild: the spare buffers re-sorted per-particle fields are gathered into, one per size
  std::vector<std::unique_ptr<Dual<unsigned char>>> _spares;
  GasFields<Exec> _gas; ///< per-cell gas fields of the CFD step, read by the modules
  bool _hasGas = false;
  bool _splitPending = false; ///< _gas holds a heat split not given yet (giveHeatSplit)
  CouplingCells<Exec> _cells; ///< PCM cell binning and frozen ε_g, read by the modules
  PairLists<Exec> _pairLists; ///< half and low lists of the neighbour lists (pair_lists.h)
  WallLists<Exec> _wallLists; ///< walls and wall candidates per particle (wall_lists.h)
  Dev<std::uint32_t> _keys, _perm, _cellOffset; ///< neighbour search
  Dev<unsigned char> _scratch;
  bool _listValid = false;
  StageTimes _t;
  StageMarks<Exec> _marks{_t}; ///< stage marks of the sub-step in flight
  Dual<double> _status;        ///< kStatusSlotCount values per sub-step (step_module.h StatusSlot)
  StepModules<Exec> _modules;  ///< drag, contacts, heat, chemistry (step_modules.h)
};

} // namespace coredem::dem
