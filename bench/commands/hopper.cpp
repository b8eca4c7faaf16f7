// The `hopper` deck of bench/decks.md for `coredem-bench dem --case hopper` (see hopper.h).
//
// Phase 1 (hopper/deck.cpp; untimed, cached in the deck directory): a jittered cubic lattice inside
// the hopper, outlet closed by a plate (the plane z = 0), settles under gravity with the analytic
// walls until it is at rest; the bed (positions, velocities, spins) is written to hopper.particles
// with the deck's parameters (hopper.deck) and the STL files (hopper.stl, cone.stl, bin.stl). Phase
// 2: a new DemSystem without the plate starts from that bed (tangential history empty, as in
// LIGGGHTS reading the same file) and discharges into the bin; WARMUP untimed steps, then STEPS
// timed ones. Every SAMPLE steps the particles whose centre lies below the outlet plane are
// counted; the discharge rate is the least-squares slope of that mass against time between the
// discharged fractions fitLo and fitHi, compared with Beverloo's correlation.
#include "hopper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "coredem/common/check.h"
#include "dem.h"
#include "hopper/deck.h"

namespace coredem::bench::hopper {

namespace fs = std::filesystem;
using namespace coredem::dem;

namespace {

/// Beverloo's correlation W = C ρ_b √g (D_o − k d_p)^2.5 and the usual spread of C and k.
constexpr double kBeverlooC = 0.58, kBeverlooK = 1.5;
constexpr double kBeverlooCLo = 0.55, kBeverlooCHi = 0.65;
constexpr double kBeverlooKLo = 1.3, kBeverlooKHi = 2.9;

MeshWall meshWall(const fs::path& file) {
  try {
    const TriangleMesh m = readStl(file);
    return MeshWall{m.name, m.vertices, m.triangles};
  } catch (const MeshError& e) {
    throw UserError(e.what());
  }
}

/// The run's system: the settled bed with the walls of the variant.
DemConfig runConfig(const Geometry& g, const Settled& s, const Options& o, const fs::path& dir) {
  DemConfig c;
  c.materials[0] = material();
  c.gravity = {0, 0, -kGravity};
  c.particleSets.push_back(explicitSet(s));
  c.heat.enabled = o.heat;
  if (o.skin >= 0)
    c.neighbour.skinFactor = o.skin;
  const double inf = std::numeric_limits<double>::infinity();
  if (o.walls == "none") { // the bed alone: no walls, no gravity
    c.gravity = {0, 0, 0};
    return c;
  }
  if (o.walls == "primitive") {
    // analytic cone; the cylinder is infinite as LIGGGHTS' zcylinder (it is the bin's wall too)
    c.walls.push_back(Wall::cone({0, 0, 0}, {0, 0, 1}, 0.0, g.hCone, g.rOut, g.rCyl));
    c.walls.push_back(Wall::cylinder({0, 0, 0}, {0, 0, 1}, g.rCyl, -inf, inf));
  } else {
    // the STL files of the deck directory, as LIGGGHTS reads them
    c.meshes.push_back(meshWall(dir / "hopper.stl"));
    c.meshes.push_back(meshWall(dir / "bin.stl"));
  }
  c.walls.push_back(Wall::plane({0, 0, g.zFloor}, {0, 0, 1}));
  if (o.closed)
    c.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
  return c;
}

struct Sample {
  double t;          ///< since the opening (s)
  std::size_t below; ///< particles with the centre below the outlet plane
  std::size_t walls; ///< wall contacts
  std::size_t pairs; ///< particle–particle contact pairs
  double wall;       ///< wall-clock seconds in advance() since the opening (warm-up included)
  unsigned long long rebuilds; ///< neighbour-list rebuilds since the opening
};

struct Fit {
  bool ok = false, complete = false;
  double rate = 0; ///< particles/s
  double t0 = 0, t1 = 0, r2 = 0;
  int points = 0;
  std::string note;
};

/// Least-squares slope of the discharged count against time over the samples with
/// lo·N <= count <= hi·N; `complete` when the run reached hi·N.
Fit fitRate(const std::vector<Sample>& samples, std::size_t n, double lo, double hi) {
  Fit f;
  const double cLo = lo * static_cast<double>(n), cHi = hi * static_cast<double>(n);
  double st = 0, sc = 0, stt = 0, stc = 0, scc = 0;
  for (const Sample& s : samples) {
    const double c = static_cast<double>(s.below);
    if (c < cLo || c > cHi)
      continue;
    if (f.points == 0)
      f.t0 = s.t;
    f.t1 = s.t;
    ++f.points;
    st += s.t;
    sc += c;
    stt += s.t * s.t;
    stc += s.t * c;
    scc += c * c;
  }
  f.complete = !samples.empty() && static_cast<double>(samples.back().below) >= cHi;
  if (f.points < 3) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "%d samples between %.0f%% and %.0f%% discharged (the run ended at %.1f%%)",
                  f.points, 100 * lo, 100 * hi,
                  samples.empty()
                      ? 0.0
                      : 100.0 * static_cast<double>(samples.back().below) / static_cast<double>(n));
    f.note = buf;
    return f;
  }
  const double m = f.points;
  const double vt = stt - st * st / m, vc = scc - sc * sc / m, cov = stc - st * sc / m;
  f.rate = cov / vt;
  f.r2 = vc > 0 ? cov * cov / (vt * vc) : 1.0;
  f.ok = true;
  if (!f.complete)
    f.note = "the run ended before the upper fraction: fitted up to its end";
  return f;
}

double beverloo(double rhoB, double c, double k, double outletD) {
  return c * rhoB * std::sqrt(kGravity) * std::pow(outletD - k * kDiameter, 2.5);
}

std::size_t countBelow(const DemSystem& sys, double z) {
  const ParticleData p = sys.particles();
  std::size_t c = 0;
  for (std::size_t i = 0; i < p.count; ++i)
    c += p.position[3 * i + 2] < z;
  return c;
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v))
    return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

/// A temporary deck directory removed at the end of the run.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "coredem-hopper.XXXXXX").string();
    if (!mkdtemp(tmpl.data()))
      throw UserError("cannot create a temporary directory under " +
                      fs::temp_directory_path().string());
    path = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

int runDeck(const Options& o);

/// The deck directory (a temporary one without --deck-dir) and its settled bed.
struct Deck {
  std::unique_ptr<TempDir> tmp;
  fs::path dir;
  Settled bed;
  bool cached = false; ///< read from the directory (else settled now and written to it)
};

/// The deck directory with the settled bed for g: read, or settled now and written.
Deck openDeck(const Geometry& g, const Options& o) {
  Deck deck;
  if (o.deckDir.empty()) {
    deck.tmp = std::make_unique<TempDir>();
    deck.dir = deck.tmp->path;
  } else {
    deck.dir = o.deckDir;
    fs::create_directories(deck.dir);
  }
  Settled& bed = deck.bed;
  deck.cached = !o.resettle && readDeck(deck.dir, g, bed);
  if (!deck.cached) {
    double dt = 0;
    bed = settle(g, o, dt);
    double ke = 0;
    for (std::size_t i = 0; i < bed.velocity.size() / 3; ++i)
      ke += 0.5 * particleMass() *
            (bed.velocity[3 * i] * bed.velocity[3 * i] +
             bed.velocity[3 * i + 1] * bed.velocity[3 * i + 1] +
             bed.velocity[3 * i + 2] * bed.velocity[3 * i + 2]);
    writeDeck(deck.dir, g, bed, dt, ke);
  }
  return deck;
}

/// --settle-only: the deck and its bed.
void reportSettled(const Options& o, const Geometry& g, const Deck& deck) {
  const fs::path& dir = deck.dir;
  const Settled& bed = deck.bed;
  const bool cached = deck.cached;
  if (o.json) {
    std::printf("{\"command\":\"dem\",\"case\":\"hopper\",\"settle_only\":true,\"particles\":%zu,"
                "\"deck_dir\":\"%s\",\"cached\":%s,\"settle_time_s\":%s,\"settle_steps\":%llu,"
                "\"rho_bulk\":%s,\"r_cyl\":%s,\"h_cone\":%s,\"outlet_d\":%s}\n",
                o.n, dir.string().c_str(), cached ? "true" : "false", jsonNumber(bed.time).c_str(),
                bed.steps, jsonNumber(bed.rhoBulk).c_str(), jsonNumber(g.rCyl).c_str(),
                jsonNumber(g.hCone).c_str(), jsonNumber(g.outletD).c_str());
  } else {
    std::printf("hopper deck in %s (%s): N = %zu, D_o = %.4g m, R_c = %.4g m, cone height "
                "%.4g m, bed top %.4g m, rho_b = %.1f kg/m^3\n",
                dir.string().c_str(), cached ? "cached" : "settled now", o.n, g.outletD, g.rCyl,
                g.hCone, bed.bedTop, bed.rhoBulk);
  }
}

/// The discharge: the samples (every o.sample steps and at the end) and the timed loop's
/// times and mean contact counts.
struct Discharge {
  std::vector<Sample> samples;
  double timedWall = 0, timedCpu = 0, sampleWall = 0;
  double wallContactsTimed = 0, pairContactsTimed = 0;
  int timedSamples = 0, done = 0;
  bool stopped = false; ///< at --until before the last step
};

/// Runs o.warmup untimed and o.steps timed steps of dt, sampling every o.sample steps.
Discharge discharge(DemSystem& sys, const Options& o, double dt) {
  const std::size_t n = o.n;
  std::vector<Sample> samples;
  double advanceWall = 0;
  unsigned long long rebuildsBefore = 0; // of the warm-up, once the stage times are reset
  auto record = [&] {
    const std::size_t all = sys.contactCount(), pairs = sys.pairContactCount();
    samples.push_back(Sample{sys.time(), countBelow(sys, 0.0), all - pairs, pairs, advanceWall,
                             rebuildsBefore + sys.stageTimes().rebuilds});
  };
  record(); // step 0
  double timedWall = 0, timedCpu = 0, sampleWall = 0;
  double wallContactsTimed = 0, pairContactsTimed = 0;
  int timedSamples = 0, done = 0;
  const int total = o.warmup + o.steps;
  bool stopped = false;
  auto lastNote = std::chrono::steady_clock::now();
  sys.resetStageTimes();
  while (done < total) {
    int next = (done / o.sample + 1) * o.sample;
    if (done < o.warmup)
      next = std::min(next, o.warmup);
    next = std::min(next, total);
    const int k = next - done;
    const bool timed = done >= o.warmup;
    const auto a = std::chrono::steady_clock::now();
    const std::clock_t ca = std::clock();
    sys.advance(k * dt, k);
    const double w = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
    const double c = static_cast<double>(std::clock() - ca) / CLOCKS_PER_SEC;
    advanceWall += w;
    if (timed) {
      timedWall += w;
      timedCpu += c;
    }
    done = next;
    if (done == o.warmup && o.warmup > 0) {
      rebuildsBefore = sys.stageTimes().rebuilds;
      sys.resetStageTimes(); // stage times of the timed loop only
    }
    if (done % o.sample == 0 || done == total) {
      const auto s0 = std::chrono::steady_clock::now();
      record();
      sampleWall += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - lastNote).count() >
          30.0) {
        lastNote = std::chrono::steady_clock::now();
        std::fprintf(stderr, "  step %d of %d: t = %.4f s, %.1f %% discharged, %zu wall contacts\n",
                     done, total, sys.time(),
                     100.0 * static_cast<double>(samples.back().below) / static_cast<double>(n),
                     samples.back().walls);
      }
      if (timed) {
        wallContactsTimed += static_cast<double>(samples.back().walls);
        pairContactsTimed += static_cast<double>(samples.back().pairs);
        ++timedSamples;
      }
      if (o.until > 0 &&
          static_cast<double>(samples.back().below) >= o.until * static_cast<double>(n) &&
          done >= o.warmup) {
        stopped = done < total;
        break;
      }
    }
  }
  return Discharge{std::move(samples), timedWall,    timedCpu, sampleWall, wallContactsTimed,
                   pairContactsTimed,  timedSamples, done,     stopped};
}

/// What the report prints besides the options, the geometry and the bed.
struct Result {
  double rhoB, wBev, wLo, wHi; ///< Beverloo: ρ_b used, the rate and its band (kg/s)
  double setup, dt, keInitial, keFinal;
  Discharge d;
  int timedSteps;
  StageTimes st;
  Fit fit;
  double m, rate, pairsPer, wallPer, wallMean, pairMean, discharged;
  int usedThreads;
};

/// --samples-out: one line per sample.
void writeSamples(const Options& o, const std::vector<Sample>& samples) {
  std::ofstream f(o.samplesOut);
  COREDEM_CHECK(static_cast<bool>(f), "cannot write --samples-out {}", o.samplesOut);
  f << "# t_s below_outlet wall_contacts pair_contacts advance_wall_s rebuilds (every " << o.sample
    << " steps; wall clock and rebuilds since the opening, warm-up included)\n";
  for (const Sample& s : samples)
    f << fmt17(s.t) << ' ' << s.below << ' ' << s.walls << ' ' << s.pairs << ' ' << fmt17(s.wall)
      << ' ' << s.rebuilds << '\n';
}

void reportJson(const Options& o, const Geometry& g, const Deck& deck, const DemSystem& sys,
                const Result& r) {
  const fs::path& dir = deck.dir;
  const Settled& bed = deck.bed;
  const bool cached = deck.cached;
  const std::size_t n = o.n;
  const Fit& fit = r.fit;
  const StageTimes& st = r.st;
  const double dt = r.dt, setup = r.setup, keInitial = r.keInitial, keFinal = r.keFinal;
  const double timedWall = r.d.timedWall, timedCpu = r.d.timedCpu, sampleWall = r.d.sampleWall;
  const double m = r.m, rate = r.rate, pairsPer = r.pairsPer, wallPer = r.wallPer;
  const double wallMean = r.wallMean, pairMean = r.pairMean, discharged = r.discharged;
  const double rhoB = r.rhoB, wBev = r.wBev, wLo = r.wLo, wHi = r.wHi;
  const int timedSteps = r.timedSteps, usedThreads = r.usedThreads;
  const bool stopped = r.d.stopped;
  std::printf(
      "{\"command\":\"dem\",\"case\":\"hopper\",\"walls\":\"%s\",\"closed\":%s,"
      "\"backend\":\"%s\",\"threads\":%d,\"particles\":%zu,\"steps\":%d,\"warmup\":%d,"
      "\"stopped_at_until\":%s,\"sample_every\":%d,"
      "\"dt_dem\":%.6e,\"skin_factor\":%.4g,\"wall_s\":%.6f,\"setup_s\":%.6f,"
      "\"sampling_s\":%.6f,\"particle_steps_per_s\":%.6e,\"cpu_s\":%.6f,"
      "\"cpu_utilisation\":%.3f,\"contacts_per_particle\":%.4f,"
      "\"wall_contacts_per_particle\":%.4f,\"wall_contacts_per_step\":%s,"
      "\"pair_contacts_per_step\":%s,\"rebuilds\":%llu,"
      "\"stage_s\":{\"neighbour\":%.6f,\"contact\":%.6f,\"integrate\":%.6f,\"heat\":%.6f},"
      "\"ke_initial\":%.17g,\"ke_final\":%.17g,\"deck_dir\":\"%s\",\"deck_cached\":%s,"
      "\"geometry\":{\"d_p\":%s,\"outlet_d\":%s,\"half_angle_deg\":%s,\"r_cyl\":%s,"
      "\"h_cone\":%s,\"h_top\":%s,\"z_floor\":%s,\"segments\":%d},"
      "\"settle\":{\"time_s\":%s,\"steps\":%llu,\"vmax\":%s,\"bed_top\":%s},"
      "\"discharge\":{\"time_s\":%s,\"discharged_fraction\":%.6f,\"fit_lo\":%g,\"fit_hi\":%g,"
      "\"fit_ok\":%s,\"fit_complete\":%s,\"fit_points\":%d,\"fit_t0\":%s,\"fit_t1\":%s,"
      "\"fit_r2\":%s,\"rate_particles_per_s\":%s,\"rate_kg_per_s\":%s,\"note\":\"%s\"},"
      "\"beverloo\":{\"C\":%g,\"k\":%g,\"rho_b\":%s,\"rho_b_measured\":%s,"
      "\"rho_b_with_wall_layer\":%s,\"g\":%g,"
      "\"rate_kg_per_s\":%s,\"band_kg_per_s\":[%s,%s],\"band_C\":[%g,%g],\"band_k\":[%g,%g],"
      "\"ratio\":%s,\"in_band\":%s}}\n",
      o.walls.c_str(), o.closed ? "true" : "false", sys.backendName().c_str(), o.threads, n,
      timedSteps, o.warmup, stopped ? "true" : "false", o.sample, dt,
      sys.config().neighbour.skinFactor, timedWall, setup, sampleWall, rate, timedCpu,
      timedWall > 0 ? timedCpu / (timedWall * usedThreads) : 0.0, pairsPer, wallPer,
      jsonNumber(wallMean).c_str(), jsonNumber(pairMean).c_str(),
      static_cast<unsigned long long>(st.rebuilds), st.neighbour, st.contact, st.integrate, st.heat,
      keInitial, keFinal, dir.string().c_str(), cached ? "true" : "false",
      jsonNumber(kDiameter).c_str(), jsonNumber(g.outletD).c_str(),
      jsonNumber(kHalfAngleDeg).c_str(), jsonNumber(g.rCyl).c_str(), jsonNumber(g.hCone).c_str(),
      jsonNumber(g.hTop).c_str(), jsonNumber(g.zFloor).c_str(), kSegments,
      jsonNumber(bed.time).c_str(), bed.steps, jsonNumber(bed.vMax).c_str(),
      jsonNumber(bed.bedTop).c_str(), jsonNumber(sys.time()).c_str(), discharged, o.fitLo, o.fitHi,
      fit.ok ? "true" : "false", fit.complete ? "true" : "false", fit.points,
      jsonNumber(fit.t0).c_str(), jsonNumber(fit.t1).c_str(), jsonNumber(fit.r2).c_str(),
      fit.ok ? jsonNumber(fit.rate).c_str() : "null",
      fit.ok ? jsonNumber(fit.rate * m).c_str() : "null", fit.note.c_str(), kBeverlooC, kBeverlooK,
      jsonNumber(rhoB).c_str(), bed.rhoBulk > 0 ? "true" : "false", jsonNumber(bed.rhoAll).c_str(),
      kGravity, jsonNumber(wBev).c_str(), jsonNumber(wLo).c_str(), jsonNumber(wHi).c_str(),
      kBeverlooCLo, kBeverlooCHi, kBeverlooKLo, kBeverlooKHi,
      fit.ok ? jsonNumber(fit.rate * m / wBev).c_str() : "null",
      fit.ok ? (fit.rate * m >= wLo && fit.rate * m <= wHi ? "true" : "false") : "null");
}

void reportText(const Options& o, const Geometry& g, const Deck& deck, const DemSystem& sys,
                const Result& r) {
  const fs::path& dir = deck.dir;
  const Settled& bed = deck.bed;
  const bool cached = deck.cached;
  const std::size_t n = o.n;
  const Fit& fit = r.fit;
  const StageTimes& st = r.st;
  const double dt = r.dt, setup = r.setup;
  const double timedWall = r.d.timedWall, timedCpu = r.d.timedCpu, sampleWall = r.d.sampleWall;
  const double m = r.m, rate = r.rate, pairsPer = r.pairsPer, wallPer = r.wallPer;
  const double wallMean = r.wallMean, pairMean = r.pairMean, discharged = r.discharged;
  const double rhoB = r.rhoB, wBev = r.wBev, wLo = r.wLo, wHi = r.wHi;
  const int timedSteps = r.timedSteps;
  std::printf("case hopper (walls %s%s), backend %s, threads %d, N = %zu, %d + %d steps of "
              "dt_DEM = %.4e s (skin %.3g d)\n",
              o.walls.c_str(), o.closed ? ", outlet closed" : "", sys.backendName().c_str(),
              o.threads, n, o.warmup, timedSteps, dt, sys.config().neighbour.skinFactor);
  std::printf("deck                     %s (%s): D_o = %.3g mm, R_c = %.3g mm, cone %.3g mm "
              "high, walls to %.3g mm, floor at %.3g mm\n",
              dir.string().c_str(), cached ? "settled bed read" : "settled now", 1e3 * g.outletD,
              1e3 * g.rCyl, 1e3 * g.hCone, 1e3 * g.hTop, 1e3 * g.zFloor);
  std::printf("particle_steps_per_s     %.4e  (timed loop, sampling excluded: %.3f s)\n", rate,
              sampleWall);
  std::printf("contacts_per_particle    %.3f  (+ %.3f wall contacts) at the end\n", pairsPer,
              wallPer);
  std::printf("wall contacts per step   %.1f  (mean over the timed samples; pair contacts "
              "%.1f)\n",
              wallMean, pairMean);
  std::printf("wall time                %.3f s  (set-up %.3f s), cpu %.3f s, %llu rebuilds\n",
              timedWall, setup, timedCpu, static_cast<unsigned long long>(st.rebuilds));
  std::printf("discharged               %.1f %% after %.4f s\n", 100 * discharged, sys.time());
  if (fit.ok)
    std::printf("discharge rate           %.4e kg/s = %.1f particles/s (fit %.0f-%.0f %%: "
                "t = %.4f..%.4f s, %d samples, R^2 = %.5f)%s%s\n",
                fit.rate * m, fit.rate, 100 * o.fitLo, 100 * o.fitHi, fit.t0, fit.t1, fit.points,
                fit.r2, fit.note.empty() ? "" : "; ", fit.note.c_str());
  else
    std::printf("discharge rate           n/a: %s\n", fit.note.c_str());
  std::printf(
      "Beverloo                 %.4e kg/s (C = %g, k = %g, rho_b = %.1f kg/m^3%s), "
      "band %.4e..%.4e kg/s (C %g-%g, k %g-%g)%s\n",
      wBev, kBeverlooC, kBeverlooK, rhoB, bed.rhoBulk > 0 ? " measured" : " = 0.6 rho_p", wLo, wHi,
      kBeverlooCLo, kBeverlooCHi, kBeverlooKLo, kBeverlooKHi,
      fit.ok ? (fit.rate * m >= wLo && fit.rate * m <= wHi ? ": in the band" : ": OUTSIDE the band")
             : "");
}

} // namespace

int run(const Options& o) {
  try {
    return runDeck(o);
  } catch (const fs::filesystem_error& e) {
    throw UserError(std::string("hopper deck directory: ") + e.what());
  }
}

namespace {

int runDeck(const Options& o) {
  const Geometry g = geometry(o.n, o.outlet);
  COREDEM_CHECK(o.walls == "primitive" || o.walls == "stl" || o.walls == "none",
                "--walls {}: use primitive, stl or none", o.walls);
  COREDEM_CHECK(o.sample >= 1, "--sample must be >= 1");
  COREDEM_CHECK(o.fitLo >= 0 && o.fitLo < o.fitHi && o.fitHi <= 1,
                "--fit-lo {} / --fit-hi {}: need 0 <= lo < hi <= 1", o.fitLo, o.fitHi);
  const Deck deck = openDeck(g, o);
  const Settled& bed = deck.bed;
  Result r{};
  r.rhoB = bed.rhoBulk > 0 ? bed.rhoBulk : kFillFraction * kDensity;
  r.wBev = beverloo(r.rhoB, kBeverlooC, kBeverlooK, g.outletD);
  r.wLo = beverloo(r.rhoB, kBeverlooCLo, kBeverlooKHi, g.outletD);
  r.wHi = beverloo(r.rhoB, kBeverlooCHi, kBeverlooKLo, g.outletD);
  if (o.settleOnly) {
    reportSettled(o, g, deck);
    return 0;
  }

  const auto t0 = std::chrono::steady_clock::now();
  DemSystem sys(runConfig(g, bed, o, deck.dir), parseBackend(o.backend), o.threads);
  r.setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.dt = sys.dtDemMax();
  r.keInitial = kineticEnergy(sys);
  const std::size_t n = o.n;

  r.d = discharge(sys, o, r.dt);
  r.timedSteps = std::max(0, r.d.done - o.warmup);
  r.st = sys.stageTimes();
  r.keFinal = kineticEnergy(sys);
  r.fit = fitRate(r.d.samples, n, o.fitLo, o.fitHi);
  r.m = particleMass();
  r.rate = r.d.timedWall > 0 ? static_cast<double>(n) * r.timedSteps / r.d.timedWall : 0.0;
  r.pairsPer = 2.0 * static_cast<double>(sys.pairContactCount()) / static_cast<double>(n);
  r.wallPer =
      static_cast<double>(sys.contactCount() - sys.pairContactCount()) / static_cast<double>(n);
  r.wallMean = r.d.timedSamples ? r.d.wallContactsTimed / r.d.timedSamples : NAN;
  r.pairMean = r.d.timedSamples ? r.d.pairContactsTimed / r.d.timedSamples : NAN;
  r.discharged = static_cast<double>(r.d.samples.back().below) / static_cast<double>(n);
  r.usedThreads = o.threads > 0 ? o.threads : 1;

  if (!o.samplesOut.empty())
    writeSamples(o, r.d.samples);
  if (o.json)
    reportJson(o, g, deck, sys, r);
  else
    reportText(o, g, deck, sys, r);
  return 0;
}

} // namespace

} // namespace coredem::bench::hopper
