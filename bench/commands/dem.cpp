// coredem-bench dem: throughput of the DEM core on the decks of bench/decks.md.
//   coredem-bench dem --case packed --particles 100000 --steps 500 --backend cpu --threads 2
//   [--json] [--velocities FILE] [--coupled] [--heat] [--jitter A]
//   coredem-bench dem --case hopper --walls primitive|stl|none [--closed] [--deck-dir DIR]
//   [--outlet D/d] [--sample K] [--until F] [--fit-lo F --fit-hi F] [--samples-out FILE]
//   [--settle-only] [--resettle]   (the hopper deck: bench/commands/hopper.cpp)
// Prints particle_steps_per_s, contacts per particle, bytes per particle and the time per
// stage, and the translational kinetic energy at the start and the end (the peer scripts
// compare it with LIGGGHTS'). Figures are measured, never asserted.
#include "dem.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "coredem/common/check.h"
#include "coredem/dem/dem_system.h"
#include "hopper.h"
#include "options.h"

namespace {

using namespace coredem::dem;
using coredem::bench::addCouplingGrid;
using coredem::bench::BenchGas;
using coredem::bench::deck;
using coredem::bench::kineticEnergy;

/// Initial velocities, one particle per line "vx vy vz" (m/s), in the deck's site order
/// (bench/peers/liggghts/make_deck.py writes them for the agitated deck).
std::vector<double> readVelocities(const std::string& path, std::size_t n) {
  std::ifstream in(path);
  if (!in)
    throw coredem::UserError("cannot open the velocity file '" + path + "'");
  std::vector<double> v;
  v.reserve(3 * n);
  std::string line;
  std::size_t lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream ls(line);
    double x, y, z;
    if (!(ls >> x >> y >> z))
      throw coredem::UserError(path + ":" + std::to_string(lineNo) +
                               ": expected three velocity components 'vx vy vz'");
    v.insert(v.end(), {x, y, z});
  }
  if (v.size() != 3 * n)
    throw coredem::UserError(path + ": " + std::to_string(v.size() / 3) + " velocities for " +
                             std::to_string(n) + " particles");
  return v;
}

/// --jitter: moves the deck's lattice sites by uniform[−a, a)·d_p per component (splitmix64
/// seeded with `seed`, site by site, x, y, z), so that contacts and lens gaps spread as in a
/// random packing: on `packed` with a = 0.02, about half the face neighbours touch and the rest
/// sit inside the gas-lens reach. The sites are those of bench/decks.md (x fastest).
void jitterSites(DemConfig& cfg, double amplitude, std::uint64_t seed) {
  ParticleSet& p = cfg.particleSets.at(0);
  const double s = p.spacing;
  const auto nx = static_cast<std::size_t>(std::llround(p.regionMax[0] / s));
  const auto ny = static_cast<std::size_t>(std::llround(p.regionMax[1] / s));
  std::uint64_t state = seed ^ 0x5bd1e995a5a5a5a5ULL;
  auto uniform = [&state] { // splitmix64, top 53 bits in [0, 1)
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) / 9007199254740992.0;
  };
  p.positions.resize(3 * p.count);
  for (std::size_t idx = 0; idx < p.count; ++idx) {
    const std::size_t site[3] = {idx % nx, (idx / nx) % ny, idx / (nx * ny)};
    for (int d = 0; d < 3; ++d)
      p.positions[3 * idx + d] = (static_cast<double>(site[d]) + 0.5) * s +
                                 amplitude * p.diameter * (2.0 * uniform() - 1.0);
  }
  p.packing = Packing::Explicit;
}

/// The options of `coredem-bench dem`.
struct DemArgs {
  std::string deckName = "packed", backend = "cpu", velocityFile;
  std::size_t n = 10000;
  int steps = 500, threads = 2, warmup = 20;
  double skin = -1;
  bool json = false, coupled = false, heat = false;
  int nSub = 50;
  double jitter = 0.0;
  coredem::bench::hopper::Options hop;
};

/// Declares the options of a; returns those of the hopper deck only.
std::vector<const coredem::bench::Opt*> declareOptions(coredem::bench::Args& app, DemArgs& a) {
  std::string& deckName = a.deckName;
  std::string& backend = a.backend;
  std::string& velocityFile = a.velocityFile;
  std::size_t& n = a.n;
  int &steps = a.steps, &threads = a.threads, &warmup = a.warmup, &nSub = a.nSub;
  double &skin = a.skin, &jitter = a.jitter;
  bool &json = a.json, &coupled = a.coupled, &heat = a.heat;
  coredem::bench::hopper::Options& hop = a.hop;
  app.option("--case", deckName, "deck: packed | agitated | hopper")
      .oneOf({"packed", "agitated", "hopper"});
  app.option("--particles", n, "number of particles (default 10000; hopper: 20000)")
      .range(1.0, 2.0e9);
  app.option("--steps", steps, "measured DEM steps").positive();
  app.option("--warmup", warmup, "unmeasured steps first").nonNegative();
  app.option("--backend", backend, "cpu | cuda | auto | cuda-sim (cpu kernels, cuda memory model)")
      .oneOf({"cpu", "cuda", "auto", "cuda-sim"});
  app.option("--threads", threads, "OpenMP threads (cpu backend)").nonNegative();
  app.option("--skin", skin, "Verlet skin as a fraction of d_max (default: the library's)");
  app.flag("--json", json, "print one JSON object");
  app.option("--velocities", velocityFile,
             "initial velocities from a file, one particle per line 'vx vy vz' (m/s), in "
             "the deck's site order (replaces the deck's seeded ones)");
  app.flag("--coupled", coupled,
           "add a PCM coupling grid (cells of 4 d_p) with air rising at 0.5 m/s");
  app.flag("--heat", heat,
           "switch the heat module on (the decks are mechanics only; with --coupled: "
           "conduction, convection with the gas, lens; radiation needs an emissivity)");
  app.option("--nsub", nSub, "with --coupled: DEM sub-steps per CFD step").positive();
  app.option("--jitter", jitter,
             "move each lattice site by uniform[-a, a) d_p per component (seeded): a "
             "random-like bed (e.g. --case packed --jitter 0.02: touching and lens-gap "
             "pairs mixed)")
      .range(0.0, 0.5);
  // The hopper deck's own options (bench/decks.md `hopper`).
  return {&app.option("--walls", hop.walls,
                      "hopper: primitive (analytic cone + cylinder) | stl (the same as STL "
                      "meshes) | none (the settled bed alone, no walls, no gravity)")
               .oneOf({"primitive", "stl", "none"}),
          &app.flag("--closed", hop.closed,
                    "hopper: keep the outlet closed by its plate (the settled bed at rest)"),
          &app.option("--deck-dir", hop.deckDir,
                      "hopper: directory for the settled bed and the STL files (reused when it "
                      "holds them for the same N and outlet; default: a temporary one)"),
          &app.option("--outlet", hop.outlet, "hopper: outlet diameter in particle diameters")
               .range(2.0, 40.0),
          &app.option("--sample", hop.sample,
                      "hopper: count the discharged particles every K steps (default 500)")
               .positive(),
          &app.option("--until", hop.until,
                      "hopper: stop once this fraction has been discharged (the steps are then "
                      "a maximum)")
               .range(0.0, 1.0),
          &app.option("--fit-lo", hop.fitLo,
                      "hopper: discharged fraction where the rate fit starts (default 0.2)")
               .range(0.0, 1.0),
          &app.option("--fit-hi", hop.fitHi,
                      "hopper: discharged fraction where the rate fit ends (default 0.8)")
               .range(0.0, 1.0),
          &app.option("--samples-out", hop.samplesOut,
                      "hopper: write the samples 't below_outlet wall_contacts pair_contacts "
                      "advance_wall_s rebuilds'"),
          &app.flag("--settle-only", hop.settleOnly,
                    "hopper: settle (or find) the bed and write the deck files, run nothing"),
          &app.flag("--resettle", hop.resettle,
                    "hopper: settle again even if the deck directory holds a settled bed")};
}

/// What a run of a deck measured (reported by report()).
struct Measured {
  double setup, dt, keInitial, wall, cpu, roundTrips, deviceSyncs, launches;
  int usedThreads;
  StageTimes st;
  double keFinal, pairsPer, wallPer, bytesPer, rate;
};

void report(const DemArgs& a, const DemSystem& sys, const DemConfig& cfg, const Measured& m) {
  const std::string &deckName = a.deckName, &velocityFile = a.velocityFile;
  const std::size_t n = a.n;
  const int steps = a.steps, threads = a.threads, warmup = a.warmup, nSub = a.nSub;
  const double jitter = a.jitter;
  const bool json = a.json, coupled = a.coupled, heat = a.heat;
  const double setup = m.setup, dt = m.dt, keInitial = m.keInitial, wall = m.wall, cpu = m.cpu;
  const double roundTrips = m.roundTrips, deviceSyncs = m.deviceSyncs, launches = m.launches;
  const int usedThreads = m.usedThreads;
  const StageTimes& st = m.st;
  const double keFinal = m.keFinal, pairsPer = m.pairsPer, wallPer = m.wallPer;
  const double bytesPer = m.bytesPer, rate = m.rate;
  if (json) {
    std::printf(
        "{\"command\":\"dem\",\"case\":\"%s\",\"backend\":\"%s\",\"threads\":%d,\"particles\":%"
        "zu,"
        "\"steps\":%d,\"dt_dem\":%.6e,\"skin_factor\":%.4g,\"wall_s\":%.6f,\"setup_s\":%.6f,"
        "\"particle_steps_per_s\":%.6e,\"contacts_per_particle\":%.4f,"
        "\"wall_contacts_per_particle\":%.4f,\"bytes_per_particle\":%.1f,"
        "\"heat\":%s,\"stage_s\":{\"neighbour\":%.6f,\"contact\":%.6f,\"integrate\":%.6f,"
        "\"coupling\":%.6f,"
        "\"heat\":%.6f,\"drag\":%.6f},"
        "\"rebuilds\":%llu,\"cpu_s\":%.6f,\"cpu_utilisation\":%.3f,"
        "\"particle_steps_per_cpu_s\":%.6e,\"warmup\":%d,\"ke_initial\":%.17g,"
        "\"ke_final\":%.17g,\"velocities\":\"%s\",\"host_round_trips_per_step\":%.3f,"
        "\"device_syncs_per_step\":%.3f,\"launches_per_step\":%.3f,\"jitter\":%.4g}\n",
        deckName.c_str(), sys.backendName().c_str(), threads, n, steps, dt,
        cfg.neighbour.skinFactor, wall, setup, rate, pairsPer, wallPer, bytesPer,
        heat ? "true" : "false", st.neighbour, st.contact, st.integrate, st.coupling, st.heat,
        st.drag, static_cast<unsigned long long>(st.rebuilds), cpu, cpu / (wall * usedThreads),
        static_cast<double>(n) * steps / cpu, warmup, keInitial, keFinal,
        velocityFile.empty() ? "deck" : "file", roundTrips, deviceSyncs, launches, jitter);
  } else {
    std::printf(
        "case %s, backend %s, threads %d, N = %zu, %d steps of dt_DEM = %.4e s (skin %.3g d, "
        "jitter %.3g d)\n",
        deckName.c_str(), sys.backendName().c_str(), threads, n, steps, dt,
        cfg.neighbour.skinFactor, jitter);
    std::printf("particle_steps_per_s     %.4e\n", rate);
    std::printf("contacts_per_particle    %.3f  (+ %.3f wall contacts)\n", pairsPer, wallPer);
    std::printf("bytes_per_particle       %.0f\n", bytesPer);
    std::printf("kinetic energy           %.10e J at the start, %.10e J at the end\n", keInitial,
                keFinal);
    std::printf("wall time                %.3f s  (set-up %.3f s)\n", wall, setup);
    std::printf("cpu time                 %.3f s  (utilisation %.0f %% of %d threads; %.4e "
                "particle steps per cpu s)\n",
                cpu, 100.0 * cpu / (wall * usedThreads), usedThreads,
                static_cast<double>(n) * steps / cpu);
    std::printf("per sub-step             %.2f host round trips, %.2f device syncs, %.1f "
                "launches (device backends)\n",
                roundTrips, deviceSyncs, launches);
    std::printf("stage neighbour search   %.3f s  (%llu rebuilds)\n", st.neighbour,
                static_cast<unsigned long long>(st.rebuilds));
    std::printf("stage contact forces     %.3f s\n", st.contact);
    std::printf("stage integration        %.3f s\n", st.integrate);
    if (coupled)
      std::printf("stage drag (gas forces)  %.3f s\n", st.drag);
    if (heat)
      std::printf("stage heat               %.3f s\n", st.heat);
    if (coupled)
      std::printf("stage coupling (PCM)     %.3f s  (%zu cells, %d sub-steps per CFD step)\n",
                  st.coupling, sys.cellCount(), nSub);
  }
}

/// The packed or agitated deck: warm-up, timed steps, report.
int runDeck(const DemArgs& a) {
  const std::string &deckName = a.deckName, &backend = a.backend, &velocityFile = a.velocityFile;
  const std::size_t n = a.n;
  const int steps = a.steps, threads = a.threads, warmup = a.warmup, nSub = a.nSub;
  const double skin = a.skin, jitter = a.jitter;
  const bool coupled = a.coupled, heat = a.heat;
  DemConfig cfg = deck(deckName, n);
  if (skin >= 0)
    cfg.neighbour.skinFactor = skin;
  if (jitter > 0)
    jitterSites(cfg, jitter, 20261202);
  if (heat)
    cfg.heat.enabled = true; // default options: contact conduction; the rest needs gas
  if (coupled)
    addCouplingGrid(cfg, 4e-3);
  if (!velocityFile.empty()) {
    cfg.particleSets.at(0).velocities = readVelocities(velocityFile, n);
    cfg.particleSets.at(0).velocityJitter = 0;
  }
  const auto t0 = std::chrono::steady_clock::now();
  DemSystem sys(cfg, parseBackend(backend), threads);
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double dt = sys.dtDemMax();
  const double keInitial = kineticEnergy(sys);
  if (coupled) {
    const BenchGas gas(sys.cellCount(), 0.5, 293.15);
    sys.setGasFields(gas.view());
  }
  // Without coupling one advance() covers all steps; with it, CFD windows of nSub steps.
  auto runSteps = [&](int count) {
    const int window = coupled ? nSub : count;
    for (int done = 0; done < count; done += window) {
      const int k = std::min(window, count - done);
      sys.advance(k * dt, k);
    }
  };
  if (warmup > 0)
    runSteps(warmup);
  sys.resetStageTimes();
  const BackendSyncCounts sync0 = backendSyncCounts();
  const auto t1 = std::chrono::steady_clock::now();
  const std::clock_t c1 = std::clock();
  runSteps(steps);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  // Process CPU time (all threads): cpu / (wall·threads) < 1 shows a shared/loaded machine.
  const double cpu = static_cast<double>(std::clock() - c1) / CLOCKS_PER_SEC;
  // Per sub-step: what made the device backends wait (0 on the cpu backend).
  const BackendSyncCounts sync1 = backendSyncCounts();
  const double perStep = steps > 0 ? 1.0 / steps : 0.0;
  const double roundTrips =
      static_cast<double>(sync1.hostRoundTrips - sync0.hostRoundTrips) * perStep;
  const double deviceSyncs = static_cast<double>(sync1.deviceSyncs - sync0.deviceSyncs) * perStep;
  const double launches = static_cast<double>(sync1.launches - sync0.launches) * perStep;
  const int usedThreads = threads > 0 ? threads : 1;
  const StageTimes st = sys.stageTimes();
  const double keFinal = kineticEnergy(sys);
  const double pairsPer =
      2.0 * static_cast<double>(sys.pairContactCount()) / static_cast<double>(n);
  const double wallPer =
      static_cast<double>(sys.contactCount() - sys.pairContactCount()) / static_cast<double>(n);
  const double bytesPer = static_cast<double>(sys.memoryBytes()) / static_cast<double>(n);
  const double rate = static_cast<double>(n) * steps / wall;
  report(a, sys, cfg,
         Measured{setup, dt, keInitial, wall, cpu, roundTrips, deviceSyncs, launches, usedThreads,
                  st, keFinal, pairsPer, wallPer, bytesPer, rate});
  return 0;
}

int runDem(int argc, char** argv) {
  coredem::bench::Args app{
      "DEM core throughput on the packed / agitated / hopper decks (bench/decks.md)",
      "coredem-bench dem"};
  DemArgs a;
  const std::vector<const coredem::bench::Opt*> hopperOnly = declareOptions(app, a);
  if (const int rc = app.parse(argc, argv); rc >= 0)
    return rc;
  try {
    if (a.deckName == "hopper") {
      COREDEM_CHECK(!a.coupled && a.velocityFile.empty() && a.jitter == 0,
                    "--case hopper takes none of --coupled, --velocities, --jitter");
      coredem::bench::hopper::Options hop = a.hop;
      hop.n = app.count("--particles") ? a.n : 20000;
      hop.steps = a.steps;
      hop.warmup = a.warmup;
      hop.threads = a.threads;
      hop.backend = a.backend;
      hop.skin = a.skin;
      hop.json = a.json;
      hop.heat = a.heat;
      return coredem::bench::hopper::run(hop);
    }
    for (const coredem::bench::Opt* opt : hopperOnly)
      COREDEM_CHECK(opt->count() == 0, "{} applies to --case hopper only", opt->name());
    return runDeck(a);
  } catch (const coredem::UserError& e) {
    std::fprintf(stderr, "coredem-bench dem: %s\n", e.what());
    return 1;
  }
}
} // namespace

COREDEM_BENCH_COMMAND("dem", "DEM core throughput on the packed / agitated decks", runDem);
