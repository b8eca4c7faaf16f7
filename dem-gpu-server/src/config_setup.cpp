// From a DemConfig to the engine's plain data: particle positions, walls, mesh triangles,
// material pairs.
#include "config_setup.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "coredem/common/check.h"
#include "coredem/dem/kernels/contact_law.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/models.h"
#include "coredem/dem/triangle_mesh.h"

namespace coredem::dem::cfg {

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
/// The engine's form of a wall (kernels/wall_contact.h): a plane, or a profile revolved about a
/// unit axis (optional bottom cap, side, optional top cap).
kernels::Wall kernelWall(const Wall& w) {
  const double l = std::hypot(w.normal[0], w.normal[1], w.normal[2]);
  const kernels::Vec3 p{w.point[0], w.point[1], w.point[2]};
  const kernels::Vec3 n{w.normal[0] / l, w.normal[1] / l, w.normal[2] / l};
  if (w.shape == WallShape::Plane) {
    kernels::Wall k = kernels::planeWall(p, n);
    k.material = w.material;
    return k;
  }
  kernels::Wall k{};
  k.material = w.material;
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
      k.material = m.material;
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
void setUpContacts(const DemConfig& config, EngineSetup& es) {
  const std::size_t nm = config.materials.size();
  es.contactLaw = config.contact;
  es.pairs.clear();
  kernels::visitModel(kernels::ContactLaws{}, static_cast<int>(config.contact), [&](auto law) {
    using Law = typename decltype(law)::type;
    const typename Law::Params& params = config.contactLaws.template of<Law>();
    for (std::size_t a = 0; a < nm; ++a)
      for (std::size_t b = 0; b < nm; ++b) {
        const auto [ma, mb] = pairMaterials(config, a, b); // material_pairs overrides
        es.pairs.push_back(kernels::ContactPair::make<Law>(Law::mix(params, ma, mb)));
      }
  });
}

/// Mass of particle i for Δt_DEM,max after a restart. With chemistry, the mass at the initial
/// diameter: shrinking particles keep the step of the run that wrote the file
/// (docs/thermochemistry.md).
double restartMass(const DemConfig& c, const HostState& st, std::size_t i) {
  if (!c.chemistry.active() || st.d0.size() != st.n)
    return st.mass[i];
  return st.density[i] * kernels::sphereVolume(0.5 * st.d0[i]);
}

void setUpHeat(const DemConfig& config, double rmax, EngineSetup& es) {
  const std::size_t nm = config.materials.size();
  // Heat transfer (heat.h): the lens needs the neighbour list to reach FLPC·R_max further.
  const HeatOptions& h = config.heat;
  HeatSetup& hs = es.heat;
  hs.options = h;
  for (const Material& mat : config.materials)
    hs.materials.push_back(HeatMaterial{mat.cp, mat.conductivity, mat.emissivity});
  hs.convectionParams.model = h.nusselt;
  hs.convectionParams.models = h.nusseltModels;
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
    const double kw = config.materials[static_cast<std::size_t>(config.wallMaterial)].conductivity;
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

} // namespace coredem::dem::cfg
