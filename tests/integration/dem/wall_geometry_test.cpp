// Reactor walls (kernels/wall_contact.h, kernels/mesh_contact.h, wall_lists.h): a triangulated
// plane behaves as the analytic plane wherever a sphere hits or rolls (faces, edges, vertices,
// coarse and fine triangles), and a packed bed in a cylinder (analytic and STL) rests on its
// walls with exactly its weight. Whole DemSystem runs on the cpu backend.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/dem/triangle_mesh.h"
#include "dem_test_util.h"

using namespace coredem::dem;
using namespace coredem::dem::testing;

namespace {

MeshWall meshWall(const TriangleMesh& m) {
  return MeshWall{m.name, m.vertices, m.triangles};
}

/// The floor z = 0 as an analytic plane (quads = 0) or as a rectangle of quads × quads squares
/// of edge `side` (two triangles each, diagonals from (i, j) to (i + 1, j + 1)) with a grid
/// node at the origin.
void addFloor(DemConfig& c, int quads, double side) {
  if (quads == 0) {
    c.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
    return;
  }
  const double half = 0.5 * quads * side;
  c.meshes.push_back(meshWall(
      meshRectangle({-half, -half, 0}, {quads * side, 0, 0}, {0, quads * side, 0}, quads, quads)));
}

struct Bounce {
  double restitution;
  int contactSteps;
};

/// A 1 mm glass sphere (k_n = 1000 N/m, e_n = 0.97, no gravity) falling at v onto the floor at
/// (x, y); the first overlap at `phase` of a step.
Bounce bounce(int quads, double side, double x, double y, double phase = 0.3) {
  DemConfig c;
  c.gravity = {0, 0, 0};
  addFloor(c, quads, side);
  const double r = 0.5e-3, v = 0.5;
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.diameter = 2 * r;
  c.particleSets.push_back(s);
  DemSystem probe(
      [&] {
        DemConfig p = c;
        p.particleSets[0].positions = {x, y, 1.0};
        return p;
      }(),
      BackendKind::Cpu, 1);
  const double dt = probe.dtDemMax();
  c.particleSets[0].positions = {x, y, r + v * dt * (5 + phase)};
  c.particleSets[0].velocities = {0, 0, -v};
  DemSystem sys(c, BackendKind::Cpu, 1);
  Bounce b{0.0, 0};
  bool started = false;
  for (int k = 0; k < 400; ++k) {
    sys.advance(dt, 1);
    if (sys.contactCount() > 0) {
      EXPECT_EQ(sys.contactCount(), 1u) << "one contact with the floor, not " << sys.contactCount();
      ++b.contactSteps;
      started = true;
    } else if (started) {
      break;
    }
  }
  const ParticleData p = sys.particles();
  b.restitution = p.velocity[2] / v;
  EXPECT_NEAR(p.velocity[0], 0.0, 1e-12) << "a head-on hit pushes straight back";
  EXPECT_NEAR(p.velocity[1], 0.0, 1e-12);
  return b;
}

} // namespace

// Head-on: the triangulated floor gives the analytic plane's restitution (to 1e-3) and contact
// duration (to 2 Δt_DEM) wherever the sphere hits: inside a face, on an axis-parallel edge, on
// a diagonal edge, on a vertex (shared by six triangles), with triangles larger (4 mm) and
// smaller (0.25 mm) than the sphere's contact patch.
TEST(MeshWall, HeadOnOnATriangulatedPlaneMatchesThePlaneWall) {
  const Bounce plane = bounce(0, 0.0, 0.0, 0.0);
  EXPECT_NEAR(plane.restitution, 0.97, 0.01); // the LSD law itself (docs/physics.md §2.1)
  struct Where {
    const char* name;
    double fx, fy; // in units of the quad edge, from a grid node
  };
  const Where where[] = {{"face", 0.71, 0.23},
                         {"axis-parallel edge", 0.5, 0.0},
                         {"diagonal edge", 0.5, 0.5},
                         {"vertex", 0.0, 0.0}};
  for (const auto& [quads, side] : {std::pair{4, 4e-3}, std::pair{32, 0.25e-3}}) {
    for (const Where& w : where) {
      const Bounce m = bounce(quads, side, w.fx * side, w.fy * side);
      EXPECT_NEAR(m.restitution, plane.restitution, 1e-3)
          << w.name << ", triangles of " << side << " m";
      EXPECT_LE(std::abs(m.contactSteps - plane.contactSteps), 2)
          << w.name << ", triangles of " << side << " m";
    }
  }
}

// Head-on on triangles much finer than the contact patch (0.05 mm against a 1 mm sphere: about
// 60 triangles within reach of its centre, more than kMaxMeshTouches): the touches kept are the
// nearest, so the floor still gives the analytic plane's restitution (to 1e-3), its contact
// duration (to 2 Δt_DEM) and one contact, on a face, an edge and a vertex.
TEST(MeshWall, HeadOnOnTrianglesFinerThanTheContactKeepsTheNearestTouches) {
  const Bounce plane = bounce(0, 0.0, 0.0, 0.0);
  const double side = 0.05e-3;
  const std::pair<const char*, std::pair<double, double>> where[] = {
      {"face", {0.71, 0.23}}, {"diagonal edge", {0.5, 0.5}}, {"vertex", {0.0, 0.0}}};
  for (const auto& [name, f] : where) {
    const Bounce m = bounce(40, side, f.first * side, f.second * side);
    EXPECT_NEAR(m.restitution, plane.restitution, 1e-3) << name;
    EXPECT_LE(std::abs(m.contactSteps - plane.contactSteps), 2) << name;
  }
}

namespace {
struct Roll {
  double v;         ///< final speed (m/s)
  double maxDevFz;  ///< largest |F_z − m g| over the run after the first 5 ms (N)
  double weight;    ///< m g (N)
  std::size_t most; ///< most contacts at once
};

/// A sphere launched sliding (ω = 0) at v0 along +x at height y0 on the floor (μ = 0.3),
/// sub-step by sub-step for 0.1 s (docs/physics.md §2.1: rolling at 5/7 v0 after 39 ms).
Roll roll(int quads, double side, double y0) {
  DemConfig c;
  c.materials[0].mu = 0.3;
  const double r = 0.5e-3, m = 2500 * 4.0 / 3.0 * kPi * r * r * r, v0 = 0.4;
  if (quads == 0) {
    c.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
  } else {
    // From x = −5 mm to 45 mm, y in [−5, 5] mm.
    const int nx = static_cast<int>(std::lround(50e-3 / side));
    c.meshes.push_back(meshWall(meshRectangle({-5e-3, -quads * side / 2, 0}, {nx * side, 0, 0},
                                              {0, quads * side, 0}, nx, quads)));
  }
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {0, y0, r - m * 9.81 / 1000.0}; // resting overlap m g / k_n
  s.velocities = {v0, 0, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const double dt = sys.dtDemMax();
  const int steps = static_cast<int>(0.1 / dt);
  Roll out{0.0, 0.0, m * 9.81, 0};
  for (int k = 0; k < steps; ++k) {
    sys.advance(dt, 1);
    out.most = std::max(out.most, sys.contactCount());
    if (k * dt > 5e-3)
      out.maxDevFz = std::max(out.maxDevFz, std::abs(sys.wallForce()[2] - out.weight));
  }
  out.v = sys.particles().velocity[0];
  return out;
}
} // namespace

// Rolling across shared edges: a sphere launched sliding on a triangulated floor ends rolling
// at 5/7 v0 (to 1 %) as on the analytic plane, with one contact at a time and no force spike:
// the normal force stays as close to the weight as on the plane (within 1 % of m g more), on a
// path along a grid line (through every vertex on it) and one across faces and edges, with
// triangles of 1 mm and of 0.2 mm (finer than the contact patch, ≈ 0.1 mm).
TEST(MeshWall, RollingAcrossEdgesKeepsFiveSeventhsWithoutForceSpikes) {
  const double v0 = 0.4;
  const Roll plane = roll(0, 0.0, 0.0);
  EXPECT_NEAR(plane.v, 5.0 / 7.0 * v0, 0.01 * 5.0 / 7.0 * v0);
  for (const auto& [quads, side] : {std::pair{10, 1e-3}, std::pair{20, 0.2e-3}}) {
    for (double y0 : {0.0, 0.37 * side}) {
      const Roll m = roll(quads, side, y0);
      const std::string what =
          "triangles of " + std::to_string(side) + " m, path y = " + std::to_string(y0);
      EXPECT_NEAR(m.v, 5.0 / 7.0 * v0, 0.01 * 5.0 / 7.0 * v0) << what;
      EXPECT_NEAR(m.v, plane.v, 1e-3 * plane.v) << what;
      EXPECT_EQ(m.most, 1u) << what;
      EXPECT_LE(m.maxDevFz, plane.maxDevFz + 0.01 * m.weight) << what;
    }
  }
}

namespace {
/// x-velocity history of a sphere resting on the floor (g = 9.81, μ = 2: it sticks) pushed at
/// 1 mm/s along x from 0.2 µm before the edge x = 0 of the triangulated floor (or the plane):
/// the tangential spring oscillates (period 0.2 ms) while the sphere rolls across the edge.
std::vector<double> stickAcrossEdge(bool mesh) {
  DemConfig c;
  c.materials[0].mu = 2.0;
  const double r = 0.5e-3, m = 2500 * 4.0 / 3.0 * kPi * r * r * r;
  if (mesh)
    c.meshes.push_back(
        meshWall(meshRectangle({-2e-3, -2e-3, 0}, {4e-3, 0, 0}, {0, 4e-3, 0}, 2, 2)));
  else
    c.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1}));
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {-2e-7, 0.3e-3, r - m * 9.81 / 1000.0};
  s.velocities = {1e-3, 0, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const double dt = sys.dtDemMax();
  std::vector<double> v;
  for (int k = 0; k < static_cast<int>(2e-3 / dt); ++k) {
    sys.advance(dt, 1);
    v.push_back(sys.particles().velocity[0]);
  }
  return v;
}
} // namespace

// Tangential history of a wall contact carries across a triangle edge: a sphere sticking on
// the floor (its tangential spring loaded, oscillating) rolls across an edge of the triangulated
// floor exactly as on the plane (velocity to 1e-6 of its amplitude at every step); a history
// restarted at the edge would jolt it.
TEST(MeshWall, TangentialHistoryCarriesAcrossAnEdge) {
  const std::vector<double> plane = stickAcrossEdge(false), mesh = stickAcrossEdge(true);
  ASSERT_EQ(plane.size(), mesh.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < plane.size(); ++k)
    worst = std::max(worst, std::abs(mesh[k] - plane[k]));
  EXPECT_LT(worst, 1e-6 * 1e-3);
}

namespace {
/// Two meshes as one, their vertices at the same point (to 1e-12 m) welded into one vertex.
MeshWall weldedMeshes(const TriangleMesh& a, const TriangleMesh& b) {
  MeshWall w{"corner", {}, {}};
  std::vector<std::int32_t> map;
  for (const TriangleMesh* m : {&a, &b}) {
    map.assign(m->vertexCount(), -1);
    for (std::size_t k = 0; k < m->vertexCount(); ++k) {
      for (std::size_t j = 0; j < w.vertices.size() / 3 && map[k] < 0; ++j) {
        double d = 0.0;
        for (int c = 0; c < 3; ++c)
          d = std::max(d, std::abs(w.vertices[3 * j + c] - m->vertices[3 * k + c]));
        if (d < 1e-12)
          map[k] = static_cast<std::int32_t>(j);
      }
      if (map[k] < 0) {
        map[k] = static_cast<std::int32_t>(w.vertices.size() / 3);
        w.vertices.insert(w.vertices.end(), m->vertices.begin() + 3 * k,
                          m->vertices.begin() + 3 * k + 3);
      }
    }
    for (std::int32_t v : m->triangles)
      w.triangles.push_back(map[v]);
  }
  return w;
}

/// Velocity and angular velocity, every sub-step, of a sphere resting on the floor z = 0 (1 mm
/// triangles, g = 9.81, μ = 0.3) launched sliding at 0.1 m/s along x and y into a side wall at
/// x = 1 mm facing −x: the side wall made of triangles welded to the floor's at the corner
/// edge (sideMesh), or the analytic plane.
std::vector<double> slideIntoCorner(bool sideMesh) {
  DemConfig c;
  c.materials[0].mu = 0.3;
  const double r = 0.5e-3, m = 2500 * 4.0 / 3.0 * kPi * r * r * r;
  const TriangleMesh floor = meshRectangle({-4e-3, -3e-3, 0}, {5e-3, 0, 0}, {0, 6e-3, 0}, 5, 6);
  const TriangleMesh side = meshRectangle({1e-3, -3e-3, 0}, {0, 0, 2e-3}, {0, 6e-3, 0}, 2, 6);
  if (sideMesh) {
    c.meshes.push_back(weldedMeshes(floor, side));
  } else {
    c.meshes.push_back(meshWall(floor));
    c.walls.push_back(Wall::plane({1e-3, 0, 0}, {-1, 0, 0}));
  }
  ParticleSet s;
  s.packing = Packing::Explicit;
  s.positions = {0.3e-3, -0.2e-3, r - m * 9.81 / 1000.0};
  s.velocities = {0.1, 0.1, 0};
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const double dt = sys.dtDemMax();
  std::vector<double> out;
  for (int k = 0; k < static_cast<int>(5e-3 / dt); ++k) {
    sys.advance(dt, 1);
    const ParticleData p = sys.particles();
    out.insert(out.end(), p.velocity.begin(), p.velocity.end());
    for (double w : p.angularVelocity)
      out.push_back(w * r);
  }
  return out;
}
} // namespace

// Tangential history is not handed to a touch of another face: a sphere sliding on a
// triangulated floor (its tangential spring loaded to μ|f_n|/k_t along the slide, 45° to the
// wall) into the side wall of a 90° corner, the side made of triangles sharing the corner's
// vertices with the floor: the side wall's new touch starts without tangential spring, as the
// analytic plane's does, while the floor's touch keeps its own. Velocities (and ω R) at every
// sub-step over 5 ms (the side hit at ≈ 2 ms, sliding on) equal those with the analytic side
// wall to 1e-9 m/s (round-off of the two walls' closest points, 1e-8 of the 0.1 m/s).
TEST(MeshWall, TangentialHistoryIsNotHandedAroundACorner) {
  const std::vector<double> plane = slideIntoCorner(false), mesh = slideIntoCorner(true);
  ASSERT_EQ(plane.size(), mesh.size());
  double worst = 0.0, moved = 0.0;
  for (std::size_t k = 0; k < plane.size(); ++k) {
    worst = std::max(worst, std::abs(mesh[k] - plane[k]));
    moved = std::max(moved, std::abs(plane[k] - plane[k % 6]));
  }
  EXPECT_GT(moved, 0.05) << "the side wall must turn the sphere back";
  EXPECT_LT(worst, 1e-9);
}

namespace {
/// 200 spheres of 1 mm settled in a vertical cylinder (radius 4 mm, floor at z = 0): the
/// analytic cylinder with its bottom cap, or the same as a closed STL surface (64 facets
/// around, so the facets' inner radius is R cos(π/64)).
double settledWallForceOverWeight(bool stl, double* sideForce) {
  DemConfig c;
  c.materials[0].kn = 100; // as PackedBed.SettledBedWallForceEqualsWeight
  c.materials[0].en = 0.3;
  c.materials[0].mu = 0.3;
  const double d = 1e-3, R = 4e-3, H = 40e-3;
  if (stl) {
    c.meshes.push_back(
        meshWall(meshRevolved({0, 0, 0}, {0, 0, 1}, {{{0.0, R}, {H, R}}}, 64, true, true)));
  } else {
    c.walls.push_back(
        Wall::cylinder({0, 0, 0}, {0, 0, 1}, R, 0.0, H, WallSide::Inside, true, true));
  }
  ParticleSet s;
  s.packing = Packing::Random;
  s.count = 200;
  s.diameter = d;
  const double a = 0.99 * R * std::cos(kPi / 64) / std::sqrt(2.0); // a square inside the facets
  s.regionMin = {-a, -a, 0};
  s.regionMax = {a, a, 0.9 * H};
  s.seed = 7;
  c.particleSets.push_back(s);
  DemSystem sys(c, BackendKind::Cpu, 1);
  const double dtCfd = 1e-3;
  const int nSub = TimeHandler::subStepsFor(dtCfd, sys.dtDemMax());
  for (int k = 0; k < 600; ++k)
    sys.advance(dtCfd, nSub);
  const std::size_t n = sys.particles().count;
  const RestingLoad load = restingLoad(sys);
  EXPECT_LT(load.vmax, 1e-3) << "bed not settled" << (stl ? " (STL)" : " (analytic)");
  *sideForce = std::hypot(load.wallForce[0], load.wallForce[1]) / load.weight;
  EXPECT_GT(sys.pairContactCount(), n);
  return load.wallForce[2] / load.weight;
}
} // namespace

// A packed bed in a cylinder: the walls (side and floor together) carry its weight to 0.1 %,
// with no net sideways force, for the analytic cylinder and its STL.
TEST(CylinderWall, PackedBedWallForceEqualsWeightPrimitiveAndStl) {
  for (bool stl : {false, true}) {
    double side = 1.0;
    const double ratio = settledWallForceOverWeight(stl, &side);
    EXPECT_NEAR(ratio, 1.0, 1e-3) << (stl ? "STL cylinder" : "analytic cylinder");
    EXPECT_LT(side, 1e-3) << (stl ? "STL cylinder" : "analytic cylinder");
  }
}

// Discharge of a flat-bottomed cylindrical silo through a central orifice vs Beverloo's
// correlation W = C ρ_b √g (D_o − k d)^2.5 (Beverloo, Leniger & van de Velde 1961; Nedderman
// 1992) with the bed's own measured bulk density ρ_b and the constants fitted for cohesionless
// spheres, C = 0.58 and k = 1.5. 2 mm spheres (k_n = 50 N/m, e_n = 0.5, μ = 0.5 particles and
// walls), silo radius 15 mm (7.5 d), orifice D_o = 12 mm (6 d), filled by settling a loose
// lattice on a closed floor, then the floor replaced by the annular plate of the orifice (an
// analytic cone of zero height would do; the plate here is a frustum 0.1 mm high). W from a
// linear fit of the discharged mass over 0.1–0.35 s after opening (steady flow: the bed, 4000
// spheres ≈ 40 mm, stays higher than the silo is wide).
// Tolerance ±15 % of the fitted W: the published fits for glass spheres scatter by about ±0.03
// in C (±5 %) and ±0.2 in k, which at D_o = 6 d moves (D_o − k d)^2.5 by ±11 %; the rate fit
// over 0.25 s of a 4000-sphere bed adds about ±2 %. (The band of all reported constants, C in
// [0.55, 0.65] and k in [1.3, 2.9], spans a factor 3.3 here and would not see a rate off by 2×.)
TEST(Silo, DischargeRateMatchesBeverloo) {
  const double d = 2e-3, R = 15e-3, Do = 12e-3, H = 0.22, rho = 2500.0, g = 9.81;
  auto base = [&] {
    DemConfig c;
    c.materials[0].kn = 50;
    c.materials[0].en = 0.5;
    c.materials[0].mu = 0.5;
    c.gravity = {0, 0, -g};
    c.walls.push_back(Wall::cylinder({0, 0, 0}, {0, 0, 1}, R, 0.0, H));
    c.walls.push_back(Wall::plane({0, 0, -0.05}, {0, 0, 1})); // catches what fell out
    return c;
  };
  DemConfig fill = base();
  fill.walls.push_back(Wall::plane({0, 0, 0}, {0, 0, 1})); // the closed floor
  ParticleSet s;
  s.packing = Packing::Lattice; // 10 × 10 sites a layer, 40 layers, then it settles
  s.spacing = 1.05 * d;
  s.count = 4000;
  s.diameter = d;
  s.density = rho;
  s.velocityJitter = 0.05;
  const double a = 0.99 * R / std::sqrt(2.0);
  s.regionMin = {-a, -a, 0};
  s.regionMax = {a, a, 0.9 * H};
  s.seed = 3;
  fill.particleSets.push_back(s);
  DemSystem settle(fill, BackendKind::Cpu, 2);
  const double dtCfd = 2e-3;
  const int nSub = TimeHandler::subStepsFor(dtCfd, settle.dtDemMax());
  for (int k = 0; k < 150; ++k) // 0.3 s
    settle.advance(dtCfd, nSub);
  const ParticleData p0 = settle.particles();
  // Bulk density of the settled bed between 1/4 and 3/4 of its height, within R − d.
  double top = 0.0;
  for (std::size_t i = 0; i < p0.count; ++i)
    top = std::max(top, p0.position[3 * i + 2]);
  double slabMass = 0.0;
  const double z0 = 0.25 * top, z1 = 0.75 * top, rs = R - d;
  for (std::size_t i = 0; i < p0.count; ++i) {
    const double x = p0.position[3 * i], y = p0.position[3 * i + 1], z = p0.position[3 * i + 2];
    if (z >= z0 && z < z1 && x * x + y * y < rs * rs)
      slabMass += p0.mass[i];
  }
  const double rhoB = slabMass / (kPi * rs * rs * (z1 - z0));
  EXPECT_GT(top, 2 * R) << "the bed must stay higher than the silo is wide";
  // Open: the floor becomes the annular plate of the orifice.
  DemConfig open = base();
  open.walls.push_back(Wall::cone({0, 0, 0}, {0, 0, 1}, -1e-4, 0.0, 0.5 * Do, R, WallSide::Inside));
  ParticleSet e;
  e.packing = Packing::Explicit;
  e.diameter = d;
  e.density = rho;
  e.positions = p0.position;
  e.velocities = p0.velocity;
  e.angularVelocities = p0.angularVelocity;
  open.particleSets.push_back(e);
  DemSystem run(open, BackendKind::Cpu, 2);
  std::vector<double> t, m;
  for (int k = 1; k <= 175; ++k) { // 0.35 s
    run.advance(dtCfd, nSub);
    if (k * dtCfd < 0.1 - 1e-12)
      continue;
    const ParticleData p = run.particles();
    double out = 0.0;
    for (std::size_t i = 0; i < p.count; ++i)
      if (p.position[3 * i + 2] < -d)
        out += p.mass[i];
    t.push_back(k * dtCfd);
    m.push_back(out);
  }
  // Least-squares slope of m(t).
  double st = 0, sm = 0, stt = 0, stm = 0;
  const double n = static_cast<double>(t.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    st += t[k], sm += m[k], stt += t[k] * t[k], stm += t[k] * m[k];
  const double w = (n * stm - st * sm) / (n * stt - st * st);
  auto beverloo = [&](double c, double k) {
    return c * rhoB * std::sqrt(g) * std::pow(Do - k * d, 2.5);
  };
  const double mid = beverloo(0.58, 1.5);
  const double lo = 0.85 * mid, hi = 1.15 * mid;
  EXPECT_GT(rhoB, 0.5 * rho);
  EXPECT_LT(rhoB, 0.66 * rho);
  EXPECT_GT(w, lo) << "W = " << w << " kg/s, Beverloo " << mid << " (±15 %: " << lo << "–" << hi
                   << "), rho_b = " << rhoB;
  EXPECT_LT(w, hi) << "W = " << w << " kg/s, Beverloo " << mid << " (±15 %: " << lo << "–" << hi
                   << "), rho_b = " << rhoB;
  RecordProperty("discharge_kg_per_s", std::to_string(w));
  RecordProperty("beverloo_kg_per_s", std::to_string(mid));
  std::printf("silo discharge W = %.5g kg/s, Beverloo (C 0.58, k 1.5) %.5g kg/s, ±15 %% %.5g-%.5g, "
              "rho_b = %.1f kg/m3\n",
              w, mid, lo, hi, rhoB);
}
