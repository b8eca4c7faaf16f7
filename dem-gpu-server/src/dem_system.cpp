// DemSystem: config validation, particle generation, Δt_DEM, sub-cycling, state I/O.
// Everything that runs per particle per step is in the backend engine (engine_impl.h).
#include "coredem/dem/dem_system.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

#include "backend/sync_counters.h"
#include "chemistry_config.h"
#include "coredem/common/check.h"
#include "coredem/common/log.h"
#include "coredem/common/version.h"
#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/models.h"
#include "coredem/dem/time_handler.h"
#include "coredem/dem/triangle_mesh.h"
#include "engine.h"
#include "state_io.h"

namespace coredem::dem {

BackendKind parseBackend(const std::string& name) {
  if (name == "cpu")
    return BackendKind::Cpu;
  if (name == "cuda")
    return BackendKind::Cuda;
  if (name == "auto")
    return BackendKind::Auto;
  if (name == "cuda-sim")
    return BackendKind::CudaSim;
  throw UserError("unknown DEM backend '" + name + "'; use cpu, cuda or auto");
}

std::string backendName(BackendKind kind) {
  switch (kind) {
  case BackendKind::Cpu:
    return "cpu";
  case BackendKind::Cuda:
    return "cuda";
  case BackendKind::Auto:
    return "auto";
  case BackendKind::CudaSim:
    return "cuda-sim";
  }
  return "?";
}

bool cudaBackendBuilt() {
#if defined(COREDEM_CUDA_ENABLED)
  return true;
#else
  return false;
#endif
}

CudaProbe probeCuda() {
#if defined(COREDEM_CUDA_ENABLED)
  return cudaProbe();
#else
  CudaProbe p;
  p.note = "this build has no CUDA backend (configure with -DCOREDEM_CUDA=ON)";
  return p;
#endif
}

int cudaDeviceCount() {
  return probeCuda().devices;
}

BackendSyncCounts backendSyncCounts() {
  const backend::SyncCounters& c = backend::syncCounters();
  return {c.hostRoundTrips.load(), c.deviceSyncs.load(), c.launches.load()};
}

void DemConfig::addBox(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  for (int d = 0; d < 3; ++d) {
    Wall a, b;
    a.point = lo;
    b.point = hi;
    a.normal = {0, 0, 0};
    b.normal = {0, 0, 0};
    a.normal[d] = 1.0;
    b.normal[d] = -1.0;
    walls.push_back(a);
    walls.push_back(b);
  }
}

Wall Wall::plane(const std::array<double, 3>& point, const std::array<double, 3>& normal) {
  Wall w;
  w.point = point;
  w.normal = normal;
  return w;
}

Wall Wall::cylinder(const std::array<double, 3>& point, const std::array<double, 3>& axis,
                    double radius, double start, double end, WallSide side, bool capStart,
                    bool capEnd) {
  Wall w;
  w.shape = WallShape::Cylinder;
  w.point = point;
  w.normal = axis;
  w.radius = w.radiusEnd = radius;
  w.start = start;
  w.end = end;
  w.side = side;
  w.capStart = capStart;
  w.capEnd = capEnd;
  return w;
}

Wall Wall::cone(const std::array<double, 3>& point, const std::array<double, 3>& axis, double start,
                double end, double rStart, double rEnd, WallSide side, bool capStart, bool capEnd) {
  Wall w = cylinder(point, axis, rStart, start, end, side, capStart, capEnd);
  w.shape = WallShape::Cone;
  w.radiusEnd = rEnd;
  return w;
}

namespace {

/// splitmix64: small, portable, reproducible.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; } // [0, 1)
};

void checkWall(const Wall& w, std::size_t k);

void validate(const DemConfig& c) {
  COREDEM_CHECK(!c.materials.empty(), "DemConfig.materials is empty; define at least one material");
  for (std::size_t m = 0; m < c.materials.size(); ++m) {
    const Material& mat = c.materials[m];
    COREDEM_CHECK(mat.kn > 0 && std::isfinite(mat.kn), "material '{}': kn = {} must be > 0",
                  mat.name, mat.kn);
    COREDEM_CHECK(mat.en > 0 && mat.en <= 1, "material '{}': en = {} must be in (0, 1]", mat.name,
                  mat.en);
    COREDEM_CHECK(mat.mu >= 0, "material '{}': mu = {} must be >= 0", mat.name, mat.mu);
    COREDEM_CHECK(mat.ktFactor > 0, "material '{}': ktFactor = {} must be > 0", mat.name,
                  mat.ktFactor);
    COREDEM_CHECK(mat.etatFactor >= 0, "material '{}': etatFactor = {} must be >= 0", mat.name,
                  mat.etatFactor);
    COREDEM_CHECK(mat.cp > 0 && std::isfinite(mat.cp), "material '{}': cp = {} J/kg/K must be > 0",
                  mat.name, mat.cp);
    COREDEM_CHECK(mat.conductivity >= 0 && std::isfinite(mat.conductivity),
                  "material '{}': conductivity = {} W/m/K must be >= 0", mat.name,
                  mat.conductivity);
    COREDEM_CHECK(mat.emissivity >= 0 && mat.emissivity <= 1,
                  "material '{}': emissivity = {} must be in [0, 1]", mat.name, mat.emissivity);
  }
  for (const ParticleSet& s : c.particleSets) {
    COREDEM_CHECK(s.material >= 0 && s.material < static_cast<int>(c.materials.size()),
                  "particle set '{}': material index {} is not in 0..{}", s.name, s.material,
                  c.materials.size() - 1);
    COREDEM_CHECK(s.diameter > 0 && std::isfinite(s.diameter),
                  "particle set '{}': diameter {} must be > 0", s.name, s.diameter);
    COREDEM_CHECK(s.density > 0 && std::isfinite(s.density),
                  "particle set '{}': density {} must be > 0", s.name, s.density);
    COREDEM_CHECK(s.temperature > 0, "particle set '{}': temperature {} K must be > 0", s.name,
                  s.temperature);
    COREDEM_CHECK(s.composition.empty() || s.composition.size() == c.solidSpecies.size(),
                  "particle set '{}': composition has {} entries but {} solid species are defined",
                  s.name, s.composition.size(), c.solidSpecies.size());
    if (!s.composition.empty()) {
      double sum = 0;
      for (double y : s.composition) {
        COREDEM_CHECK(y >= 0, "particle set '{}': negative mass fraction in composition", s.name);
        sum += y;
      }
      COREDEM_CHECK(std::fabs(sum - 1.0) < 1e-9, "particle set '{}': composition sums to {}, not 1",
                    s.name, sum);
    }
    if (s.packing == Packing::Explicit) {
      COREDEM_CHECK(s.positions.size() % 3 == 0 && !s.positions.empty(),
                    "particle set '{}': Explicit packing needs positions as x,y,z triples", s.name);
      const std::size_t n = s.positions.size() / 3;
      for (double v : s.positions)
        COREDEM_CHECK(std::isfinite(v), "particle set '{}': a position is not finite", s.name);
      for (double v : s.velocities)
        COREDEM_CHECK(std::isfinite(v), "particle set '{}': a velocity is not finite", s.name);
      COREDEM_CHECK(s.velocities.empty() || s.velocities.size() == 3 * n,
                    "particle set '{}': velocities must have 3 values per particle ({}), got {}",
                    s.name, 3 * n, s.velocities.size());
      COREDEM_CHECK(s.angularVelocities.empty() || s.angularVelocities.size() == 3 * n,
                    "particle set '{}': angularVelocities must have 3 values per particle", s.name);
    } else {
      for (int d = 0; d < 3; ++d) {
        COREDEM_CHECK(s.regionMax[d] > s.regionMin[d],
                      "particle set '{}': region max[{}] = {} must exceed min = {}", s.name, d,
                      s.regionMax[d], s.regionMin[d]);
      }
    }
  }
  for (std::size_t k = 0; k < c.walls.size(); ++k)
    checkWall(c.walls[k], k);
  for (const MeshWall& m : c.meshes) {
    COREDEM_CHECK(!m.triangles.empty() && m.triangles.size() % 3 == 0 && !m.vertices.empty() &&
                      m.vertices.size() % 3 == 0,
                  "mesh wall '{}': needs vertices as x,y,z triples and triangles as index "
                  "triples ({} vertex values, {} index values)",
                  m.name, m.vertices.size(), m.triangles.size());
    for (double v : m.vertices)
      COREDEM_CHECK(std::isfinite(v), "mesh wall '{}': a vertex coordinate is not finite", m.name);
    const auto nv = static_cast<std::int64_t>(m.vertices.size() / 3);
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      COREDEM_CHECK(m.triangles[t] >= 0 && m.triangles[t] < nv,
                    "mesh wall '{}': triangle {} names vertex {}, not one of its {} vertices",
                    m.name, t / 3 + 1, m.triangles[t], nv);
  }
  const CouplingGrid& g = c.grid;
  const bool any = g.counts[0] != 0 || g.counts[1] != 0 || g.counts[2] != 0;
  if (any) {
    for (int d = 0; d < 3; ++d) {
      COREDEM_CHECK(g.counts[d] > 0,
                    "coupling grid: counts[{}] = {} must be > 0 (or all counts 0 for no coupling)",
                    d, g.counts[d]);
      COREDEM_CHECK(g.spacing[d] > 0, "coupling grid: spacing[{}] = {} must be > 0", d,
                    g.spacing[d]);
    }
    COREDEM_CHECK(g.cellCount() < (1ull << 31),
                  "coupling grid has {} cells; at most 2^31-1 are supported", g.cellCount());
  }
  COREDEM_CHECK(c.neighbour.skinFactor >= 0, "neighbour.skinFactor {} must be >= 0",
                c.neighbour.skinFactor);
  COREDEM_CHECK(c.neighbour.initialNeighbourSlots >= 1,
                "neighbour.initialNeighbourSlots must be >= 1");
  COREDEM_CHECK(c.dtFactor >= 1, "dtFactor {} must be >= 1 (default 50, docs/physics.md §2.1)",
                c.dtFactor);
  COREDEM_CHECK(c.epsMinDrag > 0 && c.epsMinDrag < 1, "epsMinDrag {} must be in (0, 1)",
                c.epsMinDrag);
  checkModelParams(c);
  COREDEM_CHECK(c.heat.minSeparation > 0, "heat: s_min = {} m must be > 0", c.heat.minSeparation);
  COREDEM_CHECK(c.heat.lensFraction >= 0, "heat: flpc = {} must be >= 0", c.heat.lensFraction);
  COREDEM_CHECK(c.heat.lensRelTol > 0, "heat: lens_rel_tol = {} must be > 0", c.heat.lensRelTol);
  for (const Species& sp : c.gasSpecies)
    COREDEM_CHECK(sp.molarMass > 0, "gas species '{}': molar mass must be > 0 (kg/mol)", sp.name);
  for (const Species& sp : c.solidSpecies)
    COREDEM_CHECK(sp.molarMass > 0, "solid species '{}': molar mass must be > 0 (kg/mol)", sp.name);
}

/// Positions of one set (x,y,z triples).
std::vector<double> placeParticles(const ParticleSet& s, const std::atomic<bool>* interrupt) {
  std::vector<double> p;
  if (s.packing == Packing::Explicit)
    return s.positions;
  const double r = 0.5 * s.diameter;
  if (s.packing == Packing::Lattice) {
    const double sp = s.spacing > 0 ? s.spacing : s.diameter;
    long long n[3];
    for (int d = 0; d < 3; ++d)
      n[d] = static_cast<long long>(std::floor((s.regionMax[d] - s.regionMin[d]) / sp + 1e-9));
    const long long sites = n[0] * n[1] * n[2];
    COREDEM_CHECK(
        sites >= static_cast<long long>(s.count),
        "particle set '{}': the region holds {} lattice sites at spacing {} m but count = {}; "
        "enlarge the region or reduce the count",
        s.name, sites, sp, s.count);
    p.reserve(3 * s.count);
    for (std::size_t k = 0; k < s.count; ++k) {
      const long long i = static_cast<long long>(k) % n[0];
      const long long j = (static_cast<long long>(k) / n[0]) % n[1];
      const long long l = static_cast<long long>(k) / (n[0] * n[1]);
      p.push_back(s.regionMin[0] + (i + 0.5) * sp);
      p.push_back(s.regionMin[1] + (j + 0.5) * sp);
      p.push_back(s.regionMin[2] + (l + 0.5) * sp);
    }
    return p;
  }
  // Random: rejection sampling with a hash grid of cell size d.
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) {
    lo[d] = s.regionMin[d] + r;
    hi[d] = s.regionMax[d] - r;
    COREDEM_CHECK(hi[d] > lo[d],
                  "particle set '{}': the region is thinner than one diameter along axis {}",
                  s.name, d);
  }
  Rng rng{s.seed};
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
  auto cellOf = [&](double x, int d) {
    return static_cast<std::int64_t>(std::floor((x - lo[d]) / s.diameter));
  };
  auto key = [](std::int64_t a, std::int64_t b, std::int64_t c) {
    return (static_cast<std::uint64_t>(a) * 73856093ull) ^
           (static_cast<std::uint64_t>(b) * 19349663ull) ^
           (static_cast<std::uint64_t>(c) * 83492791ull);
  };
  const std::size_t maxAttempts = 2000 * s.count + 10000;
  std::size_t attempts = 0;
  while (p.size() < 3 * s.count) {
    if (interrupt != nullptr && (attempts & 4095) == 0 &&
        interrupt->load(std::memory_order_relaxed)) {
      throw Interrupted(
          coredem::format("interrupted while placing particle set '{}' ({} of {} placed)", s.name,
                          p.size() / 3, s.count));
    }
    COREDEM_CHECK(
        ++attempts < maxAttempts,
        "particle set '{}': could not place {} non-overlapping particles of diameter {} m in the "
        "region (placed {}); enlarge the region, reduce the count or use Lattice packing",
        s.name, s.count, s.diameter, p.size() / 3);
    double x[3];
    for (int d = 0; d < 3; ++d)
      x[d] = lo[d] + (hi[d] - lo[d]) * rng.uniform();
    const std::int64_t c[3] = {cellOf(x[0], 0), cellOf(x[1], 1), cellOf(x[2], 2)};
    bool ok = true;
    for (int a = -1; a <= 1 && ok; ++a)
      for (int b = -1; b <= 1 && ok; ++b)
        for (int e = -1; e <= 1 && ok; ++e) {
          auto it = grid.find(key(c[0] + a, c[1] + b, c[2] + e));
          if (it == grid.end())
            continue;
          for (std::size_t q : it->second) {
            const double dx = p[3 * q] - x[0], dy = p[3 * q + 1] - x[1], dz = p[3 * q + 2] - x[2];
            if (dx * dx + dy * dy + dz * dz < s.diameter * s.diameter) {
              ok = false;
              break;
            }
          }
        }
    if (!ok)
      continue;
    grid[key(c[0], c[1], c[2])].push_back(p.size() / 3);
    p.insert(p.end(), x, x + 3);
  }
  return p;
}

std::string hex16(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

/// A wall's own consistency (finite, positive where it must be).
void checkWall(const Wall& w, std::size_t k) {
  const double l = std::hypot(w.normal[0], w.normal[1], w.normal[2]);
  const char* what = w.shape == WallShape::Plane ? "normal" : "axis";
  COREDEM_CHECK(l > 0 && std::isfinite(l), "wall {} has a zero or non-finite {}; give a nonzero {}",
                k + 1, what, what);
  for (double p : w.point)
    COREDEM_CHECK(std::isfinite(p), "wall {}: its point is not finite", k + 1);
  if (w.shape == WallShape::Plane)
    return;
  const bool infinite = std::isinf(w.start) && std::isinf(w.end);
  COREDEM_CHECK(std::isfinite(w.radius) && w.radius >= 0 && std::isfinite(w.radiusEnd) &&
                    w.radiusEnd >= 0,
                "wall {}: radius {} / {} m: give finite radii >= 0", k + 1, w.radius, w.radiusEnd);
  if (w.shape == WallShape::Cylinder) {
    COREDEM_CHECK(w.radius > 0, "wall {}: a cylinder needs a radius > 0 (got {} m)", k + 1,
                  w.radius);
    COREDEM_CHECK(infinite || (std::isfinite(w.start) && std::isfinite(w.end) && w.start < w.end),
                  "wall {}: cylinder extent [{}, {}] m: give start < end, both finite, or "
                  "neither (an infinite cylinder)",
                  k + 1, w.start, w.end);
    COREDEM_CHECK(!infinite || (!w.capStart && !w.capEnd),
                  "wall {}: an infinite cylinder has no ends to cap; give start and end", k + 1);
  } else {
    COREDEM_CHECK(std::isfinite(w.start) && std::isfinite(w.end) && w.start < w.end,
                  "wall {}: cone extent [{}, {}] m: give finite start < end", k + 1, w.start,
                  w.end);
    COREDEM_CHECK(w.radius > 0 || w.radiusEnd > 0,
                  "wall {}: a cone needs a radius > 0 at one end at least", k + 1);
  }
}

/// The engine's form of a wall (kernels/wall_contact.h): a plane, or a profile revolved about a
/// unit axis (optional bottom cap, side, optional top cap).
kernels::Wall kernelWall(const Wall& w) {
  const double l = std::hypot(w.normal[0], w.normal[1], w.normal[2]);
  const kernels::Vec3 p{w.point[0], w.point[1], w.point[2]};
  const kernels::Vec3 n{w.normal[0] / l, w.normal[1] / l, w.normal[2] / l};
  if (w.shape == WallShape::Plane)
    return kernels::planeWall(p, n);
  kernels::Wall k{};
  k.point = p;
  k.normal = n;
  k.kind = kernels::kWallRevolved;
  k.side = w.side == WallSide::Inside ? 1 : (w.side == WallSide::Outside ? -1 : 0);
  if (std::isinf(w.start) && std::isinf(w.end)) {
    k.infinite = 1;
    k.points = 2;
    k.r[0] = k.r[1] = w.radius;
    return k;
  }
  auto add = [&](double t, double r) {
    k.t[k.points] = t;
    k.r[k.points] = r;
    ++k.points;
  };
  if (w.capStart && w.radius > 0)
    add(w.start, 0.0);
  add(w.start, w.radius);
  add(w.end, w.radiusEnd);
  if (w.capEnd && w.radiusEnd > 0)
    add(w.end, 0.0);
  return k;
}

/// The mesh walls' triangles with vertex and edge ids unique over all meshes.
std::vector<kernels::MeshTriangle> kernelTriangles(const std::vector<MeshWall>& meshes) {
  std::vector<kernels::MeshTriangle> out;
  std::int32_t vBase = 0, eBase = 0;
  for (const MeshWall& m : meshes) {
    TriangleMesh tm{m.name, m.vertices, m.triangles};
    const MeshTopology topo = meshTopology(tm);
    const std::size_t nt = m.triangles.size() / 3;
    for (std::size_t t = 0; t < nt; ++t) {
      kernels::MeshTriangle k{};
      kernels::Vec3* corner[3] = {&k.a, &k.b, &k.c};
      for (int c = 0; c < 3; ++c) {
        const std::int32_t v = m.triangles[3 * t + c];
        *corner[c] = kernels::Vec3{m.vertices[3 * v], m.vertices[3 * v + 1], m.vertices[3 * v + 2]};
        k.v[c] = vBase + v;
        k.e[c] = eBase + topo.triangleEdges[3 * t + c];
      }
      out.push_back(k);
    }
    vBase += static_cast<std::int32_t>(m.vertices.size() / 3);
    eBase += topo.edgeCount;
  }
  return out;
}

/// FNV-1a over a canonical text of everything except the particle sets.
std::string hashConfig(const DemConfig& c) {
  std::string t;
  auto num = [&](double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g;", v);
    t += b;
  };
  for (const Material& m : c.materials) {
    t += m.name + ":";
    for (double v : {m.kn, m.en, m.mu, m.ktFactor, m.etatFactor})
      num(v);
    if (c.heat.enabled)
      num(m.cp), num(m.conductivity), num(m.emissivity);
  }
  t += "|walls:";
  for (const Wall& w : c.walls) {
    for (int d = 0; d < 3; ++d)
      num(w.point[d]), num(w.normal[d]);
    if (w.shape != WallShape::Plane) { // (planes alone hash as before)
      t += w.shape == WallShape::Cylinder ? "cyl" : "cone";
      for (double v : {w.radius, w.radiusEnd, w.start, w.end})
        num(v);
      t += static_cast<char>('0' + static_cast<int>(w.side));
      t += w.capStart ? 'S' : '-';
      t += w.capEnd ? 'E' : '-';
    }
  }
  for (const MeshWall& m : c.meshes) {
    t += "|mesh:" + m.name + ":";
    for (double v : m.vertices)
      num(v);
    for (std::int32_t i : m.triangles)
      t += std::to_string(i) + ",";
  }
  t += "|g:";
  for (double v : c.gravity)
    num(v);
  t += "|grid:";
  for (int d = 0; d < 3; ++d)
    num(c.grid.origin[d]), num(c.grid.spacing[d]), num(c.grid.counts[d]);
  t += "|species:";
  for (const Species& s : c.solidSpecies)
    t += s.name + ":", num(s.molarMass);
  t += "|gas:";
  for (const Species& s : c.gasSpecies)
    t += s.name + ":", num(s.molarMass);
  t += "|opts:";
  num(c.neighbour.skinFactor), num(c.neighbour.historySlots), num(c.epsMinDrag), num(c.dtFactor);
  if (c.frozenMotion)
    t += "|frozen"; // absent otherwise: earlier hashes unchanged
  if (c.drag !=
      kernels::DragLaw::Gidaspow) { // absent for the default law: earlier hashes unchanged
    t += "|drag:";
    num(static_cast<int>(c.drag));
  }
  t += modelParamsHashText(c); // "" while every parameter of the chosen models is its default
  if (c.heat.enabled)          // heat off keeps the hash of configurations without heat transfer
    appendHeatHashText(c.heat, c.wallTemperature, static_cast<int>(c.wallMaterial), t);
  t += chemistryHashText(c); // empty without chemistry
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char ch : t) {
    h ^= ch;
    h *= 0x100000001b3ull;
  }
  return hex16(h);
}

PairProps pairProps(const Material& a, const Material& b) {
  const MaterialPair m = mixMaterials(a, b);
  return PairProps{m.kn, m.ktFactor * m.kn, kernels::dampingFactor(m.en), m.etatFactor, m.mu};
}

/// Mass of particle i for Δt_DEM,max after a restart. With chemistry, the mass at the initial
/// diameter: shrinking particles keep the step of the run that wrote the file
/// (docs/thermochemistry.md).
double restartMass(const DemConfig& c, const HostState& st, std::size_t i) {
  if (!c.chemistry.active() || st.d0.size() != st.n)
    return st.mass[i];
  return st.density[i] * kernels::sphereVolume(0.5 * st.d0[i]);
}

} // namespace

struct DemSystem::Impl {
  DemConfig config;
  EngineSetup setup;
  std::unique_ptr<Engine> engine;
  TimeHandler time;
  std::uint64_t step = 0;
  double dtMax = 0;
  std::string hash;
  CellSources sources;
  std::size_t nParticles = 0;
  const std::atomic<bool>* interrupt = nullptr; ///< setInterruptFlag
  BackendKind kind = BackendKind::Cpu;
  std::unique_ptr<Engine> makeEngine() const {
#if defined(COREDEM_CUDA_ENABLED)
    if (kind == BackendKind::Cuda)
      return makeCudaEngine(setup);
#endif
    if (kind == BackendKind::CudaSim)
      return makeCudaSimEngine(setup);
    return makeCpuEngine(setup);
  }
  std::shared_ptr<coredem::Logger> log = coredem::logger("dem.system");
};

DemSystem::DemSystem(const DemConfig& config, BackendKind backend, int threads)
    : _impl(std::make_unique<Impl>()) {
  Impl& m = *_impl;
  validate(config);
  COREDEM_CHECK(threads >= 0, "threads = {} must be >= 0 (0 = OpenMP default)", threads);
  m.config = config;
  m.interrupt = config.interrupt;
  m.hash = hashConfig(config);

  // Particles.
  HostState st;
  const int ns = static_cast<int>(config.solidSpecies.size());
  st.nSpecies = ns;
  st.historySlots = config.neighbour.historySlots;
  st.neighbourSlots = config.neighbour.initialNeighbourSlots;
  double rmax = 0;
  std::vector<double> minMass(config.materials.size(), std::numeric_limits<double>::infinity());
  std::int64_t nextId = 0;
  for (const ParticleSet& s : config.particleSets) {
    const std::vector<double> p = placeParticles(s, config.interrupt);
    const std::size_t n = p.size() / 3;
    Rng rng{s.seed ^ 0x5bd1e995a5a5a5a5ull};
    const double r = 0.5 * s.diameter;
    const double mass = s.density * kernels::sphereVolume(r);
    rmax = std::max(rmax, r);
    minMass[s.material] = std::min(minMass[s.material], mass);
    for (std::size_t k = 0; k < n; ++k) {
      for (int d = 0; d < 3; ++d) {
        st.pos.push_back(p[3 * k + d]);
        double v = s.velocity[d];
        if (!s.velocities.empty())
          v = s.velocities[3 * k + d];
        if (s.velocityJitter > 0)
          v += s.velocityJitter * (2.0 * rng.uniform() - 1.0);
        st.vel.push_back(v);
        st.omega.push_back(s.angularVelocities.empty() ? 0.0 : s.angularVelocities[3 * k + d]);
      }
      st.radius.push_back(r);
      st.mass.push_back(mass);
      st.density.push_back(s.density);
      st.temperature.push_back(s.temperature);
      for (int q = 0; q < ns; ++q)
        st.species.push_back(s.composition.empty() ? (q == 0 ? 1.0 : 0.0) : s.composition[q]);
      st.material.push_back(s.material);
      st.gid.push_back(nextId++);
    }
  }
  const std::size_t n = st.gid.size();
  COREDEM_CHECK(n < (1ull << 31), "{} particles: at most 2^31-1 are supported", n);
  st.n = n;
  st.xref = st.pos;
  st.listValid = 0;
  initChemistryReferences(config, st); // d_p0, initial C / Fe2O3-equivalent masses
  // Every other field (forces, contact counts, history, neighbour lists, ...) starts from its
  // particle-schema default (zero; empty history slots −1).
  fillDefaults(st);
  m.nParticles = n;

  const std::size_t nm = config.materials.size();
  m.dtMax = coredem::dem::dtDemMax(config, minMass);

  // Engine set-up.
  EngineSetup& es = m.setup;
  es.nMaterials = static_cast<int>(nm);
  for (std::size_t a = 0; a < nm; ++a)
    for (std::size_t b = 0; b < nm; ++b)
      es.pairs.push_back(pairProps(config.materials[a], config.materials[b]));
  for (const Wall& w : config.walls)
    es.walls.push_back(kernelWall(w));
  es.triangles = kernelTriangles(config.meshes);
  es.gravity = {config.gravity[0], config.gravity[1], config.gravity[2]};
  es.nCells = config.grid.cellCount();
  es.coupled = es.nCells > 0;
  if (es.coupled) {
    const CouplingGrid& g = config.grid;
    es.grid = kernels::GridParams{{g.origin[0], g.origin[1], g.origin[2]},
                                  {1.0 / g.spacing[0], 1.0 / g.spacing[1], 1.0 / g.spacing[2]},
                                  g.counts[0],
                                  g.counts[1],
                                  g.counts[2]};
    es.cellVolume = g.spacing[0] * g.spacing[1] * g.spacing[2];
  }
  es.nGasSpecies = static_cast<int>(config.gasSpecies.size());
  es.drag.law = config.drag;
  es.drag.laws = config.dragLaws;
  es.drag.epsMin = config.epsMinDrag;
  es.maxRadius = rmax;
  es.skin = config.neighbour.skinFactor * 2.0 * rmax;
  es.historySlots = config.neighbour.historySlots;
  es.neighbourSlots = config.neighbour.initialNeighbourSlots;
  es.threads = threads;
  es.frozen = config.frozenMotion;
  {
    // Heat transfer (heat.h): the lens needs the neighbour list to reach FLPC·R_max further.
    const HeatOptions& h = config.heat;
    HeatSetup& hs = es.heat;
    hs.options = h;
    for (const Material& mat : config.materials)
      hs.materials.push_back(HeatMaterial{mat.cp, mat.conductivity, mat.emissivity});
    hs.convectionParams.model = h.nusselt;
    hs.convectionParams.voidageExponent = h.voidageExponent;
    hs.convectionParams.reynoldsWithVoidage = h.reynoldsWithVoidage;
    hs.convectionParams.epsMin = config.epsMinDrag;
    hs.lensParams.lensFraction = h.lensFraction;
    hs.lensParams.minSeparation = h.minSeparation;
    hs.lensParams.relTol = h.lensRelTol;
    // Fixed-temperature walls (kernels/wall_conduction.h): every wall at config.wallTemperature.
    COREDEM_CHECK(std::isfinite(config.wallTemperature) && config.wallTemperature >= 0.0,
                  "wall temperature {} K: give a temperature > 0 K, or 0 for adiabatic walls",
                  config.wallTemperature);
    COREDEM_CHECK(config.wallMaterial >= 0 && config.wallMaterial < static_cast<int>(nm),
                  "wall material index {} is not one of the {} materials", config.wallMaterial, nm);
    if (h.enabled && config.wallTemperature > 0.0 && (h.wallConduction || h.wallLensConduction)) {
      const double kw =
          config.materials[static_cast<std::size_t>(config.wallMaterial)].conductivity;
      hs.walls = ThermalWalls{true, config.wallTemperature, kw};
      hs.wallParams = kernels::WallConductionParams{
          h.wallConduction, h.wallLensConduction && es.coupled, h.lensFraction, h.minSeparation};
      // Wall candidates within the lens's reach (wall_lists.h).
      if (hs.wallParams.lens)
        es.wallReachFactor = 1.0 + h.lensFraction;
    }
    es.reach =
        (h.enabled && HeatTerms::of(hs, es.coupled).lensConduction) ? h.lensFraction * rmax : 0.0;
  }

  es.chem = makeChemistrySetup(config); // chemistry (chemistry.h); validates the options

  BackendKind kind = backend;
  if (kind == BackendKind::Auto) {
    const CudaProbe cuda = probeCuda();
    kind = cuda.devices > 0 ? BackendKind::Cuda : BackendKind::Cpu;
    if (!cuda.error.empty()) // a broken GPU setup is not "no GPU": say so loudly
      m.log->warn("backend auto: running on the cpu because the CUDA backend cannot run: {}",
                  cuda.error);
    else if (cuda.devices == 0)
      m.log->info("backend auto: running on the cpu ({})", cuda.note);
  }
  if (kind == BackendKind::Cuda) {
    COREDEM_CHECK(cudaBackendBuilt(),
                  "backend 'cuda' requested but this build has no CUDA backend; "
                  "rebuild with -DCOREDEM_CUDA=ON or use --backend cpu");
    const CudaProbe cuda = probeCuda();
    COREDEM_CHECK(cuda.error.empty(), "backend 'cuda' requested but {}", cuda.error);
    COREDEM_CHECK(cuda.devices > 0,
                  "backend 'cuda' requested but there is no CUDA device: {}; use --backend cpu "
                  "(or auto)",
                  cuda.note);
  }
  m.kind = kind;
  m.engine = m.makeEngine();
  m.engine->setState(st);
  m.log->debug("DemSystem: {} particles, backend {}, dt_dem_max {:.6g} s, config {}", n,
               m.engine->name(), m.dtMax, m.hash);
}

DemSystem::~DemSystem() = default;

double DemSystem::dtDemMax() const {
  return _impl->dtMax;
}

void DemSystem::setGasFields(const GasFieldsView& gas) {
  Impl& m = *_impl;
  COREDEM_CHECK(m.setup.coupled,
                "setGasFields: no coupling grid is configured (DemConfig.grid counts are 0)");
  const std::size_t nc = m.setup.nCells;
  const std::size_t ns = m.config.gasSpecies.size();
  auto check = [&](std::span<const double> s, std::size_t want, const char* name, bool optional,
                   bool positive) -> std::vector<double> {
    if (s.empty() && optional)
      return {};
    COREDEM_CHECK(s.size() == want, "setGasFields: {} has {} values, expected {} ({} cells)", name,
                  s.size(), want, nc);
    for (std::size_t k = 0; k < s.size(); ++k) {
      COREDEM_CHECK(std::isfinite(s[k]), "setGasFields: {}[{}] is not finite", name, k);
      COREDEM_CHECK(!positive || s[k] > 0, "setGasFields: {}[{}] = {} must be > 0", name, k, s[k]);
    }
    return std::vector<double>(s.begin(), s.end());
  };
  GasArrays g;
  g.ug = check(gas.ug, 3 * nc, "u_g", false, false);
  g.gradP = check(gas.gradP, 3 * nc, "grad_p", false, false);
  g.rhoG = check(gas.rhoG, nc, "rho_g", false, true);
  g.muG = check(gas.muG, nc, "mu_g", false, true);
  g.Tg = check(gas.Tg, nc, "T_g", true, true);
  g.kappaG = check(gas.kappaG, nc, "kappa_g", true, true);
  g.cpG = check(gas.cpG, nc, "cp_g", true, true);
  g.Yg = check(gas.Yg, nc * ns, "Y_g", true, false);
  g.fluidFraction = check(gas.fluidFraction, nc, "fluid_fraction", true, false);
  for (std::size_t k = 0; k < g.fluidFraction.size(); ++k) {
    COREDEM_CHECK(g.fluidFraction[k] >= 0.0 && g.fluidFraction[k] <= 1.0,
                  "setGasFields: fluid_fraction[{}] = {} must lie in [0, 1]", k,
                  g.fluidFraction[k]);
  }
  m.engine->setGas(g);
}

const CellSources& DemSystem::advance(double dtCfd, int nSub) {
  Impl& m = *_impl;
  COREDEM_CHECK(dtCfd > 0 && std::isfinite(dtCfd), "advance: dtCfd = {} must be > 0 and finite",
                dtCfd);
  COREDEM_CHECK(nSub >= 1, "advance: nSub = {} must be >= 1", nSub);
  const double dt = dtCfd / nSub;
  COREDEM_CHECK(
      dt <= m.dtMax * (1.0 + 1e-12),
      "advance: dtCfd/nSub = {:.6g} s exceeds the stable DEM step {:.6g} s (t_col/{}); use "
      "nSub >= {} (TimeHandler::subStepsFor)",
      dt, m.dtMax, m.config.dtFactor, TimeHandler::subStepsFor(dtCfd, m.dtMax));
  m.engine->beginWindow();
  for (int s = 0; s < nSub; ++s) {
    if (m.interrupt != nullptr && m.interrupt->load(std::memory_order_relaxed)) {
      throw Interrupted(coredem::format("interrupted after {} of {} sub-steps", s, nSub));
    }
    m.engine->subStep(dt);
    m.time.add(dt);
    ++m.step;
  }
  m.engine->endWindow(dtCfd, nSub, m.sources);
  if (m.engine->takeRemovalRequest()) {
    // Particles below removalFraction·d_p0: removed at the CFD-step boundary (host compaction).
    const auto t0 = std::chrono::steady_clock::now();
    HostState st = m.engine->state();
    ChemistryTotals totals = m.engine->chemistryTotals();
    const double before = totals.removedMass();
    const std::size_t removed =
        removeSmallParticles(m.config.chemistry.removalFraction, st, totals);
    m.engine->restoreChemistryTotals(totals); // the removed mass joins the chemistry ledger
    if (removed > 0) {
      m.engine->setState(st);
      m.nParticles = st.n;
      m.log->info("t = {:.6g} s: removed {} particle(s) below {} of their initial diameter ({:.6g} "
                  "kg); {} left",
                  m.time.time(), removed, m.config.chemistry.removalFraction,
                  totals.removedMass() - before, st.n);
    }
    m.engine->times().chemistry +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return m.sources;
}

const CellSources& DemSystem::evaluateSources(double dtDem) {
  Impl& m = *_impl;
  COREDEM_CHECK(dtDem > 0 && std::isfinite(dtDem) && dtDem <= m.dtMax * (1.0 + 1e-12),
                "evaluateSources: dtDem = {:.6g} s must be > 0 and <= the stable DEM step {:.6g} s",
                dtDem, m.dtMax);
  // Everything one sub-step changes is put back afterwards: particles and contact history (the
  // host state, as a restart would), the ledgers, the stage timers. Time and step are untouched.
  const HostState saved = m.engine->state();
  const HeatTotals heat = m.engine->heatTotals();
  const ChemistryTotals chemistry = m.engine->chemistryTotals();
  const StageTimes times = m.engine->times();
  m.engine->beginWindow();
  m.engine->subStep(dtDem);
  m.engine->endWindow(dtDem, 1, m.sources);
  (void)m.engine->takeRemovalRequest(); // no removal: the state is put back
  m.engine->setState(saved);
  m.engine->restoreHeatTotals(heat);
  m.engine->restoreChemistryTotals(chemistry);
  m.engine->times() = times;
  return m.sources;
}

void DemSystem::setInterruptFlag(const std::atomic<bool>* flag) {
  _impl->interrupt = flag;
}

void DemSystem::writeState(const std::string& path, const std::string& protocolVersion) const {
  Impl& m = *_impl;
  StateMeta meta;
  meta.time = m.time.time();
  meta.timeCompensation = m.time.compensation();
  meta.step = m.step;
  meta.backend = m.engine->name();
  meta.configHash = m.hash;
  meta.softwareVersion = std::string(
      coredem::kVersion); // (not operator=(const char*): GCC 12 -Wrestrict false positive)
  meta.protocolVersion = protocolVersion.empty() ? std::string("none") : protocolVersion;
  meta.heat = m.engine->heatTotals();
  meta.hasChemistry = m.config.chemistry.active();
  meta.chemistry = m.engine->chemistryTotals();
  writeStateFile(path, m.engine->state(), meta);
}

void DemSystem::readState(const std::string& path) {
  Impl& m = *_impl;
  HostState st;
  StateMeta meta;
  readStateFile(path, st, meta);
  COREDEM_CHECK(
      meta.configHash == m.hash,
      "state file '{}' was written with config hash {} but this system's is {}: restart with "
      "the same materials, walls, gravity, grid, species and options",
      path, meta.configHash, m.hash);
  COREDEM_CHECK(st.nSpecies == static_cast<int>(m.config.solidSpecies.size()),
                "state file '{}' has {} solid species, the config {}", path, st.nSpecies,
                m.config.solidSpecies.size());
  COREDEM_CHECK(st.historySlots >= 1, "state file '{}': bad history_slots", path);
  double rmax = 0;
  std::vector<double> minMass(m.config.materials.size(), std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < st.n; ++i) {
    rmax = std::max(rmax, st.radius[i]);
    if (st.material[i] >= 0 && st.material[i] < static_cast<int>(minMass.size()))
      minMass[st.material[i]] = std::min(minMass[st.material[i]], restartMass(m.config, st, i));
    COREDEM_CHECK(
        st.material[i] >= 0 && st.material[i] < static_cast<int>(m.config.materials.size()),
        "state file '{}': particle {} has material {} not in the config", path, i, st.material[i]);
  }
  COREDEM_CHECK(rmax <= m.setup.maxRadius * (1 + 1e-12) || m.nParticles == 0,
                "state file '{}' holds particles larger (r = {}) than the configured sets (r = {})",
                path, rmax, m.setup.maxRadius);
  if (m.nParticles == 0 && rmax > 0) {
    // Built without particle sets: take the neighbour cell size from the file.
    m.setup.maxRadius = rmax;
    m.setup.skin = m.config.neighbour.skinFactor * 2.0 * rmax;
    if (m.config.heat.enabled && HeatTerms::of(m.setup.heat, m.setup.coupled).lensConduction)
      m.setup.reach = m.config.heat.lensFraction * rmax;
    m.engine.reset();
    m.engine = m.makeEngine();
  }
  m.engine->setState(st);
  m.engine->restoreHeatTotals(meta.heat);
  if (meta.hasChemistry)
    m.engine->restoreChemistryTotals(meta.chemistry);
  m.nParticles = st.n;
  m.dtMax = coredem::dem::dtDemMax(m.config, minMass);
  m.time.restore(meta.time, meta.timeCompensation);
  m.step = meta.step;
}

double DemSystem::time() const {
  return _impl->time.time();
}
std::uint64_t DemSystem::step() const {
  return _impl->step;
}
std::size_t DemSystem::particleCount() const {
  return _impl->nParticles;
}
std::size_t DemSystem::cellCount() const {
  return _impl->setup.nCells;
}
std::string DemSystem::backendName() const {
  return _impl->engine->name();
}
std::string DemSystem::configHash() const {
  return _impl->hash;
}
const DemConfig& DemSystem::config() const {
  return _impl->config;
}

ParticleData DemSystem::particles() const {
  ParticleData p;
  _impl->engine->particles(p);
  return p;
}

void DemSystem::setVelocities(std::span<const double> velocityByGid,
                              std::span<const double> omegaByGid) {
  Impl& m = *_impl;
  HostState s = m.engine->state();
  COREDEM_CHECK(velocityByGid.empty() || velocityByGid.size() == 3 * s.n,
                "setVelocities: {} velocity values, expected {}", velocityByGid.size(), 3 * s.n);
  COREDEM_CHECK(omegaByGid.empty() || omegaByGid.size() == 3 * s.n,
                "setVelocities: {} angular velocity values, expected {}", omegaByGid.size(),
                3 * s.n);
  for (double v : velocityByGid)
    COREDEM_CHECK(std::isfinite(v), "setVelocities: a velocity is not finite");
  for (double v : omegaByGid)
    COREDEM_CHECK(std::isfinite(v), "setVelocities: an angular velocity is not finite");
  for (std::size_t i = 0; i < s.n; ++i) {
    const std::size_t g = static_cast<std::size_t>(s.gid[i]);
    COREDEM_CHECK(s.gid[i] >= 0 && g < s.n,
                  "setVelocities: global ids are not 0..N-1 (state read from a file "
                  "with other ids); set velocities through ParticleSet instead");
    for (int d = 0; d < 3; ++d) {
      if (!velocityByGid.empty())
        s.vel[3 * i + d] = velocityByGid[3 * g + d];
      if (!omegaByGid.empty())
        s.omega[3 * i + d] = omegaByGid[3 * g + d];
    }
  }
  m.engine->setState(s);
}

std::size_t DemSystem::contactCount() const {
  return _impl->engine->pairContacts() + _impl->engine->wallContacts();
}
std::size_t DemSystem::pairContactCount() const {
  return _impl->engine->pairContacts();
}
std::array<double, 3> DemSystem::wallForce() const {
  return _impl->engine->wallForce();
}
std::size_t DemSystem::memoryBytes() const {
  return _impl->engine->memoryBytes();
}
StageTimes DemSystem::stageTimes() const {
  return _impl->engine->times();
}
void DemSystem::resetStageTimes() {
  _impl->engine->times() = StageTimes{};
}
HeatTotals DemSystem::heatTotals() const {
  return _impl->engine->heatTotals();
}
ChemistryTotals DemSystem::chemistryTotals() const {
  return _impl->engine->chemistryTotals();
}

double DemSystem::thermalEnergy() const {
  const ParticleData p = particles();
  double e = 0.0;
  for (std::size_t i = 0; i < p.count; ++i)
    e += p.mass[i] * _impl->config.materials[static_cast<std::size_t>(p.material[i])].cp *
         p.temperature[i];
  return e;
}

} // namespace coredem::dem
