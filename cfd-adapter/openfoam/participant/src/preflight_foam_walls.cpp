// Pre-flight of the DEM's revolved walls against the OpenFOAM mesh (checkOpenFoamCase): a DEM
// cylinder or cone that holds the particles inside must lie within the CFD mesh's boundary, or
// particles between the DEM wall and a faceted CFD wall sit in cells without fluid.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <coredem/orchestrator/preflight_locator.h>
#include <coredem/participant/foam_patches.h>
#include <coredem/participant/openfoam.h>

namespace fs = std::filesystem;

namespace coredem::orchestrator {
namespace {

using preflight::Locator;

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot3(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Distance along the ray o + t d (t > 0) to the nearest triangle of `s` (Möller–Trumbore);
/// infinity when the ray leaves through no triangle.
double nearestHit(const FoamPatchSurface& s, const Vec3& o, const Vec3& d) {
  double best = std::numeric_limits<double>::infinity();
  const auto vertex = [&](std::int32_t i) {
    return Vec3{s.vertices[3 * i], s.vertices[3 * i + 1], s.vertices[3 * i + 2]};
  };
  for (std::size_t t = 0; t + 2 < s.triangles.size(); t += 3) {
    const Vec3 a = vertex(s.triangles[t]);
    const Vec3 e1 = sub(vertex(s.triangles[t + 1]), a), e2 = sub(vertex(s.triangles[t + 2]), a);
    const Vec3 p = cross(d, e2);
    const double det = dot3(e1, p);
    if (std::abs(det) < 1e-300) {
      continue; // parallel to the triangle
    }
    const Vec3 q = sub(o, a);
    const double u = dot3(q, p) / det;
    const Vec3 r = cross(q, e1);
    const double v = dot3(d, r) / det;
    const double dist = dot3(e2, r) / det;
    constexpr double kEdge = 1e-9; // a ray through an edge hits either neighbour
    if (u >= -kEdge && v >= -kEdge && u + v <= 1.0 + kEdge && dist > 0.0) {
      best = std::min(best, dist);
    }
  }
  return best;
}

} // namespace

void checkRevolvedWallsInsideFoamMesh(const CaseConfig& c, const Locator& at, const fs::path& dir) {
  if (c.walls.revolved.empty() || !fs::exists(dir / "constant" / "polyMesh" / "faces")) {
    return; // no such walls, or the mesh is made at the run (coredemFoam checks its cells)
  }
  FoamPatchSurface surface;
  try {
    std::vector<std::string> names;
    for (const FoamPatch& p : readFoamBoundary(dir)) {
      if ((p.type == "wall" || p.type == "patch") && p.nFaces > 0) {
        names.push_back(p.name);
      }
    }
    surface = readFoamPatches(dir, names);
  } catch (const FoamMeshError&) {
    return; // a mesh this reader cannot read (binary, ...): the other checks name it
  }
  // Rays from the axis at kAngles angles and kHeights heights over [from, to] (not at the ends,
  // where a cap or the next wall meets it): the mesh's boundary must be at least the wall's
  // radius away. Between the sampled angles a faceted wall comes closer by at most a factor
  // cos(π/kAngles) (1.2e-3), inside the tolerance below.
  constexpr int kAngles = 64, kHeights = 9;
  constexpr double kTol = 2e-3;
  for (const RevolvedWallConfig& w : c.walls.revolved) {
    if (!w.finite || w.side != "inside") {
      continue;
    }
    const Vec3 n = w.axis;
    const Vec3 helper = std::abs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    Vec3 e1 = cross(n, helper);
    const double l1 = std::sqrt(dot3(e1, e1));
    e1 = {e1[0] / l1, e1[1] / l1, e1[2] / l1};
    const Vec3 e2 = cross(n, e1);
    double worst = std::numeric_limits<double>::infinity(), worstRadius = 0, worstAt = 0;
    for (int k = 0; k < kHeights; ++k) {
      const double a = w.from + (w.to - w.from) * (k + 0.5) / kHeights;
      const double radius = w.radiusFrom + (w.radiusTo - w.radiusFrom) * (k + 0.5) / kHeights;
      const Vec3 o{w.point[0] + a * n[0], w.point[1] + a * n[1], w.point[2] + a * n[2]};
      for (int j = 0; j < kAngles; ++j) {
        const double th = 2.0 * M_PI * j / kAngles;
        const Vec3 d{std::cos(th) * e1[0] + std::sin(th) * e2[0],
                     std::cos(th) * e1[1] + std::sin(th) * e2[1],
                     std::cos(th) * e1[2] + std::sin(th) * e2[2]};
        const double hit = nearestHit(surface, o, d);
        if (std::isfinite(hit) && hit / radius < worst) {
          worst = hit / radius;
          worstRadius = radius;
          worstAt = a;
        }
      }
    }
    if (worst < 1.0 - kTol) {
      const std::string key = w.key();
      at.fail({"walls", w.cone ? "cones" : "cylinders",
               std::to_string(w.index)},
              key,
              fmt::format("radius {:.6g} m at {:.6g} m along the axis, but the CFD mesh's boundary "
                          "({}) is {:.6g} m from the axis there: the DEM wall lies outside the "
                          "fluid (a CFD wall of n flat faces has the inscribed radius R cos(π/n)); "
                          "use a radius of at most the inscribed one",
                          worstRadius, worstAt, (dir / "constant" / "polyMesh").string(),
                          worst * worstRadius));
    }
  }
}

} // namespace coredem::orchestrator
