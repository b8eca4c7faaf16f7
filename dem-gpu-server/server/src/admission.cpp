// Admission control: count limits from a memory budget, checked before allocating.
#include "admission.h"

#include <cmath>
#include <cstdlib>
#include <limits>

#include <unistd.h>

#include "coredem/common/check.h"
#include "coredem/protocol/status.h"
#include "coredem/protocol/validate.h"

namespace coredem::server {

namespace {

constexpr std::uint64_t kSaturated = std::numeric_limits<std::uint64_t>::max();

std::uint64_t addSat(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_add_overflow(a, b, &r) ? kSaturated : r;
}
std::uint64_t mulSat(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? kSaturated : r;
}

std::string count(std::uint64_t n) {
  return n == kSaturated ? std::string("more than 2^64 (overflow)") : std::to_string(n);
}

std::string over(const std::string& field, std::uint64_t value, std::uint64_t limit,
                 const std::string& why) {
  return "Configure: " + field + " = " + count(value) + " exceeds the limit " +
         std::to_string(limit) + " (" + why + ")";
}

} // namespace

std::uint64_t defaultMaxMemory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  const std::uint64_t physical = pages > 0 && page > 0 ? mulSat(static_cast<std::uint64_t>(pages),
                                                                static_cast<std::uint64_t>(page))
                                                       : (std::uint64_t{8} << 30);
  return std::max<std::uint64_t>(physical / 2, std::uint64_t{1} << 30);
}

std::uint64_t parseBytes(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  std::string unit(end != nullptr ? end : "");
  while (!unit.empty() && unit.front() == ' ') {
    unit.erase(unit.begin());
  }
  double scale = 1.0;
  if (unit.empty() || unit == "B") {
    scale = 1.0;
  } else if (unit == "K" || unit == "KiB" || unit == "KB") {
    scale = 1024.0;
  } else if (unit == "M" || unit == "MiB" || unit == "MB") {
    scale = 1024.0 * 1024.0;
  } else if (unit == "G" || unit == "GiB" || unit == "GB") {
    scale = 1024.0 * 1024.0 * 1024.0;
  } else if (unit == "T" || unit == "TiB" || unit == "TB") {
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  } else {
    scale = -1.0;
  }
  const double bytes = v * scale;
  COREDEM_CHECK(end != text.c_str() && scale > 0.0 && std::isfinite(bytes) && bytes >= 1.0 &&
                    bytes < 1.8e19,
                "'{}' is not a memory size; give e.g. 8G, 512M or a number of bytes",
                protocol::printable(text));
  return static_cast<std::uint64_t>(bytes);
}

std::string formatBytes(std::uint64_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 6) {
    v /= 1024.0;
    ++u;
  }
  return u == 0 ? std::to_string(bytes) + " B" : fmt::format("{:.3g} {}", v, units[u]);
}

Limits limitsFor(std::uint64_t memoryBytes, std::uint64_t subSteps) {
  Limits l;
  l.memoryBytes = memoryBytes;
  l.particles = memoryBytes / MemoryModel::kParticleBase;
  l.cells = std::min<std::uint64_t>(memoryBytes / MemoryModel::kCellBase, protocol::kMaxCells);
  l.subSteps = subSteps;
  return l;
}

std::uint64_t estimateBytes(std::uint64_t particles, std::uint64_t cells, std::uint64_t gasSpecies,
                            std::uint64_t solidSpecies, std::uint64_t materials) {
  using M = MemoryModel;
  const std::uint64_t perParticle =
      addSat(M::kParticleBase, mulSat(M::kParticlePerSpecies, addSat(gasSpecies, solidSpecies)));
  const std::uint64_t perCell = addSat(M::kCellBase, mulSat(M::kCellPerSpecies, gasSpecies));
  std::uint64_t total = mulSat(particles, perParticle);
  total = addSat(total, mulSat(cells, perCell));
  total = addSat(total, mulSat(mulSat(materials, materials), M::kMaterialPair));
  return total;
}

std::string admitConfigure(const v1::Configure& c, const Limits& l) {
  const auto n = [](int size) { return static_cast<std::uint64_t>(size); };
  struct Row {
    const char* field;
    std::uint64_t value, limit;
    const char* why;
  };
  const Row rows[] = {
      {"materials (count)", n(c.materials_size()), l.materials,
       "the material-pair table grows with its square"},
      {"species (count)", n(c.species_size()), l.species, "gas species per cell"},
      {"solid_species (count)", n(c.solid_species_size()), l.solidSpecies,
       "solid species per particle"},
      {"particle_sets (count)", n(c.particle_sets_size()), l.particleSets, "particle sets"},
      {"reactions (count)", n(c.reactions_size()), l.reactions, "reactions"},
      {"options (count)", n(c.options_size()), l.options, "model options by name"},
      {"walls.revolved (count)", n(c.walls().revolved_size()), l.revolvedWalls,
       "cylinder and cone walls"},
      {"walls.meshes (count)", n(c.walls().meshes_size()), l.meshWalls, "mesh walls"},
      {"sub_cycling.n_sub", c.sub_cycling().n_sub(), l.subSteps,
       "sub-steps per CFD step, coredem-dem --max-sub-steps"},
  };
  for (const Row& r : rows) {
    if (r.value > r.limit) {
      return over(r.field, r.value, r.limit, r.why);
    }
  }
  const auto checkName = [&](const std::string& field, const std::string& s) -> std::string {
    if (s.size() > l.nameBytes) {
      return "Configure: " + field + " '" + protocol::printable(s, 40) + "' has " +
             std::to_string(s.size()) + " bytes; the limit is " + std::to_string(l.nameBytes);
    }
    return {};
  };
  for (const auto& kv : c.options()) {
    if (auto e = checkName("options key", kv.key()); !e.empty()) {
      return e;
    }
    if (auto e = checkName("options value", kv.value()); !e.empty()) {
      return e;
    }
  }
  for (const auto& s : c.species()) {
    if (auto e = checkName("species name", s.name()); !e.empty()) {
      return e;
    }
  }
  // Mesh walls (v1.4): the counts over all meshes before any copy is made.
  std::uint64_t triangles = 0, vertices = 0;
  for (const auto& m : c.walls().meshes()) {
    if (auto e = checkName("walls.meshes name", m.name()); !e.empty()) {
      return e;
    }
    triangles = addSat(triangles, n(m.triangles_size()) / 3);
    vertices = addSat(vertices, n(m.vertices_size()) / 3);
  }
  if (triangles > l.meshTriangles) {
    return over("walls.meshes[].triangles (total, triangles)", triangles, l.meshTriangles,
                "mesh-wall triangles; coarsen the STL surfaces");
  }
  if (vertices > l.meshVertices) {
    return over("walls.meshes[].vertices (total, vertices)", vertices, l.meshVertices,
                "mesh-wall vertices; coarsen the STL surfaces");
  }
  std::uint64_t particles = 0;
  for (const auto& ps : c.particle_sets()) {
    particles = addSat(particles, ps.count());
  }
  const std::string budget =
      formatBytes(l.memoryBytes) + " memory budget, coredem-dem --max-memory";
  if (particles > l.particles) {
    return over("particle_sets[].count (total)", particles, l.particles,
                budget + ", about " + formatBytes(MemoryModel::kParticleBase) + " per particle");
  }
  const std::uint64_t cells = protocol::cellCount(c.coupling_mesh());
  if (cells > l.cells) {
    return over("coupling_mesh cells (x*y*z)", cells, l.cells,
                budget + ", about " + formatBytes(MemoryModel::kCellBase) + " per cell");
  }
  const std::uint64_t need = addSat(estimateBytes(particles, cells, n(c.species_size()),
                                                  n(c.solid_species_size()), n(c.materials_size())),
                                    mulSat(triangles, MemoryModel::kMeshTriangle));
  if (need > l.memoryBytes) {
    return "Configure: the estimated memory " + formatBytes(need) + " (" + count(particles) +
           " particles, " + count(cells) + " cells, " + std::to_string(c.species_size()) +
           " gas species, " + std::to_string(c.materials_size()) + " materials" +
           (triangles > 0 ? ", " + count(triangles) + " mesh-wall triangles" : std::string()) +
           ") exceeds the " + budget + "; give fewer particles or cells, or raise --max-memory";
  }
  return {};
}

} // namespace coredem::server
