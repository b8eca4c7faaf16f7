// Backend conformance, every stage of the sub-step: written once, instantiated for every backend
// (cpu, cuda-sim, cuda; cuda skips when it is not built or no device is present) and compared
// with a cpu run of the same deck.
//
// Tolerances, per quantity (Tolerances below):
//   cpu, cuda-sim: bitwise. Every loop writes only its own index, the sort is stable and the only
//     reduction is a maximum (exact in any order), so the memory model changes nothing but where
//     the bytes live: any difference is a missing host↔device synchronisation or a read of
//     memory that was never written.
//   cuda: the device compiler contracts a*b+c into FMA and its libm differs in the last bits;
//     the differences then grow through the contacts. The bounds below are the expected size
//     of that drift over these short runs (not yet measured on a GPU: gpu-check prints the
//     failures with the differences found).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "coredem/dem/kernels/convection.h"
#include "coredem/dem/kernels/drag.h"
#include "coredem/dem/kernels/model_list.h"

using namespace coredem::dem;

namespace {

template <BackendKind K>
struct Backend {
  static constexpr BackendKind kind = K;
};

/// Allowed differences from the cpu reference. Zero everywhere: bitwise.
struct Tolerances {
  double position = 0;    ///< m, absolute
  double velocity = 0;    ///< m/s and rad/s, absolute
  double force = 0;       ///< relative to the largest |F| of the reference
  double temperature = 0; ///< K, absolute
  double mass = 0;        ///< relative (mass, radius, d0)
  double species = 0;     ///< mass fraction, absolute
  double sources = 0;     ///< relative to the largest |value| of the field (cell sources)
  double totals = 0;      ///< relative, ledgers (heat and chemistry totals)
};

Tolerances tolerancesFor(BackendKind k) {
  if (k != BackendKind::Cuda)
    return {};
  Tolerances t;
  t.position = 1e-9;
  t.velocity = 1e-6;
  t.force = 1e-6;
  t.temperature = 1e-8;
  t.mass = 1e-12;
  t.species = 1e-12;
  t.sources = 1e-8;
  t.totals = 1e-8;
  return t;
}

/// `field[i]` of b matches `field[i]` of a within abs (or bitwise when abs = 0).
void expectClose(const std::vector<double>& a, const std::vector<double>& b, double abs,
                 const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  if (abs == 0) {
    for (std::size_t k = 0; k < a.size(); ++k)
      ASSERT_EQ(std::bit_cast<std::uint64_t>(a[k]), std::bit_cast<std::uint64_t>(b[k]))
          << what << "[" << k << "]: " << a[k] << " vs " << b[k];
    return;
  }
  for (std::size_t k = 0; k < a.size(); ++k)
    ASSERT_NEAR(a[k], b[k], abs) << what << "[" << k << "]";
}

double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v)
    m = std::max(m, std::fabs(x));
  return m;
}

void expectCloseRel(const std::vector<double>& a, const std::vector<double>& b, double rel,
                    const char* what) {
  expectClose(a, b, rel * maxAbs(a), what);
}

/// Reorders the per-particle rows of a field by global id.
std::vector<double> byGid(const ParticleData& p, const std::vector<double>& v) {
  if (p.count == 0)
    return v;
  const std::size_t w = v.size() / p.count;
  std::vector<std::size_t> order(p.count);
  for (std::size_t i = 0; i < p.count; ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t x, std::size_t y) { return p.globalId[x] < p.globalId[y]; });
  std::vector<double> out;
  out.reserve(v.size());
  for (std::size_t i : order)
    out.insert(out.end(), v.begin() + i * w, v.begin() + (i + 1) * w);
  return out;
}

void expectSameParticles(const ParticleData& a, const ParticleData& b, const Tolerances& t) {
  ASSERT_EQ(a.count, b.count);
  std::vector<std::int64_t> ga(a.globalId), gb(b.globalId);
  std::sort(ga.begin(), ga.end());
  std::sort(gb.begin(), gb.end());
  ASSERT_EQ(ga, gb);
  expectClose(byGid(a, a.position), byGid(b, b.position), t.position, "position");
  expectClose(byGid(a, a.velocity), byGid(b, b.velocity), t.velocity, "velocity");
  expectClose(byGid(a, a.angularVelocity), byGid(b, b.angularVelocity), t.velocity, "omega");
  expectCloseRel(byGid(a, a.force), byGid(b, b.force), t.force, "force");
  expectClose(byGid(a, a.temperature), byGid(b, b.temperature), t.temperature, "temperature");
  expectCloseRel(byGid(a, a.mass), byGid(b, b.mass), t.mass, "mass");
  expectCloseRel(byGid(a, a.radius), byGid(b, b.radius), t.mass, "radius");
  expectCloseRel(byGid(a, a.initialDiameter), byGid(b, b.initialDiameter), t.mass, "d0");
  expectClose(byGid(a, a.species), byGid(b, b.species), t.species, "species");
}

void expectSameSources(const CellSources& a, const CellSources& b, const Tolerances& t) {
  expectCloseRel(a.epsG, b.epsG, t.sources, "epsG");
  expectCloseRel(a.kSl, b.kSl, t.sources, "kSl");
  expectCloseRel(a.kSlUs, b.kSlUs, t.sources, "kSlUs");
  expectCloseRel(a.heatH, b.heatH, t.sources, "heatH");
  expectCloseRel(a.heatHTp, b.heatHTp, t.sources, "heatHTp");
  expectCloseRel(a.rSpecies, b.rSpecies, t.sources, "rSpecies");
  expectCloseRel(a.qHom, b.qHom, t.sources, "qHom");
  expectCloseRel(a.qRad, b.qRad, t.sources, "qRad");
  expectCloseRel(a.momP, b.momP, t.sources, "momP");
}

void expectSameTotals(const HeatTotals& a, const HeatTotals& b, const ChemistryTotals& ca,
                      const ChemistryTotals& cb, const Tolerances& t) {
  expectCloseRel({a.convection, a.radiation, a.wall, a.splitUnassigned},
                 {b.convection, b.radiation, b.wall, b.splitUnassigned}, t.totals, "heat totals");
  expectCloseRel(ca.gasProduced, cb.gasProduced, t.totals, "gasProduced");
  expectCloseRel(ca.solidChange, cb.solidChange, t.totals, "solidChange");
  expectCloseRel(ca.removedSolid, cb.removedSolid, t.totals, "removedSolid");
  expectCloseRel({ca.releasedMomentum.begin(), ca.releasedMomentum.end()},
                 {cb.releasedMomentum.begin(), cb.releasedMomentum.end()}, t.totals,
                 "releasedMomentum");
  expectCloseRel({ca.reactionHeat, ca.homogeneousHeat, ca.gasSensibleHeat, ca.sensibleMassEnthalpy},
                 {cb.reactionHeat, cb.homogeneousHeat, cb.gasSensibleHeat, cb.sensibleMassEnthalpy},
                 t.totals, "chemistry heat totals");
  EXPECT_EQ(ca.removedCount, cb.removedCount);
}

/// Uniform gas on every cell (velocity upwards so that drag acts).
struct Gas {
  std::vector<double> u, gp, T, rho, mu, kappa, cp, Y;
  Gas(std::size_t n, int nGas, double tg) {
    for (std::size_t c = 0; c < n; ++c) {
      u.insert(u.end(), {0.01 * static_cast<double>(c % 3), 0.0, 0.4 + 0.01 * c});
      gp.insert(gp.end(), {0.0, 0.0, -2.0});
      T.push_back(tg + 3.0 * static_cast<double>(c % 5));
      rho.push_back(1.1);
      mu.push_back(2e-5);
      kappa.push_back(0.03);
      cp.push_back(1100.0);
      for (int g = 0; g < nGas; ++g)
        Y.push_back(g == 0 ? 1.0 : 0.0);
    }
  }
  void apply(DemSystem& s) const {
    s.setGasFields(GasFieldsView{u, gp, T, rho, mu, kappa, cp, Y, {}, {}});
  }
};

/// One run of a deck: the sources of every window and the final state.
struct Run {
  std::vector<CellSources> windows;
  std::vector<ParticleData> states; ///< after every window (each read clears the dirty flags)
  ParticleData p;
  HeatTotals heat;
  ChemistryTotals chem;
  std::vector<std::size_t> contacts, pairContacts;
  std::vector<std::array<double, 3>> wallForce;
  std::uint64_t rebuilds = 0;
  std::size_t memoryBefore = 0, memoryAfter = 0;
};

/// Runs `windows` CFD steps of dtCfd with nSub sub-steps each (gas fields set when the deck has a
/// grid; nSub = 0: as many as the stable step needs); optionally reads a state first and writes one
/// after `writeAfter` windows.
Run run(const DemConfig& cfg, BackendKind kind, int windows, int nSub, double dtCfd,
        const std::string& readFrom = "", const std::string& writeTo = "", int writeAfter = -1) {
  DemSystem sys(cfg, kind, 2);
  if (nSub == 0) // sub-steps from the initial particles (a restart keeps the first run's)
    nSub = static_cast<int>(std::ceil(dtCfd / sys.dtDemMax()));
  if (!readFrom.empty())
    sys.readState(readFrom);
  const Gas gas(sys.cellCount(), static_cast<int>(cfg.gasSpecies.size()), 600.0);
  Run r;
  r.memoryBefore = sys.memoryBytes();
  for (int w = 0; w < windows; ++w) {
    if (sys.cellCount() > 0)
      gas.apply(sys);
    r.windows.push_back(sys.advance(dtCfd, nSub));
    r.contacts.push_back(sys.contactCount());
    r.pairContacts.push_back(sys.pairContactCount());
    r.wallForce.push_back(sys.wallForce());
    r.states.push_back(sys.particles());
    if (w + 1 == writeAfter)
      sys.writeState(writeTo);
  }
  r.p = sys.particles();
  r.heat = sys.heatTotals();
  r.chem = sys.chemistryTotals();
  r.rebuilds = sys.stageTimes().rebuilds;
  r.memoryAfter = sys.memoryBytes();
  return r;
}

void expectSameRun(const Run& ref, const Run& r, const Tolerances& t, bool countsExact = true) {
  ASSERT_EQ(ref.windows.size(), r.windows.size());
  for (std::size_t w = 0; w < ref.windows.size(); ++w) {
    SCOPED_TRACE("window " + std::to_string(w));
    expectSameSources(ref.windows[w], r.windows[w], t);
    if (countsExact) { // contact counts: exact unless a contact opens within round-off
      EXPECT_EQ(ref.contacts[w], r.contacts[w]);
      EXPECT_EQ(ref.pairContacts[w], r.pairContacts[w]);
    }
    expectCloseRel({ref.wallForce[w][0], ref.wallForce[w][1], ref.wallForce[w][2]},
                   {r.wallForce[w][0], r.wallForce[w][1], r.wallForce[w][2]}, t.force,
                   "wall force");
    expectSameParticles(ref.states[w], r.states[w], t);
  }
  expectSameParticles(ref.p, r.p, t);
  expectSameTotals(ref.heat, r.heat, ref.chem, r.chem, t);
}

// ---------------------------------------------------------------- decks
/// A dense agitated box with walls, neighbour lists starting two slots wide (they must grow).
DemConfig denseBox() {
  DemConfig c;
  c.gravity = {0, 0, -9.81};
  Material m;
  m.kn = 50.0;
  m.en = 0.8;
  m.mu = 0.4;
  c.materials = {m};
  ParticleSet s;
  s.packing = Packing::Lattice;
  s.regionMin = {0, 0, 0};
  s.regionMax = {7 * 1.05e-3, 7 * 1.05e-3, 7 * 1.05e-3};
  s.spacing = 1.05e-3;
  s.count = 343;
  s.velocityJitter = 0.3;
  s.seed = 5;
  c.particleSets.push_back(s);
  c.addBox({0, 0, 0}, s.regionMax);
  c.neighbour.initialNeighbourSlots = 2;
  c.neighbour.historySlots = 8;
  return c;
}

/// denseBox with the Hertz–Mindlin law (kernels/hertz_mindlin_contact.h), two materials, a
/// material pair's restitution and friction, walls of their own materials (a frictionless one)
/// and others with the particles' own: every row kind of the pair table, in the pair lanes too.
DemConfig hertzBox() {
  DemConfig c = denseBox();
  c.contact = coredem::dem::kernels::ContactLaw::HertzMindlin;
  Material glass;
  glass.name = "glass";
  glass.youngsModulus = 5e6, glass.poissonRatio = 0.25, glass.en = 0.8, glass.mu = 0.4;
  Material steel = glass;
  steel.name = "steel";
  steel.youngsModulus = 2e7, steel.poissonRatio = 0.3, steel.en = 0.9, steel.mu = 0.2;
  Material slick = steel;
  slick.name = "slick";
  slick.mu = 0.0;
  c.materials = {glass, steel, slick};
  ParticleSet top = c.particleSets[0];
  c.particleSets[0].count = 196; // the lower four layers glass, the upper three steel
  c.particleSets[0].regionMax[2] = 4 * 1.05e-3;
  top.material = 1;
  top.count = 147;
  top.regionMin[2] = 4 * 1.05e-3;
  top.seed = 6;
  c.particleSets.push_back(top);
  c.materialPairs.push_back(MaterialPair{0, 1, 0.5, 0.6});
  c.walls[0].material = 2; // x = 0: frictionless
  c.walls[4].material = 1; // the floor: steel
  return c;
}

/// A settling heated bed on a coupling grid: drag, PCM, every heat term, hot walls. `scale`
/// multiplies the box edges (and the particle count by scale³).
DemConfig heatedBed(int scale = 1) {
  DemConfig cfg;
  cfg.gravity = {0, 0, -9.81};
  Material glass;
  glass.kn = 20.0;
  glass.en = 0.5;
  glass.mu = 0.3;
  glass.cp = 840.0;
  glass.conductivity = 1.0;
  glass.emissivity = 0.9;
  cfg.materials = {glass};
  ParticleSet s;
  s.packing = Packing::Random;
  const double e = 0.008 * scale;
  s.count = 200 * static_cast<std::size_t>(scale * scale * scale);
  s.diameter = 1e-3;
  s.temperature = 300.0;
  s.regionMin = {0, 0, 0};
  s.regionMax = {e, e, e};
  s.seed = 11;
  s.velocityJitter = 0.05;
  cfg.particleSets.push_back(s);
  cfg.addBox({0, 0, 0}, {e, e, 1.5 * e});
  cfg.grid.spacing = {0.002, 0.002, 0.004};
  cfg.grid.counts = {4 * scale, 4 * scale, 3 * scale};
  cfg.wallTemperature = 500.0;
  return cfg;
}

/// Two kinds of burning particles (fast and slow) and an inert one: chemistry with heat of
/// reaction, and particles removed at different times.
DemConfig burningBed() {
  DemConfig cfg = heatedBed();
  cfg.gravity = {0, 0, 0};
  cfg.particleSets.clear();
  cfg.gasSpecies = {{"G", 0.015}, {"N2", 0.028}};
  cfg.solidSpecies = {{"B", 0.015}, {"I", 0.020}};
  ParticleSet s;
  s.packing = Packing::Lattice;
  s.diameter = 1e-3;
  s.density = 2000.0;
  s.temperature = 400.0;
  s.spacing = 1.5e-3;
  s.regionMin = {0.001, 0.001, 0.001};
  s.regionMax = {0.007, 0.007, 0.003};
  s.count = 16;
  s.composition = {1.0, 0.0};
  s.seed = 3;
  s.velocityJitter = 0.01;
  ParticleSet slow = s;
  slow.regionMin[2] = 0.004;
  slow.regionMax[2] = 0.006;
  slow.composition = {0.6, 0.4};
  slow.seed = 4;
  ParticleSet inert = s;
  inert.regionMin[2] = 0.007;
  inert.regionMax[2] = 0.009;
  inert.composition = {0.0, 1.0};
  inert.seed = 6;
  cfg.particleSets = {s, slow, inert};
  ReactionConfig r;
  r.name = "burn";
  r.terms = {{"B", -1}, {"G", 1}};
  r.law = coredem::dem::kernels::RateLaw::Arrhenius;
  r.A = 0.025; // mol/s · exp(−E/RT) ≈ 0.014 mol/s: a 1 mm particle of B (7e-5 mol) goes in 5 ms
  r.E = 2e3;
  r.heatOfReaction = 50.0; // J/mol, endothermic: cools the burning particles by ≈ 10 K
  cfg.chemistry.reactions.push_back(r);
  cfg.chemistry.removalFraction = 0.3;
  return cfg;
}

} // namespace

template <class B>
class StageConformance : public ::testing::Test {
protected:
  void SetUp() override {
    if constexpr (B::kind == BackendKind::Cuda) {
      if (!cudaBackendBuilt())
        GTEST_SKIP() << "CUDA backend not built";
      const CudaProbe cuda = probeCuda();
      if (!cuda.error.empty())
        FAIL() << cuda.error; // a broken GPU setup is a failure, not a skip
      if (cuda.devices == 0)
        GTEST_SKIP() << "no CUDA device: " << cuda.note;
    }
  }
  static constexpr BackendKind kind = B::kind;
  const Tolerances tol = tolerancesFor(B::kind);
};

using AllBackends = ::testing::Types<Backend<BackendKind::Cpu>, Backend<BackendKind::CudaSim>,
                                     Backend<BackendKind::Cuda>>;
TYPED_TEST_SUITE(StageConformance, AllBackends);

TYPED_TEST(StageConformance, NeighbourSearchWithListGrowthContactsAndWalls) {
  const DemConfig cfg = denseBox();
  const double dt = DemSystem(cfg, BackendKind::Cpu, 1).dtDemMax();
  const Run ref = run(cfg, BackendKind::Cpu, 6, 25, 25 * dt);
  const Run r = run(cfg, this->kind, 6, 25, 25 * dt);
  EXPECT_GT(ref.rebuilds, 1u);
  EXPECT_GT(ref.memoryAfter, ref.memoryBefore);            // the neighbour lists grew
  EXPECT_GT(ref.contacts.back(), ref.pairContacts.back()); // wall contacts present
  EXPECT_GT(ref.pairContacts.back(), 0u);
  EXPECT_EQ(ref.rebuilds, r.rebuilds);
  expectSameRun(ref, r, this->tol, this->kind != BackendKind::Cuda);
}

TYPED_TEST(StageConformance, HertzMindlinWithMaterialPairsAndWallMaterials) {
  const DemConfig cfg = hertzBox();
  const double dt = DemSystem(cfg, BackendKind::Cpu, 1).dtDemMax();
  const Run ref = run(cfg, BackendKind::Cpu, 6, 25, 25 * dt);
  const Run r = run(cfg, this->kind, 6, 25, 25 * dt);
  EXPECT_GT(ref.contacts.back(), ref.pairContacts.back()); // wall contacts present
  EXPECT_GT(ref.pairContacts.back(), 0u);
  expectSameRun(ref, r, this->tol, this->kind != BackendKind::Cuda);
}

TYPED_TEST(StageConformance, DragPcmAndEveryHeatModelWithWallHeat) {
  struct Variant {
    const char* name;
    void (*apply)(DemConfig&);
  };
  const Variant variants[] = {
      {"li-mason, every term", [](DemConfig&) {}},
      {"ranz-marshall without voidage, no lens",
       [](DemConfig& c) {
         c.heat.nusselt = coredem::dem::kernels::NusseltModel::RanzMarshall;
         c.heat.reynoldsWithVoidage = false;
         c.heat.lensConduction = false;
         c.heat.wallLensConduction = false;
       }},
      {"conduction and radiation only, adiabatic walls",
       [](DemConfig& c) {
         c.heat.convection = false;
         c.wallTemperature = 0.0;
       }},
      {"heat off (drag and PCM only)", [](DemConfig& c) { c.heat.enabled = false; }},
  };
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.name);
    DemConfig cfg = heatedBed();
    v.apply(cfg);
    const Run ref = run(cfg, BackendKind::Cpu, 3, 10, 1e-4);
    const Run r = run(cfg, this->kind, 3, 10, 1e-4);
    if (cfg.heat.enabled && cfg.heat.convection) {
      EXPECT_NE(ref.heat.convection, 0.0);
    }
    if (cfg.heat.enabled && cfg.wallTemperature > 0) {
      EXPECT_GT(ref.heat.wall, 0.0);
    }
    EXPECT_GT(maxAbs(ref.windows.back().kSl), 0.0);
    expectSameRun(ref, r, this->tol, this->kind != BackendKind::Cuda);
  }
}

// Every registered drag law and Nusselt correlation (kernels/drag.h DragLaws,
// kernels/convection.h NusseltModels) gives the same run on this backend as on the cpu one.
TYPED_TEST(StageConformance, EveryDragLawAndNusseltCorrelation) {
  namespace k = coredem::dem::kernels;
  int laws = 0;
  k::forEachModel(k::DragLaws{}, [&]<class M>() {
    SCOPED_TRACE(std::string("drag ") + M::name);
    DemConfig cfg = heatedBed();
    cfg.drag = static_cast<k::DragLaw>(k::modelId<M, k::DragLaws>);
    const Run ref = run(cfg, BackendKind::Cpu, 2, 10, 1e-4);
    EXPECT_GT(maxAbs(ref.windows.back().kSl), 0.0);
    expectSameRun(ref, run(cfg, this->kind, 2, 10, 1e-4), this->tol,
                  this->kind != BackendKind::Cuda);
    ++laws;
  });
  k::forEachModel(k::NusseltModels{}, [&]<class M>() {
    SCOPED_TRACE(std::string("nusselt ") + M::name);
    DemConfig cfg = heatedBed();
    cfg.heat.nusselt = static_cast<k::NusseltModel>(k::modelId<M, k::NusseltModels>);
    const Run ref = run(cfg, BackendKind::Cpu, 2, 10, 1e-4);
    EXPECT_NE(ref.heat.convection, 0.0);
    expectSameRun(ref, run(cfg, this->kind, 2, 10, 1e-4), this->tol,
                  this->kind != BackendKind::Cuda);
    ++laws;
  });
  EXPECT_EQ(laws, k::DragLaws::size + k::NusseltModels::size);
}

// 5,400 particles: many slabs of each colour (pair_lists.h "Slabs"), so that the cpu backend's
// scatter and the gather backends' ordered sums of the contact and heat pair terms meet. (The
// order of a particle's heat terms moves only the last bits of Q_i, which vanish in T_p += Δt
// Q_i/(m c_p) at these rates; the contact forces, compared bitwise, do show it.)
TYPED_TEST(StageConformance, HeatAndContactsOverManySlabs) {
  // 27 blocks of 200 particles at 300–500 K: heat flows between neighbouring blocks, so that a
  // particle receives pair terms from several slabs.
  DemConfig cfg = heatedBed(3);
  const ParticleSet block = cfg.particleSets.front();
  cfg.particleSets.clear();
  for (int b = 0; b < 27; ++b) {
    ParticleSet s = block;
    const double o[3] = {0.008 * (b % 3), 0.008 * ((b / 3) % 3), 0.008 * (b / 9)};
    s.count = 200;
    s.regionMin = {o[0], o[1], o[2]};
    s.regionMax = {o[0] + 0.008, o[1] + 0.008, o[2] + 0.008};
    s.seed = 100 + static_cast<std::uint64_t>(b);
    s.temperature = 300.0 + 50.0 * (b % 5);
    cfg.particleSets.push_back(s);
  }
  const Run ref = run(cfg, BackendKind::Cpu, 2, 10, 1e-4);
  const Run r = run(cfg, this->kind, 2, 10, 1e-4);
  EXPECT_GT(ref.pairContacts.back(), 50u);
  expectSameRun(ref, r, this->tol, this->kind != BackendKind::Cuda);
}

TYPED_TEST(StageConformance, ChemistryWithRemoval) {
  for (bool coupled : {true, false}) {
    SCOPED_TRACE(coupled ? "on a coupling grid" : "uncoupled (no grid: window totals only)");
    DemConfig cfg = burningBed();
    if (!coupled)
      cfg.grid = CouplingGrid{};
    const Run ref = run(cfg, BackendKind::Cpu, 12, 0, 1e-3);
    const Run r = run(cfg, this->kind, 12, 0, 1e-3);
    EXPECT_GT(ref.chem.removedCount, 0u);
    EXPECT_LT(ref.p.count, 48u);
    EXPECT_GE(ref.p.count, 16u); // the inert particles stay
    EXPECT_NE(ref.chem.reactionHeat, 0.0);
    EXPECT_LT(ref.chem.solidChange[0], 0.0);
    expectSameRun(ref, r, this->tol, this->kind != BackendKind::Cuda);
  }
}

TYPED_TEST(StageConformance, FrozenMode) {
  DemConfig cfg = heatedBed();
  cfg.frozenMotion = true;
  const Run ref = run(cfg, BackendKind::Cpu, 3, 5, 1e-3);
  const Run r = run(cfg, this->kind, 3, 5, 1e-3);
  EXPECT_EQ(maxAbs(ref.p.velocity), 0.0);
  expectSameRun(ref, r, this->tol);
  // Positions are held exactly on every backend.
  const Run start = run(cfg, this->kind, 0, 1, 1e-3);
  expectClose(byGid(start.p, start.p.position), byGid(r.p, r.p.position), 0.0, "frozen position");
}

#if COREDEM_DEM_STATE_FILES
TYPED_TEST(StageConformance, RestartContinuesTheStraightRun) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("coredem_conformance_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string state = (dir / "state.h5").string();
  const DemConfig cfg = burningBed();
  const Run straight = run(cfg, BackendKind::Cpu, 8, 0, 1e-3);
  // This backend writes the state half-way, a fresh system of it continues from the file.
  run(cfg, this->kind, 4, 0, 1e-3, "", state, 4);
  const Run resumed = run(cfg, this->kind, 4, 0, 1e-3, state);
  std::filesystem::remove_all(dir);
  Run tail = straight;
  tail.windows.erase(tail.windows.begin(), tail.windows.begin() + 4);
  tail.contacts.erase(tail.contacts.begin(), tail.contacts.begin() + 4);
  tail.pairContacts.erase(tail.pairContacts.begin(), tail.pairContacts.begin() + 4);
  tail.wallForce.erase(tail.wallForce.begin(), tail.wallForce.begin() + 4);
  tail.states.erase(tail.states.begin(), tail.states.begin() + 4);
  expectSameRun(tail, resumed, this->tol, this->kind != BackendKind::Cuda);
}
#else
// The DEM core built alone has no HDF5: the restart above is not compiled there, and a state file
// is refused with a message that says what to build.
TYPED_TEST(StageConformance, StateFilesAreRefusedWithoutHdf5) {
  DemSystem sys(burningBed(), this->kind);
  try {
    sys.writeState("state.h5");
    FAIL() << "writeState succeeded in a build without state files";
  } catch (const coredem::UserError& e) {
    EXPECT_NE(std::string(e.what()).find("COREDEM_CORE_ONLY"), std::string::npos) << e.what();
  }
}
#endif
