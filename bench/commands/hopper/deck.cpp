// Phase 1 of the `hopper` deck (hopper.h, bench/decks.md): the geometry for N particles, the
// jittered lattice fill, its settling under gravity against the analytic walls and the deck
// directory's files (hopper.deck, hopper.particles, the STL files) that cache the settled bed.
#include "deck.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "../dem.h"
#include "coredem/common/check.h"

namespace coredem::bench::hopper {

namespace fs = std::filesystem;
using namespace coredem::dem;

namespace {

constexpr const char* kDeckVersion = "hopper-deck-2";
constexpr double kPi = std::numbers::pi;
constexpr double kSpacingFactor = 1.05;
constexpr double kJitterFactor = 0.02;
constexpr double kClearanceFactor = 0.05;

double tanTheta() {
  return std::tan(kHalfAngleDeg * kPi / 180.0);
}

double particleVolume() {
  return kPi * kDiameter * kDiameter * kDiameter / 6.0;
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

} // namespace

double particleMass() {
  return kDensity * particleVolume();
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

} // namespace coredem::bench::hopper
