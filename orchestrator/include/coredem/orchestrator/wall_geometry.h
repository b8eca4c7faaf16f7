#pragma once
/// @file
/// Geometry of the case's cylinder, cone and mesh walls for the pre-flight checks (preflight.h):
/// bounding boxes, the clearance of a particle centre inside a cylinder or cone, and whether a
/// point lies inside a closed triangle surface. Lengths in m.

#include <cstdint>
#include <optional>
#include <vector>

#include <coredem/orchestrator/case_config.h>

namespace coredem::orchestrator {

/// An axis-aligned box lo..hi (m); a component may be ±infinity (an infinite cylinder).
struct Bounds {
  Vec3 lo{}, hi{};
};

/// The bounding box of a cylinder's or cone's surface (its end discs). An infinite cylinder is
/// unbounded along every coordinate axis its axis is not perpendicular to.
Bounds wallBounds(const RevolvedWallConfig& w);

/// The bounding box of a mesh wall's vertices.
Bounds meshBounds(const MeshWallConfig& m);

/// The axial coordinate of `x` (m along the unit axis from the wall's point).
double axialCoordinate(const RevolvedWallConfig& w, const Vec3& x);

/// The distance (m) from `x` to the lateral surface of a cylinder or cone, perpendicular to the
/// surface, positive on the axis side (inside); nullopt when x's axial coordinate lies outside the
/// wall's extent [from, to] (the surface does not reach it there).
std::optional<double> insideClearance(const RevolvedWallConfig& w, const Vec3& x);

/// The corners of `box` cut to the wall's axial extent: the corners inside the slab
/// from <= t <= to and the points where the box's edges cross its two planes (the vertices of box
/// ∩ slab). A function convex in x (the radial excess over a cylinder's or cone's radius) is
/// largest at one of them. Every corner for an infinite cylinder; none when the box misses the
/// slab.
std::vector<Vec3> cornersWithinExtent(const Bounds& box, const RevolvedWallConfig& w);

/// A closed, consistently oriented triangle surface (checkMesh with requireClosed) and the test
/// whether a point lies inside it: the parity of the crossings of a ray along +x, the triangles
/// found through a grid over (y, z); a ray through an edge or a vertex is resolved by a symbolic
/// perturbation of the point (each crossing counted once). The vectors must outlive the object.
class ClosedSurface {
public:
  ClosedSurface(const std::vector<double>& vertices, const std::vector<std::int32_t>& triangles);
  bool contains(const Vec3& x) const;

private:
  const std::vector<double>& _vertices;
  const std::vector<std::int32_t>& _triangles;
  double _lo[2] = {0, 0}, _hi[2] = {0, 0}, _cell[2] = {1, 1};
  int _cells[2] = {1, 1};
  std::vector<std::int32_t> _start; ///< CSR: triangles of cell c at _items[_start[c].._start[c+1])
  std::vector<std::int32_t> _items;
  int cellOf(double v, int axis) const;
};

} // namespace coredem::orchestrator
