// The `hopper` deck of bench/decks.md for `coredem-bench dem --case hopper` (see hopper.h).
//
// Phase 1 (untimed, cached in the deck directory): a jittered cubic lattice inside the hopper,
// outlet closed by a plate (the plane z = 0), settles under gravity with the analytic walls until
// it is at rest; the bed (positions, velocities, spins) is written to hopper.particles with the
// deck's parameters (hopper.deck) and the STL files (hopper.stl, cone.stl, bin.stl).
// Phase 2: a new DemSystem without the plate starts from that bed (tangential history empty,
// as in LIGGGHTS reading the same file) and discharges into the bin; WARMUP untimed steps, then
// STEPS timed ones. Every SAMPLE steps the particles whose centre lies below the outlet plane
// are counted; the discharge rate is the least-squares slope of that mass against time between
// the discharged fractions fitLo and fitHi, compared with Beverloo's correlation.
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
#include <map>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "coredem/common/check.h"
#include "dem.h"

namespace coredem::bench::hopper {

namespace fs = std::filesystem;
using namespace coredem::dem;

namespace {

constexpr const char* kDeckVersion = "hopper-deck-2";
constexpr double kPi = std::numbers::pi;
constexpr double kFillFraction = 0.6; ///< solid fraction assumed when sizing the hopper
constexpr double kSpacingFactor = 1.05;
constexpr double kJitterFactor = 0.02;
constexpr double kClearanceFactor = 0.05;
/// Beverloo's correlation W = C ρ_b √g (D_o − k d_p)^2.5 and the usual spread of C and k.
constexpr double kBeverlooC = 0.58, kBeverlooK = 1.5;
constexpr double kBeverlooCLo = 0.55, kBeverlooCHi = 0.65;
constexpr double kBeverlooKLo = 1.3, kBeverlooKHi = 2.9;

double tanTheta() {
  return std::tan(kHalfAngleDeg * kPi / 180.0);
}

double particleVolume() {
  return kPi * kDiameter * kDiameter * kDiameter / 6.0;
}
double particleMass() {
  return kDensity * particleVolume();
}

/// Volume of the hopper's interior between heights a < b (m³).
double interiorVolume(const Geometry& g, double a, double b) {
  a = std::max(a, 0.0);
  if (b <= a)
    return 0.0;
  const double t = tanTheta();
  auto coneUpTo = [&](double z) { // frustum 0..z
    z = std::min(z, g.hCone);
    const double r1 = g.rOut + z * t;
    return kPi * z / 3.0 * (g.rOut * g.rOut + g.rOut * r1 + r1 * r1);
  };
  auto upTo = [&](double z) {
    return coneUpTo(z) + (z > g.hCone ? kPi * g.rCyl * g.rCyl * (z - g.hCone) : 0.0);
  };
  return upTo(b) - upTo(a);
}

/// Distance in the (ρ, z) half-plane from a point to the segment p–q.
double segmentDistance(double px, double pz, double ax, double az, double bx, double bz) {
  const double ux = bx - ax, uz = bz - az;
  const double len2 = ux * ux + uz * uz;
  double s = len2 > 0 ? ((px - ax) * ux + (pz - az) * uz) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  return std::hypot(px - (ax + s * ux), pz - (az + s * uz));
}

/// splitmix64, top 53 bits in [0, 1) (as the other decks' jitter).
struct SplitMix {
  std::uint64_t state;
  double uniform() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) / 9007199254740992.0;
  }
};

/// The fill: sites of a cubic lattice (spacing s, one column on the axis, layers from the plate
/// up, x fastest, then y) whose jittered sphere keeps a clearance from the plate, cone and
/// cylinder; the first n, each moved by uniform[−a, a) per component (splitmix64 seeded with
/// 20261203 ^ 0x5bd1e995a5a5a5a5, site by site, x, y, z).
std::vector<double> fillSites(const Geometry& g) {
  const double r = 0.5 * kDiameter, s = g.spacing, a = g.jitter;
  const double clear = r + kClearanceFactor * kDiameter + std::sqrt(3.0) * a;
  const int m = static_cast<int>(std::floor(g.rCyl / s));
  std::vector<double> pos;
  pos.reserve(3 * g.n);
  SplitMix rng{20261203ULL ^ 0x5bd1e995a5a5a5a5ULL};
  for (int k = 0; pos.size() < 3 * g.n; ++k) {
    const double z = clear + k * s;
    for (int j = -m; j <= m && pos.size() < 3 * g.n; ++j) {
      for (int i = -m; i <= m && pos.size() < 3 * g.n; ++i) {
        const double x = i * s, y = j * s, rho = std::hypot(x, y);
        // inside the profile (ρ < wall radius at z) and far enough from the cone and cylinder
        const double wallR = z < g.hCone ? g.rOut + z * tanTheta() : g.rCyl;
        if (rho >= wallR)
          continue;
        const double dCone = segmentDistance(rho, z, g.rOut, 0.0, g.rCyl, g.hCone);
        const double dCyl = g.rCyl - rho;
        if (std::min(dCone, dCyl) < clear)
          continue;
        for (double c : {x, y, z})
          pos.push_back(c + a * (2.0 * rng.uniform() - 1.0));
      }
    }
  }
  return pos;
}

TriangleMesh revolved(const std::string& name, const Geometry& g,
                      std::vector<std::array<double, 2>> profile) {
  for (auto& p : profile)
    p[1] *= g.stlRadiusFactor;
  TriangleMesh m = meshRevolved({0, 0, 0}, {0, 0, 1}, profile, kSegments, false, false);
  m.name = name;
  return m;
}

/// hopper.stl (cone + cylinder), cone.stl (the cone alone: LIGGGHTS' primitive variant, which
/// has no cone primitive) and bin.stl (the bin's side wall, radius R_c).
std::map<std::string, TriangleMesh> meshes(const Geometry& g) {
  std::map<std::string, TriangleMesh> m;
  m["hopper.stl"] = revolved("hopper.stl", g, {{0.0, g.rOut}, {g.hCone, g.rCyl}, {g.hTop, g.rCyl}});
  m["cone.stl"] = revolved("cone.stl", g, {{0.0, g.rOut}, {g.hCone, g.rCyl}});
  m["bin.stl"] = revolved("bin.stl", g, {{g.zBinBottom, g.rCyl}, {0.0, g.rCyl}});
  return m;
}

Material material() {
  return Material{"glass", kKn, kEn, kMu, 2.0 / 7.0, 0.5};
}

ParticleSet explicitSet(const Settled& s) {
  ParticleSet p;
  p.name = "hopper";
  p.packing = Packing::Explicit;
  p.diameter = kDiameter;
  p.density = kDensity;
  p.count = s.position.size() / 3;
  p.positions = s.position;
  p.velocities = s.velocity;
  p.angularVelocities = s.omega;
  return p;
}

/// The settling system: analytic cone + infinite cylinder, the plate z = 0, gravity.
DemConfig settleConfig(const Geometry& g, const std::vector<double>& sites, double skin) {
  DemConfig c;
  c.materials[0] = material();
  c.gravity = {0, 0, -kGravity};
  c.walls.push_back(Wall::cone({0, 0, 0}, {0, 0, 1}, 0.0, g.hCone, g.rOut, g.rCyl));
  c.walls.push_back(Wall::cylinder({0, 0, 0}, {0, 0, 1}, g.rCyl,
                                   -std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::infinity()));
  c.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
  Settled s;
  s.position = sites;
  c.particleSets.push_back(explicitSet(s));
  c.heat.enabled = false;
  if (skin >= 0)
    c.neighbour.skinFactor = skin;
  return c;
}

struct Snapshot {
  Settled bed;
  double ke = 0;
};

/// The particles in global-id order.
Snapshot snapshot(const DemSystem& sys) {
  const ParticleData p = sys.particles();
  Snapshot out;
  Settled& s = out.bed;
  s.position.assign(3 * p.count, 0.0);
  s.velocity.assign(3 * p.count, 0.0);
  s.omega.assign(3 * p.count, 0.0);
  for (std::size_t i = 0; i < p.count; ++i) {
    const auto gid = static_cast<std::size_t>(p.globalId[i]);
    COREDEM_CHECK(gid < p.count, "particle global id {} out of range", gid);
    double v2 = 0;
    for (int d = 0; d < 3; ++d) {
      s.position[3 * gid + d] = p.position[3 * i + d];
      s.velocity[3 * gid + d] = p.velocity[3 * i + d];
      s.omega[3 * gid + d] = p.angularVelocity[3 * i + d];
      v2 += p.velocity[3 * i + d] * p.velocity[3 * i + d];
    }
    s.vMax = std::max(s.vMax, std::sqrt(v2));
    out.ke += 0.5 * p.mass[i] * v2;
  }
  return out;
}

/// ρ_b of the settled bed, away from the walls: the volume of the particles whose centre lies in
/// the slab z ∈ [3 d_p, top − 4 d_p] at least 2 d_p from the cone and cylinder (ρ < r_core(z) =
/// min(R_o + z tan θ − 2 d_p / cos θ, R_c − 2 d_p)), over that region's volume (centre counting;
/// the ordered layer at the walls, looser, is left out as in a bulk measurement). rhoAll: the
/// same over the whole slab, wall layer included. 0 when the slab is thinner than 3 d_p.
void measureBulkDensity(const Geometry& g, Settled& s) {
  s.bedTop = 0;
  for (std::size_t i = 0; i < s.position.size() / 3; ++i)
    s.bedTop = std::max(s.bedTop, s.position[3 * i + 2]);
  const double z0 = 3 * kDiameter, z1 = s.bedTop - 4 * kDiameter;
  s.rhoZ[0] = z0;
  s.rhoZ[1] = z1;
  s.rhoBulk = s.rhoAll = 0;
  if (z1 - z0 < 3 * kDiameter)
    return;
  const double delta = 2 * kDiameter;
  const double cosT = std::cos(kHalfAngleDeg * kPi / 180.0);
  auto rCore = [&](double z) {
    return std::max(0.0, std::min(g.rOut + z * tanTheta() - delta / cosT, g.rCyl - delta));
  };
  double coreVolume = 0;
  const int slices = 4000;
  for (int k = 0; k < slices; ++k) {
    const double z = z0 + (k + 0.5) * (z1 - z0) / slices;
    coreVolume += kPi * rCore(z) * rCore(z) * (z1 - z0) / slices;
  }
  std::size_t inSlab = 0, inCore = 0;
  for (std::size_t i = 0; i < s.position.size() / 3; ++i) {
    const double x = s.position[3 * i], y = s.position[3 * i + 1], z = s.position[3 * i + 2];
    if (z < z0 || z >= z1)
      continue;
    ++inSlab;
    inCore += std::hypot(x, y) < rCore(z);
  }
  s.rhoAll = kDensity * static_cast<double>(inSlab) * particleVolume() / interiorVolume(g, z0, z1);
  if (coreVolume > 0 && inCore > 0)
    s.rhoBulk = kDensity * static_cast<double>(inCore) * particleVolume() / coreVolume;
}

Settled settle(const Geometry& g, const Options& o, double& dt) {
  const auto sites = fillSites(g);
  DemSystem sys(settleConfig(g, sites, o.skin), parseBackend(o.backend), o.threads);
  dt = sys.dtDemMax();
  const int chunk = static_cast<int>(std::lround(0.005 / dt)); // 5 ms
  // At rest: no particle faster than 5 mm/s (after at least 0.1 s), at most 2 s simulated.
  const double vRest = 5e-3, tMin = 0.1, tMax = 2.0;
  Snapshot snap;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    sys.advance(chunk * dt, chunk);
    snap = snapshot(sys);
    if (sys.time() >= tMin && snap.bed.vMax < vRest)
      break;
    if (sys.time() >= tMax) {
      std::fprintf(stderr,
                   "coredem-bench dem: warning: the hopper bed is not at rest after %.2f s "
                   "(fastest particle %.3g m/s); using it as it is\n",
                   sys.time(), snap.bed.vMax);
      break;
    }
  }
  if (!o.json)
    std::printf("settled %zu particles in %.3f s simulated (%llu steps, %.1f s wall), fastest "
                "%.2e m/s\n",
                g.n, sys.time(), static_cast<unsigned long long>(sys.step()),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                snap.bed.vMax);
  Settled s = std::move(snap.bed);
  s.time = sys.time();
  s.steps = sys.step();
  measureBulkDensity(g, s);
  return s;
}

std::string fmt17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string deckKey(const Geometry& g) {
  return std::string(kDeckVersion) + " n=" + std::to_string(g.n) + " outlet=" + fmt17(g.outletD);
}

std::map<std::string, std::string> readKeyValues(const fs::path& path) {
  std::map<std::string, std::string> kv;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find(" = ");
    if (eq == std::string::npos || line[0] == '#')
      continue;
    kv[line.substr(0, eq)] = line.substr(eq + 3);
  }
  return kv;
}

void writeDeck(const fs::path& dir, const Geometry& g, const Settled& s, double dt,
               double keInitial) {
  {
    std::ofstream f(dir / "hopper.particles");
    COREDEM_CHECK(static_cast<bool>(f), "cannot write {}", (dir / "hopper.particles").string());
    f << "# settled hopper bed (bench/decks.md `hopper`): one particle per line in global-id "
         "order\n# x y z (m) vx vy vz (m/s) wx wy wz (rad/s)\n";
    for (std::size_t i = 0; i < s.position.size() / 3; ++i) {
      for (int d = 0; d < 3; ++d)
        f << fmt17(s.position[3 * i + d]) << ' ';
      for (int d = 0; d < 3; ++d)
        f << fmt17(s.velocity[3 * i + d]) << ' ';
      for (int d = 0; d < 3; ++d)
        f << fmt17(s.omega[3 * i + d]) << (d == 2 ? '\n' : ' ');
    }
  }
  for (const auto& [name, mesh] : meshes(g))
    writeStl(mesh, dir / name, false); // ASCII: LIGGGHTS reads no binary STL
  std::ofstream f(dir / "hopper.deck");
  COREDEM_CHECK(static_cast<bool>(f), "cannot write {}", (dir / "hopper.deck").string());
  const double boxHalf = g.rCyl * g.stlRadiusFactor + 2 * kDiameter;
  f << "# the hopper deck (bench/decks.md), written by coredem-bench dem --case hopper\n"
    << "key = " << deckKey(g) << "\n"
    << "n = " << g.n << "\n"
    << "d_p = " << fmt17(kDiameter) << "\n"
    << "rho_p = " << fmt17(kDensity) << "\n"
    << "mass = " << fmt17(particleMass()) << "\n"
    << "k_n = " << fmt17(kKn) << "\n"
    << "e_n = " << fmt17(kEn) << "\n"
    << "mu = " << fmt17(kMu) << "\n"
    << "dt = " << fmt17(dt) << "\n"
    << "gravity = " << fmt17(kGravity) << "\n"
    << "outlet_d = " << fmt17(g.outletD) << "\n"
    << "half_angle_deg = " << fmt17(kHalfAngleDeg) << "\n"
    << "r_out = " << fmt17(g.rOut) << "\n"
    << "r_cyl = " << fmt17(g.rCyl) << "\n"
    << "h_cone = " << fmt17(g.hCone) << "\n"
    << "h_top = " << fmt17(g.hTop) << "\n"
    << "z_floor = " << fmt17(g.zFloor) << "\n"
    << "z_bin_bottom = " << fmt17(g.zBinBottom) << "\n"
    << "segments = " << kSegments << "\n"
    << "stl_radius_factor = " << fmt17(g.stlRadiusFactor) << "\n"
    << "box = " << fmt17(-boxHalf) << ' ' << fmt17(boxHalf) << ' ' << fmt17(-boxHalf) << ' '
    << fmt17(boxHalf) << ' ' << fmt17(g.zBinBottom - 2 * kDiameter) << ' '
    << fmt17(g.hTop + 2 * kDiameter) << "\n"
    << "settle_time = " << fmt17(s.time) << "\n"
    << "settle_steps = " << s.steps << "\n"
    << "settle_vmax = " << fmt17(s.vMax) << "\n"
    << "bed_top = " << fmt17(s.bedTop) << "\n"
    << "rho_bulk = " << fmt17(s.rhoBulk) << "\n"
    << "rho_bulk_with_wall_layer = " << fmt17(s.rhoAll) << "\n"
    << "rho_bulk_slab = " << fmt17(s.rhoZ[0]) << ' ' << fmt17(s.rhoZ[1]) << "\n"
    << "ke_initial = " << fmt17(keInitial) << "\n";
}

/// Reads the settled bed of `dir` if it was written for this geometry; false otherwise.
bool readDeck(const fs::path& dir, const Geometry& g, Settled& s) {
  if (!fs::exists(dir / "hopper.deck") || !fs::exists(dir / "hopper.particles"))
    return false;
  auto kv = readKeyValues(dir / "hopper.deck");
  if (kv["key"] != deckKey(g))
    return false;
  for (const char* f : {"hopper.stl", "cone.stl", "bin.stl"})
    if (!fs::exists(dir / f))
      return false;
  std::ifstream in(dir / "hopper.particles");
  std::string line;
  std::size_t lineNo = 0;
  s = Settled{};
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream ls(line);
    double v[9];
    for (double& x : v)
      if (!(ls >> x))
        throw UserError((dir / "hopper.particles").string() + ":" + std::to_string(lineNo) +
                        ": expected 9 numbers 'x y z vx vy vz wx wy wz'");
    s.position.insert(s.position.end(), v, v + 3);
    s.velocity.insert(s.velocity.end(), v + 3, v + 6);
    s.omega.insert(s.omega.end(), v + 6, v + 9);
  }
  COREDEM_CHECK(s.position.size() == 3 * g.n, "{}: {} particles, the deck says {}",
                (dir / "hopper.particles").string(), s.position.size() / 3, g.n);
  s.time = std::stod(kv["settle_time"]);
  s.steps = std::stoull(kv["settle_steps"]);
  s.vMax = std::stod(kv["settle_vmax"]);
  s.bedTop = std::stod(kv["bed_top"]);
  s.rhoBulk = std::stod(kv["rho_bulk"]);
  s.rhoAll = std::stod(kv["rho_bulk_with_wall_layer"]);
  std::istringstream slab(kv["rho_bulk_slab"]);
  slab >> s.rhoZ[0] >> s.rhoZ[1];
  return true;
}

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

} // namespace

Geometry geometry(std::size_t n, double outletOverD) {
  COREDEM_CHECK(n >= 1, "the hopper deck needs at least one particle");
  COREDEM_CHECK(outletOverD >= 2 && outletOverD <= 40,
                "--outlet {} d_p: choose an outlet of 2 to 40 particle diameters", outletOverD);
  Geometry g;
  const double d = kDiameter, t = tanTheta();
  g.n = n;
  g.outletD = outletOverD * d;
  g.rOut = 0.5 * g.outletD;
  // R_c: the smallest multiple of d_p/2, at least 1.5 D_o, for which the cone and a cylinder
  // section as high as it is wide hold the N particles at a solid fraction of 0.6.
  const double bulk = static_cast<double>(n) * particleVolume() / kFillFraction;
  double rc = std::max(1.5 * g.outletD, g.rOut + d);
  rc = std::ceil(rc / (0.5 * d) - 1e-9) * 0.5 * d;
  for (;; rc += 0.5 * d) {
    Geometry probe = g;
    probe.rCyl = rc;
    probe.hCone = (rc - g.rOut) / t;
    if (interiorVolume(probe, 0.0, probe.hCone + 2.0 * rc) >= bulk)
      break;
  }
  g.rCyl = rc;
  g.hCone = (rc - g.rOut) / t;
  g.spacing = kSpacingFactor * d;
  g.jitter = kJitterFactor * d;
  g.stlRadiusFactor = 1.0 / std::cos(kPi / kSegments);
  // top of the walls: above the loose lattice fill (checked after filling)
  const auto sites = fillSites(g);
  double top = 0;
  for (std::size_t i = 0; i < n; ++i)
    top = std::max(top, sites[3 * i + 2]);
  g.hTop = std::max(top, g.hCone) + 3 * d;
  // the bin below: the discharged bed (solid fraction 0.58) in the cylinder of radius R_c, its
  // heap (R_c tan 30°) and 10 d_p to spare under the outlet
  const double pile = static_cast<double>(n) * particleVolume() / 0.58 / (kPi * rc * rc);
  g.zFloor = -(pile + rc * t + 10 * d);
  g.zBinBottom = g.zFloor - 2 * d;
  return g;
}

namespace {
int runDeck(const Options& o);
}

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
  std::unique_ptr<TempDir> tmp;
  fs::path dir;
  if (o.deckDir.empty()) {
    tmp = std::make_unique<TempDir>();
    dir = tmp->path;
  } else {
    dir = o.deckDir;
    fs::create_directories(dir);
  }
  Settled bed;
  bool cached = !o.resettle && readDeck(dir, g, bed);
  if (!cached) {
    double dt = 0;
    bed = settle(g, o, dt);
    double ke = 0;
    for (std::size_t i = 0; i < bed.velocity.size() / 3; ++i)
      ke += 0.5 * particleMass() *
            (bed.velocity[3 * i] * bed.velocity[3 * i] +
             bed.velocity[3 * i + 1] * bed.velocity[3 * i + 1] +
             bed.velocity[3 * i + 2] * bed.velocity[3 * i + 2]);
    writeDeck(dir, g, bed, dt, ke);
  }
  const double rhoB = bed.rhoBulk > 0 ? bed.rhoBulk : kFillFraction * kDensity;
  const double wBev = beverloo(rhoB, kBeverlooC, kBeverlooK, g.outletD);
  const double wLo = beverloo(rhoB, kBeverlooCLo, kBeverlooKHi, g.outletD);
  const double wHi = beverloo(rhoB, kBeverlooCHi, kBeverlooKLo, g.outletD);
  if (o.settleOnly) {
    if (o.json) {
      std::printf("{\"command\":\"dem\",\"case\":\"hopper\",\"settle_only\":true,\"particles\":%zu,"
                  "\"deck_dir\":\"%s\",\"cached\":%s,\"settle_time_s\":%s,\"settle_steps\":%llu,"
                  "\"rho_bulk\":%s,\"r_cyl\":%s,\"h_cone\":%s,\"outlet_d\":%s}\n",
                  o.n, dir.string().c_str(), cached ? "true" : "false",
                  jsonNumber(bed.time).c_str(), bed.steps, jsonNumber(bed.rhoBulk).c_str(),
                  jsonNumber(g.rCyl).c_str(), jsonNumber(g.hCone).c_str(),
                  jsonNumber(g.outletD).c_str());
    } else {
      std::printf("hopper deck in %s (%s): N = %zu, D_o = %.4g m, R_c = %.4g m, cone height "
                  "%.4g m, bed top %.4g m, rho_b = %.1f kg/m^3\n",
                  dir.string().c_str(), cached ? "cached" : "settled now", o.n, g.outletD, g.rCyl,
                  g.hCone, bed.bedTop, bed.rhoBulk);
    }
    return 0;
  }

  const auto t0 = std::chrono::steady_clock::now();
  DemSystem sys(runConfig(g, bed, o, dir), parseBackend(o.backend), o.threads);
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double dt = sys.dtDemMax();
  const double keInitial = kineticEnergy(sys);
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
  const int timedSteps = std::max(0, done - o.warmup);
  const StageTimes st = sys.stageTimes();
  const double keFinal = kineticEnergy(sys);
  const Fit fit = fitRate(samples, n, o.fitLo, o.fitHi);
  const double m = particleMass();
  const double rate = timedWall > 0 ? static_cast<double>(n) * timedSteps / timedWall : 0.0;
  const double pairsPer =
      2.0 * static_cast<double>(sys.pairContactCount()) / static_cast<double>(n);
  const double wallPer =
      static_cast<double>(sys.contactCount() - sys.pairContactCount()) / static_cast<double>(n);
  const double wallMean = timedSamples ? wallContactsTimed / timedSamples : NAN;
  const double pairMean = timedSamples ? pairContactsTimed / timedSamples : NAN;
  const double discharged = static_cast<double>(samples.back().below) / static_cast<double>(n);
  const int usedThreads = o.threads > 0 ? o.threads : 1;

  if (!o.samplesOut.empty()) {
    std::ofstream f(o.samplesOut);
    COREDEM_CHECK(static_cast<bool>(f), "cannot write --samples-out {}", o.samplesOut);
    f << "# t_s below_outlet wall_contacts pair_contacts advance_wall_s rebuilds (every "
      << o.sample << " steps; wall clock and rebuilds since the opening, warm-up included)\n";
    for (const Sample& s : samples)
      f << fmt17(s.t) << ' ' << s.below << ' ' << s.walls << ' ' << s.pairs << ' ' << fmt17(s.wall)
        << ' ' << s.rebuilds << '\n';
  }

  if (o.json) {
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
        static_cast<unsigned long long>(st.rebuilds), st.neighbour, st.contact, st.integrate,
        st.heat, keInitial, keFinal, dir.string().c_str(), cached ? "true" : "false",
        jsonNumber(kDiameter).c_str(), jsonNumber(g.outletD).c_str(),
        jsonNumber(kHalfAngleDeg).c_str(), jsonNumber(g.rCyl).c_str(), jsonNumber(g.hCone).c_str(),
        jsonNumber(g.hTop).c_str(), jsonNumber(g.zFloor).c_str(), kSegments,
        jsonNumber(bed.time).c_str(), bed.steps, jsonNumber(bed.vMax).c_str(),
        jsonNumber(bed.bedTop).c_str(), jsonNumber(sys.time()).c_str(), discharged, o.fitLo,
        o.fitHi, fit.ok ? "true" : "false", fit.complete ? "true" : "false", fit.points,
        jsonNumber(fit.t0).c_str(), jsonNumber(fit.t1).c_str(), jsonNumber(fit.r2).c_str(),
        fit.ok ? jsonNumber(fit.rate).c_str() : "null",
        fit.ok ? jsonNumber(fit.rate * m).c_str() : "null", fit.note.c_str(), kBeverlooC,
        kBeverlooK, jsonNumber(rhoB).c_str(), bed.rhoBulk > 0 ? "true" : "false",
        jsonNumber(bed.rhoAll).c_str(), kGravity, jsonNumber(wBev).c_str(), jsonNumber(wLo).c_str(),
        jsonNumber(wHi).c_str(), kBeverlooCLo, kBeverlooCHi, kBeverlooKLo, kBeverlooKHi,
        fit.ok ? jsonNumber(fit.rate * m / wBev).c_str() : "null",
        fit.ok ? (fit.rate * m >= wLo && fit.rate * m <= wHi ? "true" : "false") : "null");
  } else {
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
    std::printf("Beverloo                 %.4e kg/s (C = %g, k = %g, rho_b = %.1f kg/m^3%s), "
                "band %.4e..%.4e kg/s (C %g-%g, k %g-%g)%s\n",
                wBev, kBeverlooC, kBeverlooK, rhoB, bed.rhoBulk > 0 ? " measured" : " = 0.6 rho_p",
                wLo, wHi, kBeverlooCLo, kBeverlooCHi, kBeverlooKLo, kBeverlooKHi,
                fit.ok ? (fit.rate * m >= wLo && fit.rate * m <= wHi ? ": in the band"
                                                                     : ": OUTSIDE the band")
                       : "");
  }
  return 0;
}
} // namespace

} // namespace coredem::bench::hopper
