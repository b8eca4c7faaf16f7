// DemConfig: its builders (addBox, the Wall shapes), its validation and its hash.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

#include "chemistry_config.h"
#include "config_setup.h"
#include "coredem/common/check.h"
#include "coredem/common/version.h"
#include "coredem/dem/models.h"
#include "coredem/dem/triangle_mesh.h"

namespace coredem::dem {

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

/// The contact law's material properties, the material pairs and the walls' materials.
void validateContactMaterials(const DemConfig& c) {
  const int nm = static_cast<int>(c.materials.size());
  if (c.contact == kernels::ContactLaw::HertzMindlin) {
    for (const Material& mat : c.materials) {
      COREDEM_CHECK(mat.youngsModulus > 0 && std::isfinite(mat.youngsModulus),
                    "material '{}': the contact law hertz-mindlin needs youngs_modulus > 0 Pa "
                    "(got {})",
                    mat.name, mat.youngsModulus);
      COREDEM_CHECK(mat.poissonRatio > -1.0 && mat.poissonRatio < 0.5,
                    "material '{}': poisson_ratio = {} must be in (-1, 0.5)", mat.name,
                    mat.poissonRatio);
    }
  }
  for (std::size_t k = 0; k < c.materialPairs.size(); ++k) {
    const MaterialPair& p = c.materialPairs[k];
    COREDEM_CHECK(p.a >= 0 && p.a < nm && p.b >= 0 && p.b < nm,
                  "material pair {}: material indices {}, {} are not in 0..{}", k + 1, p.a, p.b,
                  nm - 1);
    COREDEM_CHECK(std::isnan(p.en) || (p.en > 0 && p.en <= 1),
                  "material pair {}: en = {} must be in (0, 1]", k + 1, p.en);
    COREDEM_CHECK(std::isnan(p.mu) || (p.mu >= 0 && std::isfinite(p.mu)),
                  "material pair {}: mu = {} must be >= 0", k + 1, p.mu);
    for (std::size_t q = 0; q < k; ++q) {
      const MaterialPair& o = c.materialPairs[q];
      COREDEM_CHECK(!((o.a == p.a && o.b == p.b) || (o.a == p.b && o.b == p.a)),
                    "material pairs {} and {} name the same pair of materials", q + 1, k + 1);
    }
  }
  for (std::size_t k = 0; k < c.walls.size(); ++k)
    COREDEM_CHECK(c.walls[k].material >= -1 && c.walls[k].material < nm,
                  "wall {}: material index {} is not in 0..{} (or -1)", k + 1, c.walls[k].material,
                  nm - 1);
  for (const MeshWall& m : c.meshes)
    COREDEM_CHECK(m.material >= -1 && m.material < nm,
                  "mesh wall '{}': material index {} is not in 0..{} (or -1)", m.name, m.material,
                  nm - 1);
}

} // namespace

namespace cfg {

void validate(const DemConfig& c) {
  COREDEM_CHECK(!c.materials.empty(), "DemConfig.materials is empty; define at least one material");
  for (std::size_t m = 0; m < c.materials.size(); ++m) {
    const Material& mat = c.materials[m];
    COREDEM_CHECK(c.contact != kernels::ContactLaw::LinearSpringDashpot ||
                      (mat.kn > 0 && std::isfinite(mat.kn)),
                  "material '{}': the contact law linear-spring-dashpot needs kn > 0 N/m (got {})",
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
  validateContactMaterials(c);
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
    if (c.contact == kernels::ContactLaw::HertzMindlin) // absent for LSD: earlier hashes stay
      t += "E", num(m.youngsModulus), num(m.poissonRatio);
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
    if (w.material >= 0) // absent for the default (the particle's own): earlier hashes stay
      t += "m", num(w.material);
  }
  for (const MeshWall& m : c.meshes) {
    t += "|mesh:" + m.name + ":";
    for (double v : m.vertices)
      num(v);
    for (std::int32_t i : m.triangles)
      t += std::to_string(i) + ",";
    if (m.material >= 0)
      t += "m", num(m.material);
  }
  for (const MaterialPair& p : c.materialPairs) // none: earlier hashes stay
    t += "|pair:", num(p.a), num(p.b), num(p.en), num(p.mu);
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
  if (c.contact != kernels::ContactLaw::LinearSpringDashpot) { // absent for the default law
    t += "|contact:";
    num(static_cast<int>(c.contact));
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

} // namespace cfg
} // namespace coredem::dem
