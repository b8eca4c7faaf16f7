// Pre-flight consistency of a case (preflight.h): geometry, packing, temperatures, the
// staggered step; a participant's own input is checked by its row's pre-flight hook
// (participants.h; the OpenFOAM case: cfd-adapter/openfoam/participant).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>
#include <regex>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include <coredem/common/log.h>
#include <coredem/common/yaml_section.h>
#include <coredem/dem/kernels/mesh_contact.h>
#include <coredem/orchestrator/participants.h>
#include <coredem/orchestrator/preflight.h>
#include <coredem/orchestrator/preflight_locator.h>
#include <coredem/orchestrator/wall_geometry.h>

#include "preflight_limits.h"

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

constexpr double kPi = 3.14159265358979323846;

using preflight::dot;
using preflight::fmtVec;
using preflight::Locator;

struct Box {
  Vec3 lo{}, hi{};
};

std::string fmtBox(const Box& b) {
  return fmtVec(b.lo) + " to " + fmtVec(b.hi);
}

const char* axisName(int d) {
  static const char* names[] = {"x", "y", "z"};
  return names[d];
}

/// The first axis on which `inner` sticks out of `outer` by more than `tol`, with a message
/// naming both values; empty when inside.
std::string outside(const Box& inner, const Box& outer, double tol) {
  for (int d = 0; d < 3; ++d) {
    if (inner.lo[d] < outer.lo[d] - tol) {
      return fmt::format("{} = {:.6g} m < {:.6g} m", axisName(d), inner.lo[d], outer.lo[d]);
    }
    if (inner.hi[d] > outer.hi[d] + tol) {
      return fmt::format("{} = {:.6g} m > {:.6g} m", axisName(d), inner.hi[d], outer.hi[d]);
    }
  }
  return {};
}

/// The space the particles of a set occupy initially (whole particles): the region for lattice
/// and random packing (the DEM places them inside it), else the bounding box of the spheres.
Box occupied(const ParticleSetConfig& p) {
  if (p.positions.empty()) {
    return {p.regionMin, p.regionMax};
  }
  const double r = 0.5 * p.diameter;
  Box b{p.positions.front(), p.positions.front()};
  for (const auto& x : p.positions) {
    for (int d = 0; d < 3; ++d) {
      b.lo[d] = std::min(b.lo[d], x[d]);
      b.hi[d] = std::max(b.hi[d], x[d]);
    }
  }
  for (int d = 0; d < 3; ++d) {
    b.lo[d] -= r;
    b.hi[d] += r;
  }
  return b;
}

/// Centres a set's particles can have: explicit positions, or the corners of the region shrunk
/// by the radius (lattice and random centres lie in that box, so a plane that keeps its corners
/// keeps them all).
std::vector<Vec3> extremeCentres(const ParticleSetConfig& p) {
  if (!p.positions.empty()) {
    return p.positions;
  }
  const double r = 0.5 * p.diameter;
  std::vector<Vec3> out;
  for (int k = 0; k < 8; ++k) {
    Vec3 x{};
    for (int d = 0; d < 3; ++d) {
      x[d] = (k >> d) & 1 ? std::max(p.regionMax[d] - r, p.regionMin[d] + r)
                          : std::min(p.regionMin[d] + r, p.regionMax[d] - r);
    }
    out.push_back(x);
  }
  return out;
}

std::string setName(const ParticleSetConfig& p, std::size_t i) {
  return p.name.empty() ? fmt::format("particles[{}]", i)
                        : fmt::format("particles[{}] ({})", i, p.name);
}

void warnTemperature(const Locator& at, std::vector<std::string>& warnings,
                     const std::vector<std::string>& path, const std::string& key, double value) {
  if (value > 0.0 && value < kImplausibleTemperatureK) {
    warnings.push_back(
        at.warning(path, key,
                   fmt::format("{:.6g} K is below {:.0f} K: °C given? (temperatures "
                               "are in kelvin: {:.6g} °C = {:.6g} K)",
                               value, kImplausibleTemperatureK, value, value + 273.15)));
  }
}

/// Explicit positions of all sets: no pair overlaps by more than kMaxInitialOverlapFraction of
/// the smaller diameter (sweep along x).
void checkExplicitOverlaps(const CaseConfig& c, const Locator& at) {
  struct P {
    Vec3 x;
    double d;
    std::size_t set, index;
  };
  std::vector<P> all;
  double dMax = 0.0;
  for (std::size_t i = 0; i < c.particles.size(); ++i) {
    const auto& s = c.particles[i];
    for (std::size_t k = 0; k < s.positions.size(); ++k) {
      all.push_back({s.positions[k], s.diameter, i, k});
      dMax = std::max(dMax, s.diameter);
    }
  }
  std::sort(all.begin(), all.end(), [](const P& a, const P& b) { return a.x[0] < b.x[0]; });
  for (std::size_t a = 0; a < all.size(); ++a) {
    for (std::size_t b = a + 1; b < all.size() && all[b].x[0] - all[a].x[0] < dMax; ++b) {
      const Vec3 dx{all[b].x[0] - all[a].x[0], all[b].x[1] - all[a].x[1],
                    all[b].x[2] - all[a].x[2]};
      const double overlap = 0.5 * (all[a].d + all[b].d) - std::sqrt(dot(dx, dx));
      const double dMin = std::min(all[a].d, all[b].d);
      if (overlap > kMaxInitialOverlapFraction * dMin) {
        const P& p =
            all[a].set < all[b].set || (all[a].set == all[b].set && all[a].index < all[b].index)
                ? all[b]
                : all[a];
        const P& q = &p == &all[a] ? all[b] : all[a];
        at.fail({"particles", std::to_string(p.set), "positions", std::to_string(p.index)},
                fmt::format("particles[{}].positions[{}]", p.set, p.index),
                fmt::format("overlaps particles[{}].positions[{}] by {:.4g} m = {:.3g} of the "
                            "smaller diameter (at most {:.3g} allowed): centres {} and {}",
                            q.set, q.index, overlap, overlap / dMin, kMaxInitialOverlapFraction,
                            fmtVec(p.x), fmtVec(q.x)));
      }
    }
  }
}

/// What the consistency checkers share: the case, where its keys are, the coupling grid's box
/// with its tolerance, the closed mesh walls' insides, and the warnings so far.
struct Consistency {
  const CaseConfig& c;
  const Locator& at;
  Box grid;
  double tol = 0.0;
  std::vector<std::optional<ClosedSurface>> closed;
  std::vector<std::string> warnings;
};

/// The walls inside the coupling grid: particles can reach every point within them.
void checkWallsInGrid(Consistency& ck) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  const Box& grid = ck.grid;
  const double tol = ck.tol;
  if (c.walls.box) {
    const Box walls{c.walls.box->first, c.walls.box->second};
    const std::string why = outside(walls, grid, tol);
    if (!why.empty()) {
      at.fail({"walls", "box"}, "walls.box",
              fmt::format("the walls {} extend beyond the coupling grid {} ({}); particles "
                          "outside the grid get no gas forces: enlarge grid.cells or "
                          "grid.origin, or shrink walls.box",
                          fmtBox(walls), fmtBox(grid), why));
    }
  }

  // Cylinders and cones that hold the particles (side inside or both) and mesh walls inside the
  // coupling grid too. A wall the particles are outside of (an insert) bounds nothing; the axial
  // directions of an infinite cylinder are unbounded and left to the other walls.
  for (const auto& w : c.walls.revolved) {
    if (w.side == "outside") {
      continue;
    }
    const Bounds wb = wallBounds(w);
    Box b{wb.lo, wb.hi};
    for (std::size_t d = 0; d < 3; ++d) {
      b.lo[d] = std::isfinite(b.lo[d]) ? b.lo[d] : grid.lo[d];
      b.hi[d] = std::isfinite(b.hi[d]) ? b.hi[d] : grid.hi[d];
    }
    const std::string why = outside(b, grid, tol);
    if (!why.empty()) {
      at.fail({"walls", w.cone ? "cones" : "cylinders", std::to_string(w.index)}, w.key(),
              fmt::format("the {} spans {}, beyond the coupling grid {} ({}); particles outside "
                          "the grid get no gas forces: enlarge grid.cells or grid.origin, or move "
                          "or shrink the wall",
                          w.cone ? "cone" : "cylinder", fmtBox(b), fmtBox(grid), why));
    }
  }
  for (std::size_t k = 0; k < c.walls.meshes.size(); ++k) {
    const Bounds mb = meshBounds(c.walls.meshes[k]);
    const Box b{mb.lo, mb.hi};
    const std::string why = outside(b, grid, tol);
    if (!why.empty()) {
      const MeshWallConfig& m = c.walls.meshes[k];
      at.fail({"walls", "meshes", std::to_string(k), m.sourceKey()},
              fmt::format("walls.meshes[{}].{}", k, m.sourceKey()),
              fmt::format("the mesh '{}' spans {}, beyond the coupling grid {} ({}); enlarge "
                          "grid.cells or grid.origin, or check the mesh's position and scale{}",
                          m.name, fmtBox(b), fmtBox(grid), why,
                          m.fromCfd.empty() ? "" : " (the coupling grid must cover the CFD mesh)"));
    }
  }
  // Closed mesh walls hold the particles: their inside, for the test of every set below.
  ck.closed.resize(c.walls.meshes.size());
  for (std::size_t k = 0; k < c.walls.meshes.size(); ++k) {
    if (c.walls.meshes[k].closed) {
      ck.closed[k].emplace(c.walls.meshes[k].vertices, c.walls.meshes[k].triangles);
    }
  }
}

/// Particle set i inside the grid and every wall that holds it.
void checkSetInWalls(Consistency& ck, std::size_t i) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  const Box& grid = ck.grid;
  const double tol = ck.tol;
  const auto& closed = ck.closed;
  const auto& p = c.particles[i];
  const std::string idx = std::to_string(i);
  const std::vector<std::string> where =
      p.positions.empty() ? std::vector<std::string>{"particles", idx, "region"}
                          : std::vector<std::string>{"particles", idx, "positions"};
  const std::string key = fmt::format("particles[{}].{}", i, where.back());
  const Box b = occupied(p);
  // The grid holds the region (lattice, random) or every centre (positions: particles are
  // coupled to the cell of their centre).
  const double r = 0.5 * p.diameter;
  Box coupled = b;
  if (!p.positions.empty()) {
    for (int d = 0; d < 3; ++d) {
      coupled.lo[d] += r;
      coupled.hi[d] -= r;
    }
  }
  std::string why = outside(coupled, grid, tol);
  if (!why.empty()) {
    at.fail(where, key,
            fmt::format("{}: the particle {} {}, beyond the coupling grid {} ({}); "
                        "enlarge grid.cells or grid.origin, or move the particles",
                        setName(p, i), p.positions.empty() ? "region is" : "centres span",
                        fmtBox(coupled), fmtBox(grid), why));
  }
  if (c.walls.box) {
    const Box walls{c.walls.box->first, c.walls.box->second};
    why = outside(b, walls, tol + (p.positions.empty() ? 0.0 : kMaxInitialOverlapFraction * r));
    if (!why.empty()) {
      at.fail(where, key,
              fmt::format("{}: the particles occupy {}, outside the walls {} ({}); place "
                          "them inside walls.box",
                          setName(p, i), fmtBox(b), fmtBox(walls), why));
    }
  }
  for (std::size_t k = 0; k < c.walls.planes.size(); ++k) {
    const auto& pl = c.walls.planes[k];
    const double len = std::sqrt(dot(pl.normal, pl.normal));
    if (len <= 0.0) {
      continue;
    }
    for (const auto& x : extremeCentres(p)) {
      const Vec3 rel{x[0] - pl.point[0], x[1] - pl.point[1], x[2] - pl.point[2]};
      const double dist = dot(rel, pl.normal) / len;
      if (dist < r * (1.0 - kMaxInitialOverlapFraction) - tol) {
        at.fail(where, key,
                fmt::format("{}: a particle centre at {} is {:.6g} m from the wall "
                            "walls.planes[{}] (point {}, normal {}) on its inner side, less "
                            "than the radius {:.6g} m: the particle is behind or inside the "
                            "wall; move the region to the side the normal points to",
                            setName(p, i), fmtVec(x), dist, k, fmtVec(pl.point), fmtVec(pl.normal),
                            r));
      }
    }
  }
  // Inside every cylinder and cone that holds the particles, where its extent reaches them:
  // the centres (explicit, or the corners of the region of centres cut to the wall's extent,
  // which bound the convex excess over the radius) at least a radius from the lateral surface.
  for (const auto& w : c.walls.revolved) {
    if (w.side != "inside") {
      continue;
    }
    std::vector<Vec3> centres = p.positions;
    if (centres.empty()) {
      Bounds box;
      for (std::size_t d = 0; d < 3; ++d) {
        box.lo[d] = std::min(p.regionMin[d] + r, p.regionMax[d] - r);
        box.hi[d] = std::max(p.regionMax[d] - r, p.regionMin[d] + r);
      }
      centres = cornersWithinExtent(box, w);
    }
    for (const auto& x : centres) {
      const std::optional<double> clear = insideClearance(w, x);
      if (clear && *clear < r * (1.0 - kMaxInitialOverlapFraction) - tol) {
        at.fail(where, key,
                fmt::format("{}: a particle centre at {} (axial coordinate {:.6g} m) is {:.6g} m "
                            "inside the {} {}, less than the particle radius {:.6g} m: the "
                            "particles would start in or beyond its wall; move the {} towards "
                            "the axis (point {}, axis {}), shrink it, or widen the {}",
                            setName(p, i), fmtVec(x), axialCoordinate(w, x), *clear,
                            w.cone ? "cone" : "cylinder", w.key(), r,
                            p.positions.empty() ? "region" : "positions", fmtVec(w.point),
                            fmtVec(w.axis), w.cone ? "cone" : "cylinder"));
      }
    }
  }
  // Inside every closed mesh wall: the centres (explicit, or the corners of the region).
  for (std::size_t k = 0; k < closed.size(); ++k) {
    if (!closed[k]) {
      continue;
    }
    for (const auto& x : extremeCentres(p)) {
      if (!closed[k]->contains(x)) {
        at.fail(where, key,
                fmt::format(
                    "{}: the particle centre {} lies outside the closed mesh wall "
                    "walls.meshes[{}] ('{}', spanning {}); move the {} inside the "
                    "surface, or check the mesh's position and scale",
                    setName(p, i), fmtVec(x), k, c.walls.meshes[k].name,
                    fmtBox(Box{meshBounds(c.walls.meshes[k]).lo, meshBounds(c.walls.meshes[k]).hi}),
                    p.positions.empty() ? "region" : "positions"));
      }
    }
  }
}

/// Room for the particles of set i, and its temperature.
void checkSetRoom(Consistency& ck, std::size_t i) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  const auto& p = c.particles[i];
  const std::string idx = std::to_string(i);
  // Room for the particles.
  if (p.positions.empty()) {
    double volume = 1.0;
    long long sites = 1;
    for (int d = 0; d < 3; ++d) {
      const double len = p.regionMax[d] - p.regionMin[d];
      volume *= len;
      sites *= static_cast<long long>(std::floor(len / p.diameter + 1e-9));
    }
    const double solid = double(p.count) * kPi * p.diameter * p.diameter * p.diameter / 6.0;
    if (p.packing == "lattice" && sites < static_cast<long long>(p.count)) {
      at.fail({"particles", idx, "count"}, fmt::format("particles[{}].count", i),
              fmt::format("{}: the region holds {} lattice sites of diameter {:.6g} m, but "
                          "count = {}; enlarge the region or reduce the count",
                          setName(p, i), sites, p.diameter, p.count));
    }
    if (p.packing == "random") {
      const double phi = volume > 0.0 ? solid / volume : 1.0;
      if (phi > kMaxRandomSolidFraction) {
        at.fail({"particles", idx, "count"}, fmt::format("particles[{}].count", i),
                fmt::format("{}: {} particles of diameter {:.6g} m fill {:.3g} of the region's "
                            "volume, more than a random packing reaches ({:.2g}); enlarge the "
                            "region or reduce the count",
                            setName(p, i), p.count, p.diameter, phi, kMaxRandomSolidFraction));
      }
      if (phi > kWarnRandomSolidFraction) {
        ck.warnings.push_back(at.warning(
            {"particles", idx, "count"}, fmt::format("particles[{}].count", i),
            fmt::format("{}: solid fraction {:.3g} of the region (above {:.2g}): random "
                        "placement without overlap may not find room; use packing: lattice or "
                        "a larger region",
                        setName(p, i), phi, kWarnRandomSolidFraction)));
      }
    }
  }
  if (at.root()["particles"] && at.root()["particles"][i] &&
      at.root()["particles"][i]["temperature"]) {
    warnTemperature(at, ck.warnings, {"particles", idx, "temperature"},
                    fmt::format("particles[{}].temperature", i), p.temperature);
  }
}

void checkParticleSets(Consistency& ck) {
  for (std::size_t i = 0; i < ck.c.particles.size(); ++i) {
    checkSetInWalls(ck, i);
    checkSetRoom(ck, i);
  }
}

void checkOverlaps(Consistency& ck) {
  checkExplicitOverlaps(ck.c, ck.at);
}

/// Placed sets whose regions intersect are warned about (their particles may overlap), at most
/// kMaxIntersectionWarnings pairs and one line for the rest; pairs are found by sorting the
/// boxes along x (sweep and prune), not by testing every pair. Two placed sets with the same
/// placement (packing, region, count, diameter, and seed for random) would put their particles
/// on the same centres — coincident spheres, NaN at the first step: refused.
void warnIntersectingSets(Consistency& ck) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  const double tol = ck.tol;
  // Every set (a placed set may also meet one of explicit positions; two explicit sets are
  // checkOverlaps' business).
  std::vector<std::size_t> placed(c.particles.size());
  std::iota(placed.begin(), placed.end(), std::size_t(0));
  std::vector<Box> box(c.particles.size());
  for (std::size_t i : placed) {
    box[i] = occupied(c.particles[i]);
  }
  std::sort(placed.begin(), placed.end(),
            [&](std::size_t a, std::size_t b) { return box[a].lo[0] < box[b].lo[0]; });
  std::size_t pairs = 0;
  for (std::size_t u = 0; u < placed.size(); ++u) {
    for (std::size_t v = u + 1; v < placed.size(); ++v) {
      const std::size_t i = std::min(placed[u], placed[v]), j = std::max(placed[u], placed[v]);
      const Box &a = box[i], &b = box[j];
      if (box[placed[v]].lo[0] >= box[placed[u]].hi[0] - tol) {
        break; // sorted by lo.x: no later box reaches this one
      }
      const ParticleSetConfig &p = c.particles[i], &q = c.particles[j];
      bool meet = p.positions.empty() || q.positions.empty();
      for (int d = 0; d < 3; ++d) {
        meet = meet && std::min(a.hi[d], b.hi[d]) - std::max(a.lo[d], b.lo[d]) > tol;
      }
      if (!meet) {
        continue;
      }
      if (p.positions.empty() && q.positions.empty() && p.packing == q.packing &&
          p.regionMin == q.regionMin && p.regionMax == q.regionMax && p.count == q.count &&
          p.diameter == q.diameter && (p.packing != "random" || p.seed == q.seed)) {
        at.fail({"particles", std::to_string(j)}, fmt::format("particles[{}]", j),
                fmt::format("{} has the placement of {} ({} packing of {} particles of {} m in "
                            "{}{}): their particles would sit on the same centres; change one "
                            "region{}, or merge the sets",
                            setName(q, j), setName(p, i), p.packing, p.count, p.diameter, fmtBox(a),
                            p.packing == "random" ? ", same seed" : "",
                            p.packing == "random" ? " or seed" : ""));
      }
      if (++pairs <= kMaxIntersectionWarnings) {
        ck.warnings.push_back(
            at.warning({"particles", std::to_string(j)}, fmt::format("particles[{}]", j),
                       fmt::format("{} occupies {}, which intersects {} of {}: sets are placed "
                                   "independently, so their particles may overlap",
                                   setName(q, j), fmtBox(b), fmtBox(a), setName(p, i))));
      }
    }
  }
  if (pairs > kMaxIntersectionWarnings) {
    ck.warnings.push_back(at.warning(
        {"particles"}, "particles",
        fmt::format("{} more pairs of placed sets intersect (the first {} are listed above)",
                    pairs - kMaxIntersectionWarnings, kMaxIntersectionWarnings)));
  }
}

void warnTemperatures(Consistency& ck) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  if (at.root()["gas_properties"] && at.root()["gas_properties"]["temperature"]) {
    warnTemperature(at, ck.warnings, {"gas_properties", "temperature"},
                    "gas_properties.temperature", c.gasProperties.temperature);
  }
  if (c.walls.temperature > 0.0) {
    warnTemperature(at, ck.warnings, {"walls", "temperature"}, "walls.temperature",
                    c.walls.temperature);
  }
}

/// `walls.material` is the conduction material of fixed-temperature walls, not a contact material
/// (docs/case-schema.md "walls"): with adiabatic walls and more than one material it is easily
/// taken for the walls' contact material, which it is not.
void warnWallMaterial(Consistency& ck) {
  const CaseConfig& c = ck.c;
  const YAML::Node walls = ck.at.root()["walls"];
  if (c.walls.temperature > 0.0 || c.materials.size() < 2 || !walls || !walls.IsMap() ||
      !walls["material"]) {
    return;
  }
  ck.warnings.push_back(ck.at.warning(
      {"walls", "material"}, "walls.material",
      fmt::format("'{}' has no effect here: walls.material is the conduction material of "
                  "fixed-temperature walls, and these walls are adiabatic; it does not set how "
                  "particles touch the walls. For that give each wall its own contact material "
                  "(walls.box.material, walls.planes[i].material, ...)",
                  c.walls.material)));
}

/// The largest value of a scalar field of the prescribed gas section (a number or a time table
/// {table: [[t, v], ...]}, at the domain level and in its regions); nullopt when not given.
std::optional<double> largestPrescribed(const YAML::Node& gas, const char* key) {
  std::optional<double> best;
  for (const PrescribedValue& v : prescribedValues(gas, key)) {
    best = std::max(best.value_or(-HUGE_VAL), v.value);
  }
  return best;
}

/// The largest gas speed the prescribed gas section gives (u_g literals and table rows).
double largestPrescribedSpeed(const YAML::Node& gas) {
  double best = 0.0;
  auto speed = [&](const YAML::Node& v) {
    try {
      if (v.IsSequence() && v.size() == 3) {
        const Vec3 u{v[0].as<double>(), v[1].as<double>(), v[2].as<double>()};
        best = std::max(best, std::sqrt(dot(u, u)));
      }
    } catch (const YAML::Exception&) {
    }
  };
  auto take = [&](const YAML::Node& n) {
    if (n && n.IsSequence()) {
      speed(n);
    } else if (n && n.IsMap() && n["table"] && n["table"].IsSequence()) {
      for (const YAML::Node& row : n["table"]) {
        if (row.IsSequence() && row.size() == 2) {
          speed(row[1]);
        }
      }
    }
  };
  if (gas && gas.IsMap()) {
    take(gas["u_g"]);
    if (gas["regions"] && gas["regions"].IsSequence()) {
      for (const YAML::Node& r : gas["regions"]) {
        if (r.IsMap()) {
          take(r["u_g"]);
        }
      }
    }
  }
  return best;
}

/// The shortest particle response time of the Ergun/Gidaspow drag at ε_g = 0.4 (ε_s = 0.6):
/// K_sl = 150 ε_s² μ_g/(ε_g d²) + 1.75 ε_s ρ_g s/d, τ_p = ε_s ρ_p/K_sl, at the slip s = the larger
/// of the prescribed gas speed and the slip at which the drag carries the bed's buoyant weight,
/// K_sl(s) s = ε_s (ρ_p − ρ_g) |g| (the slip of a fluidized dense bed).
struct ResponseTime {
  double tau = 0.0, slip = 0.0;
};
ResponseTime responseTime(double rhoP, double d, double mu, double rhoG, double g, double uGas) {
  const double es = 0.6, eg = 0.4;
  const double a = 150.0 * es * es * mu / (eg * d * d), b = 1.75 * es * rhoG / d;
  const double c = es * std::max(rhoP - rhoG, 0.0) * g;
  const double sEq = c > 0.0 ? 2.0 * c / (a + std::sqrt(a * a + 4.0 * b * c)) : 0.0;
  const double s = std::max(sEq, uGas);
  return {es * rhoP / (a + b * s), s};
}

void checkStaggeredStep(Consistency& ck) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  // Staggered coupling: the drag and heat sources the gas applies are one step old, so the
  // particles must not relax to the gas within one step (docs/coupling-schemes.md "Stability").
  if (!c.coupling.staggered()) {
    return;
  }
  const bool adaptive = c.dt.kind == DtPolicyConfig::Kind::Courant;
  const double dtMax = adaptive ? c.dt.dtMax : c.dt.dt;
  const std::vector<std::string> dtPath =
      adaptive ? std::vector<std::string>{"time", "adaptive", "dt_max"}
               : std::vector<std::string>{"time", "dt"};
  const std::string dtKey = adaptive ? "time.adaptive.dt_max" : "time.dt";
  // The gas the particles see: the prescribed gas's largest μ_g, ρ_g and speed where the case
  // prescribes one, else gas_properties.
  const YAML::Node gas = at.root()[c.cfd.gasKey];
  const double mu = largestPrescribed(gas, "mu_g").value_or(c.gasProperties.viscosity);
  const double rhoG = largestPrescribed(gas, "rho_g").value_or(c.gasProperties.density);
  const double uGas = largestPrescribedSpeed(gas);
  const double g = std::sqrt(dot(c.gravity, c.gravity));
  const double removal = c.chemistry.removalFraction.value_or(0.1);
  for (std::size_t i = 0; i < c.particles.size(); ++i) {
    const ParticleSetConfig& p = c.particles[i];
    double rho = p.density;
    if (!(rho > 0.0)) {
      const int m = materialIndex(c, p.material);
      rho = m >= 0 ? c.materials[std::size_t(m)].density : 0.0;
    }
    const ResponseTime r = responseTime(rho, p.diameter, mu, rhoG, g, uGas);
    if (!(r.tau > 0.0)) {
      continue;
    }
    const std::string what = fmt::format(
        "Δt_CFD = {:.4g} s with coupling.scheme staggered and particle set {} (d_p = {:.4g} m, "
        "ρ_p = {:.4g} kg/m³; gas μ_g = {:.4g} Pa s, ρ_g = {:.4g} kg/m³): the particle response "
        "time of the Ergun drag at ε_g = 0.4 and slip {:.3g} m/s, τ_p = ε_s ρ_p/K_sl = {:.4g} s",
        dtMax, setName(p, i), p.diameter, rho, mu, rhoG, r.slip, r.tau);
    if (dtMax > r.tau) {
      at.fail(dtPath, dtKey,
              what + " is shorter than one step: the gas would apply drag and heat sources of "
                     "particles that have since relaxed (lagged sources oscillate). Use Δt_CFD "
                     "<= τ_p (better <= 0.1 τ_p) or coupling.scheme sequential");
    }
    if (dtMax > 0.1 * r.tau) {
      ck.warnings.push_back(at.warning(
          dtPath, dtKey,
          what + fmt::format(": Δt_CFD/τ_p = {:.2g} > 0.1, the one-step lag of the drag and "
                             "heat sources is more than 10 % of a particle relaxation",
                             dtMax / r.tau)));
      continue;
    }
    // A set that reacts shrinks down to its removal diameter: its smallest particles relax
    // faster (few of them, carrying a small share of the exchange: a warning).
    if (!c.usesChemistry() || p.composition.empty()) {
      continue;
    }
    const double dSmall = removal * p.diameter;
    const ResponseTime rs = responseTime(rho, dSmall, mu, rhoG, g, uGas);
    if (dtMax > 0.1 * rs.tau) {
      ck.warnings.push_back(at.warning(
          dtPath, dtKey,
          fmt::format("Δt_CFD = {:.4g} s with coupling.scheme staggered: particle set {} shrinks "
                      "by reaction down to its removal diameter {:.4g} m (chemistry."
                      "removal_fraction {:.3g}), where τ_p = {:.4g} s (slip {:.3g} m/s) and "
                      "Δt_CFD/τ_p = {:.2g} > 0.1; the lag of its smallest particles' drag and "
                      "heat is more than 10 % of their relaxation",
                      dtMax, setName(p, i), dSmall, removal, rs.tau, rs.slip, dtMax / rs.tau)));
    }
  }
}

/// model constant with a gas the CFD solves, far from the particles' or walls' temperature: the
/// density, viscosity and heat capacity would follow the temperature (ideal_gas).
void warnConstantHotGas(Consistency& ck) {
  const CaseConfig& c = ck.c;
  if (c.gasProperties.idealGas() || !participant(c.cfd.participant).solvesGas) {
    return;
  }
  const double dT = largestGasTemperatureDifference(c);
  if (dT > kConstantGasWarnDeltaT) {
    ck.warnings.push_back(ck.at.warning(
        {"gas_properties", "model"}, "gas_properties.model",
        fmt::format("constant gas properties with particles or walls up to {:.4g} K from the gas "
                    "(more than {:.0f} K): the gas density, viscosity and heat capacity change "
                    "with its temperature; model: ideal_gas computes them",
                    dT, kConstantGasWarnDeltaT)));
  }
}

void warnPrescribedGasTemperature(Consistency& ck) {
  const CaseConfig& c = ck.c;
  const Locator& at = ck.at;
  // The prescribed gas temperature (coredem-gas's section), when it is a number.
  const YAML::Node gas = at.root()[c.cfd.gasKey];
  if (gas && gas.IsMap() && gas["T_g"] && gas["T_g"].IsScalar()) {
    try {
      warnTemperature(at, ck.warnings, {c.cfd.gasKey, "T_g"}, c.cfd.gasKey + ".T_g",
                      gas["T_g"].as<double>());
    } catch (const YAML::Exception&) {
    }
  }
}

/// Mesh walls much finer than the smallest particle: a sphere touching one has about
/// π ((1.2 R)² − R²) / A of its triangles (mean area A) within its heat reach 1.2 R. The DEM
/// considers the nearest kMaxMeshTouches (kernels/mesh_contact.h: exact on flat and convex
/// parts, whatever the triangle size); more cost wall search time and, in concave corners finer
/// than that, may hide a face.
void warnFineMeshes(Consistency& ck) {
  const CaseConfig& c = ck.c;
  double dMin = std::numeric_limits<double>::infinity();
  for (const auto& p : c.particles) {
    dMin = std::min(dMin, p.diameter);
  }
  if (!std::isfinite(dMin) || dMin <= 0.0) {
    return;
  }
  const double r = 0.5 * dMin;
  constexpr double kConsidered = coredem::dem::kernels::kMaxMeshTouches;
  for (std::size_t k = 0; k < c.walls.meshes.size(); ++k) {
    const MeshWallConfig& m = c.walls.meshes[k];
    const std::size_t nt = m.triangles.size() / 3;
    if (nt == 0) {
      continue;
    }
    double area = 0.0;
    for (std::size_t t = 0; t < nt; ++t) {
      const double* a = &m.vertices[3 * std::size_t(m.triangles[3 * t])];
      const double* b = &m.vertices[3 * std::size_t(m.triangles[3 * t + 1])];
      const double* e = &m.vertices[3 * std::size_t(m.triangles[3 * t + 2])];
      const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const Vec3 v{e[0] - a[0], e[1] - a[1], e[2] - a[2]};
      const Vec3 w{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      area += 0.5 * std::sqrt(dot(w, w));
    }
    const double mean = area / double(nt);
    const double inReach = kPi * (1.44 - 1.0) * r * r / mean;
    if (inReach > kConsidered) {
      ck.warnings.push_back(ck.at.warning(
          {"walls", "meshes", std::to_string(k), m.sourceKey()},
          fmt::format("walls.meshes[{}].{}", k, m.sourceKey()),
          fmt::format("the mesh '{}' has triangles of {:.3g} mm² on average, much smaller than "
                      "the smallest particle (d = {:.3g} mm): about {:.0f} lie within a "
                      "touching particle's reach, of which the nearest 16 are considered. "
                      "Contacts stay exact on flat and convex parts; the wall search costs more, "
                      "and a concave corner meshed finer than that may lose a face: coarsen the "
                      "mesh where it is flat",
                      m.name, mean * 1e6, dMin * 1e3, inReach)));
    }
  }
}

/// The consistency checkers in the order they run (a case with two errors reports the first).
/// What the DEM server and the participants would refuse (preflight_limits.cpp).
void checkServerLimits(Consistency& ck) {
  checkServerLimits(ck.c, ck.at);
}

struct ConsistencyCheck {
  const char* what;
  void (*check)(Consistency&);
};
const ConsistencyCheck kConsistencyChecks[] = {
    {"what the DEM server and the participants would refuse", checkServerLimits},
    {"walls inside the coupling grid", checkWallsInGrid},
    {"mesh walls not much finer than the particles", warnFineMeshes},
    {"particle sets inside the grid and walls, with room", checkParticleSets},
    {"explicit positions do not overlap", checkOverlaps},
    {"placed sets do not intersect", warnIntersectingSets},
    {"temperatures in kelvin", warnTemperatures},
    {"walls.material is not a contact material", warnWallMaterial},
    {"the staggered step against the particle response time", checkStaggeredStep},
    {"the prescribed gas temperature in kelvin", warnPrescribedGasTemperature},
    {"a constant-property gas near the particles' temperature", warnConstantHotGas},
};

} // namespace

std::vector<std::string> checkCaseConsistency(const CaseConfig& c) {
  const Locator at(c);
  Consistency ck{c, at, {}, 0.0, {}, {}};
  double extent = 0.0;
  for (int d = 0; d < 3; ++d) {
    ck.grid.lo[d] = c.grid.origin[d];
    ck.grid.hi[d] = c.grid.origin[d] + c.grid.spacing[d] * double(c.grid.cells[d]);
    extent = std::max(extent, ck.grid.hi[d] - ck.grid.lo[d]);
  }
  ck.tol = 1e-9 * extent;
  for (const ConsistencyCheck& check : kConsistencyChecks) {
    check.check(ck);
  }
  return std::move(ck.warnings);
}

} // namespace coredem::orchestrator
