// coredem-bench thermochem: cost of each thermochemistry sub-model per particle and sub-step,
// like the seed's Table 2 / Fig. 19.
//   coredem-bench thermochem --particles 100000 --threads 2 [--json] [--backend cpu|cuda]
//
// Heat sub-models are timed as the DEM step runs them: the deck of bench/decks.md (packed by
// default) with a PCM coupling grid and hot gas, built once per sub-model with only that
// sub-model switched on; the sub-model's cost is its heat-stage time minus the heat stage with
// every sub-model off (the stage's loops and cell deposition: "heat_stage_base"). The
// temperature update is the motion stage with heat on minus the one with heat off.
// Reaction rates and the mass/species update are timed as loops of their kernels over the
// engine's particles (temperatures, masses, PCM cells after the same steps), which splits rates
// from the update; the engine's chemistry stage (StageTimes::chemistry: rates, mass/diameter/
// species update and deposition together) is timed per model as well (chemistry_stage_* rows,
// one variant each: CLG R1/R2, CLG R4/R5, a generic Arrhenius reaction). Figures are measured,
// never asserted.
#include "thermochem.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <omp.h>

#include "commands.h"
#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "dem.h"
#include "options.h"

namespace {

using namespace coredem::dem;
namespace tc = coredem::bench::thermochem;
using Clock = std::chrono::steady_clock;

/// One engine configuration of the benchmark.
struct Variant {
  const char* name;
  bool heat, convection, contact, lens, radiation;
  int chemistry =
      0; ///< 0 none, 1 CLG R1/R2, 2 CLG R4/R5, 3 generic reaction (the engine's chemistry stage)
};

constexpr Variant kVariants[] = {
    {"mechanics", false, false, false, false, false},
    {"heat_base", true, false, false, false, false},
    {"convection", true, true, false, false, false},
    {"contact_conduction", true, false, true, false, false},
    {"gas_lens_conduction", true, false, false, true, false},
    {"radiation", true, false, false, false, true},
    {"all_heat", true, true, true, true, true},
    {"chem_clg_r1_r2", true, false, false, false, false, 1},
    {"chem_clg_r4_r5", true, false, false, false, false, 2},
    {"chem_generic", true, false, false, false, false, 3},
};
constexpr int kAllHeat = 6;
constexpr int kVariantCount = static_cast<int>(sizeof(kVariants) / sizeof(kVariants[0]));

/// Median stage seconds of one variant (over repeats), per measured step.
struct Measured {
  double neighbour = 0, contact = 0, heat = 0, integrate = 0, coupling = 0, wall = 0, chemistry = 0;
  std::uint64_t rebuilds = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Options {
  std::string deckName = "packed", backend = "cpu";
  std::size_t n = 100000;
  int threads = 2, steps = 10, warmup = 5, repeat = 3;
  double tParticle = 1100.0, tGas = 1000.0, uGas = 0.5;
};

DemConfig makeConfig(const Options& o, const Variant& v) {
  DemConfig cfg = coredem::bench::deck(o.deckName, o.n);
  Material& m = cfg.materials[0];
  m.cp = 840.0;
  m.conductivity = 1.0;
  m.emissivity = 0.8;
  cfg.particleSets[0].temperature = o.tParticle;
  coredem::bench::addCouplingGrid(cfg, 4e-3);
  HeatOptions& h = cfg.heat;
  h.enabled = v.heat;
  h.convection = v.convection;
  h.contactConduction = v.contact;
  h.lensConduction = v.lens;
  h.radiation = v.radiation;
  // Species for the chemistry variants: a CLG bed (docs/physics.md §6) of char + oxygen carrier.
  if (v.chemistry > 0) {
    cfg.gasSpecies = {{"CO", 28.0101e-3},
                      {"CO2", 44.0095e-3},
                      {"H2", 2.01588e-3},
                      {"H2O", 18.01528e-3},
                      {"N2", 28.0134e-3}};
    cfg.solidSpecies = {
        {"C", 12.0107e-3}, {"Fe2O3", 159.6882e-3}, {"Fe3O4", 231.5326e-3}, {"Al2O3", 101.9613e-3}};
    cfg.particleSets[0].composition = {0.3, 0.4, 0.2, 0.1};
    ChemistryOptions& ch = cfg.chemistry;
    if (v.chemistry == 1)
      ch.clg.charGasification = true;
    if (v.chemistry == 2)
      ch.clg.ocReduction = true;
    if (v.chemistry == 3) { // C + CO2 -> 2 CO, Arrhenius, first order in CO2 (as genericReaction())
      ReactionConfig r;
      r.name = "boudouard";
      r.terms = {{"C", -1.0}, {"CO2", -1.0}, {"CO", 2.0}};
      r.law = coredem::dem::kernels::RateLaw::Arrhenius;
      r.A = 1.0e3;
      r.E = 1.5e5;
      r.orderSpecies = "CO2";
      r.order = 1.0;
      r.heatOfReaction = 1.72e5;
      ch.reactions.push_back(r);
    }
  }
  return cfg;
}

/// Builds the variant, runs warm-up steps, then `repeat` measured runs of `steps` sub-steps
/// (one advance() each). Optionally leaves the particles for the chemistry loops.
Measured runVariant(const Options& o, const Variant& v, ParticleData* keep, CouplingGrid* grid) {
  const DemConfig cfg = makeConfig(o, v);
  DemSystem sys(cfg, parseBackend(o.backend), o.threads);
  const coredem::bench::BenchGas gas(sys.cellCount(), o.uGas, o.tGas);
  GasFieldsView view = gas.view();
  std::vector<double> yg;
  if (!cfg.gasSpecies.empty()) { // the gasifier-like mixture of chemistryInput(), as mass fractions
    const double x[5] = {0.2, 0.2, 0.1, 0.2, 0.3};
    double mix = 0.0;
    for (int k = 0; k < 5; ++k)
      mix += x[k] * cfg.gasSpecies[k].molarMass;
    yg.resize(sys.cellCount() * 5);
    for (std::size_t c = 0; c < sys.cellCount(); ++c)
      for (int k = 0; k < 5; ++k)
        yg[5 * c + k] = x[k] * cfg.gasSpecies[k].molarMass / mix;
    view.Yg = yg;
  }
  sys.setGasFields(view);
  const double dt = sys.dtDemMax();
  if (o.warmup > 0)
    sys.advance(o.warmup * dt, o.warmup);
  std::vector<double> nb, ct, ht, in, cp, wl, chm;
  std::uint64_t rebuilds = 0;
  for (int r = 0; r < o.repeat; ++r) {
    sys.resetStageTimes();
    const auto t0 = Clock::now();
    sys.advance(o.steps * dt, o.steps);
    wl.push_back(std::chrono::duration<double>(Clock::now() - t0).count() / o.steps);
    const StageTimes st = sys.stageTimes();
    nb.push_back(st.neighbour / o.steps);
    ct.push_back(st.contact / o.steps);
    ht.push_back(st.heat / o.steps);
    in.push_back(st.integrate / o.steps);
    cp.push_back(st.coupling / o.steps);
    chm.push_back(st.chemistry / o.steps);
    rebuilds += st.rebuilds;
  }
  if (keep)
    *keep = sys.particles();
  if (grid)
    *grid = cfg.grid;
  return Measured{median(nb), median(ct), median(ht),  median(in),
                  median(cp), median(wl), median(chm), rebuilds};
}

/// The cells' gas: a gasifier-like mixture at T_g and 1 bar (mole fractions CO 0.2, CO2 0.2,
/// H2 0.1, H2O 0.2, N2 0.3).
tc::ChemInput chemistryInput(const ParticleData& p, const CouplingGrid& g, double tGas, double dt) {
  using namespace coredem::dem::kernels;
  tc::ChemInput in;
  in.n = p.count;
  in.T = p.temperature;
  in.mass = p.mass;
  in.dt = dt;
  in.Y.resize(p.count * tc::kSolids);
  in.cell.resize(p.count);
  for (std::size_t i = 0; i < p.count; ++i) {
    in.Y[tc::kSolids * i] = 0.6;
    in.Y[tc::kSolids * i + 1] = 0.3;
    in.Y[tc::kSolids * i + 2] = 0.1;
    int idx3[3];
    for (int d = 0; d < 3; ++d) {
      const int k = static_cast<int>((p.position[3 * i + d] - g.origin[d]) / g.spacing[d]);
      idx3[d] = std::clamp(k, 0, g.counts[d] - 1);
    }
    in.cell[i] = idx3[0] + g.counts[0] * (idx3[1] + g.counts[1] * idx3[2]);
  }
  const std::size_t nc = g.cellCount();
  const double x[tc::kGas] = {0.2, 0.2, 0.1, 0.2, 0.3}; // GasSpecies order: CO, CO2, H2, H2O, N2
  const double pTot = 1.0e5;
  in.pBar.resize(nc * tc::kGas);
  in.conc.resize(nc * tc::kGas);
  for (std::size_t c = 0; c < nc; ++c) {
    for (int k = 0; k < tc::kGas; ++k) {
      in.pBar[tc::kGas * c + k] = x[k] * pTot / 1.0e5;
      in.conc[tc::kGas * c + k] = x[k] * pTot / (8.314462618 * tGas);
    }
  }
  return in;
}

/// cpu: one OpenMP loop per stage with the engine's schedule (dynamic, chunks of 512).
tc::ChemTimes runChemistryCpu(const tc::ChemInput& in, int reps, int threads) {
  const std::size_t n = in.n;
  std::vector<double> m = in.mass, y = in.Y, mdot(n * tc::kSolids), mg(n * tc::kGas), q(n), d(n);
  std::vector<std::int32_t> removed(n);
  const tc::ChemArrays a{n,
                         in.T.data(),
                         in.mass.data(),
                         in.cell.data(),
                         in.pBar.data(),
                         in.conc.data(),
                         m.data(),
                         y.data(),
                         mdot.data(),
                         mg.data(),
                         q.data(),
                         d.data(),
                         removed.data(),
                         in.dt,
                         in.density};
  const auto gen = tc::genericReaction();
  const int nt = threads > 0 ? threads : omp_get_max_threads();
  tc::ChemTimes t;
  t.reps = reps;
  for (int r = 0; r < reps; ++r) {
    for (int s = 0; s < tc::kChemStageCount; ++s) {
      const auto t0 = Clock::now();
      const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(dynamic, 512) num_threads(nt)
      for (std::int64_t i = 0; i < count; ++i)
        tc::chemBody(s, a, gen, static_cast<std::size_t>(i));
      t.seconds[s] += std::chrono::duration<double>(Clock::now() - t0).count();
    }
  }
  return t;
}

int runThermochem(int argc, char** argv) {
  coredem::bench::Args app{
      "Thermochemistry sub-models: ns per particle and DEM sub-step (seed Table 2 / Fig. 19)",
      "coredem-bench thermochem"};
  Options o;
  bool json = false;
  app.option("--particles", o.n, "number of particles").range(1.0, 2.0e9);
  app.option("--threads", o.threads, "OpenMP threads (cpu backend; 0 = OpenMP default)")
      .nonNegative();
  app.option("--backend", o.backend, "cpu | cuda | auto").oneOf({"cpu", "cuda", "auto"});
  app.option("--case", o.deckName, "deck of bench/decks.md: packed | agitated")
      .oneOf({"packed", "agitated"});
  app.option("--steps", o.steps, "measured sub-steps per repeat").positive();
  app.option("--warmup", o.warmup, "unmeasured sub-steps first").nonNegative();
  app.option("--repeat", o.repeat, "measured runs per variant (medians reported)").positive();
  app.flag("--json", json, "print one JSON object");
  if (const int rc = app.parse(argc, argv); rc >= 0)
    return rc;
  try {
    const BackendKind kind = parseBackend(o.backend);
    const CudaProbe probe = probeCuda();
    if (kind == BackendKind::Cuda && (!probe.error.empty() || probe.devices == 0))
      throw coredem::UserError("--backend cuda: " +
                               (probe.error.empty() ? probe.note : probe.error));
    if (kind == BackendKind::Auto && probe.devices == 0)
      std::fprintf(stderr, "coredem-bench thermochem: backend auto runs on the cpu: %s\n",
                   (probe.error.empty() ? probe.note : probe.error).c_str());
    const bool cuda = kind == BackendKind::Cuda || (kind == BackendKind::Auto && probe.devices > 0);
    Measured m[kVariantCount];
    ParticleData particles;
    CouplingGrid grid;
    const auto t0 = Clock::now();
    for (int v = 0; v < kVariantCount; ++v) {
      const bool last = v == kAllHeat;
      m[v] = runVariant(o, kVariants[v], last ? &particles : nullptr, last ? &grid : nullptr);
      if (!json)
        std::fprintf(stderr, "  variant %-20s done (%.1f s so far)\n", kVariants[v].name,
                     std::chrono::duration<double>(Clock::now() - t0).count());
    }
    const double dt = DemSystem(makeConfig(o, kVariants[0]), BackendKind::Cpu, 1).dtDemMax();
    const tc::ChemInput chemIn = chemistryInput(particles, grid, o.tGas, dt);
    const int chemReps = o.steps * o.repeat;
    const tc::ChemTimes chem = cuda ? tc::runChemistryCuda(chemIn, chemReps)
                                    : runChemistryCpu(chemIn, chemReps, o.threads);

    // ns per particle and sub-step.
    const double per = 1e9 / static_cast<double>(o.n);
    const Measured& mech = m[0];
    const Measured& base = m[1];
    struct Row {
      std::string name, source;
      double ns;
    };
    std::vector<Row> rows;
    rows.push_back({"convection", "engine", (m[2].heat - base.heat) * per});
    rows.push_back({"contact_conduction", "engine", (m[3].heat - base.heat) * per});
    rows.push_back({"gas_lens_conduction", "engine", (m[4].heat - base.heat) * per});
    rows.push_back({"radiation", "engine", (m[5].heat - base.heat) * per});
    for (int s = 0; s < tc::kChemStageCount; ++s)
      rows.push_back({tc::kChemStageNames[s], "kernels", chem.seconds[s] / chem.reps * per});
    rows.push_back({"temperature_update", "engine", (base.integrate - mech.integrate) * per});
    rows.push_back({"heat_stage_base", "engine", base.heat * per});
    rows.push_back({"all_heat_stage", "engine", m[kAllHeat].heat * per});
    // The engine's chemistry stage (rates, mass/diameter/species update, deposition), one model a
    // run.
    rows.push_back({"chemistry_stage_clg_r1_r2", "engine", m[7].chemistry * per});
    rows.push_back({"chemistry_stage_clg_r4_r5", "engine", m[8].chemistry * per});
    rows.push_back({"chemistry_stage_generic", "engine", m[9].chemistry * per});
    // Context: the mechanics of the same step.
    std::vector<Row> ctx;
    ctx.push_back({"contact_forces", "engine", mech.contact * per});
    ctx.push_back({"integration", "engine", mech.integrate * per});
    ctx.push_back({"coupling_pcm", "engine", mech.coupling * per});
    ctx.push_back({"neighbour", "engine", mech.neighbour * per});
    ctx.push_back({"whole_step_mechanics", "engine", mech.wall * per});
    ctx.push_back({"whole_step_all_heat", "engine", m[kAllHeat].wall * per});
    ctx.push_back({"lens_neighbour_list_overhead", "engine",
                   ((m[4].contact + m[4].neighbour) - (base.contact + base.neighbour)) * per});

    const std::string backendUsed = cuda ? "cuda" : "cpu";
    if (json) {
      std::printf("{\"command\":\"thermochem\",\"case\":\"%s\",\"backend\":\"%s\",\"threads\":%d,"
                  "\"particles\":%zu,\"steps\":%d,\"repeat\":%d,\"dt_dem\":%.6e,\"unit\":\"ns per "
                  "particle per sub-step\","
                  "\"sub_models\":{",
                  o.deckName.c_str(), backendUsed.c_str(), o.threads, o.n, o.steps, o.repeat, dt);
      for (std::size_t k = 0; k < rows.size(); ++k)
        std::printf("%s\"%s\":%.3f", k ? "," : "", rows[k].name.c_str(), rows[k].ns);
      std::printf("},\"source\":{");
      for (std::size_t k = 0; k < rows.size(); ++k)
        std::printf("%s\"%s\":\"%s\"", k ? "," : "", rows[k].name.c_str(), rows[k].source.c_str());
      std::printf("},\"context\":{");
      for (std::size_t k = 0; k < ctx.size(); ++k)
        std::printf("%s\"%s\":%.3f", k ? "," : "", ctx[k].name.c_str(), ctx[k].ns);
      std::printf("},\"rebuilds\":{");
      for (int v = 0; v < kVariantCount; ++v)
        std::printf("%s\"%s\":%llu", v ? "," : "", kVariants[v].name,
                    static_cast<unsigned long long>(m[v].rebuilds));
      std::printf("}}\n");
    } else {
      std::printf("thermochem: case %s, backend %s, threads %d, N = %zu, %d sub-steps x %d repeats "
                  "(medians), dt_DEM = %.4e s\n",
                  o.deckName.c_str(), backendUsed.c_str(), o.threads, o.n, o.steps, o.repeat, dt);
      std::printf("T_p = %.0f K, T_g = %.0f K, gas rising at %.2f m/s, PCM cells of 4 d_p\n\n",
                  o.tParticle, o.tGas, o.uGas);
      std::printf("%-30s %14s   %s\n", "sub-model", "ns/particle", "how");
      for (const Row& r : rows)
        std::printf("%-30s %14.2f   %s\n", r.name.c_str(), r.ns,
                    r.source != "engine" ? "kernel loop over the engine's particles"
                    : r.name.rfind("chemistry_stage", 0) == 0
                        ? "in the DEM step (its chemistry stage)"
                        : "in the DEM step (difference of stage times)");
      std::printf("\ncontext (same deck, heat off unless named):\n");
      for (const Row& r : ctx)
        std::printf("%-30s %14.2f\n", r.name.c_str(), r.ns);
    }
    return 0;
  } catch (const coredem::UserError& e) {
    std::fprintf(stderr, "coredem-bench thermochem: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coredem-bench thermochem: %s\n", e.what());
    return 1;
  }
}

} // namespace

#if !defined(COREDEM_BENCH_CUDA)
coredem::bench::thermochem::ChemTimes coredem::bench::thermochem::runChemistryCuda(const ChemInput&,
                                                                                   int) {
  throw std::runtime_error(
      "this coredem-bench was built without the CUDA backend; configure with "
      "-DCOREDEM_CUDA=ON (scripts/gpu-check.sh) to time the cuda chemistry loops");
}
#endif

COREDEM_BENCH_COMMAND("thermochem", "thermochemistry sub-models: ns per particle per sub-step",
                      runThermochem);
